#!/bin/bash
# column_collapse_test.sh — the immersed granular column collapse (Izard 2014 ch. 5), coarse
# dense/loose pair of cases/column_collapse (README.md there): 88 grains, R0 = 8 D, a ~ 0.6,
# D/dx = 5, the fluid and contacts of Table 5.1, on 2 ranks:
#  1. dense: dry pluviation behind the gate (coarse_dense.ini); loose: the grains settled in the
#     fluid with the coupled code (coarse_settle.ini), whose last particle snapshot is the packing
#     of coarse_loose.ini; every run ends without divergence, with overlaps below 1 % of D;
#  2. the basal pore pressure p_b (the mean of the four probes across the width at x = 13/16 R0,
#     0.75 D above the bed, relative to hydrostatic and to the clear fluid far away; moving
#     average over 0.02 s): SIGNS_CHECK
# The magnitudes over Delta rho g H0, the times in T_visq = eta/(Delta rho g H0) and the initial
# solid fractions are printed (postproc/column_collapse.py).
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_collapse.XXXXXX)
C=cases/column_collapse
O="--set output.progress=off --set output.series_every=1 --set output.fields_every=0.05"
R0=0.1216
$MPIRUN -np 2 $BIN run $C/coarse_dense.ini $O --out $T/dense >$T/dense.log 2>&1 &&
    $MPIRUN -np 2 $BIN run $C/coarse_settle.ini $O --set output.fields_every=0.5 --out $T/settle >$T/settle.log 2>&1 &&
    $MPIRUN -np 2 $BIN run $C/coarse_loose.ini $O --set particles.file=$(ls $T/settle/particles_*.h5 2>/dev/null | tail -1) \
        --out $T/loose >$T/loose.log 2>&1
rc=$?
report $rc "coarse column collapse, dense and loose (settled in the fluid): the three runs end"
[ $rc = 0 ] || { tail -5 $T/*.log | sed 's/^/#   /'; tap_end $T; }
for k in dense loose; do
    $PY postproc/column_collapse.py $T/$k $R0 | sed "s/^/# $k /"
done
$PY - $T <<'PY'
import json, sys
import numpy as np
T = sys.argv[1]
ok = True
for k in ("dense", "settle", "loose"):
    s = np.genfromtxt(f"{T}/{k}/series.csv", delimiter=",", names=True)
    ov = s["dem_max_overlap"].max()
    print(f"# {k}: largest overlap {ov:.4f} of the smaller diameter")
    ok &= ov < 0.01
sys.exit(0 if ok else 1)
PY
report $? "overlaps below 1 % of D in every run"
tap_end $T
