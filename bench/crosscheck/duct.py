"""The sphere in a walled duct of the cross-check (cases duct_re20, duct_re100, duct_re250 of
bench/crosscheck/crosscheck.py; docs/validation.md "Sphere in a square duct").

Geometry (D = nu = rho = 1): a square duct of side H = 4 D, no-slip walls at y, z = 0 and H,
periodic along x with period L = 10 D, one fixed sphere at the centre (5, 2, 2).  The flow rate
is held in both codes: the bulk velocity U_b = Q/H^2 (ibmdem: `flow_rate_direction = x` with
`reynolds` = U_b, its superficial velocity being the flux per unit cross-section; OpenFOAM: the
fvOption meanVelocityForce with Ubar = U_b H^2 L / V_fluid, V_fluid the mesh's fluid volume).
The sphere sits in the duct's Poiseuille profile, whose undisturbed centreline velocity is
U_c = 2.0962 U_b (square duct, Shah & London 1978); Re = U_c D / nu (20, 100, 250) and the drag
coefficient C_D = F_x / (rho U_c^2 pi D^2 / 8).  F_x is the drag along the duct including
the mean pressure gradient's share on the sphere's volume (as for the arrays and the bed).

Reported per run: C_D, the lateral force (non-zero once the wake loses its axisymmetry), the
recirculation length L_w / D behind the sphere (from its rear x_c + D/2 to where u on the duct's
axis turns positive again; 0 without a recirculation), u_ahead / U_c on the axis 2 D ahead of
the centre (the approach flow, slowed by the wake of the sphere's periodic image 10 D upstream),
CPU seconds; for ibmdem the drift of the drag (its distance from the limit of its approach, for a
run stopped at t_end), for OpenFOAM whether SIMPLE converged.  Reference: OpenFOAM's
series extrapolated (Richardson) where its increments shrink, else its finest mesh; the unbounded
sphere's C_D (Clift, Grace & Weber 1978) is given beside it as a context only: the sphere in the
wake of its periodic image has a lower one."""
import csv
import json
import math
import os
import re
import sys

from common import (ROOT, cached_or_fresh, cpu_of, dat_rows, drop_snapshots, find_dat, foam_case, foam_env, foam_mesh,
                    foam_solve_at_flux, foam_write, ibm_method_keys, last_vector, plot_speed_error, richardson,
                    walled_box_ini, write_report)

H, LX = 4.0, 10.0
CENTRE = (5.0, 2.0, 2.0)
UC_UB = 2.0962  # centreline over bulk velocity of the laminar square duct (Shah & London 1978)

# t_end: the longest ibmdem run (D^2/nu; 40, 100, 150 D/U_c), which stops earlier once its drag,
# flux and drive change by less than steady_tol = 5e-4 Re_c/20 per unit time (the same
# relative change per D/U_c at every Re).  ibm_cpd: ibmdem cells per D (a uniform grid of 10 cpd x
# 4 cpd x 4 cpd cells); foam_N: blockMesh cells per D (D/dx = 2 N at the sphere after one level of
# refinement)
DUCT_CASES = {
    "duct_re20": dict(re_c=20.0, t_end=2.0, ibm_cpd=[8, 12, 16, 24], foam_N=[6, 8, 12]),
    "duct_re100": dict(re_c=100.0, t_end=1.0, ibm_cpd=[8, 12, 16], foam_N=[6, 8, 12]),
    "duct_re250": dict(re_c=250.0, t_end=0.6, ibm_cpd=[8, 12, 16], foam_N=[6, 8, 12]),
}


def clift_cd(re):
    """the unbounded sphere's standard drag curve (Clift, Grace & Weber 1978, Table 5.2), context only"""
    w = math.log10(re)
    if re <= 20:
        return 24 / re * (1 + 0.1315 * re ** (0.82 - 0.05 * w))
    if re <= 260:
        return 24 / re * (1 + 0.1935 * re ** 0.6305)
    return 10 ** (1.6435 - 1.1242 * w + 0.1558 * w * w)


def ahead(xs, us):
    """u on the axis 2 D ahead of the sphere's centre (linear interpolation between the samples)"""
    x0 = CENTRE[0] - 2.0
    for (xa, ua), (xb, ub) in zip(zip(xs, us), zip(xs[1:], us[1:])):
        if xa <= x0 <= xb:
            return ua + (ub - ua) * (x0 - xa) / (xb - xa)
    return float("nan")


def recirculation(xs, us):
    """L_w / D from the axis samples (x, u) behind the sphere, x >= its rear: 0 if u > 0 there,
    else the first sign change from - to + (linear interpolation) less the rear's x"""
    rear = CENTRE[0] + 0.5
    pts = [(x, u) for x, u in zip(xs, us) if x >= rear]
    umax = max((abs(u) for _, u in pts), default=0.0)
    if all(u > -1e-3 * umax for _, u in pts):  # no backflow (the samples at the surface are ~0)
        return 0.0
    neg = False
    for (x0, u0), (x1, u1) in zip(pts, pts[1:]):
        neg = neg or u0 < 0
        if neg and u0 < 0 <= u1:
            return x0 + (x1 - x0) * (-u0) / (u1 - u0) - rear
    return float("nan")


# ---------------------------------------------------------------- ibmdem

def drag_drift(series):
    """the relative distance of a run's last drag from the limit of its approach (Aitken's delta-squared
    through the drag at t_end - 2 tau, t_end - tau, t_end, tau = t_end/15; 0 if not monotone)"""
    rows = list(csv.DictReader(open(series)))
    t = [float(r["time"]) for r in rows]
    fx = [float(r["s1_fx"]) for r in rows]
    tau = t[-1] / 15

    def at(x):
        i = min(range(len(t)), key=lambda k: abs(t[k] - x))
        return fx[i]
    a, b, c = at(t[-1] - 2 * tau), at(t[-1] - tau), fx[-1]
    if (b - a) * (c - b) <= 0 or abs(c - b) >= abs(b - a):
        return 0.0
    return -(c - b) ** 2 / ((c - b) - (b - a)) / c


DUCT_INI = """# generated by bench/crosscheck/duct.py: a sphere in a periodic square duct, Re_c = {re_c}
{head}init = laminar
body_force = {f0!r} 0 0
flow_rate_direction = x
reynolds = {re_b!r}
reynolds_length = 1
cfl = 0.5
dt_max = {dt_max!r}

[ibm]
sphere1 = fixed center {cx!r} {cy!r} {cz!r} diameter 1
cn_forcing = predictor
{method}

[time]
t_end = {t_end!r}
steady_tol = {steady_tol!r}
steady_measure = integrals

[output]
fields_every = {t_end!r}
"""


def run_ibm_duct(name, cpd, corr, out):
    import h5py
    import numpy as np
    cs = DUCT_CASES[name]
    re_c = cs["re_c"]
    Ub = re_c / UC_UB
    d = os.path.join(out, name, "ibm_%s_n%d" % (corr, cpd))
    res = os.path.join(d, "result.json")
    cached = cached_or_fresh(d)
    if cached:
        return cached
    ini = os.path.join(d, "case.ini")
    # the step is adaptive (CFL 0.5); dt_max bounds the first one, taken before the velocity is known,
    # by the CFL limit of 2.5 U_b (Crank-Nicolson and the predictor forcing: the steady state does
    # not depend on the step, docs/user-guide.md)
    dt_max = 0.5 / (cpd * 2.5 * Ub)
    # the start: the duct's laminar profile at the held flux (f = 28.454 nu U_b / H^2 for the square
    # duct; init = laminar), through the sphere, which the forcing then stops
    f0 = 28.454 * Ub / H ** 2
    with open(ini, "w") as fh:
        fh.write(DUCT_INI.format(re_c=re_c, head=walled_box_ini(cpd, (LX, H, H), "periodic"), f0=f0, re_b=Ub,
                                 dt_max=dt_max, cx=CENTRE[0], cy=CENTRE[1], cz=CENTRE[2], method=ibm_method_keys(corr), t_end=cs["t_end"],
                                 steady_tol=5e-4 * re_c / 20))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    binary = os.path.join(ROOT, os.environ.get("BUILD", "build"), "ibmdem")
    cpu, wall = cpu_of([binary, "run", ini, "--out", os.path.join(d, "out")], d, os.path.join(d, "log"), env)
    s = json.load(open(os.path.join(d, "out", "summary.json")))
    sp = s["ibm"]["sphere1"]
    F = [sp["force_x"], sp["force_y"], sp["force_z"]]
    U = s["fluid"]["superficial_velocity_x"]
    # the axis behind the sphere: the mean of the four cells around y = z = H/2
    snaps = sorted(x for x in os.listdir(os.path.join(d, "out")) if re.match(r"fields_\d+\.h5$", x))
    with h5py.File(os.path.join(d, "out", snaps[-1]), "r") as h:
        u = np.asarray(h["velocity"][..., 0])  # (nz, ny, nx)
    nz, ny, nx = u.shape
    axis = u[nz // 2 - 1:nz // 2 + 1, ny // 2 - 1:ny // 2 + 1, :].mean(axis=(0, 1))
    xs = [(i + 0.5) * LX / nx for i in range(nx)]
    Uc = UC_UB * U
    r = dict(code="ibmdem", method=corr, case=name, re_c=re_c, n=cpd, dpdx=float(cpd), cells=nx * ny * nz,
             U=U, Uc=Uc, Re=Uc, F=F, CD=F[0] / (Uc ** 2 * math.pi / 8), CL=math.hypot(F[1], F[2]) / (Uc ** 2 * math.pi / 8),
             Lw=recirculation(xs, list(axis)), u_ahead=ahead(xs, list(axis)) / Uc, f=s["fluid"]["body_force_x"],
             drift=drag_drift(os.path.join(d, "out", "series.csv")),
             cpu=cpu, wall=wall, steps=s.get("steps"), t=s.get("time"), status=s.get("status"))
    json.dump(r, open(res, "w"), indent=1)
    drop_snapshots(os.path.join(d, "out"))
    return r


# ---------------------------------------------------------------- OpenFOAM

def foam_duct_case(d, N):
    """the duct's OpenFOAM case: foam_case's schemes and solution, a blockMesh of the duct (cyclic
    along x, the walls a patch), the sphere as in the arrays, a sampled axis behind it"""
    foam_case(d, 1.0, N, 0.0)
    nx, ny = int(round(LX * N)), int(round(H * N))
    foam_write(d, "system/blockMeshDict", "dictionary", """convertToMeters 1;
vertices ((0 0 0) (%(L)r 0 0) (%(L)r %(H)r 0) (0 %(H)r 0) (0 0 %(H)r) (%(L)r 0 %(H)r) (%(L)r %(H)r %(H)r) (0 %(H)r %(H)r));
blocks (hex (0 1 2 3 4 5 6 7) (%(nx)d %(ny)d %(ny)d) simpleGrading (1 1 1));
edges ();
boundary
(
    xlo { type cyclic; neighbourPatch xhi; faces ((0 4 7 3)); }
    xhi { type cyclic; neighbourPatch xlo; faces ((1 2 6 5)); }
    walls { type wall; faces ((0 1 5 4) (3 7 6 2) (0 3 2 1) (4 5 6 7)); }
);
mergePatchPairs ();
""" % dict(L=LX, H=H, nx=nx, ny=ny))
    sn = open(os.path.join(d, "system/snappyHexMeshDict")).read()
    sn = re.sub(r"centre \(.*?\);", "centre (%r %r %r);" % CENTRE, sn)
    # the near wake refined as the sphere's surroundings (one level, from 1 D ahead of the centre to
    # 3.5 D behind it, 1 D around the axis): the recirculation is then resolved as the sphere is
    sn = sn.replace("geometry\n{\n", "geometry\n{\n    wake { type searchableBox; min (%r %r %r); max (%r %r %r); }\n" % (
        CENTRE[0] - 1.0, CENTRE[1] - 1.0, CENTRE[2] - 1.0, CENTRE[0] + 3.5, CENTRE[1] + 1.0, CENTRE[2] + 1.0))
    sn = sn.replace("refinementRegions { sphere { mode distance; levels ((0.15 1)); } }",
                    "refinementRegions { sphere { mode distance; levels ((0.15 1)); } wake { mode inside; levels ((1e15 1)); } }")
    if sn.count("wake") != 2:
        sys.exit("crosscheck: %s: foam_case's snappyHexMeshDict no longer has the text the wake box replaces" % d)
    loc = (1.0 + 0.37 / N, 1.0 + 0.41 / N, 1.0 + 0.43 / N)
    sn = re.sub(r"locationInMesh \(.*?\);", "locationInMesh (%r %r %r);" % loc, sn)
    open(os.path.join(d, "system/snappyHexMeshDict"), "w").write(sn)
    cd = open(os.path.join(d, "system/controlDict")).read()
    cd = re.sub(r"CofR \(.*?\);", "CofR (%r %r %r);" % CENTRE, cd)
    cd = cd.replace("endTime 20000;", "endTime 4000;")
    cd = cd.replace("writeInterval 20000;", "writeInterval 4000;")
    # the duct's axis, written with the converged (or last) fields
    cd = cd.rstrip().rstrip("}") + """    axis
    {
        type sets;
        libs ("libsampling.so");
        writeControl writeTime;
        interpolationScheme cellPoint;
        setFormat raw;
        fields (U);
        sets
        (
            ahead { type uniform; axis x; start (%r %r %r); end (%r %r %r); nPoints 901; }
            behind { type uniform; axis x; start (%r %r %r); end (%r %r %r); nPoints 901; }
        );
    }
}
""" % (1e-6, CENTRE[1], CENTRE[2], CENTRE[0] - 0.5, CENTRE[1], CENTRE[2],
       CENTRE[0] + 0.5, CENTRE[1], CENTRE[2], LX - 1e-6, CENTRE[1], CENTRE[2])
    open(os.path.join(d, "system/controlDict"), "w").write(cd)
    # SIMPLE stops at residuals p 1e-5, U 1e-6: the drag is then within 0.01 % of its value at the
    # arrays' 1e-6 and 1e-7 (measured: Re 100, N = 8, 3068.0 at U 1e-5, 3069.3 at 1e-7)
    for rel, old, new in (("system/fvSolution", "residualControl { p 1e-6; U 1e-7; }", "residualControl { p 1e-5; U 1e-6; }"),
                          ("0/U", '"(x|y|z)(lo|hi)" { type cyclic; }', '"(xlo|xhi)" { type cyclic; }\n    walls { type noSlip; }'),
                          ("0/p", '"(x|y|z)(lo|hi)" { type cyclic; }', '"(xlo|xhi)" { type cyclic; }\n    walls { type zeroGradient; }')):
        t = open(os.path.join(d, rel)).read()
        if old not in t:
            sys.exit("crosscheck: %s: foam_case's %s no longer has %r" % (d, rel, old))
        open(os.path.join(d, rel), "w").write(t.replace(old, new))


def run_foam_duct(name, N, out):
    cs = DUCT_CASES[name]
    re_c = cs["re_c"]
    Ub = re_c / UC_UB
    d = os.path.join(out, name, "foam_N%d" % N)
    res = os.path.join(d, "result.json")
    cached = cached_or_fresh(d)
    if cached:
        return cached
    foam_duct_case(d, N)
    env = foam_env()
    cpu_mesh, cells, vol = foam_mesh(d, env)
    Vbox = LX * H * H
    cpu_solve, wall = foam_solve_at_flux(d, env, Ub * Vbox / vol)
    log = open(os.path.join(d, "log.simpleFoam")).read()
    converged = "SIMPLE solution converged" in log
    iters = len(re.findall(r"^Time = ", log, re.M))
    gp = float(re.findall(r"pressure gradient = ([-+0-9.eE]+)", log)[-1])
    fr = last_vector(find_dat(d, "forces", "force"))  # iteration, total force (3), pressure (3), viscous (3)
    fl = last_vector(find_dat(d, "flux", "volFieldValue"))  # iteration, integral of U (3)
    U = fl[1] / (LX * H * H)
    F = [fr[1] + gp * (Vbox - vol), fr[2], fr[3]]
    rows = []  # the axis ahead of and behind the sphere (a set stops at the first boundary it meets)
    for root, _, files in os.walk(os.path.join(d, "postProcessing", "axis")):
        for x in files:
            if x.endswith(".xy"):
                rows += [[float(v) for v in l.split()] for l in open(os.path.join(root, x)) if l.strip()]
    rows.sort()
    xs, us = [q[0] for q in rows], [q[1] for q in rows]
    # the spread of the drag over the last tenth of the iterations: a run that did not converge
    # (an unsteady wake) shows it
    fx_hist = [v[0] for _, v in sorted(dat_rows(find_dat(d, "forces", "force")).items())]
    tail = fx_hist[-max(20, len(fx_hist) // 10):]
    Uc = UC_UB * U
    q = Uc ** 2 * math.pi / 8
    r = dict(code="OpenFOAM", method="snappy", case=name, re_c=re_c, N=N, dpdx=2.0 * N, cells=cells,
             fluid_volume=vol, solid_volume_ratio=(Vbox - vol) / (math.pi / 6), U=U, Uc=Uc, Re=Uc, F=F,
             CD=F[0] / q, CL=math.hypot(F[1], F[2]) / q, Lw=recirculation(xs, us) if xs else float("nan"),
             u_ahead=ahead(xs, us) / Uc if xs else float("nan"),
             f=gp, iterations=iters, converged=converged, drag_tail_spread=(max(tail) - min(tail)) / q,
             cpu=cpu_mesh + cpu_solve, cpu_mesh=cpu_mesh, cpu_solve=cpu_solve, wall=wall)
    json.dump(r, open(res, "w"), indent=1)
    return r


# ---------------------------------------------------------------- report

def report_duct(out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    lines, table = [], {}
    names = [n for n in DUCT_CASES if os.path.isdir(os.path.join(out, n))]
    if not names:
        return
    fig, axes = plt.subplots(1, len(names), figsize=(5.2 * len(names), 4.4), squeeze=False)
    lines += ["## Sphere in a square duct (H = 4 D, periodic L = 10 D, Re = U_c D/nu, U_c = 2.0962 U_b)", "",
              "Reference: OpenFOAM's series extrapolated (Richardson through its three meshes) where its increments "
              "shrink, else its finest mesh; C_D of the unbounded sphere (Clift et al. 1978) for context.", ""]
    for ax, name in zip(axes[0], names):
        cs = DUCT_CASES[name]
        runs = []
        cd_ = os.path.join(out, name)
        for x in sorted(os.listdir(cd_)):
            p = os.path.join(cd_, x, "result.json")
            if os.path.exists(p):
                runs.append(json.load(open(p)))
        groups = {}
        for r in runs:
            groups.setdefault((r["code"], r["method"]), []).append(r)
        for g in groups.values():
            g.sort(key=lambda r: r["dpdx"])
        foam = groups.get(("OpenFOAM", "snappy"), [])
        ex = richardson([1 / r["dpdx"] for r in foam[-3:]], [r["CD"] for r in foam[-3:]]) if len(foam) >= 3 else None
        ex = ex if ex and ex["p"] >= 0.8 else None
        exw = richardson([1 / r["dpdx"] for r in foam[-3:]], [r["Lw"] for r in foam[-3:]]) \
            if len(foam) >= 3 and all(r["Lw"] > 0 for r in foam[-3:]) else None
        ref = ex["K"] if ex else (foam[-1]["CD"] if foam else None)
        refname = ("OpenFOAM extrapolated, order %.2f" % ex["p"] if ex else
                   "OpenFOAM's finest mesh (no extrapolation: its increments do not shrink)" if foam else "none")
        table[name] = dict(re_c=cs["re_c"], CD_ref=ref, reference=refname, Lw_ref=exw["K"] if exw else None,
                           CD_unbounded=clift_cd(cs["re_c"]), series={})
        lines += ["### %s: Re = %g (C_D reference %s: %s; L_w %s; unbounded sphere C_D %.3f)" % (
            name, cs["re_c"], "%.4f" % ref if ref else "-", refname, "%.3f D" % exw["K"] if exw else "-",
            clift_cd(cs["re_c"])), "",
            "| code | method | D/dx | cells | C_D | C_D/ref - 1 | C_L | L_w/D | u_ahead/U_c | CPU s | state |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
        for (code, meth), rs in sorted(groups.items()):
            for r in rs:
                st = ("%d it, %s" % (r["iterations"], "converged" if r["converged"] else
                                     "NOT converged (drag spread %.1e)" % r["drag_tail_spread"])
                      if code == "OpenFOAM" else "%s steps, t = %.3g, %s (drift %+.2f %%)" % (
                          r["steps"], r["t"], r["status"], 100 * r.get("drift", float("nan"))))
                lines.append("| %s | %s | %.0f | %d | %.4f | %s | %.1e | %.3f | %.3f | %.1f | %s |" % (
                    code, meth, r["dpdx"], r["cells"], r["CD"],
                    "%+.2f %%" % (100 * (r["CD"] / ref - 1)) if ref else "-", r["CL"], r["Lw"], r["u_ahead"], r["cpu"],
                    st))
            e = richardson([1 / r["dpdx"] for r in rs[-3:]], [r["CD"] for r in rs[-3:]]) if len(rs) >= 3 else None
            if e and e["p"] >= 0.8:
                lines.append("| %s | %s | Richardson | | %.4f | %s | | | | | order %.2f |" % (
                    code, meth, e["K"], "%+.2f %%" % (100 * (e["K"] / ref - 1)) if ref else "-", e["p"]))
            elif len(rs) >= 3:
                lines.append("| %s | %s | no extrapolation | | | | | | | | %s |" % (
                    code, meth, "observed order %.2f < 0.8: not in the asymptotic range" % e["p"] if e
                    else "the increments do not shrink"))
                e = None
            table[name]["series"]["%s/%s" % (code, meth)] = dict(runs=rs, extrapolation=e)
            pts = [r for r in rs if ref and r["CD"] != ref]  # not the run that is the reference
            if pts:
                plot_speed_error(ax, pts, lambda r: 100 * abs(r["CD"] / ref - 1), code, meth)
        lines.append("")
        ax.set_title("%s (ref: OpenFOAM %s)" % (name, "extrapolated" if ex else "finest mesh"), fontsize=9)
        ax.set_xlabel("CPU seconds (one core)")
        ax.set_ylabel("|C_D/C_D,ref - 1| (%)")
        ax.axhline(2.0, color="grey", lw=0.5)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    write_report(out, "duct", "duct_table", fig, lines, table)
