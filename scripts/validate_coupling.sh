#!/bin/bash
# make validate, coupling section: the bouncing sphere of Izard (2014) Fig. 3.3
# (cases/bouncing_sphere) at full size, one rank per run.
#  1. D/dx = 20 with lubrication at four phases of the contact within the fluid step (release
#     heights 40, 40.004, 40.008, 40.012 D: a quarter of a step's displacement apart at V_T):
#     each eps/eps_max and their mean, St, V_C/V_T, against the issue's targets
#     (St within 5 % of 55, V_C/V_T = 0.88 +- 0.03, eps/eps_max = 0.65 +- 0.05);
#  2. the same without lubrication (target eps/eps_max >= 0.9);
#  3. the speed-against-error series D/dx = 8, 10, 14, 20, 28, 40 (scripts/bounce_resolution.sh:
#     table and PNG in OUT/bounce_resolution; target: eps/eps_max changes by < 0.05 between
#     D/dx = 10, 20 and 40);
#  4. the 3-D counterpart (bounce_3d.ini, D/dx = 10, 2 ranks);
#  5. the seed's Table 3.2 points at St ~ 55 (eta_e/R = 1e-5, 2e-4, 1e-3 with Delta_lub = R/2,
#     and 2e-4 with Delta_lub = R): eps/eps_max beside the seed's value and model (3.30)
#     (a comparison, not a target of the issue; docs/validation.md).
# Prints PASS/MISS per target with the measured value; exits non-zero on a failed run (a
# missed target is reported, not fatal: docs/validation.md discusses them).
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
OUT=${OUT:-$BUILD/validate}/coupling
mkdir -p "$OUT"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
INI=cases/bouncing_sphere/bounce_axi.ini
S="--set coupling.stop_after_rebound=true --set output.progress=off"
rc=0
for y in 40 40.004 40.008 40.012; do
    rm -rf "$OUT/phase_$y"
    "$BUILD/ibmdem" run $INI $S --set particles.particle1=center,0,$y,0,diameter,1,density,8 --out "$OUT/phase_$y" \
        > "$OUT/phase_$y.log" 2>&1 || { echo "run y0=$y failed"; rc=1; }
done
rm -rf "$OUT/nolub"
"$BUILD/ibmdem" run $INI $S --set lubrication.model=none --out "$OUT/nolub" > "$OUT/nolub.log" 2>&1 || { echo "no-lubrication run failed"; rc=1; }
/usr/bin/python3 - "$OUT" <<'PY'
import json, statistics, sys
out = sys.argv[1]
runs = [json.load(open(f"{out}/phase_{y}/summary.json")) for y in ("40", "40.004", "40.008", "40.012")]
c = [r["coupling"] for r in runs]
e = [x["epsilon_over_max"] for x in c]
for y, x, r in zip(("40", "40.004", "40.008", "40.012"), c, runs):
    print(f"  y0 = {y}: eps/eps_max {x['epsilon_over_max']:.3f}  V_C/V_T {x['V_C_over_V_T']:.3f}  "
          f"St {x['St']:.2f}  Re_p {x['Re_p']:.2f}  wall {r['wall_time']:.1f} s")
m = statistics.mean(e)
mark = lambda ok: "PASS" if ok else "MISS"
print(f"  eps/eps_max mean {m:.3f}, spread {max(e) - min(e):.3f}: {mark(abs(m - 0.65) <= 0.05)} (0.65 +- 0.05)")
print(f"  St {c[0]['St']:.2f}: {mark(abs(c[0]['St'] - 55) <= 0.05 * 55)} (55 +- 5 %)")
vc = statistics.mean(x["V_C_over_V_T"] for x in c)
print(f"  V_C/V_T mean {vc:.3f}: {mark(abs(vc - 0.88) <= 0.03)} (0.88 +- 0.03)")
n = json.load(open(f"{out}/nolub/summary.json"))["coupling"]
print(f"  without lubrication: eps/eps_max {n['epsilon_over_max']:.3f}: {mark(n['epsilon_over_max'] >= 0.9)} (>= 0.9)")
PY
[ $? = 0 ] || rc=1
bash scripts/bounce_resolution.sh "$OUT/bounce_resolution" 8 10 14 20 28 40 || rc=1
/usr/bin/python3 postproc/bounce_resolution.py "$OUT/bounce_resolution/resolution.csv" "$OUT/bounce_resolution/resolution.png" || rc=1
rm -rf "$OUT/bounce3d"
mpirun --allow-run-as-root --oversubscribe -np 2 "$BUILD/ibmdem" run cases/bouncing_sphere/bounce_3d.ini $S --out "$OUT/bounce3d" \
    > "$OUT/bounce3d.log" 2>&1 || { echo "3-D run failed"; rc=1; }
/usr/bin/python3 -c "
import json; r = json.load(open('$OUT/bounce3d/summary.json')); c = r['coupling']
print(f\"  3-D D/dx = 10: V_T {c['V_T']:.4f}  eps/eps_max {c['epsilon_over_max']:.3f}  St {c['St']:.2f}  wall {r['wall_time']:.0f} s (2 ranks)\")" || rc=1
# 5. Table 3.2 points (two runs at a time, one rank each)
for v in "1e-5 0.5" "2e-4 0.5" "1e-3 0.5" "2e-4 1"; do
    set -- $v
    rm -rf "$OUT/t32_$1_$2"
    "$BUILD/ibmdem" run $INI $S --set lubrication.roughness=$1 --set lubrication.range=$2 --out "$OUT/t32_$1_$2" \
        > "$OUT/t32_$1_$2.log" 2>&1 &
    [ "$1 $2" = "2e-4 0.5" ] && wait
done
wait
/usr/bin/python3 - "$OUT" <<'PY' || rc=1
import json, sys
sys.path.insert(0, "postproc")
from restitution import model_330 as model  # Izard eq. 3.30 with beta of eq. 3.25
seed = {("1e-5", "0.5"): "0.59", ("2e-4", "0.5"): "-", ("1e-3", "0.5"): "0.67", ("2e-4", "1"): "0.63"}
print("  Table 3.2 at St ~ 55: eta_e/R, Delta_lub/R, eps/eps_max, seed, model (3.30), V_C_onset/V_T")
for (r, rng), sv in seed.items():
    c = json.load(open(f"{sys.argv[1]}/t32_{r}_{rng}/summary.json"))["coupling"]
    print(f"    {r:>5} {rng:>4}  {c['epsilon_over_max']:.3f}  {sv:>4}  {model(c['St'], float(r)):.3f}  "
          f"{c['V_C_onset'] / c['V_T']:.3f}  (St {c['St']:.2f})")
PY
exit $rc
