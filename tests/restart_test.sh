#!/bin/bash
# restart_test.sh — exact restart and rank-count independence.
#  1. N steps straight and N/2 steps + --restart + N/2 steps give BIT-IDENTICAL
#     fields (h5diff --delta=0 on /fluid/u, v, p of the final checkpoints) and
#     the same time-series rows after the restart, on 1 rank and on 2 ranks;
#  2. the same case on 1 and on 2 ranks agrees to round-off: |difference|
#     below 1e-12 U after N steps.  The only differences are in the order of
#     floating-point sums (global reductions, the tridiagonal and transform
#     sweeps split among the ranks), ~1e-16 per operation; N = 40 steps of a
#     stable scheme amplify them by far less than 1e4.
# Cases: the lid-driven cavity (walls, moving lid) and the periodic 2-D
# Taylor–Green vortex, both 16 x 16 so that the test takes seconds.
# Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_restart.XXXXXX)
N=40; H=$((N / 2))
final() { printf "%s/checkpoint_%08d.h5" "$1" "$N"; }
fields() { # the fluid datasets present in a checkpoint
    h5ls "$1/fluid" | awk '$2 == "Dataset" {print $1}'
}

for case in cavity taylor_green; do
    ini=cases/$case/$case.ini
    S="--set domain.nx=16 --set domain.ny=16 --set time.t_end=1000 --set time.steady_tol=0 --set output.series_every=1 --set output.fields_every=0"
    for np in 1 2; do
        d=$T/$case.np$np
        $MPIRUN -np $np $BIN run $ini $S --set time.max_steps=$N --out $d/straight >$d.log 2>&1 &&
        $MPIRUN -np $np $BIN run $ini $S --set time.max_steps=$H --out $d/split >>$d.log 2>&1 &&
        $MPIRUN -np $np $BIN run $ini $S --set time.max_steps=$N --out $d/split \
            --restart $d/split/$(printf "checkpoint_%08d.h5" $H) >>$d.log 2>&1
        rc=$?
        report $rc "$case np=$np: $N steps, and $H + restart + $H, ran"
        [ $rc = 0 ] || { sed 's/^/#   /' $d.log | tail -5; continue; }
        bad=0; list=""
        for v in $(fields "$(final $d/straight)"); do
            list="$list $v"
            h5diff --delta=0 "$(final $d/straight)" "$(final $d/split)" /fluid/$v /fluid/$v >/dev/null || bad=1
        done
        [ -n "$list" ] || bad=1
        report $bad "$case np=$np: restarted fields bit-identical to the straight run (/fluid:$list)"
        # the series rows after the restart step: every column but the wall time
        cut -d, -f1-8 $d/straight/series.csv | awk -F, -v h=$H 'NR > 1 && $1 > h' >$d/a.csv
        cut -d, -f1-8 $d/split/series.csv | awk -F, -v h=$H 'NR > 1 && $1 > h' >$d/b.csv
        cmp -s $d/a.csv $d/b.csv && [ "$(wc -l <$d/a.csv)" = $H ]
        report $? "$case np=$np: series.csv rows $((H + 1))..$N identical after the restart"
    done
    bad=1
    for v in $(fields "$(final $T/$case.np1/straight)"); do
        [ $bad = 1 ] && bad=0
        h5diff --delta=1e-12 "$(final $T/$case.np1/straight)" "$(final $T/$case.np2/straight)" /fluid/$v /fluid/$v \
            >/dev/null || { bad=2; break; }
    done
    maxdiff=$($PY - "$(final $T/$case.np1/straight)" "$(final $T/$case.np2/straight)" <<'PY'
import sys, h5py, numpy as np
a, b = h5py.File(sys.argv[1]), h5py.File(sys.argv[2])
print("%.2e" % max(np.abs(a["fluid"][k][...] - b["fluid"][k][...]).max() for k in a["fluid"]))
PY
)
    report $bad "$case: 1 and 2 ranks agree to round-off after $N steps (max |difference| $maxdiff, bound 1e-12)"
done
tap_end "$T"
