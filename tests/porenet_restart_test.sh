#!/bin/bash
# porenet_restart_test.sh — a pore-network + DEM run restarts exactly.
#  1. cases/porenet_deposition/coarse.ini (204 settling spheres, re-triangulated
#     about every 12 coupled steps): N coupled steps straight and N/2 + --restart
#     + N/2 give BIT-IDENTICAL particles (h5diff --delta=0 on /dem/position,
#     velocity, omega, force) and network state (/porenet: pressures, forces,
#     previous positions and volumes, the triangulation's positions and the
#     accumulated strain that schedules the next one), the same number of
#     triangulations, and identical series.csv rows after the restart; with the
#     direct solver (the factorisation rebuilt from the saved triangulation),
#     with PCG (whose starting guess is the previous pressure) and two DEM steps
#     per coupled step, and on 2 ranks;
#  2. the snapshot index continues: porenet.xmf of the restarted run lists the
#     snapshots of both parts.
# Prints TAP lines; ~20 s.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_porenet_restart.XXXXXX)
N=120; H=$((N / 2))
ini=cases/porenet_deposition/coarse.ini
final() { printf "%s/checkpoint_%08d.h5" "$1" "$N"; }
S0="--set output.progress=off --set time.t_end=1 --set output.fields_every=0.001"

for variant in cholmod pcg np2; do
    S="$S0"; run="$BIN"
    [ $variant = pcg ] && S="$S --set porenet.solver=pcg --set porenet.dem_steps=2"
    [ $variant = np2 ] && run="$MPIRUN -np 2 $BIN"
    d=$T/$variant
    $run run $ini $S --set time.max_steps=$N --out $d/straight >$d.log 2>&1 &&
        $run run $ini $S --set time.max_steps=$H --out $d/split >>$d.log 2>&1 &&
        $run run $ini $S --set time.max_steps=$N --out $d/split \
            --restart $d/split/$(printf "checkpoint_%08d.h5" $H) >>$d.log 2>&1
    rc=$?
    report $rc "$variant: $N coupled steps, and $H + restart + $H, ran"
    [ $rc = 0 ] || { sed 's/^/#   /' $d.log | tail -5; continue; }
    bad=0
    for v in dem/position dem/velocity dem/omega dem/force porenet/pressure porenet/force porenet/x_previous \
        porenet/x_triangulation porenet/volume; do
        h5diff --delta=0 "$(final $d/straight)" "$(final $d/split)" /$v /$v >/dev/null || { bad=1; echo "# /$v differs"; }
    done
    for a in triangulations strain_accumulated steps; do
        [ "$(h5dump -a /porenet/$a "$(final $d/straight)" | grep '(0)')" = \
            "$(h5dump -a /porenet/$a "$(final $d/split)" | grep '(0)')" ] || { bad=1; echo "# /porenet attribute $a differs"; }
    done
    ntri=$(h5dump -a /porenet/triangulations "$(final $d/straight)" | awk '/\(0\)/ {print $2}')
    nhalf=$(h5dump -a /porenet/triangulations $d/split/$(printf "checkpoint_%08d.h5" $H) | awk '/\(0\)/ {print $2}')
    [ "${ntri:-0}" -ge $((${nhalf:-0} + 2)) ] ||
        { bad=1; echo "# triangulations: $nhalf at the restart, $ntri at the end: the test needs re-triangulations after it"; }
    report $bad "$variant: restarted particles and network bit-identical to the straight run ($ntri triangulations)"
    # the series rows after the restart step: every column but the wall time
    ncol=$(head -1 $d/straight/series.csv | tr , '\n' | grep -vn wall_per_step | cut -d: -f1 | paste -sd,)
    cut -d, -f$ncol $d/straight/series.csv | awk -F, -v h=$H 'NR > 1 && $1 > h' >$d/a.csv
    cut -d, -f$ncol $d/split/series.csv | awk -F, -v h=$H 'NR > 1 && $1 > h' >$d/b.csv
    cmp -s $d/a.csv $d/b.csv && [ "$(wc -l <$d/a.csv)" = $H ]
    report $? "$variant: series.csv rows $((H + 1))..$N identical after the restart"
done

# 2. the snapshot index: every snapshot of the first part and of the restarted one
d=$T/cholmod/split
want=$(ls $d/porenet_*.h5 | wc -l)
got=$(grep -c '<Grid Name="t[0-9]' $d/porenet.xmf)
[ "$want" -ge 4 ] && [ "$got" = "$want" ]
report $? "porenet.xmf of the restarted run lists all $want snapshots (lists $got)"
tap_end "$T"
