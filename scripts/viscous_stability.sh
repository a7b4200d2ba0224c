#!/bin/bash
# The stability map of the coupled step at large viscous numbers (docs/theory.md §4.6 and §9.1;
# `make viscous_stability`): the squeeze flow (cases/squeeze_flow) with the forcing after and
# inside the Crank-Nicolson solve at dt nu/dx^2 = 20 ... 1000, the free settling sphere
# (cases/viscous_settling/free_axi.ini), and the coupled grain scenes of cases/viscous_settling
# (one grain, 40 and 150 grains at St 0.06, rho_p/rho = 2.5 and 100, the column collapse's
# packing) with and without the linearised drag, each at the fluid step the CFL and the
# acceleration limit allow and against a short-step reference where one is needed.  Runs in
# parallel on JOBS cores (default: nproc), one rank each, nice'd; then
# postproc/viscous_stability.py writes OUT/map.md (status, steps, dt, dt nu/dx^2, dt/tau_S,
# overlaps, step-to-step oscillation, drag or settling velocity against the reference).
# usage: scripts/viscous_stability.sh [OUT=build/viscous_stability]
set -e
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=$(realpath -m "${1:-$ROOT/build/viscous_stability}")
JOBS=${JOBS:-$(nproc)}
BIN=$ROOT/${BUILD:-build}/ibmdem
[ -x "$BIN" ] || { echo "$BIN missing: make all first" >&2; exit 1; }
rm -rf "$OUT"
mkdir -p "$OUT"
SQ=$ROOT/cases/squeeze_flow/squeeze_axi.ini
VS=$ROOT/cases/viscous_settling
R25="--set fluid.rho=1000 --set fluid.nu=2.8e-4 --set particles.density=2500"
R100="--set fluid.rho=25 --set fluid.nu=9.6e-3 --set particles.density=2500"
{
    # name | case | --set overrides
    echo "sq_after_0.01|$SQ|--set ibm.cn_forcing=after_solve --set fluid.dt_max=0.01"
    echo "sq_pred_0.01|$SQ|--set fluid.dt_max=0.01"
    for dt in 0.05 0.1 0.25 1; do
        echo "sq_after_$dt|$SQ|--set ibm.cn_forcing=after_solve --set fluid.dt_max=$dt"
        echo "sq_pred_$dt|$SQ|--set fluid.dt_max=$dt"
    done
    echo "sq_pred_2.5|$SQ|--set fluid.dt_max=2.5"
    for c in after_solve predictor; do
        echo "free_${c}_0.01|$VS/free_axi.ini|--set ibm.cn_forcing=$c --set fluid.dt_max=0.01"
        echo "free_${c}_cfl|$VS/free_axi.ini|--set ibm.cn_forcing=$c"
    done
    echo "free_explicit|$VS/free_axi.ini|--set fluid.viscous=explicit"
    echo "single_K0|$VS/single.ini|--set coupling.implicit_drag=0"
    echo "single_K4|$VS/single.ini|"
    echo "single_ref|$VS/single.ini|--set fluid.dt_max=3.2e-4"
    echo "single_after_K4|$VS/single.ini|--set ibm.cn_forcing=after_solve"
    echo "single_after_ref|$VS/single.ini|--set ibm.cn_forcing=after_solve --set fluid.dt_max=3.2e-4"
    echo "single_explicit_ref|$VS/single.ini|--set fluid.viscous=explicit --set coupling.implicit_drag=0"
    echo "settle_K0|$VS/settle.ini|--set coupling.implicit_drag=0 --set time.t_end=0.3"
    echo "settle_K4|$VS/settle.ini|--set time.t_end=0.3"
    echo "settle_ref|$VS/settle.ini|--set coupling.implicit_drag=0 --set fluid.dt_max=3.2e-4 --set time.t_end=0.3"
    echo "settle25_K4|$VS/settle.ini|$R25 --set time.t_end=0.5"
    echo "settle100_after_K0|$VS/settle.ini|$R100 --set ibm.cn_forcing=after_solve --set coupling.implicit_drag=0 --set time.t_end=0.5"
    echo "settle100_after_K4|$VS/settle.ini|$R100 --set ibm.cn_forcing=after_solve --set time.t_end=0.5"
    echo "settle100_K0|$VS/settle.ini|$R100 --set coupling.implicit_drag=0 --set time.t_end=0.5"
    echo "settle100_K4|$VS/settle.ini|$R100 --set time.t_end=0.5"
    echo "pack_K2|$VS/pack.ini|--set coupling.implicit_drag=2 --set time.t_end=1.5"
    echo "pack_K4|$VS/pack.ini|"
    echo "collapse_thesis|$VS/pack_collapse.ini|--set fluid.dt_max=9.8e-4"
    echo "collapse_cfl|$VS/pack_collapse.ini|"
} > "$OUT/runs.list"
start=$(date +%s)
while IFS='|' read -r name ini sets; do
    cat > "$OUT/$name.sh" <<JOB
nice -n 5 /usr/bin/time -f '%U %S' -o $OUT/$name.time $BIN run $ini $sets --set output.progress=off --out $OUT/$name > $OUT/$name.log 2>&1
echo \$? > $OUT/$name.rc
JOB
    echo "$OUT/$name.sh"
done < "$OUT/runs.list" | xargs -P "$JOBS" -n 1 bash
echo "runs: $(( $(date +%s) - start )) s on $JOBS cores" | tee "$OUT/time.txt"
/usr/bin/python3 "$ROOT/postproc/viscous_stability.py" "$OUT"
