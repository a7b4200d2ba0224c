# porenet_yade.py — the YADE half of the pore-network comparison
# (bench/porenet_vs_yade.sh), run by `yade -j1 -x bench/porenet_yade.py`.
#
# Environment: PACKING (the file bench_porenet_yade wrote: "# box x0 y0 z0 x1 y1 z1"
# and one "x y z r" line per sphere), STEPS (timed coupled steps),
# YADE_CLAMP (1: FlowEngine's default clamping of the conductances to
# [1e-4, 100] x a mean value; 0: off).
#
# 1. Permeability along z on the fixed packing: FlowEngine with p = 1 on the
#    wall z = z0, p = 0 on z = z1, no flux through the four lateral walls
#    (slipBoundary, the default), viscosity 1, the boundaries on the box faces
#    (boundaryUseMaxMin off, walls of zero thickness), CHOLMOD (useSolver 3).
#    kappa = mu Q L / (dP S) with Q = getBoundaryFlux of the inlet and outlet.
# 2. The coupled step: the same scene with the DEM running (linear
#    FrictPhys/CundallStrack contacts, gravity -z, walls) and FlowEngine every
#    step with p = 0 on z = z1, no flux elsewhere; the triangulation is built
#    at the first step and kept (meshUpdateInterval and defTolerance off):
#    time per step on a fixed topology, the first step (triangulation +
#    factorisation) reported on its own.  A dry run (FlowEngine dead) of the
#    same length gives the DEM's share.  Times: CPU time of the process (the
#    machine is shared; run with -j1 and one BLAS thread) and wall time.
import os, sys, time
from yade import utils

path = os.environ["PACKING"]
steps = int(os.environ.get("STEPS", "20"))
clamp = os.environ.get("YADE_CLAMP", "1") == "1"
box = None
sph = []
for line in open(path):
    if line.startswith("# box"):
        box = [float(v) for v in line.split()[2:8]]
    elif line.strip() and not line.startswith("#"):
        sph.append([float(v) for v in line.split()])
lo, hi = Vector3(*box[0:3]), Vector3(*box[3:6])
L = hi - lo
n = len(sph)


def scene(flow_on):
    O.reset()
    O.materials.append(FrictMat(young=1e6, poisson=0.3, frictionAngle=0.5, density=2600, label="m"))
    # walls 0..5: x0 x1 y0 y1 z0 z1 (FlowEngine's wallIds default order)
    walls = utils.aabbWalls([lo, hi], thickness=0, material="m")
    ids = O.bodies.append(walls)
    assert ids == [0, 1, 2, 3, 4, 5]
    O.bodies.append([utils.sphere(s[0:3], s[3], material="m") for s in sph])
    flow = FlowEngine(label="flow", dead=not flow_on)
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                        [Law2_ScGeom_FrictPhys_CundallStrack()]),
        flow,
        NewtonIntegrator(damping=0.2, gravity=(0, 0, -9.81)),
    ]
    flow.useSolver = 3
    flow.viscosity = 1
    flow.permeabilityFactor = 1
    flow.boundaryUseMaxMin = [False] * 6
    flow.wallThickness = 0
    flow.clampKValues = clamp
    flow.meshUpdateInterval = -1
    flow.defTolerance = -1
    flow.multithread = False
    O.dt = 0.5 * utils.PWaveTimeStep()
    return flow


# 1. permeability (the DEM does not move: one step with the integrator off).  CPU time of the
# step, split by YADE's own timers (wall-clock nanoseconds of each engine and of FlowEngine's
# checkpoints "Triangulating": triangulation, cells, volumes, conductances; "Factorize + Solve"):
# the CPU time of a part is the step's CPU time times its share of the timed wall time (one
# thread: the shares of the CPU time, up to the machine's preemptions)
flow = scene(True)
flow.bndCondIsPressure = [0, 0, 0, 0, 1, 1]
flow.bndCondValue = [0, 0, 0, 0, 1, 0]
O.engines[-1].dead = True
O.timingEnabled = True
c0 = time.process_time()
O.step()
cpu_step = time.process_time() - c0
O.timingEnabled = False
t_all = sum(e.execTime for e in O.engines)
deltas = {d[0]: d[1] for d in flow.timingDeltas.data}
share = cpu_step / t_all if t_all > 0 else 0.0
cpu_flow = flow.execTime * share
cpu_tri_net = deltas.get("Triangulating", 0) * share
cpu_factor_solve = deltas.get("Factorize + Solve", 0) * share
q_in, q_out = flow.getBoundaryFlux(4), flow.getBoundaryFlux(5)
Q = 0.5 * (abs(q_in) + abs(q_out))
kappa = flow.viscosity * Q * L[2] / (1.0 * L[0] * L[1])
print("RESULT yade_perm N= %d L= %.10g kappa= %.10e kappa/d2= %.10e Q_in= %.10e Q_out= %.10e cells= %d clamp= %d "
      "cpu_step_s= %.5g cpu_flow_s= %.5g cpu_tri_net_s= %.5g cpu_factor_solve_s= %.5g" %
      (n, L[2], kappa, kappa / 4.0, q_in, q_out, flow.nCells(), clamp, cpu_step, cpu_flow, cpu_tri_net, cpu_factor_solve))
sys.stdout.flush()

# 2. coupled step, and the dry DEM step of the same scene
res = {}
for on in (True, False):
    flow = scene(on)
    flow.bndCondIsPressure = [0, 0, 0, 0, 0, 1]
    flow.bndCondValue = [0] * 6
    t0, c0 = time.time(), time.process_time()
    O.step()  # first step: triangulation, conductances, factorisation (coupled run)
    first = (time.process_time() - c0, time.time() - t0)
    t0, c0 = time.time(), time.process_time()
    O.run(steps, True)
    res[on] = ((time.process_time() - c0) / steps, (time.time() - t0) / steps, first)
c, d = res[True], res[False]
print("RESULT yade_step N= %d steps= %d cpu_step_ms= %.5g cpu_dem_ms= %.5g cpu_flow_ms= %.5g cpu_first_s= %.4g "
      "wall_step_ms= %.5g wall_dem_ms= %.5g wall_flow_ms= %.5g wall_first_s= %.4g dt= %.3g" %
      (n, steps, 1e3 * c[0], 1e3 * d[0], 1e3 * (c[0] - d[0]), c[2][0], 1e3 * c[1], 1e3 * d[1], 1e3 * (c[1] - d[1]),
       c[2][1], O.dt))
sys.stdout.flush()
import yade
print("RESULT yade_version %s" % yade.config.version)
sys.stdout.flush()
os._exit(0)
