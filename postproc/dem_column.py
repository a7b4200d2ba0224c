#!/usr/bin/python3
"""Dry granular column collapse: front position against time, final deposit,
run-out against the empirical law of Lajeunesse et al. (2005) for a
rectangular channel, (R_inf - R0)/R0 = 1.2 a for a = H0/R0 < 3.

usage: dem_column.py RUN_DIR R0 [PLOT.png]
  RUN_DIR holds particles_*.h5 (ibmdem run or dem_run_case) and the packing
  (column_packing.h5, or the first snapshot).  Prints one line
  "column: a=... runout=... lajeunesse=... H_over_R0=..." and writes
  RUN_DIR/column.json.
The front is the 99th percentile of the x of the mobile grains plus a radius
(a few grains bounce ahead of the deposit); H0 and H_inf the 99th percentile
of the top of the grains within 2 D of the back wall.
"""
import glob
import json
import os
import sys

import h5py
import numpy as np


def load(path):
    with h5py.File(path, "r") as h:
        return (float(h.attrs["time"]), h["position"][...], h["radius"][...], h["fixed"][...] != 0)


def front(x, r, fixed):
    m = ~fixed
    return np.percentile(x[m, 0], 99) + np.mean(r[m])


def back_height(x, r, fixed):
    m = (~fixed) & (x[:, 0] < 4 * np.mean(r[~fixed]))
    return np.percentile(x[m, 2] + r[m], 99)


def main():
    d, R0 = sys.argv[1], float(sys.argv[2])
    plot = sys.argv[3] if len(sys.argv) > 3 else None
    snaps = sorted(glob.glob(os.path.join(d, "particles_*.h5")))
    first = os.path.join(d, "column_packing.h5")
    t0, x0, r0, f0 = load(first if os.path.exists(first) else snaps[0])
    H0 = back_height(x0, r0, f0)
    a = H0 / R0
    ts, fr = [], []
    for s in snaps:
        t, x, r, f = load(s)
        ts.append(t)
        fr.append(front(x, r, f))
    t, x, r, f = load(snaps[-1])
    Rinf = front(x, r, f)
    Hinf = back_height(x, r, f)
    res = {"a": a, "H0": H0, "R0": R0, "R_inf": Rinf, "runout": (Rinf - R0) / R0, "lajeunesse": 1.2 * a,
           "H_inf_over_R0": Hinf / R0, "t_final": t, "grains": int((~f).sum())}
    print("column: a=%.3f runout=%.3f lajeunesse=%.3f H_over_R0=%.3f grains=%d t=%.3f"
          % (a, res["runout"], 1.2 * a, Hinf / R0, res["grains"], t))
    json.dump(res, open(os.path.join(d, "column.json"), "w"), indent=1)
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(10, 3.5))
        ax[0].plot(ts, (np.array(fr) - R0) / R0, "o-")
        ax[0].axhline(1.2 * a, ls="--", color="k", label="Lajeunesse et al. 2005: 1.2 a")
        ax[0].set_xlabel("t (s)")
        ax[0].set_ylabel("(x_front - R0)/R0")
        ax[0].legend()
        m = ~f
        ax[1].scatter(x[m, 0] / R0, x[m, 2] / R0, s=2)
        ax[1].scatter(x0[~f0, 0] / R0, x0[~f0, 2] / R0, s=1, alpha=0.3)
        ax[1].set_aspect("equal")
        ax[1].set_xlabel("x/R0")
        ax[1].set_ylabel("z/R0")
        fig.tight_layout()
        fig.savefig(plot, dpi=120)


if __name__ == "__main__":
    main()
