"""The moving case of the cross-check: a sphere oscillating in a closed box (cases osc_sphere,
osc_sphere_dt2, osc_sphere_small of bench/crosscheck/crosscheck.py; docs/validation.md "Sphere
oscillating in a closed box").

Geometry (D = nu = rho = 1): a cube of side 6 D with no-slip walls, the fluid at rest at t = 0, a
sphere of D = 1 at the centre moved along x with the velocity u(t) = U0 cos(omega t) (so
x(t) = A sin(omega t), A = U0/omega), omega D^2/nu = 32: the Stokes layer is
delta = sqrt(2 nu/omega) = D/4 thick.  A = 0.05 D (Re = U0 D/nu = 1.6; osc_sphere_small: 0.025 D),
six periods, a fixed step of T/200 (osc_sphere_dt2: T/400) in both codes.  The prescribed motion is
the same table in both (rows every T/400, linear between rows).

Both codes give the hydrodynamic force on the sphere (pressure and viscous stress on its surface:
ibmdem's momentum balance of the sphere's volume, OpenFOAM's `forces` on the moving patch).  Over
the last period the force is fitted with F(t) = -C_u u(t) - C_a du/dt + c: C_u (in phase with the
velocity: the dissipative part) and C_a (with the acceleration: added mass and history) against
the exact periodic solution of the unsteady Stokes equations for the unbounded sphere (Stokes 1851;
Landau & Lifshitz, Fluid Mechanics, section 24, problem 5):
    C_u = 6 pi mu a (1 + a/delta),   C_a = 3 pi a^2 rho delta (1 + 2a/(9 delta)),   a = D/2,
i.e. 3 and 3.25 times the steady Stokes drag and the potential added mass at a/delta = 2.  The box
(walls 2.5 D from the surface) and the advection (A/a = 0.1) are not in it: their size is measured
(the walls in the axisymmetric cylinders of tests/test_ibm_oscillating.c, about 1 % of C_u; the
advection by osc_sphere_small, below 0.1 %).  ibmdem's force is the mean over a step (the
stage impulses over the step): it is attributed to the step's middle; OpenFOAM's is the force at
the end of its step.

ibmdem: D/dx = 8, 12, 16 (and 24 in osc_sphere; uniform cubic cells), the sphere `prescribed` with
the velocity history, the harness's methods (common.IBM_METHODS: none, the shipped band; narrow,
band_width 0.5 with forcing_time 0.05), Crank-Nicolson with the predictor forcing.  OpenFOAM: pimpleFoam on a moving mesh (dynamicMotionSolverFvMesh,
velocityComponentLaplacian along x with quadratic inverse-distance diffusivity: the sphere's patch
moves with the table, the walls stay), blockMesh of N = 2, 3, 4 (and 6 in osc_sphere) cells per D
refined two levels at the sphere (within 0.3 D of the surface) and one level within 1 D, three
layers: D/dx = 4N = 8, 12, 16 (24) at the surface; second-order backward time stepping, linear advection, two outer and two
pressure correctors."""
import json
import math
import os
import re
import sys

from common import ROOT, cached_or_fresh, cpu_of, drop_snapshots, find_dat, foam_case, foam_env, foam_mesh, foam_write, \
    ibm_method_keys, plot_speed_error, richardson, walled_box_ini, write_report

LBOX = 6.0
CENTRE = (3.0, 3.0, 3.0)
OMEGA = 32.0
PERIODS = 6
OSC_CASES = {
    "osc_sphere": dict(amp=0.05, spp=200, ibm_cpd=[8, 12, 16, 24], foam_N=[2, 3, 4, 6]),
    "osc_sphere_dt2": dict(amp=0.05, spp=400, ibm_cpd=[8, 12, 16], foam_N=[2, 3, 4]),
    "osc_sphere_small": dict(amp=0.025, spp=200, ibm_cpd=[8, 12, 16], foam_N=[2, 3, 4]),
}


def exact():
    """(C_u, C_a) of the unbounded sphere oscillating in Stokes flow (a = 1/2, mu = rho = 1)"""
    a, delta = 0.5, math.sqrt(2.0 / OMEGA)
    return 6 * math.pi * a * (1 + a / delta), 3 * math.pi * a * a * delta * (1 + 2 * a / (9 * delta))


def motion_rows(cs):
    """the prescribed velocity (t, u) every T/400 over the run and one row beyond its end"""
    T = 2 * math.pi / OMEGA
    U0 = cs["amp"] * OMEGA
    return [(i * T / 400, U0 * math.cos(OMEGA * i * T / 400)) for i in range(400 * PERIODS + 2)]


def fit_periods(ts, fs, cs):
    """C_u, C_a and the mean c of F = -C_u u - C_a du/dt + c fitted over each whole period
    (least squares on cos, sin, 1): a list of dicts, one per period"""
    import numpy as np
    T = 2 * math.pi / OMEGA
    U0 = cs["amp"] * OMEGA
    ts, fs = np.asarray(ts), np.asarray(fs)
    out = []
    for k in range(PERIODS):
        m = (ts > k * T + 1e-9) & (ts <= (k + 1) * T + 1e-9)
        if m.sum() < 20:
            continue
        M = np.c_[np.cos(OMEGA * ts[m]), np.sin(OMEGA * ts[m]), np.ones(m.sum())]
        c, *_ = np.linalg.lstsq(M, fs[m], rcond=None)
        # u = U0 cos, du/dt = -U0 omega sin:  F = -C_u U0 cos + C_a U0 omega sin + c
        out.append(dict(period=k + 1, Cu=-c[0] / U0, Ca=c[1] / (U0 * OMEGA), mean=c[2],
                        resid=float(np.std(fs[m] - M @ c))))
    return out


def result_of(code, method, name, cs, dpdx, cells, ts, fs, cpu, wall, **extra):
    per = fit_periods(ts, fs, cs)
    Cu0, Ca0 = exact()
    last, prev = per[-1], per[-2]
    U0 = cs["amp"] * OMEGA
    amp0 = math.hypot(Cu0 * U0, Ca0 * U0 * OMEGA)
    # the error of the complex amplitude of the force's first harmonic, relative to the exact one
    err = math.hypot((last["Cu"] - Cu0) * U0, (last["Ca"] - Ca0) * U0 * OMEGA) / amp0
    r = dict(code=code, method=method, case=name, dpdx=float(dpdx), cells=cells, Cu=last["Cu"], Ca=last["Ca"],
             Cu_exact=last["Cu"] / Cu0, Ca_exact=last["Ca"] / Ca0, amplitude_error=err,
             mean_force=last["mean"] / (Cu0 * U0), resid=last["resid"] / amp0,
             periodicity=max(abs(last["Cu"] / prev["Cu"] - 1), abs(last["Ca"] / prev["Ca"] - 1)),
             periods=per, cpu=cpu, wall=wall)
    r.update(extra)
    return r


# ---------------------------------------------------------------- ibmdem

OSC_INI = """# generated by bench/crosscheck/oscillating.py: a sphere oscillating in a closed box
{head}dt = {dt!r}

[ibm]
sphere1 = prescribed center {cx!r} {cy!r} {cz!r} diameter 1 history motion.csv
cn_forcing = predictor
{method}

[time]
t_end = {t_end!r}

[output]
fields_every = 0
"""


def run_ibm_osc(name, cpd, corr, out):
    import csv
    cs = OSC_CASES[name]
    d = os.path.join(out, name, "ibm_%s_n%d" % (corr, cpd))
    cached = cached_or_fresh(d)
    if cached:
        return cached
    T = 2 * math.pi / OMEGA
    with open(os.path.join(d, "motion.csv"), "w") as fh:
        fh.write("t,u,v,w\n" + "".join("%.17g,%.17g,0,0\n" % row for row in motion_rows(cs)))
    ini = os.path.join(d, "case.ini")
    with open(ini, "w") as fh:
        fh.write(OSC_INI.format(head=walled_box_ini(cpd, (LBOX, LBOX, LBOX), "noslip"), dt=T / cs["spp"],
                                cx=CENTRE[0], cy=CENTRE[1], cz=CENTRE[2], method=ibm_method_keys(corr),
                                t_end=PERIODS * T))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    binary = os.path.join(ROOT, os.environ.get("BUILD", "build"), "ibmdem")
    cpu, wall = cpu_of([binary, "run", ini, "--out", os.path.join(d, "out")], d, os.path.join(d, "log"), env)
    ts, fs, t0 = [], [], 0.0
    for row in csv.DictReader(open(os.path.join(d, "out", "series.csv"))):
        t = float(row["time"])
        ts.append(0.5 * (t0 + t))  # the step's mean force, at the step's middle
        fs.append(float(row["s1_fx"]))
        t0 = t
    n = int(round(LBOX * cpd))
    r = result_of("ibmdem", corr, name, cs, cpd, n ** 3, ts, fs, cpu, wall)
    json.dump(r, open(os.path.join(d, "result.json"), "w"), indent=1)
    drop_snapshots(os.path.join(d, "out"))
    return r


# ---------------------------------------------------------------- OpenFOAM

def foam_osc_case(d, N, cs):
    """the box's OpenFOAM case: foam_case's mesh settings with walls instead of cyclic faces, the
    sphere refined two levels, pimpleFoam on a mesh that moves with the sphere"""
    foam_case(d, 1.0, N, 0.0)
    n = int(round(LBOX * N))
    foam_write(d, "system/blockMeshDict", "dictionary", """convertToMeters 1;
vertices ((0 0 0) (%(L)r 0 0) (%(L)r %(L)r 0) (0 %(L)r 0) (0 0 %(L)r) (%(L)r 0 %(L)r) (%(L)r %(L)r %(L)r) (0 %(L)r %(L)r));
blocks (hex (0 1 2 3 4 5 6 7) (%(n)d %(n)d %(n)d) simpleGrading (1 1 1));
edges ();
boundary
(
    walls { type wall; faces ((0 4 7 3) (1 2 6 5) (0 1 5 4) (3 7 6 2) (0 3 2 1) (4 5 6 7)); }
);
mergePatchPairs ();
""" % dict(L=LBOX, n=n))
    p = os.path.join(d, "system/snappyHexMeshDict")
    sn = open(p).read()
    new = re.sub(r"centre \(.*?\);", "centre (%r %r %r);" % CENTRE, sn)
    new = new.replace("level (1 1);", "level (2 2);").replace("levels ((0.15 1));", "levels ((0.3 2) (1.0 1));")
    loc = 1.0 + 0.37 / N
    new = re.sub(r"locationInMesh \(.*?\);", "locationInMesh (%r %r %r);" % (loc, loc + 0.02 / N, loc + 0.05 / N), new)
    if new.count("(2 2)") != 1 or "((0.3 2) (1.0 1))" not in new:
        sys.exit("crosscheck: %s: foam_case's snappyHexMeshDict no longer has the levels this case replaces" % d)
    open(p, "w").write(new)
    T = 2 * math.pi / OMEGA
    # foam_case's controlDict (its forces and flux function objects), run in time: six periods of
    # fixed steps, the forces at every step
    p = os.path.join(d, "system/controlDict")
    cd = open(p).read()
    for old, rep in (("application simpleFoam;", "application pimpleFoam;"),
                     ("endTime 20000;", "endTime %r;" % (PERIODS * T * (1 + 1e-9))),
                     ("deltaT 1;", "deltaT %r;\nadjustTimeStep no;" % (T / cs["spp"])),
                     ("writeInterval 20000;", "writeInterval 1000000;"), ("timePrecision 8;", "timePrecision 10;"),
                     ("CofR (0.5 0.5 0.5);", "CofR (%r %r %r);" % CENTRE)):
        if old not in cd:
            sys.exit("crosscheck: %s: foam_case's controlDict no longer has %r" % (d, old))
        cd = cd.replace(old, rep)
    open(p, "w").write(cd)
    # foam_case's schemes, in time: second-order backward steps, linear (central) advection
    p = os.path.join(d, "system/fvSchemes")
    fs = open(p).read()
    for old, rep in (("default steadyState;", "default backward;"),
                     ("bounded Gauss linearUpwind grad(U);", "Gauss linear;")):
        if old not in fs:
            sys.exit("crosscheck: %s: foam_case's fvSchemes no longer has %r" % (d, old))
        fs = fs.replace(old, rep)
    open(p, "w").write(fs)
    foam_write(d, "system/fvSolution", "dictionary", """solvers
{
    p { solver GAMG; smoother GaussSeidel; tolerance 1e-9; relTol 0.01; }
    pFinal { $p; relTol 0; }
    "pcorr.*" { $p; relTol 0; }
    "U|UFinal" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-10; relTol 0; }
    cellMotionUx { solver PCG; preconditioner DIC; tolerance 1e-10; relTol 0; }
}
PIMPLE
{
    correctPhi yes;
    nOuterCorrectors 2;
    nCorrectors 2;
    nNonOrthogonalCorrectors 1;
    pRefCell 0;
    pRefValue 0;
}
relaxationFactors { equations { ".*" 1; } }
""")
    foam_write(d, "constant/dynamicMeshDict", "dictionary", """dynamicFvMesh dynamicMotionSolverFvMesh;
motionSolverLibs (fvMotionSolvers);
motionSolver velocityComponentLaplacian;
component x;
diffusivity quadratic inverseDistance (sphere);
""")
    os.remove(os.path.join(d, "constant/fvOptions"))
    table = " ".join("(%.17g %.17g)" % row for row in motion_rows(cs))
    foam_write(d, "0/pointMotionUx", "pointScalarField", """dimensions [0 1 -1 0 0 0 0];
internalField uniform 0;
boundaryField
{
    walls { type uniformFixedValue; uniformValue constant 0; }
    sphere { type uniformFixedValue; uniformValue table (%s); }
}
""" % table)
    foam_write(d, "0/U", "volVectorField", """dimensions [0 1 -1 0 0 0 0];
internalField uniform (0 0 0);
boundaryField
{
    walls { type noSlip; }
    sphere { type movingWallVelocity; value uniform (0 0 0); }
}
""")
    foam_write(d, "0/p", "volScalarField", """dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
    walls { type zeroGradient; }
    sphere { type zeroGradient; }
}
""")


def run_foam_osc(name, N, out):
    cs = OSC_CASES[name]
    d = os.path.join(out, name, "foam_N%d" % N)
    cached = cached_or_fresh(d)
    if cached:
        return cached
    foam_osc_case(d, N, cs)
    env = foam_env()
    cpu_mesh, cells, _ = foam_mesh(d, env)
    cpu_solve, wall = cpu_of(["pimpleFoam"], d, os.path.join(d, "log.pimpleFoam"), env)
    ts, fs = [], []  # the forces at the end of every step: time, total force (3), pressure, viscous
    for line in open(find_dat(d, "forces", "force")):
        if line.strip() and not line.startswith("#"):
            v = [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:[eE][-+]?\d+)?", line)]
            ts.append(v[0])
            fs.append(v[1])
    r = result_of("OpenFOAM", "moving mesh", name, cs, 4 * N, cells, ts, fs, cpu_mesh + cpu_solve, wall,
                  N=N, cpu_mesh=cpu_mesh, cpu_solve=cpu_solve)
    json.dump(r, open(os.path.join(d, "result.json"), "w"), indent=1)
    return r


# ---------------------------------------------------------------- report

def report_osc(out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [n for n in OSC_CASES if os.path.isdir(os.path.join(out, n))]
    if not names:
        return
    Cu0, Ca0 = exact()
    lines = ["## Sphere oscillating in a closed box (6 D, walls; omega D^2/nu = 32, delta = D/4)", "",
             "Reference: the unbounded sphere's exact periodic unsteady Stokes solution, C_u = %.4f, C_a = %.4f "
             "(Stokes 1851; Landau & Lifshitz section 24). C_u: the force in phase with the velocity; C_a: with "
             "the acceleration; error: of the complex amplitude of the force's first harmonic; residual: the rms of "
             "what the fit leaves (higher harmonics and noise), over that amplitude; mean force: over the steady "
             "Stokes drag scale; periodicity: the largest change of C_u, C_a from the period before the last."
             % (Cu0, Ca0), ""]
    table = {}
    fig, axes = plt.subplots(1, 2, figsize=(10.4, 4.4))
    for name in names:
        cs = OSC_CASES[name]
        runs = []
        for x in sorted(os.listdir(os.path.join(out, name))):
            p = os.path.join(out, name, x, "result.json")
            if os.path.exists(p):
                runs.append(json.load(open(p)))
        groups = {}
        for r in runs:
            groups.setdefault((r["code"], r["method"]), []).append(r)
        lines += ["### %s: A = %g D, %d steps per period" % (name, cs["amp"], cs["spp"]), "",
                  "| code | method | D/dx | cells | C_u/exact | C_a/exact | error | residual | mean force | periodicity | CPU s |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        table[name] = dict(amp=cs["amp"], spp=cs["spp"], Cu_exact=Cu0, Ca_exact=Ca0, series={})
        for (code, meth), rs in sorted(groups.items()):
            rs.sort(key=lambda r: r["dpdx"])
            for r in rs:
                lines.append("| %s | %s | %.0f | %d | %.4f | %.4f | %.2f %% | %.1e | %+.1e | %.1e | %.1f |" % (
                    code, meth, r["dpdx"], r["cells"], r["Cu_exact"], r["Ca_exact"], 100 * r["amplitude_error"],
                    r["resid"], r["mean_force"], r["periodicity"], r["cpu"]))
            ex = {}
            for key in ("Cu_exact", "Ca_exact"):
                e = richardson([1 / r["dpdx"] for r in rs[-3:]], [r[key] for r in rs[-3:]]) if len(rs) >= 3 else None
                ex[key] = e
            if len(rs) >= 3:
                # as for the duct: an observed order below 0.8 is not taken as the asymptotic range
                lines.append("| %s | %s | Richardson | | %s | %s | | | | | |" % (code, meth, *(
                    "none (no power law through the three)" if not ex[k] else "%.4f (order %.2f)" % (ex[k]["K"], ex[k]["p"]) if ex[k]["p"] >= 0.8
                    else "none (order %.2f < 0.8)" % ex[k]["p"] for k in ("Cu_exact", "Ca_exact"))))
                ex = {k: (e if e and e["p"] >= 0.8 else None) for k, e in ex.items()}
            table[name]["series"]["%s/%s" % (code, meth)] = dict(runs=rs, extrapolation=ex)
            if name == "osc_sphere":
                plot_speed_error(axes[1], rs, lambda r: 100 * r["amplitude_error"], code, meth)
                axes[0].plot([r["dpdx"] for r in rs], [r["Cu_exact"] for r in rs], "o-" if code == "OpenFOAM" else "s--",
                             label="%s C_u" % (code if code == "OpenFOAM" else "ibmdem " + meth))
                axes[0].plot([r["dpdx"] for r in rs], [r["Ca_exact"] for r in rs], "o:" if code == "OpenFOAM" else "s-.",
                             label="%s C_a" % (code if code == "OpenFOAM" else "ibmdem " + meth))
        lines.append("")
    axes[0].axhline(1.0, color="grey", lw=0.5)
    axes[0].set_xlabel("D/dx at the surface")
    axes[0].set_ylabel("coefficient / exact")
    axes[0].set_title("osc_sphere: in phase (C_u) and with the acceleration (C_a)", fontsize=9)
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel("CPU seconds (one core)")
    axes[1].set_ylabel("error of the force's amplitude (%)")
    axes[1].set_title("osc_sphere: speed against error", fontsize=9)
    axes[1].grid(True, which="both", lw=0.3)
    axes[1].legend(fontsize=7)
    write_report(out, "oscillating", "oscillating_table", fig, lines, table)
