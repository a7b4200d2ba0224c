#!/bin/bash
# avalanche.sh OUT [map|table|production|all|post SET] — the immersed avalanche of Izard (2014) ch. 4
# (docs/validation.md "Immersed avalanche"; cases/avalanche/README.md).
#   map         the regime map: rho_p/rho in {2.7, 4, 10, 40, 100} x St in {0.05, 0.3, 1, 4.5, 20, 100}
#               (30 runs) and the seven cases of Table 4.3, in the quick box (coarse.ini: 3 D x 3 D,
#               D/dx = 5) with the thesis' contacts to 300 sqrt(D/g) (or 40 T_v if longer), averaged from 150
#               sqrt(D/g) (or over the second half)
#   table       the seven cases of Table 4.3 alone, in the quick box as for map
#   production  the seven cases of Table 4.3 in the production box (case.ini: 5 D x 5 D x 20 D,
#               D/dx = 10, the thesis' contacts) to 300 sqrt(D/g), averaged from 200 sqrt(D/g)
#   post SET    no run: post-processes the runs of OUT/SET (map, table or production) that finished
#               (those with a summary.json), e.g. while the set runs or after it was stopped
# Runs JOBS at a time (environment, default 2), in the order of the list: the seven cases of Table 4.3
# first, then the grid, in the order of GRID (environment, "RATIO:ST ...", default the 30 runs above
# row by row); a run whose folder has a summary.json is done already and skipped.  Each run's folder,
# then OUT/<set>.md (the table with regime labels by the thesis' method) and OUT/<set>_map.png,
# OUT/<set>_profiles.png, OUT/<set>_series.png, from the runs that finished.
set -u
OUT=${1:?usage: avalanche.sh OUT [map|table|production|all|post SET]}
WHAT=${2:-map}
JOBS=${JOBS:-2}
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
BIN=$PWD/$BUILD/ibmdem
PY=/usr/bin/python3
mkdir -p "$OUT"
TG=0.022589578612141028 # sqrt(D/g), D = 5.006 mm

table43="4:0.04 4:0.31 4:7.75 4:75.4 100:0.45 100:4.5 100:111.2"
# The quick box's soft contacts (t_c five times the thesis') reach 3 % overlaps at the impact
# speeds of the inertial and free-fall flows (~1 m/s): the map takes the thesis' contacts.  With
# them, v t_c/pi passes 1 % of D at impacts of 1.6 m/s, which the fastest flows reach: a run stops at
# 3 % (not the target's 1 %, which each run's table row is read against: its largest overlap).
STIFF="--set contact.contact_time=9.93e-5 --set dem.max_overlap=0.03"
run_set() { # SET CASE T_END_G AVG_FROM_G "RATIO:ST ..." [--set options of every run]
    local set=$1 case=$2 tend=$3 avg=$4 list=$5 extra=${6:-} dirs=() pids=()
    for rs in $list; do
        local ratio=${rs%%:*} st=${rs##*:} dir="$OUT/$set/r${rs%%:*}_St${rs##*:}"
        dirs+=("$dir")
        mkdir -p "$OUT/$set"
        [ -f "$dir/summary.json" ] && continue # done already
        local opts tv te ta
        opts=$($PY scripts/avalanche_set.py "$ratio" "$st" 2>/dev/null)
        # a viscous bed triggers after ~20 T_v (case 2: ~70 sqrt(D/g) in the quick box, 37 in the
        # production one): runs of small St last 40 T_v, averaged over the second half
        tv=$($PY scripts/avalanche_set.py "$ratio" "$st" 2>&1 >/dev/null | sed 's/.*T_v = \([0-9.e+-]*\).*/\1/')
        te=$($PY -c "print(max($tend, 40 * $tv))")
        ta=$($PY -c "print($avg if $te == $tend else $te / 2)")
        $BIN run "$case" $opts $extra --set output.progress=off --set output.overwrite=true \
            --set time.t_end=$($PY -c "print($te * $TG)") \
            --set avalanche.average_from=$($PY -c "print($ta * $TG)") --out "$dir" >"$dir.log" 2>&1 &
        pids+=($!)
        if [ ${#pids[@]} -ge "$JOBS" ]; then wait "${pids[0]}"; pids=("${pids[@]:1}"); fi
    done
    wait
    post "$set" "${dirs[@]}"
}
post() { # SET [RUN_DIR ...]: the table and figures of the runs that finished (all of OUT/SET if none given)
    local set=$1 done=() d
    shift
    [ $# -gt 0 ] || set -- "$OUT/$set"/*/
    for d in "$@"; do [ -f "$d/summary.json" ] && done+=("${d%/}"); done
    if [ ${#done[@]} -eq 0 ]; then echo "avalanche.sh: no finished run in $OUT/$set" >&2; return 1; fi
    echo "avalanche.sh: $set: ${#done[@]} of $# runs finished" >&2
    $PY postproc/avalanche.py "${done[@]}" --out "$OUT/$set" --map
}
case $WHAT in
map | all)
    grid=${GRID:-}
    if [ -z "$grid" ]; then
        for r in 2.7 4 10 40 100; do for s in 0.05 0.3 1 4.5 20 100; do grid="$grid $r:$s"; done; done
    fi
    run_set map cases/avalanche/coarse.ini 300 150 "$table43 $grid" "$STIFF" ;;&
table)
    run_set table cases/avalanche/coarse.ini 300 150 "$table43" "$STIFF" ;;
production | all)
    run_set production cases/avalanche/case.ini 300 200 "$table43" ;;
post)
    post "${3:?usage: avalanche.sh OUT post SET}" ;;
esac
