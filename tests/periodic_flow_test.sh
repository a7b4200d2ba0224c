#!/bin/bash
# periodic_flow_test.sh — the periodic flow's columns (series.csv) and keys (summary.json):
# superficial velocity, flux and Reynolds number, on plane Poiseuille flow (periodic in x and z,
# walls in y), whose discrete steady state is known exactly, on 1 and 2 ranks; a
# reynolds_length without a periodic direction is bad input.  Prints TAP lines.
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
tap_end $T
