#!/bin/bash
# dem_driver_test.sh — a DEM-only scene through `ibmdem run` (src/core/sim_dem.c):
# the run, its outputs (series.csv columns, particle snapshots and their XDMF index,
# summary.json), and a restart from a checkpoint that continues the run bit for bit
# (on 1 and 2 ranks: the checkpoint holds the particles in their current order and
# the neighbour lists, so the force sums are taken in the same order).
# Also: a LAMMPS data file as the particles of a run, and a bad line of it refused as bad input.
source "$(dirname "$0")/tap.sh"
tmp=$(mktemp -d /tmp/ibmdem_dem_driver.XXXXXX)
case=cases/dem_inclined_plane/coarse.ini
set_short="--set time.t_end=0.1 --set output.fields_every=0.05 --set packing.rest_energy=1e-3"

$MPIRUN -np 1 $BIN run $case $set_short --set time.t_end=0.2 --out $tmp/full > $tmp/full.log 2>&1
report $? "DEM-only scene runs through ibmdem run"
grep -q '^step,time,dt,dem_kinetic_energy,dem_rotational_energy,dem_contacts' $tmp/full/series.csv
report $? "series.csv has the DEM columns"
$PY - $tmp/full <<'EOF'
import sys, h5py, re
d = sys.argv[1]
x = open(d + "/particles.xdmf").read()
files = re.findall(r"(particles_\d+\.h5):/position", x)
ok = len(files) == 5 and 'Polyvertex' in x
for f in files:
    with h5py.File(d + "/" + f, "r") as h:
        ok &= h["position"].shape[1] == 3 and h["radius"].shape[0] == h["position"].shape[0]
sys.exit(0 if ok else 1)
EOF
report $? "particle snapshots and their XDMF Polyvertex index (5 times, 0 to 0.2 s)"
grep -q '"particle_steps_per_second"' $tmp/full/summary.json
report $? "summary.json has the DEM entries"

for np in 1 2; do
    $MPIRUN -np $np $BIN run $case $set_short --out $tmp/a$np > $tmp/a$np.log 2>&1 &&
        $MPIRUN -np $np $BIN run $case $set_short --set time.t_end=0.2 --out $tmp/a$np \
            --restart $(ls $tmp/a$np/checkpoint_*.h5 | tail -1) > $tmp/b$np.log 2>&1
    report $? "restart from a checkpoint on $np rank(s)"
    $PY - $tmp/full $tmp/a$np <<'EOF'
import sys, h5py, glob, numpy as np
def last(d):
    f = sorted(glob.glob(d + "/particles_*.h5"))[-1]
    with h5py.File(f, "r") as h:
        return h.attrs["time"], h["position"][...], h["id"][...]
ta, xa, ia = last(sys.argv[1])
tb, xb, ib = last(sys.argv[2])
dx = np.abs(xa - xb).max()
print("# t = %.3f and %.3f, max |dx| = %.3e m" % (ta, tb, dx))
sys.exit(0 if abs(ta - tb) < 1e-12 and (ia == ib).all() and dx == 0 else 1)
EOF
    report $? "the restarted run ends exactly where the uninterrupted one does ($np rank(s))"
done
# a LAMMPS data file (atom_style sphere: id type diameter density x y z; Velocities: id vx vy vz wx wy wz),
# read as the particles of a run (src/dem/dem_lammps.c); a bad line is bad input of particles.file
cat >$tmp/two.data <<'EOF'
two spheres

2 atoms
1 atom types
0 0.04 xlo xhi
0 0.025 ylo yhi
0 0.15 zlo zhi

Atoms

1 1 0.004 2500 0.01 0.0125 0.05
2 1 0.0048 2000 0.03 0.0125 0.05

Velocities

1 1.5 0 0 0 0 3
2 -0.5 0 0 0 0 0
EOF
lm="--set particles.source=lammps_data --set particles.file=$tmp/two.data --set bed.type=none --set packing.prepare=false
    --set dem.gravity=0,0,0 --set time.t_end=0.001 --set output.fields_every=0"
$BIN run $case $lm --out $tmp/lmp > $tmp/lmp.log 2>&1 &&
$PY - $tmp/lmp <<'EOF'
import sys, h5py, glob, numpy as np
with h5py.File(sorted(glob.glob(sys.argv[1] + "/checkpoint_*.h5"))[-1], "r") as h:
    names = []
    h.visit(names.append)
    r = np.sort(np.asarray(h[[n for n in names if n.endswith("radius")][0]]))
    print("# radii", r)
sys.exit(0 if r.shape == (2,) and np.allclose(r, [0.002, 0.0024]) else 1)
EOF
report $? "a LAMMPS data file gives the run its particles (2, radii 0.002 and 0.0024 m)"
sed 's/^2 1 0.0048 2000 0.03 0.0125 0.05$/2 1 0.0048 2000 0.03 x 0.05/' $tmp/two.data >$tmp/bad.data
out=$($BIN check $case --set particles.source=lammps_data --set particles.file=$tmp/bad.data --set bed.type=none \
    --set packing.prepare=false 2>&1); rc=$?
echo "$out" | grep -q "particles.file: $tmp/bad.data:12: a Atoms line needs 7" && [ $rc = 2 ]
report $? "a LAMMPS data line with a word for a number is bad input (status $rc): $(echo "$out" | tail -1 | cut -c1-90)"

tap_end $tmp
