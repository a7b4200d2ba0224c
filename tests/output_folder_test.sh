#!/bin/bash
# output_folder_test.sh — what a run promises about its output folder (docs/user-guide.md,
# "What the outputs promise"):
#  1. a new run into a folder with an earlier run's outputs is refused (exit 2) and changes
#     nothing; output.overwrite = true deletes them first (no stale snapshot or checkpoint
#     left, the summary names a checkpoint that exists);
#  2. one run at a time in a folder: a second run (new or restart) is refused while the first
#     holds the folder's lock, and the lock goes with the first run, even killed with -9;
#  3. a restart continues in place: the checkpoints and snapshots the abandoned continuation
#     wrote after the restart step are deleted, series.csv is cut after the checkpoint's step,
#     and a series.csv whose rows are not those the run had written when it wrote the
#     checkpoint (rows missing, or not reaching its step) is refused (exit 1);
#  4. write errors: series.csv on a full file system (a 64 kB tmpfs, when mount is
#     permitted), log.txt on /dev/full, HDF5 snapshots on a full file system on 2 ranks:
#     exit 1, the file and the reason named, no hang; with room elsewhere a checkpoint is
#     left and named;
#  5. long paths: an output folder of 300 and 480 characters works on 2 ranks (MPI-IO under
#     parallel HDF5 once overflowed at 245: Open MPI's lockedfile component); a folder name
#     longer than NAME_MAX is refused before the run (exit 2).
# Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_folder.XXXXXX)
CAV="cases/cavity/cavity.ini --set domain.nx=16 --set domain.ny=16 --set time.t_end=1000 --set time.steady_tol=0
     --set output.series_every=1 --set output.fields_every=1 --set output.checkpoint_every=10 --set output.checkpoint_keep=0"
listing() { (cd $1 && ls | sort | xargs md5sum 2>/dev/null); }

# 1. an earlier run's outputs: refused, or deleted with output.overwrite
O=$T/again
$BIN run $CAV --set time.max_steps=40 --out $O >$T/a1.log 2>&1
before=$(listing $O)
$BIN run $CAV --set time.max_steps=20 --out $O >$T/a2.log 2>&1
rc=$?
[ $rc = 2 ] && grep -q "holds the outputs of an earlier run" $T/a2.log && [ "$(listing $O)" = "$before" ]
report $? "a new run into a folder with an earlier run's outputs is refused (exit $rc) and changes nothing"
$BIN run $CAV --set time.max_steps=20 --set output.overwrite=true --out $O >$T/a3.log 2>&1 &&
    $BIN run $CAV --set time.max_steps=20 --set output.overwrite=true --out $T/fresh >$T/a4.log 2>&1
rc=$?
ck=$($PY -c "import json; print(json.load(open('$O/summary.json'))['checkpoint'])")
[ $rc = 0 ] && [ -e "$ck" ] && [ "$(ls $O)" = "$(ls $T/fresh)" ] && $PY tests/compare_runs.py $O $T/fresh
report $? "output.overwrite = true: the earlier files are deleted, the folder is that of a fresh run"

# 2. the lock: one run at a time
B=$T/busy
# the busy run lasts until it is killed (t_end far) and keeps every checkpoint (the one the
# restart below names must not be pruned while this script polls for it)
setsid $BIN run $CAV --set time.max_steps=100000 --set time.t_end=100000 --set output.checkpoint_every=50 \
    --set output.checkpoint_keep=0 --out $B >$T/b1.log 2>&1 &
pid=$!
for i in $(seq 400); do [ -e $B/checkpoint_00000050.h5 ] && break; sleep 0.025; done
$BIN run $CAV --set time.max_steps=20 --set output.overwrite=true --out $B >$T/b2.log 2>&1
rc2=$?
$BIN run $CAV --set time.max_steps=100 --out $B --restart $B/checkpoint_00000050.h5 >$T/b3.log 2>&1
rc3=$?
kill -9 -- -$pid 2>/dev/null
wait $pid 2>/dev/null
[ $rc2 = 2 ] && [ $rc3 = 2 ] && grep -q "another run writes into this folder (process $pid" $T/b2.log &&
    grep -q "another run writes into this folder" $T/b3.log
report $? "a second run into a busy folder is refused, new (exit $rc2) or restarted (exit $rc3), naming the process"
ck=$(ls $B/checkpoint_*.h5 | tail -1)
$BIN run $CAV --set time.t_end=100000 --set output.checkpoint_every=50 --set output.checkpoint_keep=0 \
    --set time.max_steps=$(($(basename $ck .h5 | sed 's/checkpoint_0*//') + 10)) --out $B --restart $ck >$T/b4.log 2>&1
report $? "the lock goes with the run that held it, even killed with -9: the restart runs"

# 3. a restart continues in place
R=$T/restart
$BIN run $CAV --set time.max_steps=40 --out $R >$T/r1.log 2>&1 &&
    $BIN run $CAV --set time.max_steps=30 --out $R --restart $R/checkpoint_00000020.h5 >$T/r2.log 2>&1 &&
    $BIN run $CAV --set time.max_steps=30 --out $T/restart30 >$T/r3.log 2>&1
rc=$?
ck=$($PY -c "import json; print(json.load(open('$R/summary.json'))['checkpoint'])")
[ $rc = 0 ] && [ ! -e $R/checkpoint_00000040.h5 ] && [ -e "$ck" ] && [ "$(ls $R)" = "$(ls $T/restart30)" ] &&
    [ "$(tail -1 $R/series.csv | cut -d, -f1)" = 30 ] && $PY tests/compare_runs.py $R $T/restart30 --skip input
report $? "a restart from step 20 of a run that went to 40 deletes what came after: the folder is that of a run to 30 (but the inputs in the checkpoints)"
cp $R/series.csv $T/series.csv
sed -i '/^1[5-9],/d' $R/series.csv
$BIN run $CAV --set time.max_steps=30 --out $R --restart $R/checkpoint_00000020.h5 >$T/r4.log 2>&1
rc=$?
[ $rc = 1 ] && grep -q "series.csv: its 16 rows up to step 20 are not those the run wrote before the checkpoint" $T/r4.log
report $? "series.csv with rows missing before the checkpoint's step is refused on restart (exit $rc)"
sed '/^1[8-9],/,$d' $T/series.csv >$R/series.csv
$BIN run $CAV --set time.max_steps=30 --out $R --restart $R/checkpoint_00000020.h5 >$T/r5.log 2>&1
rc=$?
[ $rc = 1 ] && grep -q "series.csv: its rows end at step 17 (line 19 is the last), but the checkpoint of step 20 follows a row of step 20" $T/r5.log
report $? "series.csv whose rows end before the checkpoint's step is refused on restart (exit $rc)"

# 4. write errors
F=$T/full
mkdir -p $F
if mount -t tmpfs -o size=64k tmpfs $F 2>/dev/null; then
    $BIN run $CAV --set time.max_steps=100000 --set output.fields_every=0 --set output.checkpoint_every=0 \
        --out $F/o >$T/f1.log 2>&1
    rc=$?
    [ $rc = 1 ] && grep -q "error: cannot write $F/o/series.csv: No space left on device" $T/f1.log &&
        grep -q "no checkpoint could be written" $T/f1.log
    report $? "series.csv on a full file system: exit $rc, the file and the reason named ($(grep -m1 -o 'No space left on device' $T/f1.log))"
    rm -rf $F/o
    timeout 120 $MPIRUN -np 2 $BIN run $CAV --set domain.nx=32 --set domain.ny=32 --set time.max_steps=100000 \
        --set output.checkpoint_every=0 --out $F/o >$T/f2.log 2>&1
    rc=$?
    [ $rc = 1 ] && grep -q "error (rank [01]): cannot write .*HDF5 file $F/o/fields_0.*\.h5" $T/f2.log
    report $? "HDF5 snapshots on a full file system, 2 ranks: exit $rc, no hang, the file named"
    umount -l $F
else
    echo "ok $((n + 1)) - # SKIP a full file system needs mount (tmpfs) permission"; n=$((n + 1))
    echo "ok $((n + 1)) - # SKIP a full file system needs mount (tmpfs) permission"; n=$((n + 1))
fi
L=$T/log
$BIN run $CAV --set time.max_steps=10 --out $L >$T/l1.log 2>&1
rm $L/log.txt && ln -s /dev/full $L/log.txt
$BIN run $CAV --set time.max_steps=30 --out $L --restart $L/checkpoint_00000010.h5 >$T/l2.log 2>&1
rc=$?
rm $L/log.txt
ck=$(grep -o "the state at this step is saved in [^ ]*" $T/l2.log | awk '{print $NF}')
[ $rc = 1 ] && grep -q "error: cannot write $L/log.txt: No space left on device" $T/l2.log && [ -n "$ck" ] &&
    $BIN run $CAV --set time.max_steps=30 --out $L --restart $ck >$T/l3.log 2>&1
report $? "log.txt on a full device: exit $rc, the file named, a checkpoint left ($(basename "$ck")) and the run continues from it"

# 5. long paths
long() { # a path of $1 characters under $T, in names of at most 100
    local p=$T/p$1 n
    n=$(($1 - ${#p}))
    while [ $n -gt 0 ]; do
        local k=$((n > 100 ? 100 : n - 1))
        [ $k -lt 1 ] && k=1
        p=$p/$(head -c $k /dev/zero | tr '\0' d)
        n=$(($1 - ${#p}))
    done
    echo $p
}
for len in 300 480; do
    P=$(long $len)
    $MPIRUN -np 2 $BIN run $CAV --set time.max_steps=10 --out $P >$T/p$len.log 2>&1 &&
        [ -s $P/fields_00001.h5 ] && [ -s $P/checkpoint_00000010.h5 ]
    report $? "an output folder of ${#P} characters works on 2 ranks (HDF5 snapshots and checkpoints)"
done
P=$T/$(head -c 300 /dev/zero | tr '\0' n)
$BIN run $CAV --set time.max_steps=10 --out $P >$T/pn.log 2>&1
rc=$?
[ $rc = 2 ] && grep -q "output.dir: a folder name of 300 characters: at most 255" $T/pn.log && [ ! -e $P ]
report $? "a folder name of 300 characters is refused before the run (exit $rc)"

tap_end "$T"
