#!/bin/bash
# periodic_flow_test.sh — the periodic flow's columns (series.csv) and keys (summary.json):
# superficial velocity, flux and Reynolds number, on plane Poiseuille flow (periodic in x and z,
# walls in y), whose discrete steady state is known exactly, on 1 and 2 ranks; a
# reynolds_length without a periodic direction is bad input.  The held flow rate
# ([fluid] flow_rate_direction): the superficial velocity is the target at every step, the body
# force it reaches is the exact discrete one whatever the time step (explicit and Crank–Nicolson,
# 1 and 2 ranks), a Reynolds-number target, restart = uninterrupted run, bad input; the grid from
# the resolution D/dx ([domain] cells_per_diameter).
# Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_periodic_flow.XXXXXX)

# h = 1, f = 3, nu = 0.5, 16 cells across: init = laminar is the exact parabola
# u = f y (h - y) / (2 nu) at the u nodes (y at the cell centres), steady with the quadratic
# wall ghost (the discrete Laplacian of a parabola is exact)
cat >$T/channel.ini <<'INI'
[domain]
geometry = 3d
nx = 4
ny = 16
nz = 2
length = 2 1 0.5

[boundary]
x_lo = periodic
x_hi = periodic
y_lo = noslip
y_hi = noslip
z_lo = periodic
z_hi = periodic

[fluid]
nu = 0.5
body_force = 3 0 0
wall_ghost = quadratic
init = laminar
reynolds_length = 0.25
dt = 0.001

[time]
t_end = 0.01
INI
for np in 1 2; do
    $MPIRUN -np $np $BIN run $T/channel.ini --out $T/c$np >$T/log$np 2>&1
    report $? "plane Poiseuille flow on $np rank(s) ran"
    $PY - $T/c$np <<'PY'
import csv, json, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/series.csv")))
s = json.load(open(d + "/summary.json"))["fluid"]
f, nu, h, dy, Ly, Lz, ell = 3.0, 0.5, 1.0, 1.0 / 16, 1.0, 0.5, 0.25
# mean of f y (h - y)/(2 nu) over the 16 cell centres: f h^2/(12 nu) + f dy^2/(24 nu)
U = f * h * h / (12 * nu) + f * dy * dy / (24 * nu)
ok = "superficial_v" not in rows[0] and "flux_y" not in rows[0]
for r in (rows[0], rows[-1]):
    # the parabola is steady to round-off (1e-12 of U over the 10 steps)
    ok = ok and abs(float(r["superficial_u"]) / U - 1) < 1e-12
    ok = ok and abs(float(r["flux_x"]) / (U * Ly * Lz) - 1) < 1e-12
    ok = ok and abs(float(r["superficial_w"])) < 1e-14 * U and abs(float(r["flux_z"])) < 1e-14 * U
    ok = ok and abs(float(r["reynolds"]) / (U * ell / nu) - 1) < 1e-12
ok = ok and abs(s["superficial_velocity_x"] / U - 1) < 1e-12 and abs(s["flux_x"] / (U * Ly * Lz) - 1) < 1e-12
ok = ok and abs(s["reynolds"] / (U * ell / nu) - 1) < 1e-12 and "superficial_velocity_y" not in s
print("U = %.15g (exact %.15g), Re = %.15g" % (float(rows[-1]["superficial_u"]), U, s["reynolds"]))
sys.exit(0 if ok else 1)
PY
    report $? "$np rank(s): superficial_u = f h^2/(12 nu) + f dy^2/(24 nu), flux_x = U Ly Lz, superficial_w = 0, reynolds = U l/nu (series and summary)"
done

# no periodic direction: a Reynolds number of the periodic flow is bad input
$BIN check $T/channel.ini --set boundary.x_lo=noslip --set boundary.x_hi=noslip --set boundary.z_lo=noslip \
    --set boundary.z_hi=noslip --set fluid.init=rest >$T/out 2>$T/err
st=$?
[ $st = 2 ] && grep -q "fluid.reynolds_length" $T/err && grep -q "no periodic direction" $T/err
report $? "reynolds_length in a box without a periodic direction: exit 2 ($st) with file:line: fluid.reynolds_length"

# The held flow rate, from rest: superficial_u = 0.25 after every step; the body force tends to the
# discrete steady one, f = U / (h^2/(12 nu) + dy^2/(24 nu)) (the parabola above, exact with the
# quadratic ghost), in ~10 viscous times h^2/nu = 2 (t_end 30: the slowest mode decays as
# exp(-pi^2 nu t/h^2), 1e-64 by then, so the tolerance 1e-10 is round-off); explicit dt = 0.002
# (Fourier 0.34) and Crank-Nicolson dt = 0.05 (25 times the explicit limit) reach the same f.
HOLD="--set fluid.init=rest --set fluid.body_force=0,0,0 --set fluid.flow_rate_direction=x --set fluid.superficial_velocity=0.25"
$MPIRUN -np 1 $BIN run $T/channel.ini $HOLD --set time.t_end=30 --set fluid.dt=0.002 --out $T/h1 >$T/h1.log 2>&1 &&
    $MPIRUN -np 2 $BIN run $T/channel.ini $HOLD --set time.t_end=30 --set fluid.dt=0.05 --set fluid.viscous=implicit \
        --out $T/h2 >$T/h2.log 2>&1
report $? "held flow rate: explicit on 1 rank and Crank-Nicolson on 2 ranks ran"
$PY - $T/h1 $T/h2 <<'PY'
import csv, json, sys
nu, h, dy, U = 0.5, 1.0, 1.0 / 16, 0.25
fx = U / (h * h / (12 * nu) + dy * dy / (24 * nu))
ok = True
for d in sys.argv[1:]:
    rows = list(csv.DictReader(open(d + "/series.csv")))
    s = json.load(open(d + "/summary.json"))["fluid"]
    # every step ends at the target (round-off of a mean over 128 nodes)
    ok = ok and all(abs(float(r["superficial_u"]) / U - 1) < 1e-13 for r in rows[1:])
    ok = ok and abs(float(rows[-1]["body_force_x"]) / fx - 1) < 1e-10 and abs(s["body_force_x"] / fx - 1) < 1e-10
    print("%s: f = %.15g (exact %.15g), U = %.15g" % (d, s["body_force_x"], fx, s["superficial_velocity_x"]))
sys.exit(0 if ok else 1)
PY
report $? "held flow rate: superficial_u = 0.25 after every step; body_force_x = the exact discrete f to 1e-10 for dt = 0.002 (explicit) and 0.05 (Crank-Nicolson)"

# the steady path: the held flow rate with Crank-Nicolson steps of 0.05 and the integral steady test
# (time.steady_measure = integrals: the body force's relative change below 1e-6 per unit time) stops
# the run as steady long before t_end, the body force within 1e-5 of the exact f (what is left of the
# slowest mode, decaying over h^2/(pi^2 nu) = 0.2, is about 0.2 x 1e-6)
$BIN run $T/channel.ini $HOLD --set time.t_end=100 --set fluid.dt=0.05 --set fluid.viscous=implicit \
    --set time.steady_tol=1e-6 --set time.steady_measure=integrals --out $T/st >$T/st.log 2>&1 &&
    $PY - $T/st <<'PY'
import json, sys
s = json.load(open(sys.argv[1] + "/summary.json"))
nu, h, dy, U = 0.5, 1.0, 1.0 / 16, 0.25
fx = U / (h * h / (12 * nu) + dy * dy / (24 * nu))
print("status %s at t = %g (%d steps), f/f_exact - 1 = %.2e" % (s["status"], s["time"], s["steps"],
                                                             s["fluid"]["body_force_x"] / fx - 1))
sys.exit(not (s["status"] == "steady" and s["time"] < 50 and abs(s["fluid"]["body_force_x"] / fx - 1) < 1e-5))
PY
report $? "steady path (held flow rate, Crank-Nicolson dt = 0.05, steady_measure = integrals): steady before t = 50, f within 1e-5"

# the steady path past a fixed sphere: the simple cubic array c = 0.064 at D/dx = 7.9 (16^3, body
# force 1: Re 0.3), run explicitly until the velocity field is steady (the usual path: ~950 steps),
# then at the superficial velocity it reached with the held flow rate, Crank-Nicolson steps of 0.05
# (cn_forcing = predictor) and the integral test: the same drag to 1e-3 (measured 1.7e-4: the two
# tolerances) in fewer than a tenth of the steps (measured 11)
L=2.014989942520587
ARR="--set domain.nx=16 --set domain.ny=16 --set domain.nz=16 --set domain.length=$L,$L,$L
     --set boundary.y_lo=periodic --set boundary.y_hi=periodic --set fluid.init=rest --set fluid.nu=1
     --set fluid.wall_ghost=linear --set fluid.reynolds_length=1 --set fluid.dt=0
     --set ibm.sphere1=fixed,center,1.0074949712602934,1.0074949712602934,1.0074949712602934,diameter,1
     --set ibm.radius_correction=calibrated --set time.t_end=8 --set time.steady_tol=1e-3"
$BIN run $T/channel.ini $ARR --set fluid.body_force=1,0,0 --set fluid.viscous=explicit --set fluid.fourier=0.6 \
    --out $T/ae >$T/ae.log 2>&1 &&
    Ua=$($PY -c "import json; print(repr(json.load(open('$T/ae/summary.json'))['fluid']['superficial_velocity_x']))") &&
    $BIN run $T/channel.ini $ARR --set fluid.body_force=1,0,0 --set fluid.viscous=implicit --set ibm.cn_forcing=predictor \
        --set fluid.dt=0.05 --set time.steady_measure=integrals --set fluid.flow_rate_direction=x \
        --set fluid.superficial_velocity=$Ua --out $T/ah >$T/ah.log 2>&1 &&
    $PY - $T/ae $T/ah <<'PY'
import json, math, sys
a, b = (json.load(open(d + "/summary.json")) for d in sys.argv[1:])
K = [s["ibm"]["sphere1"]["force_x"] / (3 * math.pi * s["fluid"]["superficial_velocity_x"]) for s in (a, b)]
print("K explicit %.5f (%d steps), held + Crank-Nicolson %.5f (%d steps): %+.2e" % (K[0], a["steps"], K[1], b["steps"],
                                                                                 K[1] / K[0] - 1))
sys.exit(not (a["status"] == b["status"] == "steady" and abs(K[1] / K[0] - 1) < 1e-3 and 10 * b["steps"] < a["steps"]))
PY
report $? "steady path past a sphere array: the explicit drag to 1e-3 in a tenth of the steps"

# a Reynolds-number target (Re = U l/nu with reynolds_length l = 0.25: Re 2 is U = 4)
$BIN run $T/channel.ini --set fluid.init=rest --set fluid.flow_rate_direction=x --set fluid.reynolds=2 \
    --set time.t_end=0.02 --out $T/re >$T/re.log 2>&1 &&
    $PY -c "
import csv, sys
r = list(csv.DictReader(open('$T/re/series.csv')))[-1]
sys.exit(not (abs(float(r['reynolds']) / 2 - 1) < 1e-13 and abs(float(r['superficial_u']) / 4 - 1) < 1e-13))"
report $? "held Reynolds number: reynolds = 2 and superficial_u = Re nu/l = 4"

# restart = uninterrupted run (the body force is part of the checkpoint)
R="--set time.t_end=0.4 --set fluid.dt=0.002 --set output.checkpoint_every=100"
$BIN run $T/channel.ini $HOLD $R --out $T/u >$T/u.log 2>&1 && cp -r $T/u $T/r && rm -f $T/r/.ibmdem.lock &&
    $BIN run $T/channel.ini $HOLD $R --out $T/r --restart $T/r/checkpoint_00000100.h5 >$T/r.log 2>&1 &&
    $PY tests/compare_runs.py $T/u $T/r --skip input # the copied checkpoint names the folder it was written in
report $? "held flow rate: restarted at step 100, every output identical to the uninterrupted run's"

# bad input: a held flow rate along a wall-bounded direction, without or with two targets, a target without it
bad() { # WHAT KEY SETS...
    local what=$1 key=$2
    shift 2
    $BIN check $T/channel.ini "$@" >$T/out 2>$T/err
    local st=$?
    [ $st = 2 ] && grep -q "^--set $key: " $T/err
    report $? "$what: exit 2 ($st) with --set $key ($(head -1 $T/err | cut -c1-100))"
}
bad "flow rate held along y (walls)" fluid.flow_rate_direction --set fluid.flow_rate_direction=y --set fluid.superficial_velocity=1
bad "flow rate held without a target" fluid.flow_rate_direction --set fluid.flow_rate_direction=x
bad "flow rate held with two targets" fluid.flow_rate_direction --set fluid.flow_rate_direction=x \
    --set fluid.superficial_velocity=1 --set fluid.reynolds=2
bad "a target without flow_rate_direction" fluid.superficial_velocity --set fluid.superficial_velocity=1
bad "a Reynolds target without reynolds_length" fluid.reynolds --set fluid.flow_rate_direction=x --set fluid.reynolds=2 \
    --set fluid.reynolds_length=0

# the grid from the resolution D/dx: cells_per_diameter = 16 with diameter 1 is the box of 32 x 16 x 8
# cubic cells, the same run as the cell counts give (but for the input's text and fingerprint)
G="--set time.t_end=0.004 --set fluid.dt=0.001"
$BIN run $T/channel.ini $G --set domain.nx=32 --set domain.nz=8 --out $T/gn >$T/gn.log 2>&1 &&
    mkdir -p $T/cpd && sed -e '/^nx =/d' -e '/^ny =/d' -e '/^nz =/d' $T/channel.ini >$T/cpd/channel.ini &&
    $BIN run $T/cpd/channel.ini $G --set domain.cells_per_diameter=16 --set domain.diameter=1 --out $T/gd >$T/gd.log 2>&1 &&
    grep -q "32 x 16 x 8 cells" $T/gd.log && $PY tests/compare_runs.py $T/gn $T/gd --skip input --skip fingerprint
report $? "cells_per_diameter = 16, diameter = 1: 32 x 16 x 8 cells, the run of nx = 32, ny = 16, nz = 8"
$BIN check $T/channel.ini --set domain.cells_per_diameter=16 --set domain.diameter=1 >$T/out 2>$T/err
st=$?
[ $st = 2 ] && grep -q "channel.ini:[0-9]*: domain.nx: give the cell counts or cells_per_diameter" $T/err
report $? "cells_per_diameter with the cell counts: exit 2 ($st) with file:line: domain.nx"
cpdbad() { # WHAT KEY SETS... (the case without cell counts)
    local what=$1 key=$2
    shift 2
    $BIN check $T/cpd/channel.ini "$@" >$T/out 2>$T/err
    local st=$?
    [ $st = 2 ] && grep -q "^--set $key: " $T/err
    report $? "$what: exit 2 ($st) with --set $key ($(head -1 $T/err | cut -c1-120))"
}
cpdbad "a resolution that is not a whole number of cells (0.5 / 0.3 x 16)" domain.cells_per_diameter \
    --set domain.cells_per_diameter=16 --set domain.diameter=0.3
cpdbad "a diameter without cells_per_diameter" domain.diameter --set domain.diameter=0.3 --set domain.nx=4 \
    --set domain.ny=16 --set domain.nz=2
tap_end $T
