#!/bin/bash
# The cost of a steady flow past fixed spheres against the resolution: the simple cubic array
# c = 0.064 (one sphere per period, Stokes regime: body force 1, nu = 1, D = 1, Re 0.3) at
# n = 16, 24, 32, 48 cells per period (D/dx = n/2.015), two ways:
#   explicit  the explicit viscous term at its stability limit, stopped when the velocity field
#             is steady (time.steady_tol = 1e-3, steady_measure = field): steps grow as n^2;
#   held      the superficial velocity of the explicit run held ([fluid] flow_rate_direction),
#             Crank-Nicolson steps of 0.05 D^2/nu with the forcing in the solve
#             (ibm.cn_forcing = predictor), stopped on the integrals (steady_measure = integrals).
# CPU time of each run (the machine is shared), steps, K = F/(3 pi mu D U) and its ratio to
# Zick & Homsy's 2.810.  Prints "RESULT steady ..." lines and a table.
# Environment: BUILD (default build), WORK (default $BUILD/bench_steady), SIZES.
set -e
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
WORK=${WORK:-$BUILD/bench_steady}
SIZES=${SIZES:-16 24 32 48}
BIN=$PWD/$BUILD/ibmdem
mkdir -p "$WORK"
L=2.014989942520587 # (pi/6/0.064)^(1/3)
C=1.0074949712602934
cat >"$WORK/array.ini" <<INI
[domain]
nx = 16
ny = 16
nz = 16
length = $L $L $L
[fluid]
nu = 1
body_force = 1 0 0
fourier = 0.6
[ibm]
sphere1 = fixed center $C $C $C diameter 1
radius_correction = calibrated
[time]
t_end = 8
steady_tol = 1e-3
[output]
fields_every = 0
progress = off
overwrite = true
INI
result() { # DIR CPU_FILE LABEL N
    /usr/bin/python3 - "$@" <<'PY'
import json, math, sys
d, tf, label, n = sys.argv[1:]
s = json.load(open(d + "/summary.json"))
U, F = s["fluid"]["superficial_velocity_x"], s["ibm"]["sphere1"]["force_x"]
cpu = sum(float(x) for x in open(tf).read().split()[-2:])
K = F / (3 * math.pi * U)
print("RESULT steady %s n=%s D/dx=%.2f steps=%d cpu=%.2f K=%.5f K/K_ZH-1=%+.4f%% status=%s" %
      (label, n, int(n) / 2.014989942520587, s["steps"], cpu, K, 100 * (K / 2.810 - 1), s["status"]))
PY
}
for n in $SIZES; do
    G="--set domain.nx=$n --set domain.ny=$n --set domain.nz=$n"
    /usr/bin/time -f "%U %S" -o "$WORK/e$n.cpu" "$BIN" run "$WORK/array.ini" $G --set fluid.viscous=explicit \
        --out "$WORK/explicit_$n" >"$WORK/explicit_$n.log" 2>&1
    result "$WORK/explicit_$n" "$WORK/e$n.cpu" explicit $n
    U=$(/usr/bin/python3 -c "import json; print(repr(json.load(open('$WORK/explicit_$n/summary.json'))['fluid']['superficial_velocity_x']))")
    /usr/bin/time -f "%U %S" -o "$WORK/h$n.cpu" "$BIN" run "$WORK/array.ini" $G --set fluid.viscous=implicit \
        --set ibm.cn_forcing=predictor --set fluid.dt=0.05 --set time.steady_measure=integrals \
        --set fluid.flow_rate_direction=x --set fluid.superficial_velocity=$U --out "$WORK/held_$n" >"$WORK/held_$n.log" 2>&1
    result "$WORK/held_$n" "$WORK/h$n.cpu" held $n
done
