#!/bin/bash
# column_collapse_porenet_test.sh — the immersed column collapse with the pore network (DEM-PFV)
# instead of the resolved fluid: the coarse dense/loose pair of cases/column_collapse
# (porenet_coarse_dense.ini, porenet_coarse_loose.ini: the grains, packings and probes of
# coarse_dense.ini and coarse_loose.ini), the clear fluid above and ahead of the column as pores at
# the hydrostatic pressure (porenet.clear_fluid_radius), to t = 0.1 s:
#  1. both runs end without divergence, overlaps below 1 % of D;
#  2. the basal pore pressure p_b (the mean of the four probes at x = 13/16 R0, 0.75 D above the
#     bed; moving average over 0.02 s) first leaves the band of +-1.5 % of Delta rho g H0 downwards
#     in the dense column (dilation) and upwards in the loose one (compaction): the signs of Izard's
#     Fig. 5.14a and of the resolved runs (column_collapse_test.sh).  Measured (series every coupled
#     step): dense first -0.017 at 0.017 s, down to -0.051 (0.07 s); loose first +0.017 at 0.008 s,
#     up to +0.053 (0.024 s), negative from 0.035 s (-0.12 at 0.045 s): the band is a third of the
#     dense extreme and of the loose positive peak (the full runs to 0.6 s: README.md);
#  3. restart = uninterrupted run with the clear fluid and the probes: 60 coupled steps of the loose
#     column straight and 30 + --restart + 30 give bit-identical particles, pore pressures and
#     series rows;
#  4. a velocity probe with the pore network is bad input (exit 2, the key named).
# 34-47 s wall (21-22 s CPU) on the shared 2 cores.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_collapse_pn.XXXXXX)
C=cases/column_collapse
O="--set output.progress=off --set output.series_every=1 --set output.fields_every=0.05 --set time.t_end=0.1"
R0=0.1216
$BIN run $C/porenet_coarse_dense.ini $O --out $T/dense >$T/dense.log 2>&1 &&
    $BIN run $C/porenet_coarse_loose.ini $O --out $T/loose >$T/loose.log 2>&1
rc=$?
report $rc "coarse column collapse with the pore network, dense and loose: the runs end"
[ $rc = 0 ] || { tail -5 $T/*.log | sed 's/^/#   /'; tap_end $T; }
for k in dense loose; do
    $PY postproc/column_collapse.py $T/$k $R0 | sed "s/^/# $k /"
done
$PY - $T <<'PY'
import json, sys
import numpy as np
T = sys.argv[1]
ok = True
for k in ("dense", "loose"):
    s = np.genfromtxt(f"{T}/{k}/series.csv", delimiter=",", names=True)
    ov = s["dem_max_overlap"].max()
    print(f"# {k}: largest overlap {ov:.4f} of the smaller diameter")
    ok &= ov < 0.01
sys.exit(0 if ok else 1)
PY
report $? "overlaps below 1 % of D in both runs"
$PY - $T <<'PY'
import json, sys
import numpy as np
T = sys.argv[1]
sign = {}
for k in ("dense", "loose"):
    j = json.load(open(f"{T}/{k}/column.json"))
    s = np.genfromtxt(f"{T}/{k}/series.csv", delimiter=",", names=True)
    t = s["time"]
    pb = np.mean([s[c] for c in j["probes"]], axis=0) / j["drho_g_H0"]
    n = max(1, int(round(j["smooth"] / np.median(np.diff(t)))) | 1)
    ps = np.convolve(np.pad(pb, n // 2, mode="edge"), np.ones(n) / n, mode="valid")
    out = np.nonzero(np.abs(ps) > 0.015)[0]
    i = out[0] if len(out) else None
    sign[k] = np.sign(ps[i]) if i is not None else 0
    first = f"{ps[i]:+.4f} at t = {t[i]:.3f} s ({t[i] / j['T_visq']:.0f} T_visq)" if i is not None else "never"
    print(f"# {k}: p_b/(drho g H0) first beyond 1.5 %: {first}; min {j['pb_min']:+.4f} at {j['t_pb_min']:.3f} s, "
          f"max {j['pb_max']:+.4f} at {j['t_pb_max']:.3f} s")
sys.exit(0 if sign["dense"] < 0 and sign["loose"] > 0 else 1)
PY
report $? "basal pore pressure after the gate opens: first below hydrostatic (dense), above (loose)"

# 3. restart = uninterrupted run
R="--set output.progress=off --set output.series_every=1 --set output.fields_every=1 --set time.t_end=1"
N=60; H=30
ck() { printf "%s/checkpoint_%08d.h5" "$1" "$2"; }
$BIN run $C/porenet_coarse_loose.ini $R --set time.max_steps=$N --out $T/straight >$T/r.log 2>&1 &&
    $BIN run $C/porenet_coarse_loose.ini $R --set time.max_steps=$H --out $T/split >>$T/r.log 2>&1 &&
    $BIN run $C/porenet_coarse_loose.ini $R --set time.max_steps=$N --out $T/split --restart "$(ck $T/split $H)" \
        >>$T/r.log 2>&1
rc=$?
report $rc "loose column: $N coupled steps, and $H + restart + $H, ran"
bad=$rc
if [ $rc = 0 ]; then
    for v in dem/position dem/velocity porenet/pressure porenet/force; do
        h5diff --delta=0 "$(ck $T/straight $N)" "$(ck $T/split $N)" /$v /$v >/dev/null || { bad=1; echo "# /$v differs"; }
    done
    ncol=$(head -1 $T/straight/series.csv | tr , '\n' | grep -vn wall_per_step | cut -d: -f1 | paste -sd,)
    cut -d, -f$ncol $T/straight/series.csv | awk -F, -v h=$H 'NR > 1 && $1 > h' >$T/a.csv
    cut -d, -f$ncol $T/split/series.csv | awk -F, -v h=$H 'NR > 1 && $1 > h' >$T/b.csv
    cmp -s $T/a.csv $T/b.csv && [ "$(wc -l <$T/a.csv)" = $H ] || { bad=1; echo "# series rows differ after the restart"; }
fi
report $bad "loose column: restarted particles, pore pressures and series rows (probes) bit-identical"

# 4. bad input: a velocity probe in the network
$BIN run $C/porenet_coarse_loose.ini --set probes.velocity=true --out $T/bad >$T/bad.log 2>&1
rc=$?
[ $rc = 2 ] && grep -q "probes.velocity: the pore network has one pressure per pore" $T/bad.log
report $? "probes.velocity = true with the pore network: refused (exit $rc, the key named)"
tap_end $T
