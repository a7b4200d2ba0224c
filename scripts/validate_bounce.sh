#!/bin/bash
# The bouncing sphere against experiments (make validate; `make bounce` alone), one rank per run, two at a time:
#  1. the lubrication cut-off: the squeeze of cases/lubrication_calibration at D/dx = 10 and 20
#     (scripts/lubrication_calibration.sh);
#  2. Gondret et al. (2002) St ~ 27 (cases/bouncing_sphere/gondret_st27.ini) at D/dx = 10, 20 (and 40 with
#     FULL=1), the fluid step halved at D/dx = 20, and St ~ 152 (gondret_st152.ini) at D/dx = 20 (30 and 40
#     with FULL=1): postproc/bounce_experiments.py against the digitised trajectories (OUT/gondret.png,
#     .csv); checks: St 27 apex within 5 % of the experiment at every resolution, the change between the
#     two finest < 5 % (apex and epsilon_fit), halving the fluid step moves epsilon and epsilon_fit by
#     < 0.02; St 152 is printed with MISS when its apex or secant is off by more than 5 % / 0.05
#     (docs/validation.md: the immersed boundary at Re 160 needs more than D/dx = 40);
#  3. the oblique sweep (scripts/oblique_sweep.sh, 5 angles).
# usage: scripts/validate_bounce.sh   (OUT, BUILD, FULL from the environment)
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
OUT=${OUT:-$BUILD/validate}/bounce
BIN=$BUILD/ibmdem
mkdir -p "$OUT"
rc=0
bash scripts/lubrication_calibration.sh "$OUT/calibration" 10 20 || rc=1

g27=cases/bouncing_sphere/gondret_st27.ini g152=cases/bouncing_sphere/gondret_st152.ini
grid() { # N: the grid of the axisymmetric bounce at D/dx = N (the case files are at 20)
    echo "--set domain.nx=$((4 * $1)) --set domain.x_uniform_cells=$((5 * $1 / 2))"
}
jobs_list=(
    "$g27 st27_n10 $(grid 10) --set domain.ny=230 --set fluid.dt_max=1.72e-3"
    "$g27 st27_n20"
    "$g27 st27_n20_halfdt --set fluid.cfl=0.25 --set fluid.dt_max=2.15e-4"
    "$g152 st152_n20"
)
if [ -n "${FULL:-}" ]; then
    jobs_list+=("$g27 st27_n40 $(grid 40) --set domain.ny=920 --set fluid.dt_max=1.075e-4"
                "$g152 st152_n30 $(grid 30) --set domain.ny=1950 --set fluid.dt_max=1.73e-4"
                "$g152 st152_n40 $(grid 40) --set domain.ny=2600 --set fluid.dt_max=1.3e-4")
fi
pids=()
for j in "${jobs_list[@]}"; do
    read -r ini name args <<<"$j"
    # shellcheck disable=SC2086
    $BIN run "$ini" --out "$OUT/$name" --set output.progress=off $args > "$OUT/$name.log" 2>&1 &
    pids+=($!)
    if [ ${#pids[@]} -ge 2 ]; then wait "${pids[0]}" || rc=1; pids=("${pids[@]:1}"); fi
done
for p in "${pids[@]}"; do wait "$p" || rc=1; done
D=cases/bouncing_sphere/data
pairs=()
for d in "$OUT"/st27_n*/; do pairs+=("${d%/}:$D/gondret_st27_trajectory_digitized.csv"); done
for d in "$OUT"/st152_n*/; do pairs+=("${d%/}:$D/gondret_st152_trajectory_digitized.csv"); done
/usr/bin/python3 postproc/bounce_experiments.py "$OUT/gondret.png" "${pairs[@]}" || rc=1
/usr/bin/python3 - "$OUT" <<'PY' || rc=1
import csv, json, os, sys
out = sys.argv[1]
rows = {r["case"]: r for r in csv.DictReader(open(f"{out}/gondret.csv"))}
summ = lambda n: json.load(open(f"{out}/{n}/summary.json"))["coupling"]
ok = True
def check(cond, text):
    global ok
    print(("PASS " if cond else "FAIL ") + text)
    ok &= cond
st27 = sorted((n for n in rows if n.startswith("st27_n") and "halfdt" not in n), key=lambda n: int(n[6:]))
for n in st27:
    a = float(rows[n]["apex1_run"]) / float(rows[n]["apex1_exp"]) - 1
    check(abs(a) < 0.05, f"St 27 {n}: apex {float(rows[n]['apex1_run']):.4f} D against 0.329 ({100 * a:+.1f} %)")
f1, f2 = st27[-2], st27[-1]
da = float(rows[f2]["apex1_run"]) / float(rows[f1]["apex1_run"]) - 1
de = summ(f2)["epsilon_fit"] / summ(f1)["epsilon_fit"] - 1
check(abs(da) < 0.05 and abs(de) < 0.05, f"St 27 {f1} -> {f2}: apex {100 * da:+.1f} %, epsilon_fit {100 * de:+.1f} %")
a, b = summ("st27_n20"), summ("st27_n20_halfdt")
check(abs(a["epsilon"] - b["epsilon"]) < 0.02 and abs(a["epsilon_fit"] - b["epsilon_fit"]) < 0.02,
      f"St 27 fluid step halved: epsilon {a['epsilon']:.4f} -> {b['epsilon']:.4f}, epsilon_fit "
      f"{a['epsilon_fit']:.4f} -> {b['epsilon_fit']:.4f}")
for n in sorted((n for n in rows if n.startswith("st152")), key=lambda n: int(n[7:])):
    r = rows[n]
    a = float(r["apex1_run"]) / float(r["apex1_exp"]) - 1
    s = float(r["secant_run"]) - float(r["secant_exp"])
    good = abs(a) < 0.05 and abs(s) < 0.05
    print(("PASS " if good else "MISS ") + f"St 152 {n}: apex {float(r['apex1_run']):.3f} D against 2.489 ({100 * a:+.1f} %), "
          f"secant {float(r['secant_run']):.3f} against {float(r['secant_exp']):.3f} ({s:+.3f}), V_T {summ(n)['V_T']:.4f} m/s "
          f"against 0.585")
sys.exit(0 if ok else 1)
PY
IBMDEM=$BIN bash scripts/oblique_sweep.sh "$OUT/oblique" 0 10 20 30 40 || rc=1
exit $rc
