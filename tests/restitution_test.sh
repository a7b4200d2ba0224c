#!/bin/bash
# restitution_test.sh — coarse version of `make restitution` (issue 5): three runs of the
# sphere settling onto a wall (cases/bouncing_sphere/bounce_axi.ini with rho_p/rho = 8,
# eta_e/R = 2e-4 as in Izard's Table 3.2, D/dx = 10) and one binary collision
# (cases/binary_collision/binary_axi.ini at D/dx = 10), run in parallel through the sweep's own
# run list (scripts/restitution_cases.py coarse: [ibm] forcing_time = 0.2, fluid step of 0.05 D
# displacement) and post-processing (postproc/restitution.py).  About 12 s on 2 cores.
source "$(dirname "$0")/tap.sh"
tmp=$(mktemp -d /tmp/ibmdem_restitution.XXXXXX)
export IBMDEM=$BIN
$PY scripts/restitution_cases.py $tmp coarse > $tmp/cases.log
xargs -P 2 -n 1 bash < $tmp/jobs.list
ok=0
for rc in $tmp/*.rc; do [ "$(cat $rc)" = 0 ] || ok=1; done
report $ok "the four coarse runs finish (stop_after_rebound)"
$PY postproc/restitution.py $tmp --no-plot --no-check > $tmp/post.log
report $? "postproc/restitution.py writes restitution.csv and binary.csv"

# check NAME PYTHON-EXPRESSION: the expression sees r (the run's CSV row, values as floats where
# they parse) and prints the measured values
check() {
    $PY - "$tmp" "$1" "$2" <<'EOF'
import csv, math, sys
out, name, expr = sys.argv[1:]
def model(st, r=2e-4):  # Izard eq. 3.30 with beta of eq. 3.25 (reference notes §4.2)
    b = 1 + math.log(r) / st
    return 0.0 if b <= 0 else b * math.exp(-(math.pi / 2) / math.sqrt(b * st))
rows = list(csv.DictReader(open(out + "/restitution.csv"))) + list(csv.DictReader(open(out + "/binary.csv")))
def num(v):
    try: return float(v)
    except ValueError: return v
r = {k: num(v) for k, v in next(x for x in rows if x["name"] == name).items()}
print("# " + name + ": " + ", ".join(f"{k} = {r[k]:.4g}" for k in
      ("St", "St_B", "V_T", "V_C_over_V_T", "epsilon_over_max", "epsilon_B") if k in r))
sys.exit(0 if eval(expr) else 1)
EOF
}
# St ~ 5 (target; Schiller-Naumann): below the critical Stokes number of the seed's model,
# St_c = ln(R/eta_e) = 8.5 (eq. 3.31), and of the experiments (5-20).  "No rebound": a rebound
# speed below 1 % of V_T (postproc/restitution.py: a crawling contact can leave at 1e-4 V_T).
check wall_r8_St5_brenner 'r["rebound"] == 0 and r["St"] < 8'
report $? "no rebound at St ~ 5 with lubrication (rho_p/rho = 8)"
# V_T against Schiller-Naumann: with forcing_time = 0.2 the settling sphere at D/dx = 10 is 4-4.5 %
# slower (docs/theory.md §6b, side wall at 8 D); here side wall at 10.4 D and a fall of 25 D
# (quasi-steady estimate of 98 % of V_T: 17 D).  Measured -6.5 %; band -10 %/0 %.
$PY - $tmp <<'EOF'
import json, sys
m = json.load(open(sys.argv[1] + "/wall_r8_St55_brenner/meta.json"))
s = json.load(open(sys.argv[1] + "/wall_r8_St55_brenner/summary.json"))
ratio = s["coupling"]["V_T"] / m["V_SN"]
print(f"# V_T = {s['coupling']['V_T']:.4f}, Schiller-Naumann {m['V_SN']:.4f}, ratio {ratio:.3f}")
sys.exit(0 if 0.90 <= ratio <= 1.0 else 1)
EOF
report $? "terminal velocity at Ar = 3.6e3 (St ~ 55) within -10 %/0 % of Schiller-Naumann at D/dx = 10"
# St ~ 50 with lubrication: the issue's target for the lubricated curve, within 0.1 of the seed's
# model (3.30) for 20 <= St <= 1000 (model 0.64-0.67 for St 47-55).  The seed's own runs give 0.58
# (D/dx = 10, St 49) to 0.63 (D/dx = 20, St 55); this run (D/dx = 10, forcing_time = 0.2, contacts
# aligned) gives 0.68 (docs/validation.md), the seed's forcing (beta = alpha) 0.57 with a split contact.
check wall_r8_St55_brenner 'abs(r["epsilon_over_max"] - model(r["St"])) <= 0.1 and 40 <= r["St"] <= 60'
report $? "eps/eps_max within 0.1 of model (3.30) at St ~ 50 with lubrication (rho_p/rho = 8)"
# without lubrication: the seed's §3.1.5 run gives 0.98; the resolved film alone at D/dx = 10
# slows the sphere by a few per cent only, so >= 0.9 (issue 5).
check wall_r8_St55_none 'r["epsilon_over_max"] >= 0.9'
report $? "eps/eps_max >= 0.9 at St ~ 50 without lubrication (seed: 0.98)"
# binary, rho_p/rho = 8, St_B ~ 135: the seed's eps_B = 0.74 (D/dx = 20), Yang & Hunt 0.6-0.8;
# at D/dx = 10 the band is the issue's +-0.06 widened to +-0.08 (the coarse grid: the D/dx = 20
# run of `make restitution` is checked at +-0.06).
check binary_r8_StB135_brenner 'abs(r["epsilon_B"] - 0.74) <= 0.08 and 110 <= r["St_B"] <= 160'
report $? "binary collision: eps_B = 0.74 +- 0.08 at St_B ~ 135 (rho_p/rho = 8, D/dx = 10)"
tap_end $tmp
