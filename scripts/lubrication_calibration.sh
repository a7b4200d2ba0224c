#!/bin/bash
# The cut-off of the lubrication correction (docs/theory.md 9.2): the squeeze of
# cases/lubrication_calibration/squeeze_axi.ini at D/dx = N for each N given (default 10 20),
# from a gap of 0.8 D down to 0.2 dx, at nu dt/dx^2 = 1, one rank each; then
# postproc/lubrication_calibration.py prints the impulse-equivalent cut-off of each run and writes
# OUT/calibration.png.  D/dx = 40 takes about 2 hours of one core.
# usage: scripts/lubrication_calibration.sh [OUT=build/lubrication_calibration] [N ...]
set -e
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=${1:-$ROOT/build/lubrication_calibration}
shift || true
LIST=${*:-10 20}
mkdir -p "$OUT"
runs=()
for N in $LIST; do
    d=$OUT/squeeze_n$N
    read -r dt tend <<<"$(/usr/bin/python3 -c "print(1.0/($N*$N), (1.3 - 0.5 - 0.2/$N)/0.01)")"
    "$ROOT/build/ibmdem" run "$ROOT/cases/lubrication_calibration/squeeze_axi.ini" --out "$d" \
        --set domain.nx=$((6 * N)) --set domain.ny=$((12 * N)) --set domain.x_uniform_cells=$((5 * N / 2)) \
        --set fluid.dt_max="$dt" --set time.t_end="$tend" > "$d.log" 2>&1 || { echo "run N=$N failed: $d.log"; exit 1; }
    runs+=("$d")
done
/usr/bin/python3 "$ROOT/postproc/lubrication_calibration.py" "$OUT/calibration.png" "${runs[@]}"
