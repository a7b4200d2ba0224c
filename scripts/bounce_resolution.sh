#!/bin/bash
# Speed against error for the bouncing sphere of Izard's Fig. 3.3 (issue 5):
# cases/bouncing_sphere/bounce_axi.ini at D/dx = 8, 10, 14, 20, 28, 40 (the seed's grid scaled:
# 2.5 N uniform radial cells up to r = 2.5 D, 1.5 N stretched ones, 44 N axial), one rank each.
# Writes OUT/resolution.csv (D/dx, wall time, V_T, V_C/V_T, eps, eps/eps_max, St, Re_p) and,
# with /usr/bin/python3, OUT/resolution.png (change from the finest run against wall time).
# usage: scripts/bounce_resolution.sh [OUT=build/bounce_resolution] [N list]
set -e
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=${1:-$ROOT/build/bounce_resolution}
shift || true
LIST=${*:-8 10 14 20 28 40}
LUB=${LUB:-brenner}
mkdir -p "$OUT"
CSV=$OUT/resolution.csv
echo "d_over_dx,nx,ny,steps,wall_s,V_T,V_C_over_V_T,epsilon,epsilon_over_max,St,Re_p" > "$CSV"
for N in $LIST; do
    nu=$(( 5 * N / 2 )); nx=$(( 4 * N )); ny=$(( 44 * N ))
    d=$OUT/n$N
    rm -rf "$d"
    "$ROOT/build/ibmdem" run "$ROOT/cases/bouncing_sphere/bounce_axi.ini" --out "$d" \
        --set domain.nx=$nx --set domain.ny=$ny --set domain.x_uniform_cells=$nu \
        --set lubrication.model=$LUB --set coupling.stop_after_rebound=true \
        --set output.series_every=1 --set output.progress=off > "$d.log" 2>&1 || { echo "run N=$N failed: $d.log"; exit 1; }
    /usr/bin/python3 - "$d/summary.json" "$N" "$nx" "$ny" >> "$CSV" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); c = s["coupling"]
print(f'{sys.argv[2]},{sys.argv[3]},{sys.argv[4]},{s["steps"]},{s["wall_time"]:.3f},{c["V_T"]:.6f},'
      f'{c["V_C_over_V_T"]:.6f},{c["epsilon"]:.6f},{c["epsilon_over_max"]:.6f},{c["St"]:.4f},{c["Re_p"]:.4f}')
PY
    tail -1 "$CSV"
done
if [ -x /usr/bin/python3 ]; then /usr/bin/python3 "$ROOT/postproc/bounce_resolution.py" "$CSV" "$OUT/resolution.png" || true; fi
