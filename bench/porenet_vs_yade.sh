#!/bin/bash
# Pore network: ibmdem against YADE's FlowEngine (Debian package yade) on the
# same packing, in the same run.
#
#   bench/porenet_vs_yade.sh [N ...]        default sizes: 300 1000 5000 20000 50000
#
# For each N, build/bench/bench_porenet_yade writes the packing (radii 1 ± 5 %,
# solid fraction 0.58, relaxed in a walled cube) and measures ibmdem; then
# `yade -j1 -x bench/porenet_yade.py` measures YADE on that file.  Both:
#   permeability along z, p = 1 / 0 on the walls z = 0 / L, no flux through
#     the lateral walls (slip: symmetry planes), mu = 1; ibmdem with its
#     default wall throats (mirror) and with porenet.wall_throats = yade, and
#     with the earlier engine (qhull, METIS, images to 6 r_max: kappa to
#     round-off); YADE with its default conductance clamping; the CPU time of
#     the whole computation and of its parts (ibmdem: triangulation, network,
#     factorisation, solve; YADE: its timers "Triangulating" = triangulation +
#     network, "Factorize + Solve"); ibmdem is run before and after YADE (the
#     second run reads the packing back) and the smaller time of each part kept;
#   time per coupled step (DEM step + fluid step, gravity -z, p = 0 on z = L,
#     no flux elsewhere) on a fixed topology: the triangulation is built at
#     the first step and kept (ibmdem porenet.retriangulate = 10, never reached;
#     YADE meshUpdateInterval = defTolerance = -1); the first step
#     (triangulation + factorisation) is reported on its own; CPU time of
#     each process (the machine is shared), one thread each.
# Writes the table to $WORK/porenet_yade.md.
#
# Environment: BUILD (default build), WORK (default $BUILD/bench_porenet_yade),
# STEPS (timed coupled steps, default 20).
set -e
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=${BUILD:-build}
WORK=${WORK:-$BUILD/bench_porenet_yade}
STEPS=${STEPS:-20}
PY=/usr/bin/python3
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# one thread per code (CHOLMOD's BLAS included)
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1

bash bench/deps_bench.sh
command -v yade >/dev/null || { echo "porenet bench: yade not installed"; exit 1; }
[ -x "$BUILD/bench/bench_porenet_yade" ] || make --no-print-directory "$BUILD/bench/bench_porenet_yade"
BENCH=$(cd "$BUILD/bench" && pwd)/bench_porenet_yade
mkdir -p "$WORK"
WORK=$(cd "$WORK" && pwd)
SIZES=${*:-"300 1000 5000 20000 50000"}
: > "$WORK/results.txt"
for N in $SIZES; do
    echo "porenet bench: N = $N, ibmdem"
    (cd "$WORK" && "$BENCH" "$N" packing_$N.txt "$STEPS" > ibm_$N.log 2>&1) || { cat "$WORK/ibm_$N.log"; exit 1; }
    grep RESULT "$WORK/ibm_$N.log"
    echo "porenet bench: N = $N, YADE"
    (cd "$WORK" && PACKING=packing_$N.txt STEPS=$STEPS yade -j1 -x "$ROOT/bench/porenet_yade.py" > yade_$N.log 2>&1) ||
        true # the script ends with os._exit(0); a failure shows as missing RESULT lines
    grep -a RESULT "$WORK/yade_$N.log" || { tail -20 "$WORK/yade_$N.log"; exit 1; }
    echo "porenet bench: N = $N, ibmdem again (interleaved)"
    (cd "$WORK" && REUSE=1 "$BENCH" "$N" packing_$N.txt "$STEPS" > ibm2_$N.log 2>&1) || { cat "$WORK/ibm2_$N.log"; exit 1; }
    grep RESULT "$WORK/ibm2_$N.log"
    echo "$N ibm_$N.log yade_$N.log ibm2_$N.log" >> "$WORK/results.txt"
done

cd "$WORK"
$PY - results.txt <<'EOF'
import re, sys
def kv(line):
    t = line.split()
    return {t[i].rstrip("="): t[i + 1] for i in range(len(t) - 1) if t[i].endswith("=")}
out = ["CPU times of each process, one thread each (ibmdem: the smaller of two runs around YADE's).\n",
       "| N | pores (ibmdem / YADE cells) | kappa/d^2 YADE | ibmdem mirror (ratio) | ibmdem wall_throats = yade (ratio) "
       "| ibmdem kappa / earlier engine's - 1 "
       "| YADE tri + net s | ibmdem tri + net s (YADE/ibmdem) | YADE factor + solve s | ibmdem factor + solve s (YADE/ibmdem) "
       "| YADE permeability s | ibmdem permeability s (YADE/ibmdem) |",
       "|---|---|---|---|---|---|---|---|---|---|---|---|"]
steps = ["\n| N | ms/step YADE (flow + DEM) | ms/step ibmdem (flow + DEM) | YADE/ibmdem per step | first step s YADE / ibmdem |",
         "|---|---|---|---|---|"]
version = "?"
for N, il, yl, il2 in (l.split() for l in open(sys.argv[1]) if l.strip()):
    runs = [[kv(l) for l in open(f) if l.startswith("RESULT ibmdem_perm")] for f in (il, il2)]
    im = {(d["wall_throats"], d["engine"]): d for d in runs[0]}
    best = {}
    for part in ("tri_s", "net_s", "factor_s", "solve_s", "total_s"):
        best[part] = min(float(r[part]) for rr in runs for r in rr if r["wall_throats"] == "mirror" and r["engine"] == "default")
    ist = [kv(l) for l in open(il) if l.startswith("RESULT ibmdem_step")][0]
    ytxt = open(yl, errors="replace").read().splitlines()
    yp = [kv(l) for l in ytxt if l.startswith("RESULT yade_perm")][0]
    ys = [kv(l) for l in ytxt if l.startswith("RESULT yade_step")][0]
    version = [l.split()[2] for l in ytxt if l.startswith("RESULT yade_version")][0]
    ky = float(yp["kappa/d2"])
    km, kyd = float(im[("mirror", "default")]["kappa/d2"]), float(im[("yade", "default")]["kappa/d2"])
    kold = float(im[("mirror", "qhull+metis+6rmax")]["kappa/d2"])
    ytn, yfs, yfl = float(yp["cpu_tri_net_s"]), float(yp["cpu_factor_solve_s"]), float(yp["cpu_flow_s"])
    itn, ifs = best["tri_s"] + best["net_s"], best["factor_s"] + best["solve_s"]
    out.append("| %s | %s / %s | %.5e | %.5e (%.4f) | %.5e (%.4f) | %.1e | %.4g | %.4g + %.4g = %.4g (%.2f) | %.4g "
               "| %.4g + %.4g = %.4g (%.2f) | %.4g | %.4g (%.2f) |"
               % (N, im[("mirror", "default")]["pores"], yp["cells"], ky, km, km / ky, kyd, kyd / ky, km / kold - 1, ytn,
                  best["tri_s"], best["net_s"], itn, ytn / itn, yfs, best["factor_s"], best["solve_s"], ifs, yfs / ifs, yfl,
                  best["total_s"], yfl / best["total_s"]))
    ys_ms, is_ms = float(ys["cpu_step_ms"]), float(ist["cpu_step_ms"])
    steps.append("| %s | %.2f (%.2f + %.2f) | %.2f (%.2f + %.2f) | %.2f | %.3g / %.3g |"
                 % (N, ys_ms, float(ys["cpu_flow_ms"]), float(ys["cpu_dem_ms"]), is_ms, float(ist["cpu_flow_ms"]),
                    float(ist["cpu_dem_ms"]), ys_ms / is_ms, float(ys["cpu_first_s"]), float(ist["cpu_first_s"])))
out.insert(0, "YADE %s (Debian package), FlowEngine; ibmdem porenet.\n" % version)
out += steps
text = "\n".join(out)
print(text)
open("porenet_yade.md", "w").write(text + "\n")
EOF
