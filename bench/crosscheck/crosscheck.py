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
with OpenFOAM's finest mesh (bed_table.md, bed_table.json, bed.png).

  crosscheck.py run CASE [--code ibm|foam] [--levels 0,1,2] OUT   (one result.json per run)
  crosscheck.py report OUT                                        (table.md, table.json, figure)
"""
import argparse
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

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


def cpu_of(cmd, cwd, log, env=None, may_fail=False):
    """run cmd, its output to log; returns the CPU seconds (user + system) of its process tree
    (may_fail: a failure is not fatal, the caller reads what the run wrote)"""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.time()
    with open(log, "w") as fh:
        p = subprocess.run(cmd, cwd=cwd, stdout=fh, stderr=subprocess.STDOUT, env=env)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0 and not may_fail:
        sys.exit("crosscheck: %s failed (exit %d), see %s" % (" ".join(cmd), p.returncode, log))
    return (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime), time.time() - t0


# ---------------------------------------------------------------- ibmdem

IBM_INI = """# generated by bench/crosscheck/crosscheck.py: simple cubic array, c = {c}, one period
[domain]
nx = {n}
ny = {n}
nz = {n}
length = {B!r} {B!r} {B!r}

[boundary]
x_lo = periodic
x_hi = periodic
y_lo = periodic
y_hi = periodic
z_lo = periodic
z_hi = periodic

[fluid]
nu = 1
rho = 1
viscous = explicit
body_force = {f!r} 0 0
reynolds_length = 1
fourier = 0.6
cfl = 0.5

[ibm]
{spheres}
forcing_time = 0.2
radius_correction = {corr}

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
    if os.path.exists(res):
        return json.load(open(res))
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    ini = os.path.join(d, "case.ini")
    with open(ini, "w") as fh:
        fh.write(IBM_INI.format(c=c, n=n, B=B, f=f, spheres=spheres, corr=corr, t_end=8, steady_tol=1e-3))
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

HEADER = """FoamFile
{
    version 2.0;
    format ascii;
    class %s;
    object %s;
}
"""


def foam_write(d, rel, cls, body):
    p = os.path.join(d, rel)
    os.makedirs(os.path.dirname(p), exist_ok=True)
    with open(p, "w") as fh:
        fh.write(HEADER % (cls, os.path.basename(rel)) + body)


def foam_case(d, L, N, f):
    h = L / 2
    faces = dict(xlo="(0 4 7 3)", xhi="(1 2 6 5)", ylo="(0 1 5 4)", yhi="(3 7 6 2)", zlo="(0 3 2 1)",
                 zhi="(4 5 6 7)")
    pair = dict(xlo="xhi", xhi="xlo", ylo="yhi", yhi="ylo", zlo="zhi", zhi="zlo")
    bnd = "".join("    %s { type cyclic; neighbourPatch %s; faces (%s); }\n" % (k, pair[k], v)
                  for k, v in faces.items())
    foam_write(d, "system/blockMeshDict", "dictionary", """convertToMeters 1;
vertices ((0 0 0) (%(L)r 0 0) (%(L)r %(L)r 0) (0 %(L)r 0) (0 0 %(L)r) (%(L)r 0 %(L)r) (%(L)r %(L)r %(L)r) (0 %(L)r %(L)r));
blocks (hex (0 1 2 3 4 5 6 7) (%(N)d %(N)d %(N)d) simpleGrading (1 1 1));
edges ();
boundary
(
%(bnd)s);
mergePatchPairs ();
""" % dict(L=L, N=N, bnd=bnd))
    # a point of the fluid that is on no face of the base mesh
    loc = 0.37 * L / N
    foam_write(d, "system/snappyHexMeshDict", "dictionary", """castellatedMesh true;
snap true;
addLayers true;
geometry
{
    sphere { type searchableSphere; centre (%(h)r %(h)r %(h)r); radius 0.5; }
}
castellatedMeshControls
{
    maxLocalCells 2000000;
    maxGlobalCells 4000000;
    minRefinementCells 0;
    maxLoadUnbalance 0.1;
    nCellsBetweenLevels 2;
    features ();
    refinementSurfaces { sphere { level (1 1); patchInfo { type wall; } } }
    resolveFeatureAngle 30;
    refinementRegions { sphere { mode distance; levels ((0.15 1)); } }
    locationInMesh (%(loc)r %(loc)r %(loc)r);
    allowFreeStandingZoneFaces true;
}
snapControls
{
    nSmoothPatch 3;
    tolerance 2.0;
    nSolveIter 100;
    nRelaxIter 5;
    nFeatureSnapIter 10;
    implicitFeatureSnap false;
    explicitFeatureSnap false;
    multiRegionFeatureSnap false;
}
addLayersControls
{
    relativeSizes true;
    layers { sphere { nSurfaceLayers 3; } }
    expansionRatio 1.2;
    finalLayerThickness 0.5;
    minThickness 0.1;
    nGrow 0;
    featureAngle 60;
    slipFeatureAngle 30;
    nRelaxIter 3;
    nSmoothSurfaceNormals 1;
    nSmoothNormals 3;
    nSmoothThickness 10;
    maxFaceThicknessRatio 0.5;
    maxThicknessToMedialRatio 0.3;
    minMedialAxisAngle 90;
    nBufferCellsNoExtrude 0;
    nLayerIter 50;
}
meshQualityControls
{
    #includeEtc "caseDicts/mesh/generation/meshQualityDict.cfg"
    relaxed { maxNonOrtho 75; }
    nSmoothScale 4;
    errorReduction 0.75;
}
mergeTolerance 1e-6;
""" % dict(h=h, loc=loc))
    foam_write(d, "system/controlDict", "dictionary", """application simpleFoam;
startFrom startTime;
startTime 0;
stopAt endTime;
endTime 20000;
deltaT 1;
writeControl timeStep;
writeInterval 20000;
purgeWrite 1;
writeFormat ascii;
writePrecision 10;
writeCompression off;
timeFormat general;
timePrecision 8;
runTimeModifiable false;
functions
{
    forces
    {
        type forces;
        libs ("libforces.so");
        writeControl timeStep;
        writeInterval 1;
        patches (sphere);
        rho rhoInf;
        rhoInf 1;
        CofR (%(h)r %(h)r %(h)r);
        log false;
    }
    flux
    {
        type volFieldValue;
        libs ("libfieldFunctionObjects.so");
        writeControl timeStep;
        writeInterval 1;
        writeFields false;
        regionType all;
        operation volIntegrate;
        fields (U);
        log false;
    }
}
""" % dict(h=h))
    foam_write(d, "system/fvSchemes", "dictionary", """ddtSchemes { default steadyState; }
gradSchemes { default Gauss linear; }
divSchemes
{
    default none;
    div(phi,U) bounded Gauss linearUpwind grad(U);
    div((nuEff*dev2(T(grad(U))))) Gauss linear;
}
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
""")
    foam_write(d, "system/fvSolution", "dictionary", """solvers
{
    p { solver GAMG; smoother GaussSeidel; tolerance 1e-10; relTol 0.01; }
    U { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-12; relTol 0.01; }
}
SIMPLE
{
    consistent yes;
    nNonOrthogonalCorrectors 1;
    pRefCell 0;
    pRefValue 0;
    residualControl { p 1e-6; U 1e-7; }
}
relaxationFactors { equations { U 0.9; } }
""")
    foam_write(d, "constant/transportProperties", "dictionary", "transportModel Newtonian;\nnu [0 2 -1 0 0 0 0] 1;\n")
    foam_write(d, "constant/turbulenceProperties", "dictionary", "simulationType laminar;\n")
    foam_write(d, "constant/fvOptions", "dictionary", """drive
{
    type vectorSemiImplicitSource;
    timeStart 0;
    duration 1e30;
    selectionMode all;
    volumeMode specific;
    injectionRateSuSp { U ((%r 0 0) 0); }
}
""" % f)
    cyc = '    "(x|y|z)(lo|hi)" { type cyclic; }\n'
    foam_write(d, "0/U", "volVectorField", """dimensions [0 1 -1 0 0 0 0];
internalField uniform (0 0 0);
boundaryField
{
%s    sphere { type noSlip; }
}
""" % cyc)
    foam_write(d, "0/p", "volScalarField", """dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
%s    sphere { type zeroGradient; }
}
""" % cyc)


def foam_env():
    """the environment of OpenFOAM's bashrc (FOAM_BASHRC, default Debian's)"""
    rc = os.environ.get("FOAM_BASHRC", "/usr/share/openfoam/etc/bashrc")
    out = subprocess.run(["bash", "-c", "source %s >/dev/null 2>&1; env -0" % rc], capture_output=True,
                         check=True).stdout.decode()
    env = dict(x.split("=", 1) for x in out.split("\0") if "=" in x)
    env["FOAM_SIGFPE"] = "false"
    return env


def last_vector(path):
    """the last row of a function object's .dat file: time and the numbers in it"""
    last = None
    with open(path) as fh:
        for line in fh:
            if line.strip() and not line.startswith("#"):
                last = line
    nums = [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:[eE][-+]?\d+)?", last)]
    return nums


def find_dat(d, fo, stem):
    for root, _, files in os.walk(os.path.join(d, "postProcessing", fo)):
        for x in files:
            if x.startswith(stem) and x.endswith(".dat"):
                return os.path.join(root, x)
    sys.exit("crosscheck: no %s*.dat of %s in %s" % (stem, fo, d))


def run_foam(name, N, out):
    cs = CASES[name]
    c, L, f = cs["c"], period(cs["c"]), drive(name)
    d = os.path.join(out, name, "foam_N%d" % N)
    res = os.path.join(d, "result.json")
    if os.path.exists(res):
        return json.load(open(res))
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    foam_case(d, L, N, f)
    env = foam_env()
    cpu_mesh = 0.0
    for cmd in (["blockMesh"], ["snappyHexMesh", "-overwrite"], ["checkMesh"]):
        cpu, _ = cpu_of(cmd, d, os.path.join(d, "log." + cmd[0]), env)
        cpu_mesh += cpu
    cm = open(os.path.join(d, "log.checkMesh")).read()
    cells = int(re.search(r"^\s*cells:\s+(\d+)", cm, re.M).group(1))
    vol = float(re.search(r"Total volume = ([-+0-9.eE]+?)\.?\s", cm).group(1))
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
BED = os.environ.get("CROSSCHECK_BED", "bench/crosscheck/bed30.csv")  # another bed: a CSV of the same layout
BED_CASES = {
    "bed30_stokes": dict(re_target=0.01, ibm_n=[27, 41, 54, 82, 109], foam_N=[14, 20, 28, 40]),
    "bed30_re20": dict(re_target=20, ibm_n=[27, 41, 54, 82], foam_N=[14, 20, 28]),
}


def read_bed(path=None):
    """the bed's L and centres [(x, y, z)], diameter 1"""
    path = path or os.path.join(ROOT, BED)
    L = float(re.search(r"L = ([0-9.eE+-]+),", open(path).readline()).group(1))
    xs = [tuple(float(v) for v in line.split(",")[:3]) for line in open(path)
          if line.strip() and line[0] not in "#x"]
    return L, xs


BED_INI = """# generated by bench/crosscheck/crosscheck.py: random fixed bed {bed}, held flow rate
[domain]
nx = {n}
ny = {n}
nz = {n}
length = {L!r} {L!r} {L!r}

[boundary]
x_lo = periodic
x_hi = periodic
y_lo = periodic
y_hi = periodic
z_lo = periodic
z_hi = periodic

[fluid]
nu = 1
rho = 1
viscous = explicit
body_force = {f0!r} 0 0
flow_rate_direction = x
reynolds = {re!r}
reynolds_length = 1
fourier = 0.6
cfl = 0.5
dt_max = {dt_max!r}

[ibm]
spheres_file = {bedpath}
forcing_time = 0.2
radius_correction = {corr}

[time]
t_end = {t_end}
steady_tol = {steady_tol}
steady_measure = integrals

[output]
fields_every = {t_end}
"""


def bed_guess_drive(re_target, L):
    # the initial body force: Carman-Kozeny's K ~ 10 at phi = 0.4 (held flow rate corrects it)
    return 30 * 10.0 * 3 * math.pi * re_target / L ** 3


def run_ibm_bed(name, n, corr, out):
    cs = BED_CASES[name]
    L, xs = read_bed()
    re_t = cs["re_target"]
    d = os.path.join(out, name, "ibm_%s_n%d" % (corr, n))
    res = os.path.join(d, "result.json")
    if os.path.exists(res):
        return json.load(open(res))
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    ini = os.path.join(d, "case.ini")
    with open(ini, "w") as fh:
        fh.write(BED_INI.format(bed=BED, n=n, L=L, f0=bed_guess_drive(re_t, L), re=re_t,
                                bedpath=os.path.join(ROOT, BED), corr=corr, t_end=8, steady_tol=1e-3,
                                dt_max=0.2 * L / n / re_t))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    binary = os.path.join(ROOT, os.environ.get("BUILD", "build"), "ibmdem")
    cpu, wall = cpu_of([binary, "run", ini, "--out", os.path.join(d, "out")], d, os.path.join(d, "log"), env)
    s = json.load(open(os.path.join(d, "out", "summary.json")))
    rows = [line.strip().split(",") for line in open(os.path.join(d, "out", "spheres.csv"))]
    head, rows = rows[0], rows[1:]
    ic = {k: head.index(k) for k in ("step", "sphere", "fx", "fy", "fz")}
    last = max(int(r[ic["step"]]) for r in rows)
    F = {}
    for r in rows:
        if int(r[ic["step"]]) == last:
            F[int(r[ic["sphere"]])] = [float(r[ic[k]]) for k in ("fx", "fy", "fz")]
    Fx = [F[q][0] for q in sorted(F)]
    if len(Fx) != len(xs):
        sys.exit("crosscheck: %s: %d spheres in spheres.csv, %d in the bed" % (d, len(Fx), len(xs)))
    U = s["fluid"]["superficial_velocity_x"]
    f = s["fluid"]["body_force_x"]
    r = dict(code="ibmdem", method=corr, case=name, L=L, n=n, dpdx=n / L, cells=n ** 3, U=U, Re=U, f=f,
             Fx=Fx, Fyz=[F[q][1:] for q in sorted(F)], K=[x / (3 * math.pi * U) for x in Fx],
             Kmean=sum(Fx) / len(Fx) / (3 * math.pi * U), balance=sum(Fx) / (f * L ** 3),
             cpu=cpu, wall=wall, steps=s.get("steps"), t=s.get("time"), status=s.get("status"))
    if abs(r["balance"] - 1) > 1e-3:  # the drag of the spheres balances the drive at a steady state
        sys.exit("crosscheck: %s: the spheres' drag is %.4g of the drive (status %s after %s steps): not a steady "
                 "state" % (d, r["balance"], r["status"], r["steps"]))
    json.dump(r, open(res, "w"), indent=1)
    for x in os.listdir(os.path.join(d, "out")):
        if x.startswith("checkpoint_") or x.startswith("fields_"):
            os.remove(os.path.join(d, "out", x))
    return r


def bed_images(L, xs):
    """every sphere and each periodic image of it that cuts the cube: [(sphere, image, centre)]"""
    out = []
    for q, c in enumerate(xs):
        k = 0
        for sx in (-1, 0, 1):
            for sy in (-1, 0, 1):
                for sz in (-1, 0, 1):
                    p = (c[0] + sx * L, c[1] + sy * L, c[2] + sz * L)
                    # distance from the centre to the cube
                    dist = math.sqrt(sum(max(0.0, -v, v - L) ** 2 for v in p))
                    if dist < 0.5:
                        out.append((q, k, p))
                        k += 1
    return out


def bed_location(L, xs, N):
    """a point of the fluid, on no face of the base mesh, far from every sphere"""
    h = L / N
    best, bp = -1, None
    for i in range(N):
        for j in range(N):
            for k in range(N):
                p = ((i + 0.37) * h, (j + 0.41) * h, (k + 0.43) * h)
                dmin = min(math.sqrt(sum((min_img(p[a] - c[a], L)) ** 2 for a in range(3))) for c in xs)
                if dmin > best:
                    best, bp = dmin, p
    return bp


def min_img(x, L):
    return x - L * round(x / L)


def foam_bed_case(d, L, xs, N, U):
    """the bed's OpenFOAM case: the cyclic cube of foam_case, the spheres and their periodic images
    as searchableSpheres (patch sNN_K: sphere NN, image K), a meanVelocityForce drive (its Ubar
    written after meshing, from the fluid volume)"""
    foam_case(d, L, N, 0.0)  # blockMeshDict, schemes, solution, transport; overwritten below
    ims = bed_images(L, xs)
    names = ["s%02d_%d" % (q, k) for q, k, _ in ims]
    geom = "".join("    %s { type searchableSphere; centre (%r %r %r); radius 0.5; }\n" % ((nm,) + p)
                   for nm, (_, _, p) in zip(names, ims))
    rsurf = "".join("        %s { level (1 1); patchInfo { type wall; } }\n" % nm for nm in names)
    rreg = "".join("        %s { mode distance; levels ((0.15 1)); }\n" % nm for nm in names)
    lay = "".join("        %s { nSurfaceLayers 3; }\n" % nm for nm in names)
    loc = bed_location(L, xs, N)
    sn = open(os.path.join(d, "system/snappyHexMeshDict")).read()
    sn = re.sub(r"geometry\n\{.*?\n\}\n", "geometry\n{\n%s}\n" % geom, sn, flags=re.S)
    sn = re.sub(r"refinementSurfaces \{.*?\} \} \}", "refinementSurfaces\n    {\n%s    }" % rsurf, sn, flags=re.S)
    sn = re.sub(r"refinementRegions \{.*?\} \}", "refinementRegions\n    {\n%s    }" % rreg, sn, flags=re.S)
    sn = re.sub(r"layers \{.*?\} \}", "layers\n    {\n%s    }" % lay, sn, flags=re.S)
    sn = re.sub(r"locationInMesh \(.*?\);", "locationInMesh (%r %r %r);" % loc, sn)
    open(os.path.join(d, "system/snappyHexMeshDict"), "w").write(sn)
    fo = "".join("""    f%02d
    {
        type forces;
        libs ("libforces.so");
        writeControl timeStep;
        writeInterval 1;
        patches ("s%02d_.*");
        rho rhoInf;
        rhoInf 1;
        CofR (%r %r %r);
        log false;
    }
""" % ((q, q) + xs[q]) for q in range(len(xs)))
    cd = open(os.path.join(d, "system/controlDict")).read()
    cd = re.sub(r"    forces\n    \{.*?\n    \}\n", fo, cd, flags=re.S)
    cd = cd.replace("endTime 20000;", "endTime 300;")  # converged runs take 125-132 iterations
    open(os.path.join(d, "system/controlDict"), "w").write(cd)
    for fld in ("U", "p"):
        t = open(os.path.join(d, "0", fld)).read()
        t = t.replace("sphere {", '"s.*" {')
        open(os.path.join(d, "0", fld), "w").write(t)


def dat_rows(path):
    """a function object's .dat file: {iteration: [the numbers after it]}"""
    out = {}
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            nums = [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:[eE][-+]?\d+)?", line)]
            out[int(round(nums[0]))] = nums[1:]
    return out


def foam_bed_result(d, name, N, L, xs):
    """the per-sphere forces of a bed run from its logs and .dat files.  A run that converged: its
    last iteration.  One that did not (SIMPLE stopped at endTime, or diverged): the iteration of its
    smallest initial pressure residual, flagged converged = False."""
    log = open(os.path.join(d, "log.simpleFoam")).read()
    converged = "SIMPLE solution converged" in log
    blocks = {}
    for b in re.split(r"^Time = ", log, flags=re.M)[1:]:
        g = re.findall(r"pressure gradient = ([-+0-9.eE]+)", b)
        p = re.findall(r"Solving for p, Initial residual = ([-+0-9.eE]+),", b)
        if g and p:
            blocks[int(b.split()[0])] = (float(g[-1]), float(p[0]))
    fl = dat_rows(find_dat(d, "flux", "volFieldValue"))
    F = [dat_rows(find_dat(d, "f%02d" % q, "force")) for q in range(len(xs))]
    have = [i for i in blocks if i in fl and all(i in f for f in F)]
    it = max(have) if converged else min(have, key=lambda i: blocks[i][1])
    gp = blocks[it][0]
    cm = open(os.path.join(d, "log.checkMesh")).read()
    cells = int(re.search(r"^\s*cells:\s+(\d+)", cm, re.M).group(1))
    vol = float(re.search(r"Total volume = ([-+0-9.eE]+?)\.?\s", cm).group(1))
    Us = fl[it][0] / L ** 3
    Vs = (L ** 3 - vol) / len(xs)  # the mesh's volume of one sphere (the mean over the spheres)
    Fp = [f[it][:3] for f in F]
    Fx = [x[0] + gp * Vs for x in Fp]
    return dict(code="OpenFOAM", method="snappy", case=name, L=L, N=N, dpdx=2 * N / L, cells=cells,
                fluid_volume=vol, solid_volume_ratio=(L ** 3 - vol) / (len(xs) * math.pi / 6), U=Us, Re=Us, f=gp,
                Fx=Fx, Fyz=[x[1:] for x in Fp], K=[x / (3 * math.pi * Us) for x in Fx],
                Kmean=sum(Fx) / len(Fx) / (3 * math.pi * Us), balance=sum(x[0] for x in Fp) / (gp * vol),
                iterations=len(blocks), iteration_used=it, p_residual=blocks[it][1], converged=converged)


def run_foam_bed(name, N, out):
    cs = BED_CASES[name]
    L, xs = read_bed()
    U = cs["re_target"]  # D = nu = 1
    d = os.path.join(out, name, "foam_N%d" % N)
    res = os.path.join(d, "result.json")
    if os.path.exists(res):
        return json.load(open(res))
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    foam_bed_case(d, L, xs, N, U)
    env = foam_env()
    cpu_mesh = 0.0
    for cmd in (["blockMesh"], ["snappyHexMesh", "-overwrite"], ["checkMesh"]):
        cpu, _ = cpu_of(cmd, d, os.path.join(d, "log." + cmd[0]), env)
        cpu_mesh += cpu
    cm = open(os.path.join(d, "log.checkMesh")).read()
    cells = int(re.search(r"^\s*cells:\s+(\d+)", cm, re.M).group(1))
    vol = float(re.search(r"Total volume = ([-+0-9.eE]+?)\.?\s", cm).group(1))
    mesh_ok = "Mesh OK." in cm
    sn = open(os.path.join(d, "log.snappyHexMesh")).read()
    # the layer table's rows: patch, faces, layers, thickness [m], thickness [%]
    lay = re.findall(r"^(s\d\d_\d+)\s+(\d+)\s+([0-9.]+)\s+([0-9.eE+-]+)\s+([0-9.]+)\s*$", sn, re.M)[-len(bed_images(L, xs)):]  # the last (final) table
    nf = sum(int(x[1]) for x in lay)
    layers = (sum(int(x[1]) * float(x[2]) for x in lay) / nf, sum(int(x[1]) * float(x[4]) for x in lay) / nf) \
        if nf else (0.0, 0.0)
    Ubar = U * L ** 3 / vol
    foam_write(d, "constant/fvOptions", "dictionary", """drive
{
    type meanVelocityForce;
    selectionMode all;
    fields (U);
    Ubar (%r 0 0);
    relaxation 1.0;
}
""" % Ubar)
    cpu_solve, wall = cpu_of(["simpleFoam"], d, os.path.join(d, "log.simpleFoam"), env, may_fail=True)
    r = foam_bed_result(d, name, N, L, xs)
    r.update(mesh_ok=mesh_ok, layers_mean=layers[0], layers_thickness_percent=layers[1],
             cpu=cpu_mesh + cpu_solve, cpu_mesh=cpu_mesh, cpu_solve=cpu_solve, wall=wall)
    json.dump(r, open(res, "w"), indent=1)
    return r


def rms(v):
    return math.sqrt(sum(x * x for x in v) / len(v))


def bed_compare(r, ref):
    """per-sphere relative differences of K against the reference vector: rms, max, and of the
    mean K (the total drag at the same flux)"""
    rel = [a / b - 1 for a, b in zip(r["K"], ref)]
    mean_ref = sum(ref) / len(ref)
    return dict(rms=rms(rel), max=max(rel, key=abs), rms_of_mean=rms([(a - b) / mean_ref for a, b in zip(r["K"], ref)]),
                mean=(sum(r["K"]) / len(ref)) / mean_ref - 1)


def bed_extrapolate(runs):
    """each sphere's K extrapolated through the last three runs (Richardson); None where not monotone.
    Returns (the vector or None, the number of spheres extrapolated, the median observed order)"""
    if len(runs) < 3:
        return None, 0, None
    h = [1 / r["dpdx"] for r in runs[-3:]]
    ex, ps = [], []
    for q in range(len(runs[-1]["K"])):
        e = richardson(h, [r["K"][q] for r in runs[-3:]])
        ex.append(e["K"] if e else None)
        if e:
            ps.append(e["p"])
    ok = sum(x is not None for x in ex)
    ps.sort()
    return (ex if ok == len(ex) else None), ok, (ps[len(ps) // 2] if ps else None)


def report_bed(out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    lines, table = [], {}
    names = [n for n in BED_CASES if os.path.isdir(os.path.join(out, n))]
    if not names:
        return
    fig, axes = plt.subplots(len(names), 2, figsize=(10.4, 4.4 * len(names)), squeeze=False)
    for (ax1, ax2), name in zip(axes, names):
        cd = os.path.join(out, name)
        runs = [json.load(open(os.path.join(cd, x, "result.json"))) for x in sorted(os.listdir(cd))
                if os.path.exists(os.path.join(cd, x, "result.json"))]
        groups = {}
        for r in runs:
            groups.setdefault((r["code"], r["method"]), []).append(r)
        for k in groups:
            groups[k].sort(key=lambda r: r["dpdx"])
        foam = groups.get(("OpenFOAM", "snappy"))
        if not foam:
            continue
        ref = foam[-1]["K"]
        fex, fok, fp = bed_extrapolate(foam)
        L, xs = read_bed()
        lines += ["### %s: %d spheres, phi = %.3f, L = %.5f D, Re = U D/nu = %g (U superficial, held)"
                  % (name, len(xs), len(xs) * math.pi / 6 / L ** 3, L, BED_CASES[name]["re_target"]), "",
                  "Reference: OpenFOAM N = %d (D/dx = %.2f at the surfaces), mean K = %.5f, per-sphere K %.4f … %.4f."
                  % (foam[-1]["N"], foam[-1]["dpdx"], sum(ref) / len(ref), min(ref), max(ref)), "",
                  "| code | method | resolution | D/dx | cells | Re | mean K | mean K vs ref | rms of K_i/K_i,ref − 1 "
                  "| max | rms of ΔK_i/mean K | vs own extrapolation: rms | CPU s | steady |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        table[name] = dict(reference=dict(N=foam[-1]["N"], K=ref), series={})
        for (code, meth), rs in sorted(groups.items()):
            ex, ok, p = bed_extrapolate(rs)
            for r in rs:
                c = bed_compare(r, ref)
                ce = bed_compare(r, ex) if ex else None
                resol = "N = %d" % r["N"] if code == "OpenFOAM" else "n = %d" % r["n"]
                cpu = "%.1f" % r["cpu"] + (" (mesh %.1f)" % r["cpu_mesh"] if "cpu_mesh" in r else "")
                st = ("%d it, %s%s, layers %.2f at %.0f %%" % (r["iterations"], "converged" if r["converged"] else
                                                                "NOT converged (forces of iteration %d, p residual %.1e)"
                                                                % (r.get("iteration_used", 0), r.get("p_residual", 0)),
                                                                "" if r["mesh_ok"] else ", mesh NOT OK",
                                                                r["layers_mean"], r["layers_thickness_percent"])
                      if code == "OpenFOAM" else "%s steps, t = %.3g, %s" % (r["steps"], r["t"], r["status"]))
                if r.get("note"):
                    st += "; " + r["note"]
                lines.append("| %s | %s | %s | %.2f | %d | %.4g | %.5f | %+.3f %% | %.3f %% | %+.3f %% | %.3f %% | %s | %s | %s |"
                             % (code, meth, resol, r["dpdx"], r["cells"], r["Re"], r["Kmean"], 100 * c["mean"],
                                100 * c["rms"], 100 * c["max"], 100 * c["rms_of_mean"],
                                "%.3f %%" % (100 * ce["rms"]) if ce else "", cpu, st))
                r["cmp"] = c
            if ex:
                cx = bed_compare(dict(K=ex), ref)
                exs = ("extrapolated sphere by sphere (last three, Richardson; median order %.2f): mean K %.5f, "
                       "against the reference: rms %.3f %%, mean %+.3f %%" % (p, sum(ex) / len(ex), 100 * cx["rms"],
                                                                          100 * cx["mean"]))
                if fex and code != "OpenFOAM":
                    cf = bed_compare(dict(K=ex), fex)
                    exs += "; against OpenFOAM's extrapolation: rms %.3f %%, mean %+.3f %%" % (100 * cf["rms"],
                                                                                           100 * cf["mean"])
            else:
                exs = "no sphere-by-sphere extrapolation (%d of %d spheres monotone over the last three runs%s)" % (
                    ok, len(rs[-1]["K"]), ", median order %.2f" % p if p else "") if len(rs) >= 3 else \
                    "no extrapolation (fewer than three runs)"
            lines.append("| %s | %s | %s | | | | | | | | | | | |" % (code, meth, exs))
            table[name]["series"]["%s/%s" % (code, meth)] = dict(runs=rs, extrapolation=ex, monotone=ok, order=p)
            ax2.loglog([r["cpu"] for r in rs if r is not foam[-1]], [100 * r["cmp"]["rms"] for r in rs if r is not foam[-1]],
                       "o-" if code == "OpenFOAM" else "s--", label="%s (%s)" % (code, meth))
            for r in rs:
                if r is not foam[-1]:
                    ax2.annotate("%.0f" % r["dpdx"], (r["cpu"], 100 * r["cmp"]["rms"]), fontsize=7,
                                 textcoords="offset points", xytext=(3, 3))
            if code != "OpenFOAM":
                ax1.plot(ref, rs[-1]["K"], "s", ms=4, label="ibmdem %s, D/dx = %.1f" % (meth, rs[-1]["dpdx"]))
            elif len(rs) > 1:
                ax1.plot(ref, rs[-2]["K"], "o", ms=4, mfc="none", label="OpenFOAM N = %d" % rs[-2]["N"])
        lines.append("")
        lo, hi = min(ref), max(ref)
        ax1.plot([lo, hi], [lo, hi], "k-", lw=0.5)
        ax1.set_xlabel("K_i, OpenFOAM N = %d" % foam[-1]["N"])
        ax1.set_ylabel("K_i")
        ax1.set_title("%s: per-sphere K = F_x/(3 pi mu D U)" % name, fontsize=9)
        ax1.legend(fontsize=7)
        ax2.set_xlabel("CPU seconds (one core)")
        ax2.set_ylabel("rms over the spheres of |K_i/K_i,ref - 1| (%)")
        ax2.set_title("%s: against OpenFOAM N = %d" % (name, foam[-1]["N"]), fontsize=9)
        ax2.axhline(5.0, color="grey", lw=0.5)
        ax2.grid(True, which="both", lw=0.3)
        ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "bed.png"), dpi=120)
    with open(os.path.join(out, "bed_table.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    json.dump(table, open(os.path.join(out, "bed_table.json"), "w"), indent=1)
    print("\n".join(lines))


# ---------------------------------------------------------------- extrapolation and report

def richardson(h, K):
    """K = K_inf + A h^p through three (h, K), any ratios: p by bisection; None if not monotone"""
    (h1, h2, h3), (k1, k2, k3) = h, K
    d12, d23 = k1 - k2, k2 - k3
    if d12 == 0 or d23 == 0 or d12 * d23 < 0:
        return None
    g = lambda p: (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - d12 / d23
    lo, hi = 0.05, 8.0
    if g(lo) * g(hi) > 0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    A = d23 / (h2 ** p - h3 ** p)
    return dict(p=p, K=k3 - A * h3 ** p)


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
        foam = ser.get(("OpenFOAM", "snappy"))
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
                ax.loglog([r["cpu"] for r in runs], [100 * abs(r["K"] / ref - 1) for r in runs],
                          "o-" if code == "OpenFOAM" else "s--", label="%s (%s)" % (code, meth))
                for r in runs:
                    ax.annotate("%.0f" % r["dpdx"], (r["cpu"], 100 * abs(r["K"] / ref - 1)), fontsize=7,
                                textcoords="offset points", xytext=(3, 3))
        lines.append("")
        ax.set_title("%s (ref: %s)" % (name, "Zick & Homsy" if stokes else "Z & H x OpenFOAM K(Re)/K(0)"),
                     fontsize=9)
        ax.set_xlabel("CPU seconds (one core)")
        ax.set_ylabel("|K/K_ref - 1| (%)")
        ax.axhline(1.0, color="grey", lw=0.5)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    lines = summary_lines(table) + lines
    fig.tight_layout()
    fig.savefig(os.path.join(out, "speed_error.png"), dpi=120)
    with open(os.path.join(out, "table.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    json.dump(table, open(os.path.join(out, "table.json"), "w"), indent=1)
    print("\n".join(lines))


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("run")
    a.add_argument("case", choices=sorted(CASES) + sorted(BED_CASES))
    a.add_argument("out")
    a.add_argument("--code", choices=["ibm", "foam", "both"], default="both")
    a.add_argument("--levels", default=None, help="indices into the case's series, e.g. 0,1,2")
    a.add_argument("--methods", default="calibrated", help="ibmdem radius_correction values, e.g. none,calibrated,gaps")
    b = sub.add_parser("report")
    b.add_argument("out")
    args = ap.parse_args()
    if args.cmd == "report":
        report(args.out)
        report_bed(args.out)
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
