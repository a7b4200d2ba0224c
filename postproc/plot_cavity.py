#!/usr/bin/python3
"""plot_cavity.py OUTDIR [PNG] — lid-driven cavity: centreline velocities of the
last snapshot in OUTDIR against Ghia, Ghia & Shin (1982) at the Reynolds number
1/nu of the run (100, 400 or 1000: cases/cavity/ghia1982.csv), and a map of the
velocity magnitude.  Prints the largest difference from the table and writes
OUTDIR/cavity_ghia.json with it.

The snapshot holds cell-centred velocities (fields_NNNNN.h5, x fastest); the
centreline values at x = 0.5 (or y = 0.5) are interpolated linearly between the
two cell centres on either side, which is second order like the solver."""
import glob
import json
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
TABLE = os.path.join(HERE, "..", "cases", "cavity", "ghia1982.csv")


def reynolds(outdir):
    """Re = U L / nu of the run, from its resolved input (unit lid velocity and size)."""
    section = ""
    for line in open(os.path.join(outdir, "input.ini")):
        line = line.split(";")[0].strip()
        if line.startswith("["):
            section = line.strip("[]")
        elif section == "fluid" and line.startswith("nu") and "=" in line:
            return round(1.0 / float(line.split("=")[1]))
    raise SystemExit("no fluid.nu in %s/input.ini" % outdir)


def read_ghia(re, path=TABLE):
    rows = [line.strip().split(",") for line in open(path) if line.strip() and not line.startswith("#")]
    head, rows = rows[0], rows[1:]
    if "Re%d" % re not in head:
        raise SystemExit("Ghia et al. tabulate Re = %s, not %d" % (", ".join(h[2:] for h in head[2:]), re))
    col = head.index("Re%d" % re)
    out = {"u": [], "v": []}
    for r in rows:
        out[r[0]].append((float(r[1]), float(r[col])))
    return {k: np.array(sorted(v)) for k, v in out.items()}


def centreline(coord, field, at):
    """Linear interpolation of field (..., n) along its last axis at coordinate `at`."""
    i = np.searchsorted(coord, at) - 1
    w = (at - coord[i]) / (coord[i + 1] - coord[i])
    return (1 - w) * field[..., i] + w * field[..., i + 1]


def main():
    outdir = sys.argv[1]
    png = sys.argv[2] if len(sys.argv) > 2 else os.path.join(outdir, "cavity.png")
    snap = sorted(glob.glob(os.path.join(outdir, "fields_*.h5")))[-1]
    with h5py.File(snap) as f:
        t = f.attrs["time"]
        xf, yf, xc, yc = f["x"][...], f["y"][...], f["xc"][...], f["yc"][...]
        vel = f["velocity"][0]  # [ny][nx][3], 2-D: one layer in z
    u, v = vel[..., 0], vel[..., 1]
    lid = 1.0
    # u(0.5, y): interpolate in x (last axis); add the wall values at y = 0 and 1
    uc = centreline(xc, u, 0.5)
    y_u = np.concatenate([[yf[0]], yc, [yf[-1]]])
    u_line = np.concatenate([[0.0], uc, [lid]])
    # v(x, 0.5): interpolate in y (first axis)
    vc = centreline(yc, v.T, 0.5)
    x_v = np.concatenate([[xf[0]], xc, [xf[-1]]])
    v_line = np.concatenate([[0.0], vc, [0.0]])

    re = reynolds(outdir)
    ghia = read_ghia(re)
    err_u = np.abs(np.interp(ghia["u"][:, 0], y_u, u_line) - ghia["u"][:, 1])
    err_v = np.abs(np.interp(ghia["v"][:, 0], x_v, v_line) - ghia["v"][:, 1])
    res = {"snapshot": os.path.basename(snap), "time": float(t), "grid": [len(xc), len(yc)],
           "max_abs_error_u": float(err_u.max()), "max_abs_error_v": float(err_v.max()),
           "reynolds": re, "reference": "Ghia, Ghia & Shin (1982), J. Comput. Phys. 48, 387-411"}
    with open(os.path.join(outdir, "cavity_ghia.json"), "w") as f:
        json.dump(res, f, indent=2)
    print("cavity Re = %d, %d x %d, t = %.4g: max |u - Ghia| = %.4f, max |v - Ghia| = %.4f (lid velocity 1)"
          % (re, len(xc), len(yc), t, err_u.max(), err_v.max()))

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6))
    ax[0].plot(u_line, y_u, "-", label="ibmdem %d x %d" % (len(xc), len(yc)))
    ax[0].plot(ghia["u"][:, 1], ghia["u"][:, 0], "o", mfc="none", label="Ghia et al. (1982)")
    ax[0].set_xlabel("u(x = 0.5, y)")
    ax[0].set_ylabel("y")
    ax[0].set_title("vertical centreline")
    ax[0].legend()
    ax[1].plot(x_v, v_line, "-", label="ibmdem")
    ax[1].plot(ghia["v"][:, 0], ghia["v"][:, 1], "o", mfc="none", label="Ghia et al. (1982)")
    ax[1].set_xlabel("x")
    ax[1].set_ylabel("v(x, y = 0.5)")
    ax[1].set_title("horizontal centreline")
    ax[1].legend()
    mag = np.hypot(u, v)
    m = ax[2].pcolormesh(xf, yf, mag, shading="flat", cmap="viridis")
    fig.colorbar(m, ax=ax[2], label="|u|")
    if np.allclose(np.diff(xc), xc[1] - xc[0]) and np.allclose(np.diff(yc), yc[1] - yc[0]):
        ax[2].streamplot(xc, yc, u, v, color="w", linewidth=0.6, density=1.2)
    ax[2].set_aspect("equal")
    ax[2].set_xlim(xf[0], xf[-1])
    ax[2].set_ylim(yf[0], yf[-1])
    ax[2].set_title("velocity magnitude, t = %.3g" % t)
    fig.suptitle("lid-driven cavity, Re = %d" % re)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print("wrote", png)


if __name__ == "__main__":
    main()
