#!/bin/bash
# DEM benchmark: ibmdem against LIGGGHTS (Debian package liggghts) on the
# scene of ../shared/bench/dem/README.md, with the input files given there.
#
#   bench/dem_vs_liggghts.sh [N ...]        default sizes: 20000 100000
#
# For each N: the initial state (gen_init.py, /usr/bin/python3), the settled
# bed of phase D (150 000 steps from the initial state, run by ibmdem and
# written as a LAMMPS data file; cached in the work directory), then phase S
# (settling, 20 000 steps) and phase D (dense bed, 10 000 steps) with both
# codes on 1 and 2 ranks (and ibmdem on 1 rank with 2 OpenMP threads, compared with
# LIGGGHTS on 2 ranks).  Reports particle-steps/s (N × steps / loop wall
# time), the ratio ibmdem/LIGGGHTS, the fingerprints (centre-of-mass height,
# packing fraction, mean coordination number) and the memory per particle,
# and writes the table to $WORK/dem_bench.md.
#
# Environment: BUILD (build directory, default build), WORK (default
# $BUILD/bench_dem), RANKS (default "1 2"), STEPS_S (20000), STEPS_D (10000),
# PREP_STEPS (150000), SCENE (directory of the shared scene files).
# Sizes other than the standard ones use nx = ny = round(sqrt(N/22)).
set -e
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=${BUILD:-build}
WORK=${WORK:-$BUILD/bench_dem}
RANKS=${RANKS:-"1 2"}
STEPS_S=${STEPS_S:-20000}
STEPS_D=${STEPS_D:-10000}
PREP_STEPS=${PREP_STEPS:-150000}
if [ -z "$SCENE" ]; then
    for s in "$ROOT/../shared/bench/dem" /work/shared/bench/dem; do [ -d "$s" ] && SCENE=$(cd "$s" && pwd) && break; done
fi
[ -f "$SCENE/in.bench.liggghts" ] || { echo "dem bench: scene files not found (set SCENE)"; exit 1; }
PY=/usr/bin/python3
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
MPIRUN="mpirun --allow-run-as-root --oversubscribe"

bash bench/deps_bench.sh
command -v liggghts >/dev/null || { echo "dem bench: liggghts not installed"; exit 1; }
[ -x "$BUILD/bench/bench_dem" ] || make --no-print-directory "$BUILD/bench/bench_dem"
BENCH=$(cd "$BUILD/bench" && pwd)/bench_dem

mkdir -p "$WORK"
WORK=$(cd "$WORK" && pwd)
cp "$SCENE/in.bench.liggghts" "$WORK/"
cp bench/cpustamp.py "$WORK/" && chmod +x "$WORK/cpustamp.py"
cd "$WORK"
SIZES=${*:-"20000 100000"}
results=$WORK/results.txt
: > "$results"

for N in $SIZES; do
    case $N in
        20000) NX=30 ;;
        100000) NX=67 ;;
        *) NX=$($PY -c "import math; print(max(2, round(math.sqrt($N / 22))))") ;;
    esac
    [ -f init_$N.data ] || $PY "$SCENE/gen_init.py" $N $NX 12345 init_$N.data
    if [ ! -f settled_${N}_$PREP_STEPS.data ]; then
        echo "dem bench: preparing the settled bed of N = $N ($PREP_STEPS steps by ibmdem)"
        $MPIRUN -np 1 "$BENCH" init_$N.data $PREP_STEPS prep_$N settled_${N}_$PREP_STEPS.data > prep_$N.log 2>&1
        grep BENCH prep_$N.log
    fi
    for phase in S D; do
        if [ $phase = S ]; then data=init_$N.data; steps=$STEPS_S; else data=settled_${N}_$PREP_STEPS.data; steps=$STEPS_D; fi
        for np in $RANKS; do
            tag=${phase}_${N}_np$np
            echo "dem bench: phase $phase, N = $N, $np rank(s): LIGGGHTS"
            rm -f lig_$tag.cpu
            $MPIRUN -np $np liggghts -in in.bench.liggghts -var data $data -var nsteps $steps -var out lig_$tag \
                -log lig_$tag.log > lig_$tag.out 2>&1 || { echo "LIGGGHTS failed, see $WORK/lig_$tag.out"; exit 1; }
            echo "dem bench: phase $phase, N = $N, $np rank(s): ibmdem"
            par=replicated; [ $np -gt 1 ] && par=split
            $MPIRUN -np $np "$BENCH" $data $steps ibm_$tag - $par > ibm_$tag.out 2>&1 || { echo "ibmdem failed, see $WORK/ibm_$tag.out"; exit 1; }
            echo "$phase $N $np $steps lig_$tag.out ibm_$tag.out" >> "$results"
            if [ $np -gt 1 ]; then
                # the same with one rank and $np OpenMP threads ([dem] threads); Open MPI binds a
                # single rank to one core unless told not to, which would put every thread on it
                echo "dem bench: phase $phase, N = $N, 1 rank x $np threads: ibmdem"
                $MPIRUN --bind-to none -np 1 "$BENCH" $data $steps ibm_${tag}t - replicated $np > ibm_${tag}t.out 2>&1 ||
                    { echo "ibmdem failed, see $WORK/ibm_${tag}t.out"; exit 1; }
                echo "$phase $N ${np}t $steps lig_$tag.out ibm_${tag}t.out" >> "$results"
            fi
        done
    done
done

$PY - "$results" <<'EOF'
import re, sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip()]
out = []
out.append("Indicative numbers (shared, loaded machine; the lead re-measures on a quiet one).\n")
out.append("ranks: MPI ranks of both codes; 2t: LIGGGHTS on 2 ranks, ibmdem on 1 rank with 2 threads.\n")
out.append("CPU ratio: the same ratio in CPU time of the loop (rank 0's process), the robust measure on a shared machine (1-rank rows).\n")
out.append("| phase | N | ranks | LIGGGHTS p-steps/s | ibmdem p-steps/s | ratio | CPU ratio | z_com L / i (mm) | phi L / i | Z L / i | B/particle L / i |")
out.append("|---|---|---|---|---|---|---|---|---|---|---|")
worst = []
for phase, N, np_, steps, lf, bf in rows:
    threads = np_.endswith("t")
    N, np_, steps = int(N), int(np_.rstrip("t")), int(steps)
    lt = open(lf).read()
    loop = float(re.search(r"Loop time of ([0-9.eE+-]+) on \d+ procs for %d steps" % steps, lt).group(1))
    fp = re.search(r"FINGERPRINT \S+: zbar= (\S+) zmax= (\S+) phi_com= (\S+) Zmean= (\S+)", lt)
    mem = float(re.search(r"Memory usage per processor = ([0-9.]+) Mbytes", lt).group(1))
    lz, lphi, lZ = float(fp.group(1)), float(fp.group(3)), float(fp.group(4))
    lpps = N * steps / loop
    lcpu = None
    try:
        stamps = dict((l.split()[0], float(l.split()[2])) for l in open(lf.replace(".out", ".cpu")) if l.strip())
        lcpu = stamps["loopend"] - stamps["loopstart"]
    except (OSError, KeyError, IndexError, ValueError):
        pass
    lmem = mem * np_ * 2**20 / N
    bt = open(bf).read()
    m = re.search(r" particle_steps_per_s= (\S+) cpu= \S+ s cpu_particle_steps_per_s= \S+ zbar= (\S+) zmax= (\S+) phi_com= (\S+) Zmean= (\S+).*"
                  r"mem_alloc_per_particle= (\S+) B peak_rss_per_particle= (\S+) B", bt)
    ipps, iz, iphi, iZ, imem, irss = (float(m.group(k)) for k in (1, 2, 4, 5, 6, 7))
    ratio = ipps / lpps
    c = re.search(r" cpu= (\S+) s", bt)
    cpu_ratio = lcpu / float(c.group(1)) if (c and lcpu and np_ == 1 and not threads) else None
    worst.append((ratio, phase, N, np_ if not threads else 0, cpu_ratio))
    out.append("| %s | %d | %s | %.3g | %.3g | %.2f | %s | %.4f / %.4f | %.4f / %.4f | %.3f / %.3f | %.0f / %.0f (rss %.0f) |"
               % (phase, N, "%dt" % np_ if threads else str(np_), lpps, ipps, ratio,
                  "%.2f" % cpu_ratio if cpu_ratio else "—", 1e3 * lz, 1e3 * iz, lphi, iphi, lZ, iZ, lmem, imem, irss))
    dphi, dZ = abs(iphi / lphi - 1), abs(iZ / lZ - 1) if lZ > 0.05 else abs(iZ - lZ)
    if dphi > 0.02 or (lZ > 0.05 and dZ > 0.02):
        out.append("|  | fingerprint differs by more than 2 %% (phi %.2f %%, Z %.2f %%) | | | | | | | | | |" % (100 * dphi, 100 * dZ))
text = "\n".join(out)
print(text)
open(sys.argv[1].replace("results.txt", "dem_bench.md"), "w").write(text + "\n")
one = [w for w in worst if w[3] == 1]
if one:
    r = min(one)
    print("\nsmallest ratio on 1 rank: %.2f (phase %s, N = %d); target >= 2" % r[:3])
    cpu = [w for w in one if w[4]]
    if cpu:
        r = min(cpu, key=lambda w: w[4])
        print("smallest CPU-time ratio on 1 rank: %.2f (phase %s, N = %d); target >= 2" % (r[4], r[1], r[2]))
EOF
