#!/bin/bash
# make bench: every benchmark, side by side with its reference measured in the
# same run, on 1 and 2 ranks.  The raw result lines are written between the
# "make bench" markers of docs/performance.md (with the date, the commit and
# the load average, since a busy machine skews wall times).
#
#   ONLY=regex   run only the sections whose name matches (fluid, poisson,
#                multigrid, porenet, dem, ibm)
#   N=64         grid size of the fluid/Poisson benches (default 128)
#   Builds nothing (`make bench` builds first).
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
N=${N:-128}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
OUT=$BUILD/bench_results
mkdir -p "$OUT"
RES=$OUT/results.txt
: >"$RES"
status=0

want() { [ -z "$ONLY" ] || [[ "$1" =~ $ONLY ]]; }
# run NAME CMD...: print the output, keep its result lines
run() {
    local name=$1; shift
    echo "=== $name: $*"
    local log=$OUT/$name.log
    if "$@" >"$log" 2>&1; then cat "$log"; else cat "$log"; echo "!!! $name failed"; status=1; fi
    grep -E '^(bench_|RESULT|BENCH|walls |periodic |channel |ibm_|#? +[0-9]+ |#   N = [0-9]+:)' "$log" | sed "s/^/[$name] /" >>"$RES"
}

if want fluid; then
    for np in 1 2; do
        run fluid_periodic_np$np $MPIRUN -np $np "$BUILD/bench/bench_fluid_step" "$N" periodic fft explicit 5
        run fluid_walls_np$np $MPIRUN -np $np "$BUILD/bench/bench_fluid_step" "$N" walls fft explicit 5
        run fluid_walls_mg_np$np $MPIRUN -np $np "$BUILD/bench/bench_fluid_step" "$N" walls multigrid explicit 3
    done
fi
if want poisson; then
    for np in 1 2; do run poisson_np$np $MPIRUN -np $np "$BUILD/bench/bench_poisson" "$N" 10; done
fi
if want multigrid; then
    for np in 1 2; do run multigrid_np$np $MPIRUN -np $np "$BUILD/bench/bench_mg" "$N"; done
fi
if want porenet && [ -x "$BUILD/bench/bench_porenet" ]; then
    run porenet $MPIRUN -np 1 "$BUILD/bench/bench_porenet" 5000 20000 80000
    # against YADE's FlowEngine on the same packings (installs yade)
    run porenet_yade bash bench/porenet_vs_yade.sh
    [ -f "$BUILD/bench_porenet_yade/porenet_yade.md" ] &&
        sed 's/^/[porenet_yade] /' "$BUILD/bench_porenet_yade/porenet_yade.md" >>"$RES"
fi
if want ibm && [ -x "$BUILD/bench/bench_ibm" ]; then
    for np in 1 2; do run ibm_np$np $MPIRUN -np $np "$BUILD/bench/bench_ibm"; done
fi
if want dem; then
    # ibmdem against LIGGGHTS on ../shared/bench/dem (installs liggghts; long)
    run dem bash bench/dem_vs_liggghts.sh
    [ -f "$BUILD/bench_dem/dem_bench.md" ] && sed 's/^/[dem] /' "$BUILD/bench_dem/dem_bench.md" >>"$RES"
fi

# Record the raw results in docs/performance.md.
/usr/bin/python3 - "$RES" <<'PY'
import re, subprocess, sys, datetime
res = open(sys.argv[1]).read()
rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
load = open("/proc/loadavg").read().split()[:3]
block = ("<!-- make bench: begin -->\n"
         f"Last `make bench` run: {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {rev}, "
         f"load average {' '.join(load)} (2 cores).\n\n```\n{res}```\n<!-- make bench: end -->")
p = "docs/performance.md"
doc = open(p).read()
if "<!-- make bench: begin -->" in doc:
    doc = re.sub(r"<!-- make bench: begin -->.*?<!-- make bench: end -->", lambda m: block, doc, flags=re.S)
else:
    doc = doc.rstrip("\n") + "\n\n## Raw results of the last run\n\n" + block + "\n"
open(p, "w").write(doc)
print("bench: results recorded in docs/performance.md")
PY
exit $status
