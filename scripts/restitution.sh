#!/bin/bash
# Restitution curves of issue 5 (`make restitution`): the wall sweep (rho_p/rho = 2.5, 8, 16, 32,
# 12 Stokes numbers each in [1, 1000], Brenner lubrication on and off, eta_e/R = 2e-4, D/dx = 10)
# with two runs of the seed's Re ~ 100 series (rho_p/rho = 64, 128: St ~ 700, 1400), and the
# binary sweep (rho_p/rho = 8, St_B = 4 ... 160 with and without lubrication, and the seed's
# rho_p/rho = 2.3 at St_B = 7 and 90 at St_B = 1352; D/dx = 20).  Runs in parallel, one rank each,
# nice'd, on JOBS cores (default: nproc).  Then postproc/restitution.py writes OUT/restitution.csv,
# OUT/binary.csv, OUT/restitution.png, OUT/binary.png and checks the targets (PASS/FAIL lines;
# exit status 1 if a target fails).  The run list: scripts/restitution_cases.py.  Further arguments
# key=value are `--set` overrides given to every run after the run list's own (e.g.
# lubrication.overlap=saturated); `make restitution RESTITUTION_SET='key=value ...' RESTITUTION_OUT=dir`.
# usage: scripts/restitution.sh [OUT=build/restitution] [full|coarse] [key=value ...]
set -e
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=$(realpath -m "${1:-$ROOT/build/restitution}")
MODE=${2:-full}
JOBS=${JOBS:-$(nproc)}
PY=/usr/bin/python3
export IBMDEM=$ROOT/${BUILD:-build}/ibmdem
[ -x "$IBMDEM" ] || { echo "$IBMDEM missing: make all first" >&2; exit 1; }
rm -rf "$OUT"
mkdir -p "$OUT"
$PY "$ROOT/scripts/restitution_cases.py" "$OUT" "$MODE" "${@:3}"
start=$(date +%s)
xargs -P "$JOBS" -n 1 nice -n 5 bash < "$OUT/jobs.list"
cpu=$(cat "$OUT"/*.time 2>/dev/null | awk '{s += $1 + $2} END {printf "%.0f", s}')
echo "sweep: $(( $(date +%s) - start )) s on $JOBS cores, $cpu CPU s in the runs" | tee "$OUT/sweep_time.txt"
for rc in "$OUT"/*.rc; do
    [ "$(cat "$rc")" = 0 ] || echo "run failed: ${rc%.rc}.log" >&2
done
$PY "$ROOT/postproc/restitution.py" "$OUT"
