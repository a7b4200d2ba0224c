#!/bin/bash
# The coupled step of the column collapse against the fluid step alone (issue 20: at most 2 times):
# case A (cases/column_collapse/case.ini, 2.2 M cells, 327 grains) on one rank with the explicit
# viscous term at its limit, STEPS steps (default 300: the first 2.9 sqrt(D/g), the column starting
# to move, every contact of the packing present) from case A's dense packing, against the same
# grid, fluid and step without grains (the case file without its [particles], [bed], [contact],
# [walls], [packing], [dem], [lubrication], [coupling] and [ibm] sections), interleaved PAIRS
# times (default 2).  CPU time of each whole run (start-up included; the machine is shared).
# Prints "RESULT collapse_step ..." lines.  Environment: BUILD (default build), WORK (default
# $BUILD/bench_collapse), STEPS, PAIRS.
set -e
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
WORK=${WORK:-$BUILD/bench_collapse}
STEPS=${STEPS:-300}
PAIRS=${PAIRS:-2}
BIN=$PWD/$BUILD/ibmdem
C=cases/column_collapse/case.ini
mkdir -p "$WORK"
# case A's dense packing (the dry preparation of the case file, without the fluid)
"$BIN" run $C --set coupling.fluid=off --set time.t_end=1e-9 --set output.overwrite=true \
    --out "$WORK/packing" >"$WORK/packing.log" 2>&1
/usr/bin/python3 - "$C" "$WORK/fluid_only.ini" <<'PY'
import re, sys
keep, out = True, []
for line in open(sys.argv[1]).read().splitlines():
    m = re.match(r"\[(\w+)\]", line)
    if m:
        keep = m.group(1) not in ("particles", "bed", "contact", "walls", "packing", "dem", "lubrication",
                                  "coupling", "ibm")
    if keep:
        out.append(line)
open(sys.argv[2], "w").write("\n".join(out) + "\n")
PY
common="--set fluid.viscous=explicit --set time.max_steps=$STEPS --set output.fields_every=0
    --set output.checkpoint_every=0 --set output.overwrite=true --set output.progress=off"
cpu() { awk '{print $1 + $2}' "$1"; }
for i in $(seq "$PAIRS"); do
    /usr/bin/time -f "%U %S" -o "$WORK/fluid$i.cpu" "$BIN" run "$WORK/fluid_only.ini" $common \
        --out "$WORK/fluid$i" >"$WORK/fluid$i.log" 2>&1
    /usr/bin/time -f "%U %S" -o "$WORK/coupled$i.cpu" "$BIN" run $C $common --set packing.prepare=false \
        --set bed.type=none --set particles.source=file --set particles.file="$WORK/packing/column_packing.h5" \
        --out "$WORK/coupled$i" >"$WORK/coupled$i.log" 2>&1
    f=$(cpu "$WORK/fluid$i.cpu") c=$(cpu "$WORK/coupled$i.cpu")
    echo "RESULT collapse_step pair=$i steps=$STEPS cpu_fluid=$f cpu_coupled=$c ratio=$(/usr/bin/python3 -c "print('%.3f' % ($c / $f))")"
done
