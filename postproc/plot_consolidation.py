#!/usr/bin/python3
"""Terzaghi consolidation (tests/test_porenet_consolidation.c, PN_SERIES): the excess pore
pressure at mid-height and at the sealed base and the degree of consolidation U against
Terzaghi's series (catalano_pfv.md §2.2), for each run in the CSV (default criterion,
re-triangulation at every step).

usage: plot_consolidation.py series.csv out.png
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def terzaghi_p(zeta, T):
    """p/dsigma at height zeta = z/H above the sealed base, drained at z = H."""
    m = np.arange(200)[:, None]
    M = (2 * m + 1) * np.pi / 2
    return np.sum(2 / M * np.sin(M * (1 - zeta)) * np.exp(-M * M * T), axis=0)


def terzaghi_U(T):
    m = np.arange(200)[:, None]
    M = (2 * m + 1) * np.pi / 2
    return 1 - np.sum(2 / (M * M) * np.exp(-M * M * T), axis=0)


rows = np.genfromtxt(sys.argv[1], delimiter=",", names=True, dtype=None, encoding=None)
fig, ax = plt.subplots(1, 2, figsize=(10, 4))
T = np.linspace(1e-4, 1.05, 400)
zmid, zbase = rows["zmid_over_H"][-1], rows["zbase_over_H"][-1]
ax[0].plot(T, terzaghi_p(zmid, T), "k-", label="Terzaghi, mid-height")
ax[0].plot(T, terzaghi_p(zbase, T), "k--", label="Terzaghi, base")
ax[1].plot(T, terzaghi_U(T), "k-", label="Terzaghi")
styles = {"default": "C0", "every_step": "C1"}
for run in dict.fromkeys(rows["run"]):
    r = rows[rows["run"] == run]
    c = styles.get(run, "C2")
    ax[0].plot(r["Tv"], r["pmid"], color=c, lw=1, label="%s, mid-height" % run)
    ax[0].plot(r["Tv"], r["pbase"], color=c, lw=1, ls="--", label="%s, base" % run)
    ax[1].plot(r["Tv"], r["U"], color=c, lw=1, label=run)
for t in (0.1, 0.2, 0.5, 1.0):
    for a in ax:
        a.axvline(t, color="0.85", lw=0.8, zorder=0)
ax[0].set_xlabel("$T_v = C_v t/L^2$")
ax[0].set_ylabel(r"$p/\Delta\sigma$")
ax[1].set_xlabel("$T_v$")
ax[1].set_ylabel("U = settlement / dry settlement")
ax[0].legend(fontsize=7)
ax[1].legend(fontsize=7)
fig.suptitle("DEM-PFV oedometer against Terzaghi (cases/consolidation)")
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=120)
print("wrote", sys.argv[2])
