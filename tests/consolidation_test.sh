#!/bin/bash
# consolidation_test.sh — Terzaghi's consolidation in an oedometer, the coarse column
# (cases/consolidation/coarse.ini, 300 spheres, 11 grains high) through `ibmdem run` ([oedometer],
# src/core/sim_oedometer.c; docs/validation.md "Terzaghi consolidation"):
#  1. the run to T_v = 1: the incompressible fluid takes the load step at once (the base pressure
#     jumps to Δσ; its peak is above 1 by the impact of the piston, measured 1.13); p_mid, p_base and
#     U corrected by Taylor's √t method within COARSE_TOL of the series at T_v = 0.1, 0.2, 0.5, 1
#     (measured 0.066; make validate asserts ±0.05 on the 600-sphere column); the marker layer's U
#     without correction within 0.055 (measured 0.033); the raw U within 0.10 (measured 0.082); the
#     corrected zero d_s an immediate compression, 0 < d_s < 0.3 ΔH (measured 0.099).  These bound the
#     coarse column's departure (its first layer is a ninth of it): they guard the set-up against
#     regressions, not Terzaghi's accuracy;
#  2. multi-rate (docs/theory.md §8): two DEM steps per coupled step give p_mid, p_base, U and U_marker
#     at the four T_v within 1e-3 of the run solving every DEM step (measured 6.3e-4);
#  3. restart: the run stopped at step 3000 and restarted gives the same summary.json values (the
#     CPU times aside), pressure_profile.csv and series.csv rows, bit for bit;
#  4. the figure and the table of postproc/plot_consolidation.py.
# Prints TAP lines; about 30 s of CPU.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_consolidation.XXXXXX)
INI=cases/consolidation/coarse.ini
Q="--set output.progress=off"
$BIN run $INI $Q --out $T/default >$T/default.log 2>&1
report $? "coarse.ini runs to T_v = 1"
$PY - $T/default/summary.json <<'PY'
import json, sys
o = json.load(open(sys.argv[1]))["oedometer"]
COARSE_TOL, MARKER_TOL, RAW_TOL = 0.09, 0.055, 0.10
print(f"# {o['coupled_steps']} coupled steps, E_oed {o['E_oed']:.5g} Pa, kappa/d^2 {o['kappa_over_d2']:.4g}, "
      f"C_v {o['C_v']:.4g} m^2/s; peak p_base {o['p_base_max']:.3f}; deviations {o['deviation']:.4f} (p, U_corr), "
      f"{o['deviation_marker']:.4f} (marker), {o['deviation_raw_U']:.4f} (raw U); d_s {o['taylor_zero']:.4f}; "
      f"coupled/dry step {o['coupled_over_dry']:.1f}")
ok = (o["Tv_points"] == 4 and o["p_base_max"] > 0.95 and o["deviation"] < COARSE_TOL and o["deviation_marker"] < MARKER_TOL
      and o["deviation_raw_U"] < RAW_TOL and 0 < o["taylor_zero"] < 0.3)
sys.exit(0 if ok else 1)
PY
report $? "the coarse column against Terzaghi's series (T_v = 0.1, 0.2, 0.5, 1)"

$BIN run $INI $Q --set porenet.dem_steps=2 --out $T/multirate >$T/multirate.log 2>&1 &&
    $PY - $T/default/summary.json $T/multirate/summary.json <<'PY'
import json, sys
a, b = (json.load(open(p))["oedometer"] for p in sys.argv[1:3])
keys = ("Tv_0_1", "Tv_0_2", "Tv_0_5", "Tv_1")
worst = max(abs(a[t][q] - b[t][q]) for t in keys for q in ("p_mid", "p_base", "U", "U_marker"))
print(f"# multi-rate: {b['coupled_steps']} coupled steps of two DEM steps; largest difference {worst:.2e}")
sys.exit(0 if b["Tv_points"] == 4 and worst < 1e-3 else 1)
PY
report $? "two DEM steps per coupled step: within 1e-3 at the four T_v"

$BIN run $INI $Q --set time.max_steps=3000 --out $T/split >$T/split.log 2>&1 &&
    $BIN run $INI $Q --out $T/split --restart $T/split/checkpoint_00003000.h5 >>$T/split.log 2>&1 &&
    $PY - $T/default $T/split <<'PY'
import json, sys
a, b = (json.load(open(p + "/summary.json")) for p in sys.argv[1:3])
def flat(d, pre=""):
    for k, v in d.items():
        if isinstance(v, dict):
            yield from flat(v, pre + k + ".")
        elif not any(w in k for w in ("cpu", "over_dry", "time", "wall", "per_second")):
            yield pre + k, v
fa, fb = dict(flat(a["oedometer"])), dict(flat(b["oedometer"]))
diff = [k for k in fa if fa[k] != fb.get(k)]
prof = open(sys.argv[1] + "/pressure_profile.csv").read() == open(sys.argv[2] + "/pressure_profile.csv").read()
rows = lambda p: [",".join(l.split(",")[:-1]) for l in open(p + "/series.csv")]
ser = rows(sys.argv[1]) == rows(sys.argv[2])
print(f"# restart at step 3000: summary values that differ: {diff or 'none'}; pressure_profile.csv "
      f"{'identical' if prof else 'differs'}; series.csv {'identical' if ser else 'differs'}")
sys.exit(0 if not diff and prof and ser else 1)
PY
report $? "restarted at step 3000: summary, pressure profiles and series bit-identical"

$PY postproc/plot_consolidation.py $T/consolidation.png $T/default $T/multirate >$T/plot.log 2>&1 && [ -s $T/consolidation.png ]
report $? "postproc/plot_consolidation.py draws the runs"
sed 's/^/# /' $T/plot.log | head -12
tap_end "$T"
