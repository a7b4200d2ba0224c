#!/bin/bash
# rollback_test.sh — a diverging run keeps its last good state, in every mode, exactly:
#  1. a run made to diverge at step N (IBMDEM_FAULT=diverge@N: the checks after step N say
#     "diverged") stops with status 3 and the checkpoint of step N-1; restarted from it with
#     the same input it leaves the same folder as the uninterrupted run (every output, bit for
#     bit: tests/compare_runs.py) — fluid (cavity), immersed sphere (settling, axisymmetric),
#     DEM alone (inclined plane, on 1 and 2 ranks), resolved coupling (bouncing sphere), pore network with DEM
#     (deposition; step 89 re-triangulates, so its undoing rebuilds the network);
#  2. a coupled run that really diverges (the DEM's overlap limit at the contact) saves the
#     state at the start of the failed step: the checkpoint equals the uninterrupted run's at
#     that step (the groups of the parts);
#  3. a checkpoint with a NaN in it is refused on restart (exit 1, the dataset named);
#  4. the divergence advice is a command that works as printed: the run's own --set and --out
#     (a folder with a space and a quote in its name), shell-quoted, and a smaller step (the
#     cavity at dt = 0.12 diverges at step 6; the advice's dt = 0.06 runs to the end);
#  5. a step of an adaptive step that diverges is taken again with half its dt (time.step_retries;
#     IBMDEM_FAULT=diverge_retry@N: a divergence that the smaller step cures): the run goes on, logs
#     the retry, counts it in summary.json (rejected_steps = 1), its step N is at most half the
#     uninterrupted run's; restarted from a checkpoint after the retry, the folder is the faulted
#     run's (resolved coupling: the bouncing sphere);
#  6. a retried step does not end a run with time.steady_tol as steady (the state restored at the
#     start of the step compared with itself).
# Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_rollback.XXXXXX)

CAV="cases/cavity/cavity.ini --set domain.nx=16 --set domain.ny=16 --set time.t_end=1000 --set time.steady_tol=0"
SET="cases/settling_sphere/settling_axi.ini --set domain.nx=20 --set domain.ny=60 --set domain.length=2,6,1
     --set ibm.sphere1=free,center,0,5,0,diameter,1,density,4 --set fluid.dt=0.08 --set time.t_end=1000"
DEM="cases/dem_inclined_plane/coarse.ini --set packing.rest_energy=1e-3 --set time.t_end=1000"
BNC="cases/bouncing_sphere/bounce_axi.ini --set domain.nx=40 --set domain.ny=440 --set domain.x_uniform_cells=25
     --set output.progress=off"
PNT="cases/porenet_deposition/coarse.ini"
OUT="--set output.fields_every=0.05 --set output.checkpoint_keep=1"

# 1. made to diverge at step N, restarted with the same input: the uninterrupted run
rollback() { # name N args... (NP ranks)
    local name=$1 N=$2; shift 2
    local d=$T/$name E=$((N + 6)) run="$BIN run"
    [ "${NP:-1}" = 1 ] || run="$MPIRUN -np $NP $BIN run"
    IBMDEM_FAULT=diverge@$N $run "$@" $OUT --set time.max_steps=$E --out $d >$d.log 2>&1
    local rc=$?
    local ck=$d/$(printf "checkpoint_%08d.h5" $((N - 1)))
    grep -q "the run diverged at step $N " $d.log && rc=3 # (mpirun's status is its own)
    echo "# $name: exit $rc at the divergence"
    [ $rc = 3 ] && [ -e $ck ] && grep -q "the state at the start of that step (step $((N - 1))" $d.log &&
        $run "$@" $OUT --set time.max_steps=$E --out $d --restart $ck >>$d.log 2>&1 &&
        $run "$@" $OUT --set time.max_steps=$E --out $d.straight >$d.straight.log 2>&1 &&
        $PY tests/compare_runs.py $d $d.straight
}
said() { echo "$1: diverged at step $2, the state of step $(($2 - 1)) kept; restarted from it, the folder is the uninterrupted run's"; }
# the one-rank cases two at a time
side_start fluid rollback fluid 15 $CAV
side_start ibm rollback ibm 8 $SET
side_report fluid "$(said fluid 15)"
side_report ibm "$(said ibm 8)"
side_start dem rollback dem 25 $DEM
side_start coupled rollback coupled 30 $BNC
side_report dem "$(said dem 25)"
side_report coupled "$(said coupled 30)"
NP=2 rollback dem_np2 25 $DEM
report $? "$(said dem_np2 25)"
rollback porenet 89 $PNT
report $? "$(said porenet 89)"

# 2. a coupled run that diverges: the DEM's overlap limit at the first contact
R="$BNC --set particles.particle1=center,0,0.7,0,diameter,1,density,8 --set dem.max_overlap=1e-6 --set lubrication.model=none"
$BIN run $R --out $T/overlap >$T/overlap.log 2>&1
rc=$?
step=$(grep -o "diverged at step [0-9]*" $T/overlap.log | awk '{print $NF}')
ck=$T/overlap/$(printf "checkpoint_%08d.h5" $((step - 1)))
[ $rc = 3 ] && grep -q "maximum overlap" $T/overlap.log && [ -e $ck ] &&
    $BIN run $R --set time.max_steps=$((step - 1)) --out $T/overlap_ref >$T/overlap_ref.log 2>&1 &&
    $PY tests/compare_runs.py $ck $T/overlap_ref/$(basename $ck) --checkpoint-groups
report $? "a coupled run diverging at step $step (DEM overlap) saves the state at the start of that step, as the uninterrupted run had it"

# 3. a NaN in a checkpoint
$BIN run $CAV --set time.max_steps=10 --out $T/nan >$T/nan.log 2>&1
$PY -c "import h5py; f = h5py.File('$T/nan/checkpoint_00000010.h5', 'r+'); u = f['fluid/u']; u[3, 4, 0] = float('nan')"
$BIN run $CAV --set time.max_steps=20 --out $T/nan --restart $T/nan/checkpoint_00000010.h5 >>$T/nan.log 2>&1
rc=$?
[ $rc = 1 ] && grep -q "checkpoint_00000010.h5: /fluid/u holds non-finite values" $T/nan.log
report $? "a checkpoint with a NaN in /fluid/u is refused on restart (exit $rc), the dataset named"

# 4. the advice, followed as printed
A="$T/out dir's"
$BIN run $CAV --set fluid.dt=0.12 --set time.t_end=6 --out "$A" >$T/advice.log 2>&1
rc=$?
cmd=$(grep -A1 "continue from it with a smaller time step" $T/advice.log | tail -1)
echo "# $cmd"
[ $rc = 3 ] && [[ $cmd == *" --set fluid.dt=0.12 "*" --restart "*" --set fluid.dt=0.06" ]] &&
    eval "$cmd" >$T/advice2.log 2>&1 && grep -q "restarted from $A/checkpoint_" $T/advice2.log &&
    grep -q "reached t_end" $T/advice2.log
report $? "the divergence advice (exit $rc) is a command that works as printed: the run's --set and --out, quoted, and dt = 0.06"

# 5. a diverging adaptive step taken again with half its dt
N=30
RT="$BNC $OUT --set time.max_steps=40 --set output.checkpoint_every=4 --set output.checkpoint_keep=0"
IBMDEM_FAULT=diverge_retry@$N $BIN run $RT --out $T/retry >$T/retry.log 2>&1
rc=$?
$BIN run $RT --out $T/retry_plain >$T/retry_plain.log 2>&1
dts=$($PY -c "
import csv
a = {r['step']: float(r['dt']) for r in csv.DictReader(open('$T/retry/series.csv'))}
b = {r['step']: float(r['dt']) for r in csv.DictReader(open('$T/retry_plain/series.csv'))}
print(a['$N'], b['$N'])")
echo "# step $N: dt $dts (retried, plain)"
# the restart continues in a copy of the faulted run's folder, from the checkpoint after the retry
cp -r $T/retry $T/retry_copy && rm -f $T/retry_copy/checkpoint_0000003[6-9].h5 $T/retry_copy/checkpoint_00000040.h5
[ $rc = 0 ] && grep -q "step $N (t = .*) diverged: .*injected.*; taken again with dt <= .* (retry 1 of 4)" $T/retry.log &&
    grep -q '"rejected_steps": 1,' $T/retry/summary.json &&
    $PY -c "a, b = map(float, '$dts'.split()); assert a <= 0.5 * b" &&
    $BIN run $RT --out $T/retry_copy --restart $T/retry_copy/checkpoint_00000032.h5 >$T/retry_re.log 2>&1 &&
    grep -q '"rejected_steps": 1,' $T/retry_copy/summary.json &&
    $PY tests/compare_runs.py $T/retry_copy $T/retry
report $? "a diverging adaptive step (IBMDEM_FAULT=diverge_retry@$N, exit $rc) is taken again with half its dt, logged and counted; a restart after it gives the faulted run's folder"

# 6. a retried step is not a steady state: the steady test compares the state with the one at the
#    start of the step, and after a retry both are the restored state (a change rate of 0)
$BIN run $CAV --set time.steady_tol=1e-12 --set time.max_steps=40 --set output.fields_every=0 --out $T/steady0 \
    >$T/steady0.log 2>&1
r0=$?
IBMDEM_FAULT=diverge_retry@20 $BIN run $CAV --set time.steady_tol=1e-12 --set time.max_steps=40 \
    --set output.fields_every=0 --out $T/steady1 >$T/steady1.log 2>&1
r1=$?
[ $r0 = 0 ] && [ $r1 = 0 ] && grep -q "step 20 (t = .*) diverged: .*taken again" $T/steady1.log &&
    grep -q '"status": "max_steps",' $T/steady0/summary.json && grep -q '"status": "max_steps",' $T/steady1/summary.json
report $? "a retried step does not end a run with steady_tol as steady (cavity, retry at step 20: max_steps 40 reached)"

tap_end "$T"
