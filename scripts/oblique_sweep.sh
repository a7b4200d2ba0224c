#!/bin/bash
# Oblique bounces (Izard 2014 §3.4, Joseph & Hunt 2004): cases/oblique_bounce/oblique_3d.ini with gravity
# turned by xi in the (x, y) plane, for each angle (default 0 5 10 15 20 25 30 35 40 degrees), two runs at a
# time; OUT/oblique.csv (xi, Psi_in, Psi_out, beta, mu_f, e_n, rebound angle, epsilon_fit, St) and, with
# /usr/bin/python3, OUT/oblique.png (postproc/oblique.py).  Extra arguments after the angles, key=value,
# are --set overrides of every run (e.g. lubrication.model=brenner).
# usage: scripts/oblique_sweep.sh [OUT=build/oblique] [angles ...] [-- key=value ...]
set -e
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=${1:-$ROOT/build/oblique}
shift || true
ANGLES=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do ANGLES+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
SETS=()
for kv in "$@"; do SETS+=(--set "$kv"); done
[ ${#ANGLES[@]} -gt 0 ] || ANGLES=(0 5 10 15 20 25 30 35 40)
BIN=${IBMDEM:-$ROOT/${BUILD:-build}/ibmdem}
mkdir -p "$OUT"
run() {
    local xi=$1 d=$OUT/xi$1
    local g
    g=$(/usr/bin/python3 -c "import math; a=math.radians($xi); print(f'{9.81*math.sin(a):.10g} {-9.81*math.cos(a):.10g} 0')")
    "$BIN" run "$ROOT/cases/oblique_bounce/oblique_3d.ini" --out "$d" --set dem.gravity="$g" \
        "${SETS[@]}" > "$d.log" 2>&1 || { echo "run xi=$xi failed: $d.log"; return 1; }
}
pids=()
for xi in "${ANGLES[@]}"; do
    run "$xi" &
    pids+=($!)
    if [ ${#pids[@]} -ge 2 ]; then wait "${pids[0]}"; pids=("${pids[@]:1}"); fi
done
for p in "${pids[@]}"; do wait "$p"; done
/usr/bin/python3 - "$OUT" "${ANGLES[@]}" > "$OUT/oblique.csv" <<'PY'
import json, sys
out, angles = sys.argv[1], sys.argv[2:]
print("xi_deg,psi_in,psi_out,beta,mu_f,e_n,rebound_angle_deg,epsilon_fit,St")
for xi in angles:
    c = json.load(open(f"{out}/xi{xi}/summary.json"))["coupling"]
    e_n = c["V_release"] / c["V_C_onset"] if c["V_C_onset"] > 0 else 0.0
    print(f"{xi},{c['psi_in']:.6f},{c['psi_out']:.6f},{c['beta']:.6f},{c['mu_f']:.6f},{e_n:.6f},"
          f"{c['rebound_angle_deg']:.4f},{c['epsilon_fit']:.6f},{c['St']:.4f}")
PY
cat "$OUT/oblique.csv"
if [ -x /usr/bin/python3 ]; then /usr/bin/python3 "$ROOT/postproc/oblique.py" "$OUT/oblique.csv" "$OUT/oblique.png" || true; fi
