#!/usr/bin/python3
"""Dry flow down a rough inclined plane: steadiness, velocity and solid
fraction profiles, and the fit of the Bagnold profile (Izard 2014 eq. 2.23)
    u(z) = u_b + A [h^{3/2} - (h - z)^{3/2}]
over the flowing layer (above the bed grains, below the dilute surface).

usage: dem_incline.py RUN_DIR T_START T_END AREA [PLOT.png]
  averages the snapshots particles_*.h5 with T_START <= t <= T_END; AREA is
  the bed area Lx*Ly (m^2).  Prints one line "incline: h/D=... bagnold_misfit=...
  linear_misfit=... flux_change=..." and writes RUN_DIR/incline.json.
Slab averages share each sphere's volume among the slabs it crosses.
"""
import glob
import json
import os
import sys

import h5py
import numpy as np


def main():
    d, t1, t2, area = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
    plot = sys.argv[5] if len(sys.argv) > 5 else None
    snaps = []
    for s in sorted(glob.glob(os.path.join(d, "particles_*.h5"))):
        with h5py.File(s, "r") as h:
            t = float(h.attrs["time"])
            if t1 - 1e-9 <= t <= t2 + 1e-9:
                snaps.append((t, h["position"][...], h["velocity"][...], h["radius"][...], h["fixed"][...] != 0))
    D = 2 * np.mean(snaps[0][3][~snaps[0][4]])
    dz = D / 4
    zmax = max(s[1][:, 2].max() for s in snaps) + D
    nb = int(zmax / dz) + 1
    vol = np.zeros(nb)
    mom = np.zeros(nb)
    flux = []
    for t, x, v, r, fixed in snaps:
        m = ~fixed
        flux.append(np.sum(r[m] ** 3 * v[m, 0]) / np.sum(r[m] ** 3))
        for zc, rr, vx in zip(x[m, 2], r[m], v[m, 0]):
            for b in range(max(0, int((zc - rr) / dz)), min(nb, int((zc + rr) / dz) + 1)):
                z1 = max(b * dz, zc - rr) - zc
                z2 = min((b + 1) * dz, zc + rr) - zc
                if z2 <= z1:
                    continue
                vs = np.pi * (rr * rr * (z2 - z1) - (z2 ** 3 - z1 ** 3) / 3)
                vol[b] += vs
                mom[b] += vs * vx
    z = (np.arange(nb) + 0.5) * dz
    phi = vol / len(snaps) / (area * dz)
    u = np.where(vol > 0, mom / np.maximum(vol, 1e-300), 0)
    bulk = phi[(z > D) & (z < 4 * D)].max()
    top = np.argmax((z > D) & (phi < 0.5 * bulk))
    h = z[top]
    sel = (z > D) & (z < h - D)
    half = len(flux) // 2
    change = np.mean(flux[half:]) / np.mean(flux[:half]) - 1

    def fit(g):
        A = np.vstack([np.ones(sel.sum()), g(z[sel])]).T
        c, *_ = np.linalg.lstsq(A, u[sel], rcond=None)
        return c, np.sqrt(np.sum((A @ c - u[sel]) ** 2) / np.sum(u[sel] ** 2))

    bag = lambda zz: h ** 1.5 - np.clip(h - zz, 0, None) ** 1.5
    cb, eb = fit(bag)
    cl, el = fit(lambda zz: zz)
    res = {"h_over_D": h / D, "surface_velocity": float(u[top - 1]), "bagnold_misfit": eb, "linear_misfit": el,
           "basal_slip": cb[0], "flux_change": change, "samples": len(snaps), "phi_bulk": float(np.median(phi[sel]))}
    print("incline: h/D=%.2f u_surface=%.4f bagnold_misfit=%.4f linear_misfit=%.4f slip=%.4f flux_change=%.4f "
          "phi=%.3f samples=%d" % (h / D, u[top - 1], eb, el, cb[0], change, res["phi_bulk"], len(snaps)))
    json.dump(res, open(os.path.join(d, "incline.json"), "w"), indent=1)
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(8, 4), sharey=True)
        ax[0].plot(u[: top + 2], z[: top + 2] / D, "o", ms=3, label="DEM")
        ax[0].plot(cb[0] + cb[1] * bag(z[sel]), z[sel] / D, "-", label="Bagnold fit")
        ax[0].plot(cl[0] + cl[1] * z[sel], z[sel] / D, ":", label="linear fit")
        ax[0].set_xlabel("u (m/s)")
        ax[0].set_ylabel("z/D")
        ax[0].legend()
        ax[1].plot(phi[: top + 2], z[: top + 2] / D, "o-", ms=3)
        ax[1].set_xlabel("solid fraction")
        fig.tight_layout()
        fig.savefig(plot, dpi=120)


if __name__ == "__main__":
    main()
