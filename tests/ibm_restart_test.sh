#!/bin/bash
# ibm_restart_test.sh — a run with immersed spheres restarts exactly.
#  1. N steps straight and N/2 + --restart + N/2 give BIT-IDENTICAL fluid
#     fields and sphere states (h5diff --delta=0 on /fluid/* and /ibm/*)
#     and identical series.csv rows after the restart, on 1 and 2 ranks, for
#     a free settling sphere (axisymmetric) and a 3-D scene with a free, a
#     fixed and a prescribed sphere, the latter also with free_alpha = step;
#  2. the outputs of the part: series columns, spheres.csv, spheres_*.h5,
#     spheres.xmf, the solid fraction in the field snapshots, summary.json.
# Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_ibm_restart.XXXXXX)
N=20; H=$((N / 2))
final() { printf "%s/checkpoint_%08d.h5" "$1" "$N"; }

cat >$T/scene3d.ini <<'EOF'
[domain]
nx = 16
ny = 16
nz = 16
length = 2 2 2
[boundary]
y_lo = noslip
y_hi = noslip
[fluid]
nu = 0.05
viscous = implicit
dt = 0.02
[ibm]
gravity = 0 -1 0
sphere1 = free center 0.5 1.4 1.0 diameter 0.5 density 3
sphere2 = fixed center 1.5 0.6 1.0 diameter 0.5
sphere3 = prescribed center 1.0 1.0 0.3 diameter 0.4 velocity 0.2 0 0.1 omega 0 0 1
[time]
t_end = 100
[output]
fields_every = 0.2
EOF

for case in settling scene3d scene3d_step; do
    if [ $case = settling ]; then
        ini=cases/settling_sphere/settling_axi.ini
        S="--set domain.nx=20 --set domain.ny=60 --set domain.length=2,6,1 --set ibm.sphere1=free,center,0,5,0,diameter,1,density,4 --set fluid.dt=0.08 --set output.fields_every=0.4"
    elif [ $case = scene3d ]; then
        ini=$T/scene3d.ini
        S=""
    else
        # the free sphere's solid fraction held over each step, moved between steps
        # (the jump carried in the momentum: state that must survive the restart)
        ini=$T/scene3d.ini
        S="--set ibm.free_alpha=step"
    fi
    S="$S --set time.t_end=1000 --set output.series_every=1"
    for np in 1 2; do
        d=$T/$case.np$np
        $MPIRUN -np $np $BIN run $ini $S --set time.max_steps=$N --out $d/straight >$d.log 2>&1 &&
        $MPIRUN -np $np $BIN run $ini $S --set time.max_steps=$H --out $d/split >>$d.log 2>&1 &&
        $MPIRUN -np $np $BIN run $ini $S --set time.max_steps=$N --out $d/split \
            --restart $d/split/$(printf "checkpoint_%08d.h5" $H) >>$d.log 2>&1
        rc=$?
        report $rc "$case np=$np: $N steps, and $H + restart + $H, ran"
        [ $rc = 0 ] || { sed 's/^/#   /' $d.log | tail -5; continue; }
        bad=0; list=""
        for g in fluid ibm; do
            for v in $(h5ls "$(final $d/straight)/$g" | awk '$2 == "Dataset" {print $1}'); do
                list="$list $g/$v"
                h5diff --delta=0 "$(final $d/straight)" "$(final $d/split)" /$g/$v /$g/$v >/dev/null || bad=1
            done
        done
        echo "$list" | grep -q "ibm/position" || bad=1
        report $bad "$case np=$np: restarted fluid and spheres bit-identical to the straight run ($list )"
        cut -d, -f1-$(head -1 $d/straight/series.csv | tr , '\n' | grep -vn wall_per_step | tail -1 | cut -d: -f1) \
            $d/straight/series.csv | awk -F, -v h=$H 'NR > 1 && $1 > h' >$d/a.csv
        cut -d, -f1-$(head -1 $d/split/series.csv | tr , '\n' | grep -vn wall_per_step | tail -1 | cut -d: -f1) \
            $d/split/series.csv | awk -F, -v h=$H 'NR > 1 && $1 > h' >$d/b.csv
        cmp -s $d/a.csv $d/b.csv && [ "$(wc -l <$d/a.csv)" = $H ]
        report $? "$case np=$np: series.csv rows $((H + 1))..$N identical after the restart"
        cmp -s $d/straight/spheres.csv $d/split/spheres.csv
        report $? "$case np=$np: spheres.csv identical after the restart"
    done
done

# the outputs of the part (3-D scene, 1 rank)
d=$T/scene3d.np1/straight
$PY - "$d" <<'PY'
import sys, json, h5py, numpy as np, glob, os
d = sys.argv[1]
head = open(d + "/series.csv").readline().strip().split(",")
need = ["s%d_%s" % (p, c) for p in (1, 2, 3) for c in ("x", "y", "z", "u", "v", "w", "ox", "oy", "oz", "fx", "fy", "fz", "tx", "ty", "tz")]
missing = [c for c in need if c not in head]
rows = np.loadtxt(d + "/spheres.csv", delimiter=",", skiprows=1)
snaps = sorted(glob.glob(d + "/spheres_*.h5"))
f = h5py.File(snaps[-1])
ok = not missing and rows.shape[1] == 18 and set(rows[:, 2]) == {1, 2, 3}
ok &= f["position"].shape == (3, 3) and f["radius"].shape == (3,)
fl = h5py.File(sorted(glob.glob(d + "/fields_*.h5"))[-1])
a = fl["solid_fraction"][...]
# the solid volume at the cell centres: three spheres, 2 * (pi/6) 0.5^3 + (pi/6) 0.4^3, plus
# the excess of the smoothed profile, pi^2 w^2/(4 R^2) with w = 0.62 h (test_ibm_alpha.c):
# 24 % and 37 % at D/h = 4 and 3.2
vol = a.sum() * (2.0 / 16) ** 3
h = 2.0 / 16; w = 0.62 * h
exact = np.pi / 6 * (2 * 0.5 ** 3 * (1 + np.pi ** 2 * w ** 2 / (4 * 0.25 ** 2)) + 0.4 ** 3 * (1 + np.pi ** 2 * w ** 2 / (4 * 0.2 ** 2)))
ok &= a.min() >= 0 and 0.9 < a.max() <= 1.0 and abs(vol / exact - 1) < 0.05
xmf = open(d + "/spheres.xmf").read()
ok &= xmf.count("<Grid Name=\"spheres_") == len(snaps) and "solid_fraction" in open(d + "/fields.xmf").read()
s = json.load(open(d + "/summary.json"))
ok &= s["ibm"]["spheres"] == 3 and "settling_velocity" in s["ibm"]["sphere1"]
print("ok" if ok else "bad", "missing columns:", missing, "solid volume %.4f (spheres with the smoothing excess %.4f)" % (vol, exact))
sys.exit(0 if ok else 1)
PY
report $? "3-D scene: series columns of 3 spheres, spheres.csv, spheres_*.h5, spheres.xmf, solid_fraction, summary.json"
tap_end $T
