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
  front_t the front against t, t in seconds, in sqrt(D/g) and in T_visq (each particle snapshot)
The deposit (the last particle snapshot):
  h(x)    the deposit profile: in bins of x of one D from the wall x = 0, the top (z + r) of the
          highest mobile grain of the bin (0 where the bin holds none), heights from the bed's
          centres (z = 0), as H0
  R_inf   the final front x_front (as above, not relative to R0): R_inf/R0 = 1 + front_final
  H_inf   the final height at the wall: the larger h of the first two bins (x in [0, 2D]: the
          grains against the wall sit lower than the next ones); H_inf/R0 and H_inf/H0; H_wall0
          the same on the first snapshot (H0 is a mean over 4 bins of R0/4, H_wall0 a maximum over
          two bins of D: H_inf/H_wall0 says whether the column's top at the wall went down)
  flank   the angle of the free surface: a least-squares line through the bins where the
          deposit's monotone envelope (max of h over the bins further out) lies between 0.2 and
          0.8 H_inf; its slope -> the angle in degrees
  plateau the length from the wall over which the envelope stays within D/2 of H_inf; the shape
          is "trapezoid" when the plateau spans at least 3 D, else "triangle"
The stopping time:
  t_stop  the last series time at which the grains' translational kinetic energy (column
          dem_kinetic_energy) exceeds 1e-3 of its maximum (velocities ~3 % of the peak); also
          t_stop_1e-2 with 1e-2, and t_front99, the first particle snapshot at which the front
          reaches 99 % of its final value; all in s, sqrt(D/g) and T_visq
The grain Reynolds number (Izard's "3R sphere"):
  Re_p    rho |V_p - U| D / eta with D the mean diameter and U the fluid velocity averaged over
          the cells whose centres lie within 3R of the grain's centre, weighted by the fluid
          fraction 1 - alpha (the grain's own cells excluded); at each fluid snapshot that has a
          particle snapshot at the same time (resolved runs only); its maximum over grains and
          snapshots, and the maximum at each snapshot.  Re_p_max_all: the same with U the plain
          mean of the snapshot's velocity over those cells, the solid ones included (the one-fluid
          field of the immersed boundary, which inside a grain is the grain's velocity);
          Re_p_p99_max and Re_p_mean_max: the largest over the snapshots of the 99th percentile and
          of the mean over the grains (fluid-weighted U)
The pressure signal's shape: pb_first, t_pb_first: the first value of the smoothed p_b beyond
1.5 % of Delta rho g H0 (its sign: below or above hydrostatic first) and its time; pb_end: the
smoothed p_b at the end of the run.  t_front_start: the time at which the front has moved 0.05 R0
(linear between particle snapshots; None if it never does).
Also: the largest overlap (column dem_max_overlap, of the smaller diameter), rejected_steps, the
wall time and cost.* of summary.json when the run wrote one.  With matplotlib, RUN_DIR/column.png
shows the front against t/sqrt(D/g) and t/T_visq, E_cx and the deposit profile.
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


def deposit(x, r, D, R0):
    """The deposit profile h(x) in bins of one D from the wall, H_inf, the flank angle and shape."""
    nb = int(np.ceil(x[:, 0].max() / D)) + 1
    edges = np.arange(nb + 1) * D
    h = np.zeros(nb)
    top = x[:, 2] + r
    ib = np.clip((x[:, 0] // D).astype(int), 0, nb - 1)
    np.maximum.at(h, ib, top)
    xc = 0.5 * (edges[:-1] + edges[1:])
    H = float(h[:2].max())
    env = np.maximum.accumulate(h[::-1])[::-1]  # max of h over the bins from here outwards
    sel = (env >= 0.2 * H) & (env <= 0.8 * H)
    if sel.sum() >= 2:
        slope = np.polyfit(xc[sel], h[sel], 1)[0]
        angle = float(np.degrees(np.arctan(-slope)))
    else:
        angle = float("nan")
    plateau = float(D * np.argmax(env < H - 0.5 * D)) if (env < H - 0.5 * D).any() else float(edges[-1])
    return {"profile_dx": D, "profile_x": xc.tolist(), "profile_h": h.tolist(), "H_inf": H,
            "flank_angle_deg": angle, "flank_fit_bins": int(sel.sum()),
            "flank_fit_x": [float(xc[sel].min()), float(xc[sel].max())] if sel.any() else [],
            "plateau": plateau, "shape": "trapezoid" if plateau >= 3 * D else "triangle"}


def reynolds(d, rho, eta, D):
    """Izard's grain Reynolds number: grain velocity against the fluid's within 3R, at each fluid
    snapshot with a particle snapshot at the same time.  Returns [(t, max Re_p)]."""
    parts = {}
    for p in sorted(glob.glob(os.path.join(d, "particles_*.h5"))):
        with h5py.File(p, "r") as h:
            parts[round(float(np.ravel(h.attrs["time"])[0]), 9)] = p
    out = []
    for f in sorted(glob.glob(os.path.join(d, "fields_*.h5"))):
        with h5py.File(f, "r") as h:
            tf = round(float(np.ravel(h.attrs["time"])[0]), 9)
            if tf not in parts:
                continue
            xc, yc, zc = h["xc"][...], h["yc"][...], h["zc"][...]
            W = float(h["y"][-1] - h["y"][0])
            U = h["velocity"][...]          # [nz][ny][nx][3], cell centred
            wf = 1.0 - h["solid_fraction"][...]
        _, x, v, r, _, fx = load(parts[tf])
        dx, dy, dz = xc[1] - xc[0], yc[1] - yc[0], zc[1] - zc[0]
        res, res_all = [], []
        for c, vv, rr in zip(x[~fx], v[~fx], r[~fx]):
            R3 = 3 * rr
            ix = np.nonzero(np.abs(xc - c[0]) <= R3)[0]
            iz = np.nonzero(np.abs(zc - c[2]) <= R3)[0]
            ny = len(yc)
            j0 = int(np.floor((c[1] - R3 - yc[0]) / dy))
            jy = np.arange(j0, int(np.ceil((c[1] + R3 - yc[0]) / dy)) + 1)
            jy = np.unique(jy % ny) if len(jy) >= ny else jy % ny
            if len(ix) == 0 or len(iz) == 0:
                continue
            qy = yc[jy] - c[1]
            qy -= W * np.round(qy / W)
            d2 = ((zc[iz] - c[2])[:, None, None] ** 2 + qy[None, :, None] ** 2
                  + (xc[ix] - c[0])[None, None, :] ** 2)
            inb = d2 <= R3 * R3
            w = np.where(inb, wf[np.ix_(iz, jy, ix)], 0.0)
            if w.sum() <= 0:
                continue
            Ub = U[np.ix_(iz, jy, ix)]
            Uf = (w[..., None] * Ub).sum((0, 1, 2)) / w.sum()
            Ua = Ub[inb].mean(0)
            res.append(rho * float(np.linalg.norm(vv - Uf)) * D / eta)
            res_all.append(rho * float(np.linalg.norm(vv - Ua)) * D / eta)
        if res:
            out.append((tf, max(res), max(res_all), float(np.percentile(res, 99)), float(np.mean(res))))
    return out


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
    beyond = np.nonzero(np.abs(ps) > 0.015 * scale)[0]  # the first excursion beyond 1.5 % (the test's)
    ifirst = int(beyond[0]) if len(beyond) else None

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
    # the front's start: the time it passes 0.05 R0 beyond its position at t = 0 (linear between snapshots)
    t_start = None
    for (ta, fa), (tb, fb) in zip(fronts, fronts[1:]):
        if fb - fronts[0][1] >= 0.05:
            t_start = float(ta + (tb - ta) * (0.05 + fronts[0][1] - fa) / (fb - fa)) if fb > fa else float(tb)
            break
    # the deposit, from the last particle snapshot
    ts, xs, vs, rs, rps, fx = load(snaps[-1])
    dep = deposit(xs[~fx], rs[~fx], D, R0)
    H_wall0 = deposit(x, r, D, R0)["H_inf"]  # the same estimator on the first snapshot
    R_inf = R0 * (1 + fronts[-1][1])
    # the stopping time
    ek = s["dem_kinetic_energy"]
    ikm = int(np.argmax(ek))
    stop = {}
    for name, frac in (("t_stop", 1e-3), ("t_stop_1e-2", 1e-2)):
        above = np.nonzero(ek > frac * ek[ikm])[0]
        ts_ = float(t[above[-1]]) if len(above) else float(t[0])
        stop[name] = ts_
        stop[name + "_sqrt_D_g"] = ts_ / tg
        stop[name + "_Tvisq"] = ts_ / tv
        stop[name + "_at_end"] = bool(above[-1] == len(t) - 1) if len(above) else False
    ff = fronts[-1][1]
    i99 = next((i for i, (_, fr) in enumerate(fronts) if ff > 0 and fr >= 0.99 * ff), len(fronts) - 1)
    stop["t_front99"] = fronts[i99][0]
    stop["t_front99_sqrt_D_g"] = fronts[i99][0] / tg
    stop["t_front99_Tvisq"] = fronts[i99][0] / tv
    # the grain Reynolds number (resolved runs)
    rep = reynolds(d, rho, eta, D) if os.path.exists(fields) else []
    irep = int(np.argmax([b[1] for b in rep])) if rep else None
    extra = {}
    sj = os.path.join(d, "summary.json")
    if os.path.exists(sj):
        with open(sj) as f:
            sm = json.load(f)
        for k in ("status", "ranks", "steps", "rejected_steps", "wall_time", "steps_per_second", "last_dt", "cost"):
            if k in sm:
                extra[k] = sm[k]
    out = {
        "grains": int(mob.sum()), "D": D, "H0": H0, "H0_over_D": H0 / D, "R0_over_D": R0 / D, "a": H0 / R0,
        "W_over_D": W / D, "phi_mass": phi_mass, "phi_alpha": phi_alpha, "phi_inner": phi_inner, "drho_g_H0": scale,
        "T_visq": tv, "sqrt_D_over_g": tg, "probes": cols, "smooth": smooth,
        "pb_min": float(ps[imin] / scale), "t_pb_min": float(t[imin]), "t_pb_min_Tvisq": float(t[imin] / tv),
        "pb_max": float(ps[imax] / scale), "t_pb_max": float(t[imax]), "t_pb_max_Tvisq": float(t[imax] / tv),
        "pb_mean": float(pb.mean() / scale), "pb_end": float(ps[-1] / scale),
        "pb_first": float(ps[ifirst] / scale) if ifirst is not None else 0.0,
        "t_pb_first": float(t[ifirst]) if ifirst is not None else None,
        "t_pb_first_Tvisq": float(t[ifirst] / tv) if ifirst is not None else None,
        "pb_series": [[float(a), float(b / scale)] for a, b in zip(t[::max(1, len(t) // 200)],
                                                                   ps[::max(1, len(t) // 200)])],
        "front": fronts, "front_final": fronts[-1][1], "Ecx_max": ecx[ie][1], "t_Ecx_max": ecx[ie][0],
        "Ecx": ecx[::max(1, len(ecx) // 200)],
        "front_t": [[a, a / tg, a / tv, b] for a, b in fronts],
        "t_front_start": t_start, "t_front_start_sqrt_D_g": t_start / tg if t_start is not None else None,
        "R_inf": R_inf, "R_inf_over_R0": R_inf / R0, "H_inf_over_R0": dep["H_inf"] / R0,
        "H_inf_over_H0": dep["H_inf"] / H0, "H_wall0": H_wall0, "H_inf_over_H_wall0": dep["H_inf"] / H_wall0, "H_inf_over_D": dep["H_inf"] / D, "deposit_time": ts, **dep, **stop,
        "Re_p_max": rep[irep][1] if rep else float("nan"), "t_Re_p_max": rep[irep][0] if rep else float("nan"),
        "Re_p_max_all": max(b[2] for b in rep) if rep else float("nan"),
        "Re_p_p99_max": max(b[3] for b in rep) if rep else float("nan"),
        "Re_p_mean_max": max(b[4] for b in rep) if rep else float("nan"),
        "Re_p_series": rep,
        "max_overlap": float(s["dem_max_overlap"].max()) if "dem_max_overlap" in s.dtype.names else float("nan"),
        **extra,
    }
    with open(os.path.join(d, "column.json"), "w") as f:
        json.dump(out, f, indent=1)
    print(f"column: grains={out['grains']} H0/D={H0 / D:.2f} a={H0 / R0:.3f} phi_mass={phi_mass:.3f} "
          f"phi_alpha={phi_alpha:.3f} phi_inner={phi_inner:.3f} pb_min={out['pb_min']:+.4f}@{t[imin]:.3f}s({t[imin] / tv:.0f}Tv) "
          f"pb_max={out['pb_max']:+.4f}@{t[imax]:.3f}s({t[imax] / tv:.0f}Tv) pb_mean={out['pb_mean']:+.4f} "
          f"front_final={out['front_final']:.3f} Ecx_max={out['Ecx_max']:.4f}@{ecx[ie][0]:.3f}s "
          f"Tvisq={tv:.3g}s sqrt(D/g)={tg:.4f}s")
    print(f"deposit: t={ts:.3f}s R_inf/R0={R_inf / R0:.3f} H_inf/R0={out['H_inf_over_R0']:.3f} "
          f"H_inf/H0={out['H_inf_over_H0']:.3f} H_inf/H_wall0={out['H_inf_over_H_wall0']:.3f} flank={dep['flank_angle_deg']:.1f}deg ({dep['flank_fit_bins']} bins) "
          f"plateau={dep['plateau'] / D:.0f}D shape={dep['shape']} "
          f"t_stop(1e-3 Ek_max)={stop['t_stop']:.3f}s({stop['t_stop_sqrt_D_g']:.1f}sqrt(D/g),{stop['t_stop_Tvisq']:.0f}Tv"
          f"{',at the end' if stop['t_stop_at_end'] else ''}) "
          f"t_stop(1e-2)={stop['t_stop_1e-2']:.3f}s({stop['t_stop_1e-2_sqrt_D_g']:.1f}) "
          f"t_front99={stop['t_front99']:.3f}s({stop['t_front99_sqrt_D_g']:.1f}) "
          f"Re_p_max={out['Re_p_max']:.3f}@{out['t_Re_p_max']:.3f}s(all cells {out['Re_p_max_all']:.3f}; p99 {out['Re_p_p99_max']:.3f}, mean {out['Re_p_mean_max']:.3f}) max_overlap={out['max_overlap']:.5f}")
    plot(d, out, D)


def plot(d, out, D):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    ft = np.array(out["front_t"])
    fig, ax = plt.subplots(2, 2, figsize=(10, 7))
    ax[0, 0].plot(ft[:, 1], ft[:, 3], "o-", ms=3)
    ax[0, 0].set_xlabel("t / sqrt(D/g)")
    ax[0, 0].set_ylabel("(x_f - R0)/R0")
    ax[0, 1].plot(ft[:, 2], ft[:, 3], "o-", ms=3)
    ax[0, 1].set_xlabel("t / T_visq")
    ax[0, 1].set_ylabel("(x_f - R0)/R0")
    e = np.array(out["Ecx"])
    ax[1, 0].plot(e[:, 0] / out["sqrt_D_over_g"], e[:, 1])
    ax[1, 0].set_xlabel("t / sqrt(D/g)")
    ax[1, 0].set_ylabel("E_cx / (m g D)")
    ax[1, 1].step(np.array(out["profile_x"]) / D, np.array(out["profile_h"]) / D, where="mid")
    ax[1, 1].axhline(out["H0"] / D, ls=":", c="k")
    ax[1, 1].axvline(out["R0_over_D"], ls=":", c="k")
    ax[1, 1].set_aspect("equal")
    ax[1, 1].set_xlabel("x / D")
    ax[1, 1].set_ylabel("h / D")
    ax[1, 1].set_title(f"{out['shape']}, flank {out['flank_angle_deg']:.1f} deg", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "column.png"), dpi=90)
    plt.close(fig)


if __name__ == "__main__":
    main()
