#!/bin/bash
# output_test.sh — what a run leaves in its output folder, on 2 ranks:
# the resolved input (valid input itself), the log, series.csv, summary.json,
# field snapshots indexed by a valid XDMF file (postproc/check_xdmf.py checks
# the XDMF 2 structure and every dataset it names, with its shape), and
# checkpoints; the same for a stretched 3-D grid.  Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_output.XXXXXX)

O=$T/tgv
$MPIRUN $BIN run cases/taylor_green/taylor_green.ini --set domain.nx=32 --set domain.ny=32 --set time.t_end=1 \
    --set output.fields_every=0.25 --set output.series_every=2 --out $O >$T/stdout 2>$T/stderr
report $? "2-D Taylor-Green on 2 ranks ran"
ok=0; for f in input.ini log.txt series.csv summary.json fields.xmf fields_00000.h5; do [ -s $O/$f ] || ok=1; done
report $ok "the folder has input.ini log.txt series.csv summary.json fields.xmf fields_00000.h5"

$BIN check $O/input.ini >/dev/null 2>$T/err
report $? "the resolved input input.ini is itself a valid case file"

[ "$(head -1 $O/series.csv)" = "step,time,dt,cfl,kinetic_energy,div_max,poisson_residual,poisson_iterations,superficial_u,flux_x,superficial_v,flux_y,wall_per_step" ]
report $? "series.csv has the documented columns"
$PY - $O <<'PY'
import csv, json, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/series.csv")))
s = json.load(open(d + "/summary.json"))
steps = [int(r["step"]) for r in rows]
last = rows[-1]
ok = (steps[0] == 0 and all(st % 2 == 0 for st in steps[:-1]) and steps[-1] == s["steps"]
      and float(last["time"]) == 1.0 and s["time"] == 1.0 and s["status"] == "t_end" and s["ranks"] == 2
      and abs(s["fluid"]["kinetic_energy"] / float(last["kinetic_energy"]) - 1) < 1e-11   # %.12g in the CSV
      and s["case"] == "taylor_green" and s["checkpoint"].endswith("checkpoint_%08d.h5" % s["steps"]))
sys.exit(0 if ok else 1)
PY
report $? "series.csv rows every 2 steps to t_end = 1, summary.json agrees with its last row"

$PY postproc/check_xdmf.py $O/fields.xmf >$T/xdmf 2>&1
report $? "fields.xmf is valid XDMF 2 and its datasets exist with their shapes ($(tail -1 $T/xdmf | sed 's/.*: //'))"
$PY - $O <<'PY'
import glob, h5py, sys
t = [h5py.File(f).attrs["time"] for f in sorted(glob.glob(sys.argv[1] + "/fields_*.h5"))]
# snapshots at t = 0, at the first step reaching each multiple of 0.25, and at the end
ok = len(t) == 5 and t[0] == 0 and t[-1] == 1.0 and all(t[k] >= 0.25 * k and t[k] < 0.25 * k + 0.2 for k in range(1, 4))
sys.exit(0 if ok else 1)
PY
report $? "snapshots at t = 0, every 0.25 (first step after) and at the end"

h5dump -H $O/$(cd $O && ls checkpoint_*.h5 | tail -1) >$T/h5 2>&1 && grep -q 'DATASET "u"' $T/h5 &&
    grep -q 'DATASET "p"' $T/h5 && grep -q 'DATASET "input"' $T/h5 && grep -q 'ATTRIBUTE "fingerprint"' $T/h5
report $? "the final checkpoint is valid HDF5 (h5dump) with /fluid u v p, the input and its fingerprint"

grep -q "taylor_green: reached t_end" $O/log.txt && ! grep -q $'\r' $O/log.txt $T/stdout
report $? "log.txt has what rank 0 printed, no carriage return when stdout is not a terminal"

# a stretched 3-D grid: the mesh nodes are the real faces
cat >$T/box.ini <<'INI'
[domain]
geometry = 3d
nx = 8
ny = 6
nz = 4
length = 2 1 1
x_stretch = tanh_both
[boundary]
x_lo = noslip
x_hi = noslip
[fluid]
nu = 0.1
body_force = 0 1 0
[time]
t_end = 1
max_steps = 3
INI
$MPIRUN $BIN run $T/box.ini --out $T/box >$T/stdout 2>&1 && $PY postproc/check_xdmf.py $T/box/fields.xmf >$T/xdmf 2>&1 &&
$PY - $T/box <<'PY'
import h5py, sys, numpy as np
f = h5py.File(sys.argv[1] + "/fields_00001.h5")
x = f["x"][...]
dx = np.diff(x)
ok = (f["velocity"].shape == (4, 6, 8, 3) and len(x) == 9 and x[0] == 0 and abs(x[-1] - 2) < 1e-15
      and dx[0] < 0.8 * dx[4] and np.allclose(f["xc"][...], 0.5 * (x[1:] + x[:-1]), rtol=0, atol=1e-15))
sys.exit(0 if ok else 1)
PY
report $? "stretched 3-D channel on 2 ranks: valid XDMF, x nodes are the stretched faces"

tap_end "$T"
