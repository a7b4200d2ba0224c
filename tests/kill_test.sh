#!/bin/bash
# kill_test.sh — runs killed at random moments and at chosen points inside a checkpoint
# write, restarted from their newest checkpoint until they end, leave the same outputs as
# the uninterrupted run: every file of the folder (series.csv, spheres.csv, the snapshots
# and their indexes, the checkpoints, summary.json, input.ini) identical, bit for bit on
# the same rank count (tests/compare_runs.py; only the wall-clock column of series.csv and
# the timings of summary.json are not compared).  A kill at a chosen point uses
# IBMDEM_FAULT=POINT@STEP (the program leaves with _exit, as at a kill -9, at that point):
#   checkpoint-data     the checkpoint's data written, the file not closed (incomplete)
#   checkpoint-written  the checkpoint complete under its temporary name, not renamed
#   checkpoint-renamed  renamed, the older checkpoints not yet pruned (also at the last step)
#   series-row          half a row of series.csv written and flushed
# The other kills are kill -9 at a random moment of the time loop (a delay after the run
# created series.csv, within the duration of the uninterrupted run's loop).
#   KILL_TEST=long (scripts/validate.sh) kills each case at the 5 points and 12 times at random,
#   on 1 and 2 ranks;
#   the default (make test) is the quick version: a small fluid case (cavity 16 x 16) and a
#   small coupled case (the bouncing sphere at D/dx = 10), 4 + 3 kills.
# Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_kill.XXXXXX)
MODE=${KILL_TEST:-quick}
RANDOM=17 # the same delays every time (the moments they hit vary with the machine's load)

CAV="cases/cavity/cavity.ini --set domain.nx=16 --set domain.ny=16 --set time.t_end=1000 --set time.steady_tol=0
     --set time.max_steps=300 --set output.checkpoint_every=40 --set output.fields_every=2 --set output.overwrite=true"
BNC="cases/bouncing_sphere/bounce_axi.ini --set domain.nx=40 --set domain.ny=440 --set domain.x_uniform_cells=25
     --set output.progress=off --set time.max_steps=120 --set output.checkpoint_every=20 --set output.fields_every=0.4
     --set output.overwrite=true"

# go NP DIR ARGS...: one attempt (its exit status)
go() {
    local np=$1 d=$2; shift 2
    if [ "$np" = 1 ]; then $BIN run "$@" --out $d >>$d.log 2>&1
    else $MPIRUN -np $np $BIN run "$@" --out $d >>$d.log 2>&1; fi
}
# finish NP DIR ARGS...: restart from the newest complete checkpoint until the run ends
# (no checkpoint yet: start again; output.overwrite = true lets it replace the killed run's files)
finish() {
    local np=$1 d=$2; shift 2
    for attempt in 1 2 3; do
        local ck
        ck=$(ls $d/checkpoint_*.h5 2>/dev/null | tail -1)
        if [ -n "$ck" ]; then
            echo "#   restart from $(basename $ck)"
            go $np $d "$@" --restart $ck && return 0
        else
            echo "#   no checkpoint yet: started again"
            go $np $d "$@" && return 0
        fi
    done
    return 1
}
# started DIR PID: wait until the run of PID has created DIR/series.csv (its time loop starts)
started() {
    for i in $(seq 400); do
        [ -e $1/series.csv ] && return 0
        kill -0 $2 2>/dev/null || return 1
        sleep 0.025
    done
}
# killed NP DIR HOW ARGS...: a run killed (HOW = POINT@STEP, or a delay in seconds after
# the loop started), then finished
killed() {
    local np=$1 d=$2 how=$3; shift 3
    if [[ $how == *@* ]]; then
        IBMDEM_FAULT=$how go $np $d "$@"
        [ $? = 86 ] || [ "$np" != 1 ] || { echo "# $how: the fault point was not reached"; return 1; }
    else
        # a process group of its own: kill -9 reaches every rank (and mpirun)
        setsid bash -c "$(declare -f go); BIN=$BIN MPIRUN='$MPIRUN'; go $np $d $*" &
        local pid=$!
        started $d $pid && sleep $how
        kill -9 -- -$pid 2>/dev/null
        wait $pid 2>/dev/null
    fi
    finish $np $d "$@"
}

check_case() { # name np end args... : the uninterrupted run (to step end), then the kills
    local name=$1 np=$2 end=$3; shift 3
    local ref=$T/$name.np$np.ref t0 t1 dur rc
    go $np $ref "$@" &
    local pid=$!
    started $ref $pid
    t0=$(date +%s.%N)
    wait $pid
    rc=$?
    t1=$(date +%s.%N)
    report $rc "$name np=$np: the uninterrupted run"
    dur=$(awk -v a=$t0 -v b=$t1 'BEGIN{print b - a}') # of its time loop
    local kills
    if [ "$MODE" = long ]; then
        kills="checkpoint-data@80 checkpoint-written@80 checkpoint-renamed@80 series-row@90 checkpoint-renamed@$end"
        for i in $(seq 12); do kills="$kills $(awk -v r=$RANDOM -v d=$dur 'BEGIN{printf "%.3f", r / 32768 * d}')"; done
    elif [ "$name" = cavity ]; then
        kills="checkpoint-data@80 checkpoint-renamed@$end series-row@90 $(awk -v r=$RANDOM -v d=$dur 'BEGIN{printf "%.3f", r / 32768 * d}')"
    else
        kills="checkpoint-written@60 $(awk -v r=$RANDOM -v d=$dur 'BEGIN{printf "%.3f %.3f", r / 32768 * d, (32767 - r) / 32768 * d}')"
    fi
    local k=0
    for how in $kills; do
        k=$((k + 1))
        local d=$T/$name.np$np.k$k
        killed $np $d $how "$@" &&
            $PY tests/compare_runs.py $ref $d
        report $? "$name np=$np: killed ($how), restarted: every output identical to the uninterrupted run's"
    done
}

check_case cavity 1 300 $CAV
check_case bounce 1 120 $BNC
if [ "$MODE" = long ]; then
    check_case cavity 2 300 $CAV
    check_case bounce 2 120 $BNC
fi
tap_end "$T"
