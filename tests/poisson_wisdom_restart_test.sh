#!/bin/bash
# poisson_wisdom_restart_test.sh — the measuring FFTW planner made
# reproducible by FFTW wisdom ([poisson] fftw_planner = measure,
# fftw_wisdom = FILE; src/poisson/fft.c, "FFTW wisdom"):
#  1. a first run creates the wisdom file (= OUT/fftw.wisdom, the wisdom its
#     plans were made from); a second run given the same file gives
#     BIT-IDENTICAL fields (h5diff --delta=0 on every /fluid dataset of the
#     final checkpoints) and series rows;
#  2. N/2 steps, the wisdom file deleted, --restart + N/2 steps: bit-identical
#     to the N-step run (the checkpoint's copy of the wisdom is used) and the
#     file is written again, identical to the first run's;
#  3. both on 1 and on 2 ranks (the ranks' measurements are merged);
#  4. measure agrees with estimate to round-off: max |difference| below
#     1e-12 U after N steps.  The two planners compute the same transforms
#     with other operation orders, ~1e-16 relative per transform; N = 20
#     steps of a stable scheme amplify that by far less than 1e4 (the bound
#     of tests/restart_test.sh for 1 vs 2 ranks);
#  5. bad input: fftw_wisdom with the estimate planner, a file in a missing
#     folder, a file that is not wisdom: status 2, `file:line: poisson.fftw_wisdom: reason`.
# Cases (implicit viscous term, so the Helmholtz solvers of u, v, w plan
# too): the triply periodic Taylor–Green vortex, 16^3 (2-D r2c fast path),
# and the lid-driven cavity with walls on every side, 32^3 (Neumann pressure:
# the reordered cosine path; Dirichlet velocities: the r2r steps).  On the
# project machine the measured plans of the 32^3 cavity round differently
# from the estimated ones (2e-15 after 20 steps, measured), so there the
# bit-for-bit comparisons see a change of plan; at 16^3 both planners gave
# the same bits.  Three measure runs without wisdom gave the same bits too:
# on a quiet machine FFTW's timings rarely change its choice at these sizes,
# so the wisdom is checked by what it guarantees (same plans), and a note
# says whether a restart planned by estimate would have differed.
# Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_wisdom.XXXXXX)
N=20; H=$((N / 2))
final() { printf "%s/checkpoint_%08d.h5" "$1" "$2"; }
fields() { h5ls "$1/fluid" | awk '$2 == "Dataset" && $1 != "fftw_wisdom" {print $1}'; }
# same_fields A B: every fluid dataset of the final checkpoints of A and B bit-identical
same_fields() {
    local list="" v
    for v in $(fields "$(final $1 $N)"); do
        list="$list $v"
        h5diff --delta=0 "$(final $1 $N)" "$(final $2 $N)" /fluid/$v /fluid/$v >/dev/null || return 1
    done
    [ -n "$list" ]
}
# same_wisdom A B: the same wisdom entries (one per line; their order follows
# FFTW's hash table, which may differ between exports of the same wisdom)
same_wisdom() { [ -s $1 ] && cmp -s <(sort $1) <(sort $2); }
# same_series A B FROM: the series rows after step FROM, every column but the wall time
same_series() {
    cut -d, -f1-8 $1/series.csv | awk -F, -v h=$3 'NR > 1 && $1 > h' >$T/a.csv
    cut -d, -f1-8 $2/series.csv | awk -F, -v h=$3 'NR > 1 && $1 > h' >$T/b.csv
    cmp -s $T/a.csv $T/b.csv && [ "$(wc -l <$T/a.csv)" = $((N - $3)) ]
}

L="6.283185307179586 6.283185307179586 6.283185307179586"
G3="--set domain.geometry=3d --set fluid.viscous=implicit"
RUNS="--set time.t_end=1000 --set time.steady_tol=0 --set output.series_every=1 --set output.fields_every=0"
for case in taylor_green cavity; do
    ini=cases/$case/$case.ini
    if [ $case = taylor_green ]; then
        S="$G3 --set domain.nx=16 --set domain.ny=16 --set domain.nz=16 --set domain.length=${L// /,}"
    else
        S="$G3 --set domain.nx=32 --set domain.ny=32 --set domain.nz=32 --set domain.length=1,1,1"
        S="$S --set boundary.z_lo=noslip --set boundary.z_hi=noslip"
    fi
    S="$S $RUNS"
    for np in 1 2; do
        d=$T/$case.np$np; mkdir -p $d
        W=$d/fftw.wisdom
        M="--set poisson.fftw_planner=measure --set poisson.fftw_wisdom=$W"
        run() { $MPIRUN -np $np $BIN run $ini $S "$@" >>$d.log 2>&1; }
        run $M --set time.max_steps=$N --out $d/first &&
        run $M --set time.max_steps=$N --out $d/second &&
        run --set time.max_steps=$N --out $d/estimate &&
        run $M --set time.max_steps=$H --out $d/split &&
        mv $W $d/first.wisdom &&
        run $M --set time.max_steps=$N --out $d/split --restart "$(final $d/split $H)"
        rc=$?
        report $rc "$case np=$np: two measure runs sharing a wisdom file, an estimate run, a restart, ran"
        [ $rc = 0 ] || { sed 's/^/#   /' $d.log | tail -5; continue; }
        same_wisdom $d/first.wisdom $d/first/fftw.wisdom &&
            h5dump -d /fluid/fftw_wisdom "$(final $d/first $N)" >/dev/null 2>&1
        report $? "$case np=$np: the first run wrote the wisdom file = OUT/fftw.wisdom, and the checkpoint holds it"
        same_fields $d/first $d/second && same_series $d/first $d/second 0
        report $? "$case np=$np: second run with the same wisdom file bit-identical (fields and series)"
        same_fields $d/first $d/split && same_series $d/first $d/split $H
        report $? "$case np=$np: restart at $H with the wisdom file deleted bit-identical to $N steps straight"
        same_wisdom $W $d/first.wisdom
        report $? "$case np=$np: the restart wrote the missing wisdom file again (the checkpoint's: same entries)"
        maxdiff=$($PY - "$(final $d/first $N)" "$(final $d/estimate $N)" <<'PY'
import sys, h5py, numpy as np
a, b = h5py.File(sys.argv[1]), h5py.File(sys.argv[2])
print("%.2e" % max(np.abs(a["fluid"][k][...] - b["fluid"][k][...]).max() for k in b["fluid"]))
PY
)
        $PY -c "import sys; sys.exit(0 if float('$maxdiff') < 1e-12 else 1)" 2>/dev/null
        report $? "$case np=$np: measure vs estimate after $N steps: max |difference| $maxdiff (bound 1e-12)"
        [ "$maxdiff" = 0.00e+00 ] && echo "# $case np=$np: estimate gave the same bits as measure (no plan change to detect)"
    done
done

# ---- bad input ------------------------------------------------------------------
# check NAME REGEX CASEFILE: `ibmdem check` stops with status 2 and a message matching REGEX
check() {
    $BIN check "$3" >$T/out 2>$T/err
    local rc=$?
    [ $rc = 2 ] && grep -Eq -- "$2" $T/err
    report $? "$1"
    [ $rc = 2 ] || sed 's/^/#   /' $T/err | head -3
}
mk() { # mk NAME PLANNER WISDOM: a 2-D periodic case, fftw_wisdom on line 11
    printf '[domain]\ngeometry = 2d\nnx = 8\nny = 8\nlength = 1 1 1\n[fluid]\nnu = 0.01\n[poisson]\nmethod = fft\nfftw_planner = %s\nfftw_wisdom = %s\n[time]\nt_end = 1\n' \
        "$2" "$3" >$T/$1.ini
    echo $T/$1.ini
}
f=$(mk estimate estimate $T/w)
check "fftw_wisdom with the estimate planner refused" "^$f:11: poisson.fftw_wisdom: .*measure only" $f
f=$(mk nodir measure $T/no/such/dir/w)
check "fftw_wisdom in a missing folder refused" "^$f:11: poisson.fftw_wisdom: cannot create $T/no/such/dir/w: folder $T/no/such/dir: No such file" $f
echo "not wisdom" >$T/garbage.wisdom
f=$(mk garbage measure $T/garbage.wisdom)
check "fftw_wisdom that is not FFTW wisdom refused" "^$f:11: poisson.fftw_wisdom: $T/garbage.wisdom is not FFTW wisdom of this FFTW build" $f
f=$(mk folder measure $T)
check "fftw_wisdom naming a folder refused" "^$f:11: poisson.fftw_wisdom: $T is not a regular file" $f
tap_end "$T"
