#!/bin/bash
# avalanche.sh OUT [map|table|production|all|domain|convergence|post SET] — the immersed avalanche of Izard (2014) ch. 4
# (docs/validation.md "Immersed avalanche"; cases/avalanche/README.md).
#   map         the regime map: rho_p/rho in {2.7, 4, 10, 40, 100} x St in {0.05, 0.3, 1, 4.5, 20, 100}
#               (30 runs) and the seven cases of Table 4.3, in the quick box (coarse.ini: 3 D x 3 D,
#               D/dx = 5) with the thesis' contacts to 300 sqrt(D/g) (or 80 T_v if longer), averaged from 150
#               sqrt(D/g) (or over the second half)
#   table       the seven cases of Table 4.3 alone, in the quick box as for map
#   production  the seven cases of Table 4.3 in the production box (case.ini: 5 D x 5 D x 20 D,
#               D/dx = 10, the thesis' contacts) to 300 sqrt(D/g), averaged from 200 sqrt(D/g)
#   domain      target 7 (Table 4.1's box sizes): rho_p/rho = 4, Ar = 9 (St 0.153), L x W = 3 D, 5 D and 10 D
#               (DOMAIN_BOXES, in D), H = 12 D, D/dx = 6, the thesis' contacts with t_c/dt = 20, beds of
#               bed.ini's recipe scaled to the box (213 W^2/25 grains, hexagonal base; W = 5 reads bed.h5), to
#               300 sqrt(D/g) averaged from 200 (DOMAIN_WINDOW="T_END AVG_FROM [WALL_LIMIT_S]"), one run at a time;
#               OUT/domain/domain.md compares each box with the last (T, relative L2 of the grains' profile)
#   convergence target 8: Table 4.3's cases 2 (viscous) and 3 (inertial) in the quick box (coarse.ini with the
#               thesis' contacts) at D/dx in CONV_RES (default "5 8 10"), from a flowing bed (case 2 at D/dx 5
#               from coarse_bed.h5 to 150 sqrt(D/g)), 60 sqrt(D/g) averaged from 30 (CONV_WINDOW="T_END AVG_FROM");
#               one run at a time; CONV_CASES (default "0.31 7.75") the cases' St;
#               OUT/convergence/case2.md and case3.md compare each resolution with the finest
#   post SET    no run: post-processes the runs of OUT/SET (map, table or production) that finished
#               (those with a summary.json), e.g. while the set runs or after it was stopped
# Runs JOBS at a time (environment, default 2), in the order of the list: the seven cases of Table 4.3
# first, then the grid, in the order of GRID (environment, "RATIO:ST ...", default the 30 runs above
# row by row); a run whose folder has a summary.json is done already and skipped.  Each run's folder,
# then OUT/<set>.md (the table with regime labels by the thesis' method) and OUT/<set>_map.png,
# OUT/<set>_profiles.png, OUT/<set>_series.png, from the runs that finished.
set -u
OUT=${1:?usage: avalanche.sh OUT [map|table|production|all|domain|convergence|post SET]}
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
    local set=$1 case=$2 tend=$3 avg=$4 list=$5 extra=${6:-} dirs=()
    for rs in $list; do
        local ratio=${rs%%:*} st=${rs##*:} dir="$OUT/$set/r${rs%%:*}_St${rs##*:}"
        dirs+=("$dir")
        mkdir -p "$OUT/$set"
        [ -f "$dir/summary.json" ] && continue # done already
        local opts tv te ta
        opts=$($PY scripts/avalanche_set.py "$ratio" "$st" 2>/dev/null)
        # a viscous bed triggers after ~10-30 T_v (case 2: ~70 sqrt(D/g) = 17 T_v in the quick box, 37 in
        # the production one; St ~0.05 at 7-27 T_v in the quick box, lighter grains later): runs of small St last 80 T_v,
        # averaged over the second half (after the triggering)
        tv=$($PY scripts/avalanche_set.py "$ratio" "$st" 2>&1 >/dev/null | sed 's/.*T_v = \([0-9.e+-]*\).*/\1/')
        te=$($PY -c "print(max($tend, 80 * $tv))")
        ta=$($PY -c "print($avg if $te == $tend else $te / 2)")
        $BIN run "$case" $opts $extra --set output.progress=off --set output.overwrite=true \
            --set time.t_end=$($PY -c "print($te * $TG)") \
            --set avalanche.average_from=$($PY -c "print($ta * $TG)") --out "$dir" >"$dir.log" 2>&1 &
        # a slot frees when any run ends (a short run next to a long one does not hold a core idle)
        while [ "$(jobs -pr | wc -l)" -ge "$JOBS" ]; do wait -n; done
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
g() { $PY -c "print($1 * $TG)"; } # sqrt(D/g) -> s
domain() {
    local dirs=() w L n bed dir win=(${DOMAIN_WINDOW:-300 200 0})
    mkdir -p "$OUT/domain"
    for w in ${DOMAIN_BOXES:-3 5 10}; do
        L=$($PY -c "print($w * 0.005)") bed=cases/avalanche/bed.h5 dir="$OUT/domain/W$w"
        if [ "$w" != 5 ]; then # bed.ini's packing (213 grains in 5 D x 5 D) scaled to the box
            bed="$OUT/domain/bed$w/bed.h5"
            [ -f "$bed" ] || $BIN run cases/avalanche/bed.ini --set "domain.length=$L $L 0.15" \
                --set particles.count=$($PY -c "print(round(213 * $w * $w / 25))") \
                --set "particles.region_hi=$L $L 0.145" --set output.progress=off --set output.overwrite=true \
                --out "$OUT/domain/bed$w" >"$OUT/domain/bed$w.log" 2>&1
        fi
        dirs+=("$dir")
        [ -f "$dir/summary.json" ] && continue
        n=$((6 * w))
        $BIN run cases/avalanche/case.ini $($PY scripts/avalanche_set.py 4 0.153 2>/dev/null) \
            --set particles.file="$bed" --set "domain.length=$L $L 0.06" --set domain.nx=$n --set domain.ny=$n \
            --set domain.nz=72 --set dem.steps_per_contact=20 --set avalanche.flow_length=0.025 \
            --set output.fields_every=0 --set output.checkpoint_every=1000 --set output.progress=off \
            --set output.overwrite=true --set time.t_end=$(g ${win[0]}) --set avalanche.average_from=$(g ${win[1]}) \
            --set time.wall_limit=${win[2]:-0} --out "$dir" >"$dir.log" 2>&1
    done
    $PY postproc/avalanche.py "${dirs[@]}" --compare --out "$OUT/domain/domain"
}
convergence() {
    local c n dir dirs flow="$OUT/convergence/flowing" win=(${CONV_WINDOW:-60 30})
    mkdir -p "$OUT/convergence"
    if [ ! -f "$flow.h5" ]; then # the quick bed flowing: case 2 at D/dx 5 to 150 sqrt(D/g)
        $BIN run cases/avalanche/coarse.ini $STIFF --set output.progress=off --set output.overwrite=true \
            --set time.t_end=$(g 150) --set avalanche.average_from=$(g 100) --out "$flow" >"$flow.log" 2>&1
        $PY scripts/checkpoint_particles.py "$(ls "$flow"/checkpoint_*.h5 | tail -1)" "$flow.h5"
    fi
    for c in ${CONV_CASES:-0.31 7.75}; do
        dirs=()
        for n in ${CONV_RES:-5 8 10}; do
            dir="$OUT/convergence/St${c}_res$n"
            dirs+=("$dir")
            [ -f "$dir/summary.json" ] && continue
            $BIN run cases/avalanche/coarse.ini $STIFF $($PY scripts/avalanche_set.py 4 $c 2>/dev/null) \
                --set particles.file="$flow.h5" --set domain.nx=$((3 * n)) --set domain.ny=$((3 * n)) \
                --set domain.nz=$((12 * n)) --set output.progress=off --set output.overwrite=true \
                --set time.t_end=$(g ${win[0]}) --set avalanche.average_from=$(g ${win[1]}) --out "$dir" >"$dir.log" 2>&1
        done
        $PY postproc/avalanche.py "${dirs[@]}" --compare --out "$OUT/convergence/case$([ $c = 0.31 ] && echo 2 || echo 3)"
    done
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
domain)
    domain ;;
convergence)
    convergence ;;
post)
    post "${3:?usage: avalanche.sh OUT post SET}" ;;
esac
