#!/usr/bin/python3
"""Terzaghi consolidation (tests/test_porenet_consolidation.c, PN_SERIES): the excess pore
pressure at mid-height and at the sealed base and the degree of consolidation U against
Terzaghi's series (catalano_pfv.md §2.2), for each run in the CSV (default criterion,
re-triangulation at every step).  U is shown raw (settlement from the instant of loading) and
corrected for the initial compression by Taylor's square-root-of-time method (ASTM D2435): the
straight part of U against sqrt(T_v), fitted on TAYLOR_LO <= T_v <= TAYLOR_HI (the window of the
test), extrapolated to t = 0 gives the corrected zero d_s; U_corr = (U - d_s)/(1 - d_s).
The marker layer (the grains below the first layer under the piston, centres at z_m in S0):
its settlement over its dry settlement, U_marker, against the degree of consolidation of the
sub-layer z < z_m of Terzaghi's layer (docs/validation.md), no correction.

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


def terzaghi_U_sub(zeta_m, T):
    """Degree of consolidation of the sub-layer 0 <= z <= zeta_m L (drained face at z = L):
    1 - (1/zeta_m) int_0^zeta_m p/dsigma dzeta."""
    m = np.arange(200)[:, None]
    M = (2 * m + 1) * np.pi / 2
    return 1 - np.sum(2 * np.cos(M * (1 - zeta_m)) / (M * M * zeta_m) * np.exp(-M * M * T), axis=0)


# Taylor's window, as in tests/test_porenet_consolidation.c (TAYLOR_LO, TAYLOR_HI)
TAYLOR_LO, TAYLOR_HI = 0.02, 0.2


def taylor_zero(Tv, U):
    """Least-squares line U = a sqrt(T_v) + d_s on Taylor's window: (a, d_s, largest residual)."""
    m = (Tv >= TAYLOR_LO) & (Tv <= TAYLOR_HI)
    a, ds = np.polyfit(np.sqrt(Tv[m]), U[m], 1)
    return a, ds, np.abs(U[m] - a * np.sqrt(Tv[m]) - ds).max()


rows = np.genfromtxt(sys.argv[1], delimiter=",", names=True, dtype=None, encoding=None)
fig, ax = plt.subplots(1, 3, figsize=(15, 4))
T = np.linspace(1e-4, 1.05, 400)
zmid, zbase, zmark = rows["zmid_over_H"][-1], rows["zbase_over_H"][-1], rows["zeta_marker"][-1]
ax[0].plot(T, terzaghi_p(zmid, T), "k-", label="Terzaghi, mid-height")
ax[0].plot(T, terzaghi_p(zbase, T), "k--", label="Terzaghi, base")
ax[1].plot(T, terzaghi_U(T), "k-", label="Terzaghi")
ax[1].plot(T, terzaghi_U_sub(zmark, T), "k-.", label="Terzaghi, sub-layer $z < z_m$ ($z_m/L$ = %.3f)" % zmark)
styles = {"default": "C0", "every_step": "C1"}
for run in dict.fromkeys(rows["run"]):
    r = rows[rows["run"] == run]
    c = styles.get(run, "C2")
    ax[0].plot(r["Tv"], r["pmid"], color=c, lw=1, label="%s, mid-height" % run)
    ax[0].plot(r["Tv"], r["pbase"], color=c, lw=1, ls="--", label="%s, base" % run)
    a, ds, res = taylor_zero(r["Tv"], r["U"])
    Ucorr = (r["U"] - ds) / (1 - ds)
    ax[1].plot(r["Tv"], r["U"], color=c, lw=1, ls=":", label="%s, raw" % run)
    ax[1].plot(r["Tv"], Ucorr, color=c, lw=1, label="%s, corrected (Taylor)" % run)
    ax[1].plot(r["Tv"], r["U_marker"], color=c, lw=1, ls="-.", label="%s, marker layer" % run)
    ax[2].plot(np.sqrt(r["Tv"]), r["U"], color=c, lw=1, label="%s, raw U" % run)
    x = np.linspace(0, np.sqrt(TAYLOR_HI) * 1.3, 2)
    ax[2].plot(x, a * x + ds, color=c, lw=0.8, ls="--", label="fit on %g <= $T_v$ <= %g: $d_s$ = %.3f" % (TAYLOR_LO, TAYLOR_HI, ds))
    print("%s: Taylor d_s = %.4f dH, slope %.4f (Terzaghi %.4f), largest residual %.4f" % (run, ds, a, 2 / np.sqrt(np.pi), res))
    for t in (0.1, 0.2, 0.5, 1.0):
        if r["Tv"][-1] >= 0.99 * t:  # the series is written every 20 steps
            u, um = np.interp(t, r["Tv"], r["U"]), np.interp(t, r["Tv"], r["U_marker"])
            print("  T_v = %.1f: U = %.4f, U_corr = %.4f, Terzaghi %.4f; U_marker = %.4f, Terzaghi (sub-layer) %.4f"
                  % (t, u, (u - ds) / (1 - ds), terzaghi_U(np.array([t]))[0], um, terzaghi_U_sub(zmark, np.array([t]))[0]))
ax[2].plot(np.sqrt(T), terzaghi_U(T), "k-", label="Terzaghi")
for t in (0.1, 0.2, 0.5, 1.0):
    for a in ax[:2]:
        a.axvline(t, color="0.85", lw=0.8, zorder=0)
ax[0].set_xlabel("$T_v = C_v t/L^2$")
ax[0].set_ylabel(r"$p/\Delta\sigma$")
ax[1].set_xlabel("$T_v$")
ax[1].set_ylabel("U = settlement / dry settlement")
ax[0].set_xlim(0, 1.05)
ax[1].set_xlim(0, 1.05)
ax[2].set_xlim(0, np.sqrt(0.5))
ax[2].set_ylim(0, 0.9)
ax[2].set_xlabel(r"$\sqrt{T_v}$")
ax[2].set_ylabel("raw U")
ax[2].set_title("Taylor's construction", fontsize=9)
for a in ax:
    a.legend(fontsize=7)
fig.suptitle("DEM-PFV oedometer against Terzaghi (cases/consolidation)")
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=120)
print("wrote", sys.argv[2])
