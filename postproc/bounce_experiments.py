#!/usr/bin/python3
"""The bouncing sphere against the experiments of Gondret, Lance & Petit (2002).

usage: bounce_experiments.py OUT.png RUN_DIR:DATA.csv [RUN_DIR:DATA.csv ...]

Each RUN_DIR is an `ibmdem run` of cases/bouncing_sphere/gondret_st*.ini (or a variant of it), DATA.csv the
digitised trajectory of the experiment (cases/bouncing_sphere/data/, columns t_s, gap_m; third-party
digitisation, provenance in the file header).  The experiment's time origin is taken as the lift-off of the
first rebound for the St ~ 27 data (its first point is at 0.6 ms and 0.16 mm) and as the first impact for the
St ~ 152 data (its approach ends at t ~ 0); the run is shifted to the same origin (its release, or its contact).

Prints per case: the apex heights of the rebounds (gap/D) and their times after the first lift-off, the
experiment-like restitution as the digitised data allow it (the secant slope of the gap between the first two
samples after lift-off, over the impact speed), the same for the run at the same times, and the rms difference
of the gap over the first rebound.  Writes OUT.png (gap/D against t/sqrt(D/g)) and OUT.csv (the numbers).
"""
import csv
import json
import os
import sys

import numpy as np


def load_run(d):
    s = json.load(open(os.path.join(d, "summary.json")))
    a = np.genfromtxt(os.path.join(d, "series.csv"), delimiter=",", names=True)
    c = s["coupling"]
    D = c["numbers"]["D"] if "numbers" in c else 1.0
    gap = a["s1_y"] - 0.5 * D  # the wall at y = 0 (y_lo)
    return s, c, D, a["time"], gap, a["s1_v"]


def apices(t, gap, t0, n=3):
    """Local maxima of the gap after t0 (the rebounds), up to n."""
    out = []
    m = t > t0
    tt, gg = t[m], gap[m]
    for k in range(1, len(gg) - 1):
        if gg[k] > gg[k - 1] and gg[k] >= gg[k + 1] and gg[k] > 1e-3 * gg.max():
            if not out or tt[k] - out[-1][0] > 0.005:
                out.append((tt[k], gg[k]))
        if len(out) == n:
            break
    return out


def main():
    out_png, pairs = sys.argv[1], sys.argv[2:]
    rows = []
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    # one panel per experiment: the runs compared with the same data are drawn over each other
    datasets = list(dict.fromkeys(p.split(":")[1] for p in pairs))
    fig, axes = plt.subplots(1, len(datasets), figsize=(7 * len(datasets), 4.4), squeeze=False)
    drawn = set()
    for n_run, pair in enumerate(pairs):
        d, data = pair.split(":")
        ax = axes[0][datasets.index(data)]
        s, c, D, t, gap, v = load_run(d)
        g = 9.81
        tref = np.sqrt(D / g)
        e = np.loadtxt(data, delimiter=",", comments="#", skiprows=1 + sum(1 for l in open(data) if l.startswith("#")))
        te, ge = e[:, 0], e[:, 1]
        approach = te.min() < 0  # the St ~ 152 data start before the impact
        origin = c["t_contact"] if approach else c["t_release"]
        ts = t - origin
        # impact speed: the experiment's (Biegert et al. 2017, Table 1) is the run's V_in within the
        # tolerance of the set-up; the run's own fitted V_in is used for both ratios
        Vin = c["V_in"]
        # experiment-like restitution as the data allow: the secant of the first two samples after lift-off
        k0 = np.searchsorted(te, 0.0)
        t1, t2 = te[k0], te[k0 + 1]
        e_exp = (ge[k0 + 1] - ge[k0]) / (t2 - t1) / Vin
        g1, g2 = np.interp(t1, ts, gap), np.interp(t2, ts, gap)
        e_run = (g2 - g1) / (t2 - t1) / Vin
        # rms difference of the gap over the first rebound (between the first lift-off and the next impact)
        first = (te >= 0) & (te <= te[k0:][np.argmax(ge[k0:])] * 2.2) & (te <= ts[-1])
        rms = np.sqrt(np.mean((np.interp(te[first], ts, gap) - ge[first]) ** 2)) / D
        ae, ar = apices(te, ge, 0.0), apices(ts, gap, 0.0)
        name = os.path.basename(os.path.normpath(d))
        print(f"{name}: St = {c['St']:.1f} (V_T {c['V_T']:.4f} m/s, fitted impact {Vin:.4f} m/s), "
              f"epsilon_fit {c['epsilon_fit']:.3f} over {c['fit_window'] * 1e3:.2f} ms")
        for k in range(max(len(ae), len(ar))):
            xe = f"{ae[k][1] / D:.3f} D at {ae[k][0] * 1e3:.1f} ms" if k < len(ae) else "-"
            xr = f"{ar[k][1] / D:.3f} D at {ar[k][0] * 1e3:.1f} ms" if k < len(ar) else "-"
            print(f"  apex {k + 1}: experiment {xe}, run {xr}")
        print(f"  secant of the first 2 samples after lift-off ({t1 * 1e3:.2f}-{t2 * 1e3:.2f} ms) over the impact "
              f"speed: experiment {e_exp:.3f}, run {e_run:.3f}; rms gap difference over the first rebound "
              f"{rms:.4f} D")
        rows.append(dict(case=name, St=c["St"], V_in=Vin, epsilon_fit=c["epsilon_fit"],
                         apex1_exp=ae[0][1] / D if ae else np.nan, apex1_run=ar[0][1] / D if ar else np.nan,
                         t_apex1_exp=ae[0][0] if ae else np.nan, t_apex1_run=ar[0][0] if ar else np.nan,
                         secant_exp=e_exp, secant_run=e_run, rms_gap_over_D=rms))
        if data not in drawn:
            drawn.add(data)
            ax.plot(te / tref, ge / D, "ko", ms=3.5, mfc="none", label="Gondret et al. (2002), digitised", zorder=3)
            ax.set_xlim(te.min() / tref - 0.3, te.max() / tref + 0.3)
            ax.set_ylim(-0.05, max(ge.max(), gap[ts > te.min()].max()) / D * 1.15)
            ax.set_xlabel(r"$t/\sqrt{D/g}$")
            ax.set_ylabel(r"gap$/D$")
            ax.set_title(f"St = {c['St']:.0f}")
        ax.plot(ts / tref, gap / D, f"C{n_run % 10}-", lw=1.2,
                label=f"ibmdem {name}, D/dx = {c['numbers']['D_over_dx']:.0f}")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_png, dpi=130)
    with open(os.path.splitext(out_png)[0] + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
