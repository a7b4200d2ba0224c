#!/usr/bin/python3
"""Cross-check of ibmdem against OpenFOAM on the simple cubic array of spheres.

One sphere (D = 1) at the centre of a periodic cube of side L = (pi/(6c))^(1/3) D, fluid of
nu = rho = 1 driven along x by a uniform pressure gradient rho f (the same drive in both codes,
so the Reynolds number is an outcome of each run).  Both cases are generated here from that one
geometry:

- ibmdem: `[ibm] sphere1 = fixed ...` in a triply periodic box of n^3 cells (one period, or 2 x 2 x 2
  periods and spheres for the dense arrays, whose period cannot hold a sphere and its forcing band
  at D/dx = 8-18), `body_force = f 0 0`
  (on the whole box, solid included), `forcing_time = 0.2`, explicit viscous term (adaptive step at
  dt nu/dx^2 <= 0.2, `fourier = 0.6`, and CFL <= 0.5: a steady state that does not depend on dt),
  the chosen `radius_correction`; run from rest until `time.steady_tol = 1e-3` (K then within
  0.04 % of its converged value: docs/validation.md).  From `summary.json`: the force
  ibm.sphere1.force_x, the superficial velocity fluid.superficial_velocity_x (the box mean of u,
  by discrete continuity the flux through any cross-section per unit area; checked against the
  last snapshot's mean u) and fluid.reynolds.
- OpenFOAM: blockMesh (N^3 cells, cyclic pairs on the cube faces) + snappyHexMesh (the sphere as
  a searchableSphere, one level of refinement at its surface and within 0.15 D of it, three
  boundary layers), simpleFoam (laminar, SIMPLEC) with the drive as a vectorSemiImplicitSource of
  f per unit volume on the fluid cells, to its residual tolerance.  The force is the `forces`
  function object's total on the sphere patch (the periodic part of the pressure and the viscous
  stress) plus the mean gradient's share rho f (L^3 - V_fluid) (the drive on the volume the
  mesh leaves to the sphere), U = volIntegrate(U)_x / L^3.

K = F_x / (6 pi mu a U) (Zick & Homsy's definition), Re = U D / nu with U the superficial
velocity.  CPU time: getrusage of the children (user + system), meshing included for OpenFOAM
(also given apart).

The random fixed bed (cases bed30_stokes, bed30_re20; BED_CASES below): 30 spheres of bed30.csv
(make_bed.py) in a periodic cube, the flow rate held in both codes, per-sphere forces compared
with OpenFOAM's finest mesh (bed_table.md, bed_table.json, bed.png).  The sphere in a walled duct
(duct.py: duct_re20, duct_re100, duct_re250) and the sphere oscillating in a closed box, OpenFOAM
on a moving mesh (oscillating.py: osc_sphere, osc_sphere_dt2, osc_sphere_small) have their own
modules.

  crosscheck.py run CASE [--code ibm|foam] [--levels 0,1,2] OUT   (one result.json per run)
  crosscheck.py report OUT                                        (table.md, table.json, figure)
"""
import argparse
import json
import math
import os
import re
import sys

from bed import BED_CASES, report_bed, run_foam_bed, run_ibm_bed
from duct import DUCT_CASES, report_duct, run_foam_duct, run_ibm_duct
from oscillating import OSC_CASES, report_osc, run_foam_osc, run_ibm_osc
from common import (ROOT, cached_or_fresh, cpu_of, periodic_cube_ini, find_dat, foam_case, foam_env, foam_mesh,
                    ibm_method_keys, last_vector, plot_speed_error, richardson, write_report)

# Zick & Homsy (1982) Table 2 (K of the simple cubic array in Stokes flow)
K_ZH = {0.064: 2.810, 0.216: 7.442, 0.343: 15.4}

# The cases.  f: the drive (body acceleration along x, D = nu = rho = 1).  Stokes: f sets
# Re = 0.01 with Zick & Homsy's K.  Re 10 and 50: f gives Re within a few % of the target with
# the K of the OpenFOAM runs (the measured Re of every run is in the table).
# ibm_n: cells per period (D/dx = n/L); foam_N: blockMesh cells per side (surface cells
# D/dx = 2N/L after one level of refinement).  Each series has a constant ratio 1.5.
CASES = {
    "sc064_stokes": dict(c=0.064, re_target=0.01, ibm_n=[16, 24, 36, 54], foam_N=[8, 12, 18, 27]),
    "sc064_re10": dict(c=0.064, re_target=10, ibm_n=[16, 24, 36], foam_N=[8, 12, 18, 27]),
    "sc064_re50": dict(c=0.064, re_target=50, ibm_n=[16, 24, 36], foam_N=[8, 12, 18, 27]),
    # denser arrays: a period holds a sphere and its band only from L/dx >= D/dx + 6.5 (n >= 26 at
    # c = 0.216, 47 at 0.343), so ibmdem's box holds 2 x 2 x 2 periods (n cells across the box)
    "sc216_stokes": dict(c=0.216, re_target=0.01, periods=2, ibm_n=[22, 32, 48, 72], foam_N=[8, 12, 18, 27]),
    "sc343_stokes": dict(c=0.343, re_target=0.01, periods=2, ibm_n=[19, 28, 42, 63], foam_N=[8, 12, 18, 27]),
}
# drives measured for the finite Reynolds numbers (see CASES); Stokes from K_ZH
DRIVE = {"sc064_re10": 33.6, "sc064_re50": 186.5}


def period(c):
    return (math.pi / (6.0 * c)) ** (1.0 / 3.0)


def drive(name):
    cs = CASES[name]
    if name in DRIVE:
        return DRIVE[name]
    L = period(cs["c"])
    return K_ZH[cs["c"]] * 3.0 * math.pi * cs["re_target"] / L ** 3


# ---------------------------------------------------------------- ibmdem

IBM_INI = """# generated by bench/crosscheck/crosscheck.py: simple cubic array, c = {c}, one period
{head}body_force = {f!r} 0 0
reynolds_length = 1
fourier = 0.6
cfl = 0.5

[ibm]
{spheres}
{method}

[time]
t_end = {t_end}
steady_tol = {steady_tol}

[output]
fields_every = {t_end}
"""


def run_ibm(name, n, corr, out):
    import h5py
    import numpy as np
    cs = CASES[name]
    c, L, f = cs["c"], period(cs["c"]), drive(name)
    m = cs.get("periods", 1)  # periods per side of the box
    B = m * L
    centres = [((i + 0.5) * L, (j + 0.5) * L, (k + 0.5) * L) for i in range(m) for j in range(m) for k in range(m)]
    spheres = "\n".join("sphere%d = fixed center %r %r %r diameter 1" % ((q + 1,) + x) for q, x in enumerate(centres))
    d = os.path.join(out, name, "ibm_%s_n%d" % (corr, n))
    res = os.path.join(d, "result.json")
    cached = cached_or_fresh(d)
    if cached:
        return cached
    ini = os.path.join(d, "case.ini")
    with open(ini, "w") as fh:
        fh.write(IBM_INI.format(head=periodic_cube_ini(n, B), c=c, f=f, spheres=spheres, method=ibm_method_keys(corr), t_end=8, steady_tol=1e-3))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    binary = os.path.join(ROOT, os.environ.get("BUILD", "build"), "ibmdem")
    cpu, wall = cpu_of([binary, "run", ini, "--out", os.path.join(d, "out")], d, os.path.join(d, "log"), env)
    s = json.load(open(os.path.join(d, "out", "summary.json")))
    # the mean drag of the spheres summary.json lists (the first four; by symmetry they all have it)
    fs = [s["ibm"]["sphere%d" % (q + 1)]["force_x"] for q in range(min(4, len(centres)))]
    fx = sum(fs) / len(fs)
    # the box mean of the cell-centred u of the last snapshot (each the mean of its two faces,
    # so the same mean in a periodic box): a check of summary.json's superficial velocity
    snaps = sorted(x for x in os.listdir(os.path.join(d, "out")) if re.match(r"fields_\d+\.h5$", x))
    with h5py.File(os.path.join(d, "out", snaps[-1]), "r") as h:
        U_h5 = float(np.mean(h["velocity"][..., 0]))
    U = s["fluid"].get("superficial_velocity_x", U_h5)
    if abs(U / U_h5 - 1) > 1e-9:
        sys.exit("crosscheck: %s: superficial_velocity_x %.12g is not the snapshot's mean u %.12g" % (d, U, U_h5))
    r = dict(code="ibmdem", method=corr, case=name, c=c, L=L, f=f, n=n, periods=m, dpdx=n / B, U=U, Fx=fx,
             force_spread=(max(fs) - min(fs)) / abs(fx), K=fx / (3 * math.pi * U), Re=s["fluid"].get("reynolds", U),
             balance=fx / (f * L ** 3), cpu=cpu, wall=wall,
             steps=s.get("steps"), t=s.get("time"), status=s.get("status"))
    json.dump(r, open(res, "w"), indent=1)
    for x in os.listdir(os.path.join(d, "out")):  # the final checkpoint: up to 50 MB, not needed
        if x.startswith("checkpoint_"):
            os.remove(os.path.join(d, "out", x))
    return r


# ---------------------------------------------------------------- OpenFOAM

def run_foam(name, N, out):
    cs = CASES[name]
    c, L, f = cs["c"], period(cs["c"]), drive(name)
    d = os.path.join(out, name, "foam_N%d" % N)
    res = os.path.join(d, "result.json")
    cached = cached_or_fresh(d)
    if cached:
        return cached
    foam_case(d, L, N, f)
    env = foam_env()
    cpu_mesh, cells, vol = foam_mesh(d, env)
    sn = open(os.path.join(d, "log.snappyHexMesh")).read()
    # the last layer table: patch, faces, layers, overall thickness [m] and [% of the target]
    layers = re.findall(r"^sphere\s+\d+\s+([0-9.]+)\s+([0-9.eE+-]+)\s+([0-9.]+)\s*$", sn, re.M)[-1:]
    cpu_solve, wall = cpu_of(["simpleFoam"], d, os.path.join(d, "log.simpleFoam"), env)
    log = open(os.path.join(d, "log.simpleFoam")).read()
    iters = len(re.findall(r"^Time = ", log, re.M))
    converged = "SIMPLE solution converged" in log
    fr = last_vector(find_dat(d, "forces", "force"))  # time, total(3), pressure(3), viscous(3)
    fl = last_vector(find_dat(d, "flux", "volFieldValue"))  # time, integral of U (3)
    F_patch = fr[1]
    Fx = F_patch + f * (L ** 3 - vol)
    U = fl[1] / L ** 3
    r = dict(code="OpenFOAM", method="snappy", case=name, c=c, L=L, f=f, N=N, dpdx=2 * N / L, cells=cells,
             fluid_volume=vol, solid_volume_ratio=(L ** 3 - vol) / (math.pi / 6), layers=layers, U=U, Fx=Fx,
             K=Fx / (3 * math.pi * U), Re=U, balance=F_patch / (f * vol), iterations=iters, converged=converged,
             cpu=cpu_mesh + cpu_solve, cpu_mesh=cpu_mesh, cpu_solve=cpu_solve, wall=wall)
    json.dump(r, open(res, "w"), indent=1)
    return r


# ---------------------------------------------------------------- the random fixed bed

# The random bed (bench/crosscheck/bed30.csv, written by make_bed.py: 30 spheres of D = 1,
# phi = 0.40, smallest surface gap 0.1 D, triply periodic cube of side L = 3.399).  The flow
# rate is held in both codes (Re = U D / nu, U the superficial velocity): ibmdem
# `flow_rate_direction = x` with `reynolds`; OpenFOAM the fvOption meanVelocityForce with Ubar
# = U L^3 / V_fluid (V_fluid that of the mesh, from checkMesh), so that both carry the same flux.
# ibm_n: cells per side (D/dx = n/L); foam_N: blockMesh cells per side (surface cells D/dx =
# 2N/L after one level of refinement).
def series_of(runs):
    runs = sorted(runs, key=lambda r: r["dpdx"])
    ex = richardson([1 / r["dpdx"] for r in runs[-3:]], [r["K"] for r in runs[-3:]]) if len(runs) >= 3 else None
    return runs, ex


def finite_re_reference(name, cs, allruns):
    """The reference K at finite Re: OpenFOAM's K(Re)/K(Stokes) on the same meshes (the error of the
    geometry, most of each mesh's error, cancels in it), extrapolated, times Zick & Homsy's K.
    Returns (K, description, the ratio's series and extrapolation)."""
    st = [n for n, x in CASES.items() if x["c"] == cs["c"] and x["re_target"] < 1]
    foam = lambda case: {r["N"]: r for r in allruns if r["case"] == case and r["code"] == "OpenFOAM"}
    if not st:
        return None, "none", None
    fr, fs = foam(name), foam(st[0])
    Ns = sorted(set(fr) & set(fs))
    rat = [(N, fr[N]["K"] / fs[N]["K"]) for N in Ns]
    ex = richardson([1.0 / N for N, _ in rat[-3:]], [q for _, q in rat[-3:]]) if len(rat) >= 3 else None
    if not ex:
        return None, "none (OpenFOAM's K(Re)/K(Stokes) series: %s)" % rat, dict(series=rat, extrapolation=None)
    K = K_ZH[cs["c"]] * ex["K"]
    desc = ("Zick & Homsy's Stokes K %.3f times OpenFOAM's K(Re)/K(Stokes) on the same meshes, %s, extrapolated "
            "(order %.2f) to %.5f: K = %.4f" % (K_ZH[cs["c"]], ", ".join("N = %d %.5f" % x for x in rat),
                                               ex["p"], ex["K"], K))
    return K, desc, dict(series=rat, extrapolation=ex)


def summary_lines(table):
    """one row per case and D/dx: K, error and CPU seconds of each code side by side"""
    keys = ["OpenFOAM/snappy", "ibmdem/calibrated", "ibmdem/none", "ibmdem/gaps"]
    out = ["## Summary: K, K/K_ref - 1, CPU seconds (one core)", "",
           "| case | K_ref | D/dx | " + " | ".join(keys) + " |", "|---|---|---|" + "---|" * len(keys)]
    for name, t in table.items():
        rows = {}
        for k in keys:
            for r in t["series"].get(k, {}).get("runs", []):
                rows.setdefault(round(r["dpdx"], 2), {})[k] = r
        for dpdx in sorted(rows):
            cells = []
            for k in keys:
                r = rows[dpdx].get(k)
                cells.append("%.4f, %+.2f %%, %.1f s" % (r["K"], 100 * (r["K"] / t["reference"] - 1), r["cpu"])
                             if r and t["reference"] else "")
            out.append("| %s | %s | %.2f | %s |" % (name, "%.4f" % t["reference"] if t["reference"] else "-", dpdx,
                                                     " | ".join(cells)))
        for k in keys:
            ex = t["series"].get(k, {}).get("extrapolation")
            if ex and t["reference"]:
                out.append("| %s | | Richardson | %s |" % (name, " | ".join(
                    "%.4f, %+.2f %%, order %.2f" % (ex["K"], 100 * (ex["K"] / t["reference"] - 1), ex["p"])
                    if kk == k else "" for kk in keys)))
    return out + [""]


def report(out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    allruns = []
    for name in CASES:
        cd = os.path.join(out, name)
        if not os.path.isdir(cd):
            continue
        for x in sorted(os.listdir(cd)):
            p = os.path.join(cd, x, "result.json")
            if os.path.exists(p):
                allruns.append(json.load(open(p)))
    lines, table = [], {}
    names = [n for n in CASES if any(r["case"] == n for r in allruns)]
    if not names:
        return
    ncols = min(3, len(names))
    nrows = (len(names) + ncols - 1) // ncols
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.2 * ncols, 4.4 * nrows), squeeze=False)
    for ax in axes.flat[len(names):]:
        ax.set_visible(False)
    for ax, name in zip(axes.flat, names):
        cs = CASES[name]
        groups = {}
        for r in allruns:
            if r["case"] == name:
                groups.setdefault((r["code"], r["method"]), []).append(r)
        ser = {k: series_of(v) for k, v in groups.items()}
        stokes = cs["re_target"] < 1
        ratio = None
        if stokes:
            ref, refname = K_ZH[cs["c"]], "Zick & Homsy (1982) K = %.3f" % K_ZH[cs["c"]]
        else:
            ref, refname, ratio = finite_re_reference(name, cs, allruns)
        lines.append("### %s: c = %.3f, L = %.5f D, drive f D^3/nu^2 = %.6g (Re = U D/nu, U superficial)"
                     % (name, cs["c"], period(cs["c"]), drive(name)))
        lines.append("")
        lines.append("Reference: %s." % refname)
        lines.append("")
        lines.append("| code | method | resolution | D/dx | cells | Re | K | K/K_ref - 1 | force balance - 1 | CPU s | steady |")
        lines.append("|---|---|---|---|---|---|---|---|---|---|---|")
        table[name] = dict(reference=ref, reference_name=refname, series={}, foam_re_ratio=ratio)
        for (code, meth), (runs, ex) in sorted(ser.items()):
            for r in runs:
                err = r["K"] / ref - 1 if ref else float("nan")
                resol = "N = %d" % r["N"] if code == "OpenFOAM" else "n = %d" % r["n"]
                cells = r.get("cells", r.get("n", 0) ** 3)
                cpu = "%.1f" % r["cpu"] + (" (mesh %.1f)" % r["cpu_mesh"] if "cpu_mesh" in r else "")
                st = ("%d it, %s" % (r["iterations"], "converged" if r["converged"] else "NOT converged")
                      if code == "OpenFOAM" else "%s steps, t = %.3g" % (r["steps"], r["t"]))
                lines.append("| %s | %s | %s | %.2f | %d | %.4g | %.5f | %+.3f %% | %+.1e | %s | %s |"
                             % (code, meth, resol, r["dpdx"], cells, r["Re"], r["K"], 100 * err,
                                r["balance"] - 1, cpu, st))
            exs = ("extrapolated (last three, Richardson): K = %.5f (%+.3f %% of the reference), observed order %.2f"
                   % (ex["K"], 100 * (ex["K"] / ref - 1) if ref else float("nan"), ex["p"]) if ex
                   else "no Richardson extrapolation (fewer than three runs or a non-monotone series)")
            lines.append("| %s | %s | %s | | | | | | | | |" % (code, meth, exs))
            table[name]["series"]["%s/%s" % (code, meth)] = dict(runs=runs, extrapolation=ex)
            if ref:
                plot_speed_error(ax, runs, lambda r: 100 * abs(r["K"] / ref - 1), code, meth)
        lines.append("")
        ax.set_title("%s (ref: %s)" % (name, "Zick & Homsy" if stokes else "Z & H x OpenFOAM K(Re)/K(0)"),
                     fontsize=9)
        ax.set_xlabel("CPU seconds (one core)")
        ax.set_ylabel("|K/K_ref - 1| (%)")
        ax.axhline(1.0, color="grey", lw=0.5)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    lines = summary_lines(table) + lines
    write_report(out, "speed_error", "table", fig, lines, table)


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("run")
    a.add_argument("case", choices=sorted(CASES) + sorted(BED_CASES) + sorted(DUCT_CASES) + sorted(OSC_CASES))
    a.add_argument("out")
    a.add_argument("--code", choices=["ibm", "foam", "both"], default="both")
    a.add_argument("--levels", default=None, help="indices into the case's series, e.g. 0,1,2")
    a.add_argument("--methods", default="calibrated", help="ibmdem methods (common.IBM_METHODS), e.g. none,calibrated,gaps,narrow")
    b = sub.add_parser("report")
    b.add_argument("out")
    args = ap.parse_args()
    if args.cmd == "report":
        report(args.out)
        report_bed(args.out)
        report_duct(args.out)
        report_osc(args.out)
        return
    pick = lambda lst: [lst[int(i)] for i in args.levels.split(",")] if args.levels else lst
    if args.case in BED_CASES:
        cs = BED_CASES[args.case]
        if args.code in ("foam", "both"):
            for N in pick(cs["foam_N"]):
                r = run_foam_bed(args.case, N, args.out)
                print("%s OpenFOAM N = %d: mean K = %.5f, Re = %.4g, cells %d, CPU %.1f s"
                      % (args.case, N, r["Kmean"], r["Re"], r["cells"], r["cpu"]))
        if args.code in ("ibm", "both"):
            for meth in args.methods.split(","):
                for n in pick(cs["ibm_n"]):
                    r = run_ibm_bed(args.case, n, meth, args.out)
                    print("%s ibmdem %s n = %d: mean K = %.5f, Re = %.4g, CPU %.1f s"
                          % (args.case, meth, n, r["Kmean"], r["Re"], r["cpu"]))
        return
    if args.case in DUCT_CASES:
        cs = DUCT_CASES[args.case]
        if args.code in ("foam", "both"):
            for N in pick(cs["foam_N"]):
                r = run_foam_duct(args.case, N, args.out)
                print("%s OpenFOAM N = %d: C_D = %.5f, L_w = %.3f, Re = %.4g, cells %d, CPU %.1f s, %s"
                      % (args.case, N, r["CD"], r["Lw"], r["Re"], r["cells"], r["cpu"],
                         "converged" if r["converged"] else "NOT converged"))
        if args.code in ("ibm", "both"):
            for meth in args.methods.split(","):
                for n in pick(cs["ibm_cpd"]):
                    r = run_ibm_duct(args.case, n, meth, args.out)
                    print("%s ibmdem %s D/dx = %d: C_D = %.5f, L_w = %.3f, Re = %.4g, CPU %.1f s, %s"
                          % (args.case, meth, n, r["CD"], r["Lw"], r["Re"], r["cpu"], r["status"]))
        return
    if args.case in OSC_CASES:
        cs = OSC_CASES[args.case]
        if args.code in ("foam", "both"):
            for N in pick(cs["foam_N"]):
                r = run_foam_osc(args.case, N, args.out)
                print("%s OpenFOAM N = %d: C_u/exact = %.4f, C_a/exact = %.4f, cells %d, CPU %.1f s"
                      % (args.case, N, r["Cu_exact"], r["Ca_exact"], r["cells"], r["cpu"]))
        if args.code in ("ibm", "both"):
            for meth in args.methods.split(","):
                for n in pick(cs["ibm_cpd"]):
                    r = run_ibm_osc(args.case, n, meth, args.out)
                    print("%s ibmdem %s D/dx = %d: C_u/exact = %.4f, C_a/exact = %.4f, CPU %.1f s"
                          % (args.case, meth, n, r["Cu_exact"], r["Ca_exact"], r["cpu"]))
        return
    cs = CASES[args.case]
    if args.code in ("foam", "both"):
        for N in pick(cs["foam_N"]):
            r = run_foam(args.case, N, args.out)
            print("%s OpenFOAM N = %d: K = %.5f, Re = %.4g, cells %d, CPU %.1f s" % (args.case, N, r["K"], r["Re"],
                                                                                    r["cells"], r["cpu"]))
    if args.code in ("ibm", "both"):
        for meth in args.methods.split(","):
            for n in pick(cs["ibm_n"]):
                r = run_ibm(args.case, n, meth, args.out)
                print("%s ibmdem %s n = %d: K = %.5f, Re = %.4g, CPU %.1f s" % (args.case, meth, n, r["K"], r["Re"],
                                                                              r["cpu"]))


if __name__ == "__main__":
    main()
