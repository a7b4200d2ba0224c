#!/bin/bash
# collapse.sh OUT [all|resolved|porenet|packings|post] — the immersed column collapse of Izard (2014)
# ch. 5, Table 5.1 (docs/validation.md "Granular column collapse"; cases/column_collapse/README.md).
#   all (default)  resolved, then porenet, then post
#   resolved   cases A (case.ini), D (case_D.ini), E (case_E.ini) and F (case_settle.ini: the grains
#              settled in the fluid in the column's box; postproc/collapse_loose_packing.py puts them on
#              the bed of A's box; then case.ini from that packing) at D/dx = 10, on NP
#              ranks (default 2) with the explicit viscous term (VISCOUS=implicit keeps the case files'
#              Crank-Nicolson step, 2.5 times longer, 1.5-3 times slower per CPU second)
#   porenet    cases A and F with the pore network (porenet_A.ini, porenet_F.ini), one rank
#   packings   the dense packings of D and E (case_D_packing.h5, case_E_packing.h5), settled dry in a
#              box taller than the collapse's (random insertion needs room), written to OUT/packings;
#              copy them to cases/column_collapse to ship them
#   post       no run: OUT/collapse.md (the table and the targets of issue 20) and OUT/collapse.png
#              from the runs of OUT that finished
# ONLY="A D E F pnA pnF" limits the runs.  A run whose folder holds a summary.json with status t_end is
# done and skipped (a stopped set resumes where it stopped).  Each run: OUT/<run>/ and OUT/<run>.log;
# postproc/column_collapse.py writes OUT/<run>/column.json and column.png; where ParaView (pvpython)
# and xvfb-run are installed, postproc/collapse_paraview.py the pressure at p_b's minimum, OUT/<run>/pressure.png.
set -u
OUT=${1:?usage: collapse.sh OUT [all|resolved|porenet|packings|post]}
WHAT=${2:-all}
NP=${NP:-2}
VISCOUS=${VISCOUS:-explicit}
ONLY=${ONLY:-A D E F pnA pnF}
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
BIN=$PWD/$BUILD/ibmdem
PY=/usr/bin/python3
C=cases/column_collapse
R0=0.2432 # 16 D
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)

want() { case " $ONLY " in *" $1 "*) return 0 ;; esac; return 1; }
done_run() { [ -f "$1/summary.json" ] && grep -q '"status": "t_end"' "$1/summary.json"; }
mpi() { if [ "$NP" -gt 1 ]; then mpirun --allow-run-as-root --oversubscribe -np "$NP" "$@"; else "$@"; fi; }
run() { # NAME NP CASE [options]: one run into OUT/NAME, then its post-processing
    local name=$1 np=$2 case=$3 dir=$OUT/$1
    shift 3
    if done_run "$dir"; then echo "collapse: $name done already"; return 0; fi
    echo "collapse: $name ($case, $np rank(s)) from $(date -u +%H:%M:%S)"
    NP=$np mpi "$BIN" run "$case" "$@" --set output.progress=off --set output.overwrite=true \
        --out "$dir" >"$dir.log" 2>&1 || { echo "collapse: $name failed (exit $?): $dir.log"; return 1; }
    $PY postproc/column_collapse.py "$dir" $R0 >>"$dir.log" 2>&1 || { echo "collapse: post-processing of $name failed"; return 1; }
    paraview "$dir"
}
paraview() { # RUN_DIR: the pressure slice at p_b's minimum as ParaView renders it (resolved runs, when installed)
    [ -f "$1/fields.xmf" ] && command -v pvpython >/dev/null && command -v xvfb-run >/dev/null || return 0
    local i
    for i in 1 2 3; do # xvfb-run's server is sometimes not up when ParaView connects: try again
        xvfb-run -a pvpython postproc/collapse_paraview.py "$1" "$1/pressure.png" >>"$1.log" 2>&1 && return 0
    done
    echo "collapse: ParaView could not render $1 ($1.log)"
}

resolved() {
    local v="--set fluid.viscous=$VISCOUS" st=0
    want A && { run A "$NP" $C/case.ini $v || st=1; }
    if want F; then
        # the loose packing: the grains settled in the fluid behind the gate (the settling keeps the
        # case file's step: its Crank-Nicolson step grows to 3e-3 s as the grains come to rest)
        # in the column's own box, then put on the bed of case A's box (A's packing: the A run's)
        run F_settle "$NP" $C/case_settle.ini || st=1
        local last
        last=$(ls "$OUT"/F_settle/particles_*.h5 2>/dev/null | tail -1)
        if [ -n "$last" ] && [ -f "$OUT/A/column_packing.h5" ] &&
            $PY postproc/collapse_loose_packing.py "$last" "$OUT/A/column_packing.h5" $R0 "$OUT/F_packing.h5" \
                >"$OUT/F_packing.log" 2>&1; then
            run F "$NP" $C/case.ini $v --set particles.source=file --set particles.file="$OUT/F_packing.h5" \
                --set packing.prepare=false --set bed.type=none || st=1
        else
            echo "collapse: F needs the settling and case A's packing ($OUT/F_packing.log)"
            st=1
        fi
    fi
    want D && { run D "$NP" $C/case_D.ini $v || st=1; }
    want E && { run E "$NP" $C/case_E.ini $v || st=1; }
    return $st
}

porenet() {
    local st=0
    want pnA && { run pnA 1 $C/porenet_A.ini || st=1; }
    want pnF && { run pnF 1 $C/porenet_F.ini || st=1; }
    return $st
}

packings() { # the dense packings of D and E: random insertion in a tall box, dry frictionless settling
    local common="--set coupling.fluid=off --set particles.source=insert --set particles.radius=0.0076
        --set particles.polydispersity=0.05 --set particles.density=8000 --set particles.seed=3
        --set particles.region_lo=0,0,0.0076 --set bed.type=random --set bed.radius=0.0076
        --set bed.polydispersity=0.05 --set bed.coverage=0.5 --set packing.prepare=true
        --set packing.variant=dense --set packing.rest_energy=1e-6 --set packing.max_time=3
        --set packing.output=column_packing.h5 --set time.t_end=1e-9 --set output.overwrite=true"
    mkdir -p "$OUT/packings"
    # D: 665 grains inserted up to 43 D (44 D box), E: 985 grains up to 61 D (62 D box)
    $BIN run $C/case_D.ini $common --set particles.count=665 --set domain.nz=440 \
        --set domain.length="0.9728 0.03344 0.6688" --set particles.region_hi="0.2432 0.03344 0.66" \
        --out "$OUT/packings/D" >"$OUT/packings/D.log" 2>&1 &&
        cp "$OUT/packings/D/column_packing.h5" "$OUT/packings/case_D_packing.h5" || return 1
    $BIN run $C/case_E.ini $common --set particles.count=985 --set domain.nz=620 \
        --set domain.length="1.0944 0.03344 0.9424" --set particles.region_hi="0.2432 0.03344 0.93" \
        --out "$OUT/packings/E" >"$OUT/packings/E.log" 2>&1 &&
        cp "$OUT/packings/E/column_packing.h5" "$OUT/packings/case_E_packing.h5" || return 1
    echo "collapse: packings in $OUT/packings"
}

post() { $PY postproc/collapse_table.py "$OUT"; }

case $WHAT in
all) resolved; s1=$?; porenet; s2=$?; post; s3=$?; exit $((s1 | s2 | s3)) ;;
resolved) resolved ;;
porenet) porenet ;;
packings) packings ;;
post) post ;;
*) echo "collapse.sh: unknown mode $WHAT" >&2; exit 2 ;;
esac
