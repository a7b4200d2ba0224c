#!/usr/bin/python3
"""Oblique bounces against a wall: Psi_out against Psi_in, beta and mu_f against the impact angle.

usage: oblique.py oblique.csv OUT.png      (oblique.csv from scripts/oblique_sweep.sh)

Psi_in = u_t/u_n of the contact point before the contact, Psi_out = u_t,out/u_n,in after it (Joseph & Hunt
2004), beta = -Psi_out/Psi_in, mu_f = 2 (1 + beta) Psi_in / (7 (1 + e)).  Drawn with them: the rigid-body
sliding line Psi_out = Psi_in - (7/2) mu_c (1 + e) of a homogeneous sphere (Walton 1993; Foerster et al. 1994)
for the contact law's friction mu_c and the runs' mean wet normal restitution e, which every impact beyond
Psi_crit = (7/2) mu_c (1 + e) follows if the contact slides throughout and nothing else acts tangentially.
"""
import sys

import numpy as np


def main():
    csv, out = sys.argv[1], sys.argv[2]
    d = np.genfromtxt(csv, delimiter=",", names=True)
    mu_c = 0.106  # cases/oblique_bounce/oblique_3d.ini [contact] friction
    e = float(np.mean(d["e_n"]))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    x = np.linspace(0, max(1.0, d["psi_in"].max() * 1.1), 100)
    pc = 3.5 * mu_c * (1 + e)
    ax[0].plot(d["psi_in"], d["psi_out"], "o-", label="ibmdem")
    ax[0].plot(x, np.where(x > pc, x - pc, np.nan), "k--", label=rf"sliding, $\mu_c$ = {mu_c}, e = {e:.2f}")
    ax[0].set_xlabel(r"$\Psi_{in}$")
    ax[0].set_ylabel(r"$\Psi_{out}$")
    ax[0].legend(fontsize=8)
    ax[1].plot(d["xi_deg"], d["beta"], "o-")
    ax[1].set_xlabel(r"$\xi_{in}$ (deg)")
    ax[1].set_ylabel(r"$\beta = -\Psi_{out}/\Psi_{in}$")
    ax[2].plot(d["xi_deg"], d["mu_f"], "o-", label=r"$\mu_f$")
    ax[2].axhline(mu_c, color="k", ls="--", label=r"$\mu_c$")
    ax[2].set_xlabel(r"$\xi_{in}$ (deg)")
    ax[2].set_ylabel(r"$\mu_f$")
    ax[2].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=130)
    for r in d:
        slide = r["psi_in"] - pc
        print(f"xi {r['xi_deg']:4.0f}: Psi_in {r['psi_in']:.4f} Psi_out {r['psi_out']:+.4f} "
              f"(sliding line {slide:+.4f}) beta {r['beta']:+.3f} mu_f {r['mu_f']:.4f} e_n {r['e_n']:.3f} "
              f"rebound angle {r['rebound_angle_deg']:.1f}")


if __name__ == "__main__":
    main()
