"""What the cross-check's cases share (bench/crosscheck/crosscheck.py: the simple cubic arrays;
bench/crosscheck/bed.py: the random bed; bench/crosscheck/duct.py: the sphere in a duct): running
a code and timing it, a run directory's cached result, the OpenFOAM case of a cyclic cube, its
meshing, its solve at a held flux and its function objects' output, Richardson extrapolation,
and writing a report (table and speed-against-error figure)."""
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

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

def cached_or_fresh(d):
    """the result.json of a run directory d if there is one; else None with d emptied and created"""
    res = os.path.join(d, "result.json")
    if os.path.exists(res):
        return json.load(open(res))
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    return None


def foam_solve_at_flux(d, env, Ubar):
    """simpleFoam with the flow rate held (fvOption meanVelocityForce: the mean velocity over the
    fluid cells is Ubar along x); a run that does not converge is not fatal.  (CPU s, wall s)"""
    foam_write(d, "constant/fvOptions", "dictionary", """drive
{
    type meanVelocityForce;
    selectionMode all;
    fields (U);
    Ubar (%r 0 0);
    relaxation 1.0;
}
""" % Ubar)
    return cpu_of(["simpleFoam"], d, os.path.join(d, "log.simpleFoam"), env, may_fail=True)


# ibmdem's methods in the harness (--methods): the [ibm] keys of each.  none, calibrated, gaps: the
# shipped forcing (forcing_time 0.2) with that radius_correction; narrow: the seed's volume fraction
# on a band half as wide (band_width 0.5) with a stiffer forcing (forcing_time 0.05), no calibration
IBM_METHODS = {"none": "forcing_time = 0.2\nradius_correction = none",
               "calibrated": "forcing_time = 0.2\nradius_correction = calibrated",
               "gaps": "forcing_time = 0.2\nradius_correction = gaps",
               "narrow": "forcing_time = 0.05\nband_width = 0.5\nradius_correction = none"}


def ibm_method_keys(method):
    if method not in IBM_METHODS:
        sys.exit("crosscheck: unknown method %r (one of %s)" % (method, ", ".join(IBM_METHODS)))
    return IBM_METHODS[method]


def plot_speed_error(ax, runs, err, code, meth):
    """one series on a speed-against-error plot: CPU seconds against err(run) (%), each point
    labelled with its D/dx"""
    ax.loglog([r["cpu"] for r in runs], [err(r) for r in runs], "o-" if code == "OpenFOAM" else "s--",
              label="%s (%s)" % (code, meth))
    for r in runs:
        ax.annotate("%.0f" % r["dpdx"], (r["cpu"], err(r)), fontsize=7, textcoords="offset points", xytext=(3, 3))


def write_report(out, figure, name, fig, lines, table):
    """a report's figure OUT/figure.png, its table OUT/name.md and OUT/name.json, and the table on
    stdout"""
    fig.tight_layout()
    fig.savefig(os.path.join(out, figure + ".png"), dpi=120)
    with open(os.path.join(out, name + ".md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    json.dump(table, open(os.path.join(out, name + ".json"), "w"), indent=1)
    print("\n".join(lines))


def foam_mesh(d, env):
    """blockMesh, snappyHexMesh and checkMesh in the case d: (CPU seconds, cells, fluid volume)"""
    cpu_mesh = 0.0
    for cmd in (["blockMesh"], ["snappyHexMesh", "-overwrite"], ["checkMesh"]):
        cpu, _ = cpu_of(cmd, d, os.path.join(d, "log." + cmd[0]), env)
        cpu_mesh += cpu
    cm = open(os.path.join(d, "log.checkMesh")).read()
    cells = int(re.search(r"^\s*cells:\s+(\d+)", cm, re.M).group(1))
    vol = float(re.search(r"Total volume = ([-+0-9.eE]+?)\.?\s", cm).group(1))
    return cpu_mesh, cells, vol


def drop_snapshots(out):
    """remove an ibmdem run's checkpoints and field snapshots (up to 50 MB each, not needed once
    its result is read)"""
    for x in os.listdir(out):
        if x.startswith("checkpoint_") or x.startswith("fields_"):
            os.remove(os.path.join(out, x))


# The head of an ibmdem case file of the cross-check: a triply periodic cube of n^3 cells and side L,
# the fluid of nu = rho = 1 with the explicit viscous term (the harness's steady settings).
def periodic_cube_ini(n, L):
    return """[domain]
nx = %d
ny = %d
nz = %d
length = %r %r %r

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
""" % (n, n, n, L, L, L)


# The head of an ibmdem case file of the walled cases (duct.py, oscillating.py): a box of the given
# lengths at cpd cells per D (D = 1), no-slip walls on y and z and x_bc (periodic or noslip) along x,
# the fluid of nu = rho = 1 with the Crank-Nicolson viscous term.
def walled_box_ini(cpd, lengths, x_bc):
    return """[domain]
cells_per_diameter = %d
diameter = 1
length = %r %r %r

[boundary]
x_lo = %s
x_hi = %s
y_lo = noslip
y_hi = noslip
z_lo = noslip
z_hi = noslip

[fluid]
nu = 1
rho = 1
viscous = implicit
""" % (cpd, lengths[0], lengths[1], lengths[2], x_bc, x_bc)


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


def dat_rows(path):
    """a function object's .dat file: {iteration: [the numbers after it]}"""
    out = {}
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            nums = [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:[eE][-+]?\d+)?", line)]
            out[int(round(nums[0]))] = nums[1:]
    return out


def find_dat(d, fo, stem):
    for root, _, files in os.walk(os.path.join(d, "postProcessing", fo)):
        for x in files:
            if x.startswith(stem) and x.endswith(".dat"):
                return os.path.join(root, x)
    sys.exit("crosscheck: no %s*.dat of %s in %s" % (stem, fo, d))

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
