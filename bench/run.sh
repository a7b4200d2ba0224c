#!/bin/bash
# make bench: every benchmark, side by side with its reference measured in the
# same run, on 1 and 2 ranks.  The raw result lines are written between the
# "make bench" markers of docs/performance.md (with the date, the commit and
# the load average, since a busy machine skews wall times).
#
#   ONLY=regex   run only the sections whose name matches (fluid, poisson,
#                multigrid, porenet, dry, dem, ibm, steady, collapse)
#   N=64         grid size of the fluid/Poisson benches (default 128)
#   FFTW_WISDOM  wisdom file of the measuring planner (default $BUILD/bench_results/fftw.wisdom)
#   Builds nothing (`make bench` builds first).
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
N=${N:-128}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
OUT=$BUILD/bench_results
mkdir -p "$OUT"
RES=$OUT/results.txt
# the measuring FFTW planner's wisdom (bench_fluid_step, bench_poisson time both
# planners): measured by the first run that needs a transform, reused after
export FFTW_WISDOM=${FFTW_WISDOM:-$PWD/$OUT/fftw.wisdom}
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
        run fluid_periodic_np$np $MPIRUN -np $np "$BUILD/bench/bench_fluid_step" "$N" periodic fft explicit 10
        run fluid_walls_np$np $MPIRUN -np $np "$BUILD/bench/bench_fluid_step" "$N" walls fft explicit 10
        run fluid_walls_mg_np$np $MPIRUN -np $np "$BUILD/bench/bench_fluid_step" "$N" walls multigrid explicit 3
    done
fi
if want poisson; then
    for np in 1 2; do run poisson_np$np $MPIRUN -np $np "$BUILD/bench/bench_poisson" "$N" 10; done
    # the r2r kinds from complex DFTs against FFTW's r2r (80 lines of 880: the axisymmetric bounce)
    run r2r $MPIRUN -np 1 "$BUILD/bench/bench_r2r" 80 880 50
fi
if want multigrid; then
    for np in 1 2; do run multigrid_np$np $MPIRUN -np $np "$BUILD/bench/bench_mg" "$N"; done
fi
if want porenet && [ -x "$BUILD/bench/bench_porenet" ]; then
    run porenet $MPIRUN -np 1 "$BUILD/bench/bench_porenet" 5000 20000 50000
    # against YADE's FlowEngine on the same packings (installs yade)
    run porenet_yade bash bench/porenet_vs_yade.sh
    [ -f "$BUILD/bench_porenet_yade/porenet_yade.md" ] &&
        sed 's/^/[porenet_yade] /' "$BUILD/bench_porenet_yade/porenet_yade.md" >>"$RES"
fi
if want dry; then
    # the dry switch (coupling.fluid = off) of every shipped coupled case against the DEM alone
    run dry_switch bash bench/dry_switch.sh
fi
if want ibm && [ -x "$BUILD/bench/bench_ibm" ]; then
    for np in 1 2; do run ibm_np$np $MPIRUN -np $np "$BUILD/bench/bench_ibm"; done
fi
if want steady; then
    # a steady flow past a sphere array: explicit path against the held flow rate with Crank-Nicolson steps
    run steady bash bench/steady_path.sh
fi
if want collapse; then
    # the coupled step of the column collapse (case A) against the fluid step alone, one rank
    run collapse_step bash bench/collapse_step.sh
fi
if want dem; then
    # ibmdem against LIGGGHTS on ../shared/bench/dem (installs liggghts; long)
    run dem bash bench/dem_vs_liggghts.sh
    [ -f "$BUILD/bench_dem/dem_bench.md" ] && sed 's/^/[dem] /' "$BUILD/bench_dem/dem_bench.md" >>"$RES"
fi

# Record the raw results in docs/performance.md: the sections run now replace
# their own lines; the lines of sections not run (ONLY=...) are kept, with the
# date and commit of the run that wrote them.
/usr/bin/python3 - "$RES" <<'PY'
import re, subprocess, sys, datetime
rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
load = " ".join(open("/proc/loadavg").read().split()[:3])
stamp = f"{datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {rev}, load {load}"
def section(line):
    m = re.match(r"\[([^\]]+)\]", line)
    return m.group(1) if m else None
new = [l for l in open(sys.argv[1]).read().splitlines() if l.strip()]
run_now = {section(l) for l in new}
p = "docs/performance.md"
doc = open(p).read()
m = re.search(r"<!-- make bench: begin -->.*?```\n(.*?)```", doc, flags=re.S)
old = m.group(1).splitlines() if m else []
# an old line "[name] text" or "[name] (stamp) text": keep it with its stamp if name was not run now
kept, cur_stamp = [], None
m2 = re.search(r"Last `make bench` run: ([^(]*?), load average ([0-9. ]+)", doc)
default_stamp = f"{m2.group(1)}, load {m2.group(2).strip()}" if m2 else "earlier run"
for l in old:
    name = section(l)
    if name is None or name in run_now:
        continue
    if re.match(r"\[[^\]]+\] \{", l):
        kept.append(l)
    else:
        kept.append(l.replace(f"[{name}] ", f"[{name}] {{{default_stamp}}} ", 1))
body = "\n".join([l.replace(f"[{section(l)}] ", f"[{section(l)}] {{{stamp}}} ", 1) for l in new] + kept)
block = ("<!-- make bench: begin -->\n"
         f"Last `make bench` run: {stamp} (2 cores); each line carries the run that wrote it "
         "(sections not run by the last call keep their earlier lines).\n\n"
         f"```\n{body}\n```\n<!-- make bench: end -->")
if "<!-- make bench: begin -->" in doc:
    doc = re.sub(r"<!-- make bench: begin -->.*?<!-- make bench: end -->", lambda m: block, doc, flags=re.S)
else:
    doc = doc.rstrip("\n") + "\n\n## Raw results of the last run\n\n" + block + "\n"
open(p, "w").write(doc)
print("bench: results recorded in docs/performance.md")
PY
exit $status
