#!/usr/bin/python3
"""Issue 6 cross-check: the permeability of cases/permeability_crosscheck/packing_N200.h5 from
the resolved solver (runs of ibm.ini at several resolutions) against the pore network
(porenet.ini), written as a Markdown table.

Usage: permeability_crosscheck.py OUT PORENET_DIR IBM_DIR... [--sc SC_LOG]
  PORENET_DIR  output folder of `ibmdem run porenet.ini` (summary.json)
  IBM_DIR      output folders of `ibmdem run ibm.ini` at different nx (fields_*.h5, summary.json)
  SC_LOG       output of `IBM_PERM_FULL=1 test_ibm_perm` (lines "SC c ..."), optional
Writes OUT.md and OUT.json; prints the table.

kappa_IBM = mu <w> / (rho f): <w> the mean of w over the whole box at the last snapshot, which
is the flux through any z cross-section per unit area (discrete continuity; the snapshot's
cell-centred velocity is the mean of the two faces of each cell, so its box mean equals the
faces' mean in a periodic box). kappa/d^2 with d = 2 x the mean radius, for both solvers."""
import glob, json, os, sys
import h5py
import numpy as np

args = sys.argv[1:]
sc_log = None
if "--sc" in args:
    i = args.index("--sc")
    sc_log = args[i + 1]
    del args[i:i + 2]
out, pn_dir, ibm_dirs = args[0], args[1], args[2:]

with h5py.File("cases/permeability_crosscheck/packing_N200.h5") as f:
    r = f["radius"][...]
    L = float(f.attrs["L"])
d = 2 * r.mean()
phi = (4 / 3 * np.pi * r ** 3).sum() / L ** 3

pn = json.load(open(os.path.join(pn_dir, "summary.json")))["porenet"]
k_pn = pn["permeability_z"] / d ** 2

rows = []
for dd in ibm_dirs:
    s = json.load(open(os.path.join(dd, "summary.json")))
    inp = s["input"] if isinstance(s["input"], str) else ""
    snaps = sorted(glob.glob(os.path.join(dd, "fields_*.h5")))
    w, t = [], []
    for fn in snaps[-2:]:
        with h5py.File(fn) as f:
            w.append(float(f["velocity"][..., 2].mean()))
            t.append(float(f.attrs["time"]))
            nx = f["pressure"].shape[2]
            sf = float(f["solid_fraction"][...].mean())
    # the run's own parameters, from its resolved input
    res = open(os.path.join(dd, "input.ini")).read()
    nu = rho = fz = None
    sec = None
    for line in res.splitlines():
        line = line.split(";")[0].strip()
        if line.startswith("["):
            sec = line.strip("[]")
        elif "=" in line and sec == "fluid":
            k, v = (x.strip() for x in line.split("=", 1))
            if k == "nu": nu = float(v)
            if k == "rho": rho = float(v)
            if k == "body_force": fz = float(v.split()[2])
    kappa = rho * nu * w[-1] / (rho * fz)
    rows.append(dict(nx=nx, dpd=d / (L / nx), kappa_over_d2=kappa / d ** 2, ratio=kappa / d ** 2 / k_pn,
                     change=abs(w[-1] - w[-2]) / w[-1], dt_snap=t[-1] - t[-2], solid_fraction=sf,
                     re=w[-1] * d / nu, wall=s["wall_time"], steps=s["steps"], ranks=s["ranks"],
                     wall_ibm=s.get("ibm", {}).get("wall_time")))
rows.sort(key=lambda x: x["nx"])

# Extrapolation kappa(h) = kappa_0 + C h^p through the three finest (p from the three levels);
# with two levels, p = 1 (the immersed boundary's first order, docs/validation.md).
extrap = None
if len(rows) >= 2:
    h = np.array([1 / x["dpd"] for x in rows[-3:]])
    k = np.array([x["kappa_over_d2"] for x in rows[-3:]])
    p = 1.0
    if len(rows) >= 3:
        from math import log
        # solve (k0 - k1)/(k1 - k2) = (h0^p - h1^p)/(h1^p - h2^p) for p by bisection
        q = (k[0] - k[1]) / (k[1] - k[2])
        g = lambda p: (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - q
        lo, hi = 0.05, 6.0
        if g(lo) * g(hi) < 0:
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                if g(lo) * g(mid) <= 0: hi = mid
                else: lo = mid
            p = 0.5 * (lo + hi)
        else:
            p = float("nan")
    if np.isfinite(p):
        C = (k[-2] - k[-1]) / (h[-2] ** p - h[-1] ** p)
        k0 = k[-1] - C * h[-1] ** p
        k0_first = k[-1] - (k[-2] - k[-1]) / (h[-2] - h[-1]) * h[-1]
        extrap = dict(order=p, kappa_over_d2=k0, ratio=k0 / k_pn, kappa_over_d2_order1=k0_first,
                      ratio_order1=k0_first / k_pn)

lines = []
lines.append(f"packing: {len(r)} spheres, radii {r.min():.4f}-{r.max():.4f} (mean {r.mean():.6f}), "
             f"solid fraction {phi:.4f}, periodic cube L = {L:.6f}; d = 2 x mean radius = {d:.6f}")
lines.append(f"pore network: kappa_z/d^2 = {k_pn:.6e} ({pn.get('pores')} pores, "
             f"{sum(pn.get(k, 0) for k in ('time_triangulation', 'time_network', 'time_factorisation', 'time_solves')):.3f} s)")
lines.append("")
lines.append("| nx | D/dx | kappa_IBM/d^2 | kappa_IBM/kappa_PFV | mean solid fraction (phi = %.3f) | Re_d | last change of <w> | steps | wall (ranks) |" % phi)
lines.append("|---|---|---|---|---|---|---|---|---|")
for x in rows:
    lines.append(f"| {x['nx']} | {x['dpd']:.2f} | {x['kappa_over_d2']:.4e} | {x['ratio']:.3f} | {x['solid_fraction']:.4f} | "
                 f"{x['re']:.3f} | {x['change']:.1e} over {x['dt_snap']:.2f} | {x['steps']} | {x['wall']:.0f} s ({x['ranks']}) |")
if extrap:
    lines.append(f"| extrapolated (order {extrap['order']:.2f}) | inf | {extrap['kappa_over_d2']:.4e} | {extrap['ratio']:.3f} | | | | | |")
    lines.append(f"| extrapolated (order 1, two finest) | inf | {extrap['kappa_over_d2_order1']:.4e} | {extrap['ratio_order1']:.3f} | | | | | |")
if sc_log:
    lines.append("")
    lines.append("Simple cubic array (tests/test_ibm_perm.c), against Zick & Homsy (1982):")
    lines.append("")
    lines.append("| c | D/dx | K | K_ZH | kappa_IBM/kappa_ZH | wall |")
    lines.append("|---|---|---|---|---|---|")
    for line in open(sc_log):
        if line.startswith("SC c"):
            t = line.split()
            lines.append(f"| {t[2]} | {float(t[4]):.2f} | {float(t[6]):.4f} | {t[8]} | {float(t[12]):.4f} | {float(t[14]):.1f} s |")
text = "\n".join(lines)
print(text)
open(out + ".md", "w").write(text + "\n")
json.dump(dict(kappa_pfv_over_d2=k_pn, runs=rows, extrapolated=extrap), open(out + ".json", "w"), indent=1)
