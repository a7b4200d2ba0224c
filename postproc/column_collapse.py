#!/usr/bin/python3
"""Immersed granular column collapse (Izard 2014 ch. 5): the initial column, the basal pore
pressure, the front and the horizontal kinetic energy of a run of cases/column_collapse.

usage: column_collapse.py RUN_DIR R0 [SMOOTH]
  RUN_DIR  output folder of an ibmdem run of the collapse (series.csv with the p_probeN
           columns, particles_*.h5, input.ini; fields_00000.h5 with the resolved fluid, none
           with the pore network, whose viscosity and density are those of [porenet])
  R0       the column's length (m; the gate's position)
  SMOOTH   width of the moving average of the basal pressure (s, default 0.02)
Prints one line "column: key=value ..." and writes RUN_DIR/column.json.

Definitions:
  D       mean diameter of the mobile grains; m their mean mass
  H0      the column's height at t = 0: the mean over four bins of x in [0, R0] of the top of
          the highest grain of the bin
  a       H0/R0
  phi_mass  N V_p/(R0 W H0) (Rondon's estimate, as the thesis' 0.585)
  phi_alpha the immersed boundary's solid fraction averaged over the cells inside the column
          (x in [2D, R0 - 2D], z in [1.5D, H0 - 1.5D]) at t = 0 (the thesis' 0.60); NaN after a
          [packing] prepare, whose t = 0 fluid snapshot shows the grains before the preparation
  phi_inner the solid fraction of the same box from the grains' exact spheres
  p_b     the basal pore pressure: the mean of the probes' columns (relative to hydrostatic and
          to probes.reference), smoothed over SMOOTH; reported over Delta rho g H0
  T_visq  eta/(Delta rho g H0); t also in sqrt(D/g)
  front   (x_front - R0)/R0 with x_front the 99th percentile of the x of the mobile grains plus
          their mean radius, at each particle snapshot
  E_cx    sum of m_i u_i^2/2 over the mobile grains / N, over m g D: at every series row from the
          column dem_kinetic_energy_x, else at each particle snapshot
"""
import configparser
import glob
import json
import os
import sys

import h5py
import numpy as np

G = 9.81


def load(path):
    with h5py.File(path, "r") as h:
        return (float(h.attrs["time"]), h["position"][...], h["velocity"][...], h["radius"][...],
                h["density"][...], h["fixed"][...] != 0)


def column_height(x, r, R0):
    tops = []
    for b in range(4):
        sel = (x[:, 0] >= b * R0 / 4) & (x[:, 0] < (b + 1) * R0 / 4)
        if sel.any():
            tops.append((x[sel, 2] + r[sel]).max())
    return float(np.mean(tops))


def main():
    d, R0 = sys.argv[1], float(sys.argv[2])
    smooth = float(sys.argv[3]) if len(sys.argv) > 3 else 0.02
    ini = configparser.ConfigParser(inline_comment_prefixes=(";", "#"), strict=False)
    ini.read(os.path.join(d, "input.ini"))
    if ini.has_section("fluid"):
        rho = float(ini.get("fluid", "rho", fallback="1"))
        eta = rho * float(ini.get("fluid", "nu"))
    else:  # the pore network
        rho = float(ini.get("porenet", "fluid_density", fallback="1000"))
        eta = float(ini.get("porenet", "viscosity"))
    snaps = sorted(glob.glob(os.path.join(d, "particles_*.h5")))
    t0, x, v, r, rp, fixed = load(snaps[0])
    mob = ~fixed
    x, r, rp = x[mob], r[mob], rp[mob]
    D = 2 * r.mean()
    mass = rp * 4 / 3 * np.pi * r**3
    m = mass.mean()
    drho = rp.mean() - rho
    H0 = column_height(x, r, R0)
    fields = os.path.join(d, "fields_00000.h5")
    if os.path.exists(fields):
        with h5py.File(fields, "r") as f:
            yf, xc, zc = f["y"][...], f["xc"][...], f["zc"][...]
            alpha = f["solid_fraction"][...]  # [nz][ny][nx]
        ix = (xc > 2 * D) & (xc < R0 - 2 * D)
        iz = (zc > 1.5 * D) & (zc < H0 - 1.5 * D)
        phi_alpha = float(alpha[np.ix_(iz, np.ones(alpha.shape[1], bool), ix)].mean())
    else:  # the pore network: no grid (the box of [domain])
        L = [float(v) for v in ini.get("domain", "length").split()]
        yf, phi_alpha = np.array([0.0, L[1]]), float("nan")
    W = yf[-1] - yf[0]
    if glob.glob(os.path.join(d, "*packing*.h5")):
        phi_alpha = float("nan")  # the t = 0 snapshot of the fluid precedes [packing] prepare
    # the same box, exact sphere volumes (Monte Carlo, 2e5 points, sd ~ 0.001)
    rng = np.random.default_rng(1)
    P = rng.uniform([2 * D, yf[0], 1.5 * D], [R0 - 2 * D, yf[-1], H0 - 1.5 * D], size=(200000, 3))
    inside = np.zeros(len(P), bool)
    for c, rr in zip(x, r):
        q = P - c
        q[:, 1] -= W * np.round(q[:, 1] / W)
        inside |= (q**2).sum(1) < rr * rr
    phi_inner = float(inside.mean())
    phi_mass = float((4 / 3 * np.pi * r**3).sum() / (R0 * W * H0))
    scale = drho * G * H0
    tg = np.sqrt(D / G)
    tv = eta / scale

    s = np.genfromtxt(os.path.join(d, "series.csv"), delimiter=",", names=True)
    t = s["time"]
    cols = [c for c in s.dtype.names if c.startswith("p_probe")]
    pb = np.mean([s[c] for c in cols], axis=0)
    dt = np.median(np.diff(t)) if len(t) > 1 else 1.0
    k = max(1, int(round(smooth / dt)) | 1)
    pad = np.pad(pb, k // 2, mode="edge")
    ps = np.convolve(pad, np.ones(k) / k, mode="valid")
    imin, imax = int(np.argmin(ps)), int(np.argmax(ps))

    fronts, ecx = [], []
    for p in snaps:
        ts, xs, vs, rs, rps, fx = load(p)
        mm = ~fx
        fronts.append((ts, (np.percentile(xs[mm, 0], 99) + rs[mm].mean() - R0) / R0))
        ms = rps[mm] * 4 / 3 * np.pi * rs[mm]**3
        ecx.append((ts, float((0.5 * ms * vs[mm, 0]**2).sum() / mm.sum() / (m * G * D))))
    if "dem_kinetic_energy_x" in s.dtype.names:  # every series row (the DEM's column)
        ecx = [(float(a), float(b / mob.sum() / (m * G * D))) for a, b in zip(t, s["dem_kinetic_energy_x"])]
    ie = int(np.argmax([e for _, e in ecx]))
    out = {
        "grains": int(mob.sum()), "D": D, "H0": H0, "H0_over_D": H0 / D, "R0_over_D": R0 / D, "a": H0 / R0,
        "W_over_D": W / D, "phi_mass": phi_mass, "phi_alpha": phi_alpha, "phi_inner": phi_inner, "drho_g_H0": scale,
        "T_visq": tv, "sqrt_D_over_g": tg, "probes": cols, "smooth": smooth,
        "pb_min": float(ps[imin] / scale), "t_pb_min": float(t[imin]), "t_pb_min_Tvisq": float(t[imin] / tv),
        "pb_max": float(ps[imax] / scale), "t_pb_max": float(t[imax]), "t_pb_max_Tvisq": float(t[imax] / tv),
        "pb_mean": float(pb.mean() / scale),
        "pb_series": [[float(a), float(b / scale)] for a, b in zip(t[::max(1, len(t) // 200)],
                                                                   ps[::max(1, len(t) // 200)])],
        "front": fronts, "front_final": fronts[-1][1], "Ecx_max": ecx[ie][1], "t_Ecx_max": ecx[ie][0],
        "Ecx": ecx[::max(1, len(ecx) // 200)],
    }
    with open(os.path.join(d, "column.json"), "w") as f:
        json.dump(out, f, indent=1)
    print(f"column: grains={out['grains']} H0/D={H0 / D:.2f} a={H0 / R0:.3f} phi_mass={phi_mass:.3f} "
          f"phi_alpha={phi_alpha:.3f} phi_inner={phi_inner:.3f} pb_min={out['pb_min']:+.4f}@{t[imin]:.3f}s({t[imin] / tv:.0f}Tv) "
          f"pb_max={out['pb_max']:+.4f}@{t[imax]:.3f}s({t[imax] / tv:.0f}Tv) pb_mean={out['pb_mean']:+.4f} "
          f"front_final={out['front_final']:.3f} Ecx_max={out['Ecx_max']:.4f}@{ecx[ie][0]:.3f}s "
          f"Tvisq={tv:.3g}s sqrt(D/g)={tg:.4f}s")


if __name__ == "__main__":
    main()
