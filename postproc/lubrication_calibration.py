#!/usr/bin/python3
"""Cut-off of the lubrication correction from the squeeze runs (cases/lubrication_calibration/squeeze_axi.ini).

usage: lubrication_calibration.py OUT.png RUN_DIR [RUN_DIR ...]   (each RUN_DIR named ..._nN, N = D/dx)

A sphere driven at U towards a wall feels F = 6 pi mu R U lambda(delta); Brenner's (1961) exact lambda (his
series, summed here) goes as R/delta at small gaps, while the grid carries the film down to about a cell.  The
correction adds 6 pi mu R^2 U (1/(delta + eta) - 1/(delta_c + eta)) below delta_c.  What matters for a bounce
is the impulse of the film over an approach, int F dt = 6 pi mu R int lambda d(delta): delta_c is chosen so
that resolved + correction carries Brenner's impulse from delta_1 = 0.25 D down to contact,

    ln(delta_c) = [I_B - I_res]/R + ln(delta_1) + 1,
    I_B = int_0^delta_1 (lambda_B - R/delta) d(delta),   I_res = int_0^delta_1 lambda_res d(delta),

(eta -> 0; the singular parts cancel), with lambda_res measured down to the run's last gap (0.02 D) and held
at its last value below (the resolved force levels off within a cell of the wall), and the resolved curve
shifted to Brenner's at delta_1 (the box's confinement and the start).  Prints delta_c/dx per run and writes
OUT.png (lambda against delta/R: Brenner, each run, each run plus its correction).
"""
import os
import re
import sys

import numpy as np


def brenner_lambda(h, R=0.5, nmax=4000):
    """Brenner (1961): F = 6 pi mu R U lambda for a sphere approaching a plane no-slip wall at gap h."""
    out = []
    n = np.arange(1, nmax + 1, dtype=float)
    for hh in np.atleast_1d(h):
        a = np.arccosh(1 + hh / R)
        with np.errstate(over="ignore", invalid="ignore"):
            num = 2 * np.sinh((2 * n + 1) * a) + (2 * n + 1) * np.sinh(2 * a)
            den = 4 * np.sinh((n + 0.5) * a) ** 2 - (2 * n + 1) ** 2 * np.sinh(a) ** 2
            term = n * (n + 1) / ((2 * n - 1) * (2 * n + 3)) * (num / den - 1)
        out.append(4.0 / 3.0 * np.sinh(a) * term[np.isfinite(term)].sum())
    return np.array(out)


def main():
    out, runs = sys.argv[1], sys.argv[2:]
    R, U, mu, d1 = 0.5, 0.01, 1.0, 0.25
    F0 = 6 * np.pi * mu * R * U
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.2))
    gg = np.geomspace(0.01, 1.0, 200)
    ax.loglog(gg / R, brenner_lambda(gg), "k-", lw=2, label="Brenner (1961)")
    for k, d in enumerate(runs):
        N = int(re.search(r"_n(\d+)", os.path.basename(os.path.normpath(d))).group(1))
        dx = 1.0 / N
        a = np.genfromtxt(os.path.join(d, "series.csv"), delimiter=",", names=True)
        gap, lam = a["s1_y"] - R, a["s1_fy"] / F0
        m = (gap > 0.0201) & (gap <= d1)
        o = np.argsort(gap[m])
        g, l = gap[m][o], lam[m][o]
        off = l[-1] - brenner_lambda([g[-1]])[0]
        l = l - off
        Ires = l[0] * g[0] + np.trapz(l, g)
        gb = np.concatenate([np.geomspace(1e-7, g[0], 400), g])
        lb = brenner_lambda(gb)
        IB = np.trapz(lb - R / gb, gb) + 1e-7 * (lb[0] - R / gb[0])
        dc = np.exp((IB - Ires) / R + np.log(g[-1]) + 1)
        print(f"{d}: D/dx = {N}: impulse-equivalent cut-off delta_c = {dc / dx:.3f} dx = {dc / R:.4f} R "
              f"(resolved lambda at {g[0] / dx:.2f} dx: {l[0]:.2f}, Brenner {brenner_lambda([g[0]])[0]:.2f}; "
              f"shift at {d1} D: {off:+.3f})")
        ax.loglog(g / R, l, f"C{k}-", lw=1.2, label=f"resolved, D/dx = {N}")
        corr = np.where(g < dc, R / g - R / dc, 0.0)
        ax.loglog(g / R, l + corr, f"C{k}--", lw=1.0, label=f"resolved + correction ($\\delta_c$ = {dc / dx:.2f} dx)")
    ax.set_xlabel(r"$\delta/R$")
    ax.set_ylabel(r"$F/(6\pi\mu R U)$")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=130)


if __name__ == "__main__":
    main()
