#!/bin/bash
# permeability_packing_test.sh — the packing file of cases/permeability_crosscheck is read
# identically by both fluid models: the pore network on the HDF5 packing gives the
# permeability of the same packing given as text (tests/data/porenet/, the reference
# prototype's kappa_z/d^2 = 1.2539188e-3), to the last bit; the resolved solver reads the
# same 200 fixed spheres (ibmdem check); a malformed HDF5 packing is refused with
# "file:line: porenet.packing: reason".  The walled permeameter (cases/permeameter/permeameter.ini,
# 300 spheres, a fixed packing solved once): no snapshot and no checkpoint unless asked
# (porenet.snapshots = on), kappa and kappa/d^2 in summary.json; porenet.margin narrower than its
# pores at the walls need is widened with a warning, and kappa is that of the default margin to
# round-off (without the widening, a margin of 1 (0.83 r_max) kept 1524 of the 1653 pores and gave a third of
# kappa, one of 2.2 all the pores and kappa 5.4 % low, silently).  TAP lines; about 3 s.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_perm_packing.XXXXXX)
C=cases/permeability_crosscheck
$BIN run $C/porenet.ini --out $T/h5 >$T/h5.log 2>&1 &&
    $BIN run $C/porenet.ini --out $T/txt --set porenet.packing=tests/data/porenet/proto_N200_phi0.60_pd0.05.txt >$T/txt.log 2>&1
report $? "porenet.ini runs on the HDF5 packing and on the text one"
$PY - $T <<'PY'
import json, sys, h5py
t = sys.argv[1]
a = json.load(open(t + "/h5/summary.json"))["porenet"]["permeability_z"]
b = json.load(open(t + "/txt/summary.json"))["porenet"]["permeability_z"]
r = h5py.File("cases/permeability_crosscheck/packing_N200.h5")["radius"][...]
k = a / (2 * r.mean()) ** 2
print("# kappa_z/d^2 = %.10e (HDF5), %.10e (text), prototype 1.2539188190e-03" % (k, b / (2 * r.mean()) ** 2))
sys.exit(0 if a == b and abs(k / 1.2539188190e-3 - 1) < 1e-8 else 1)
PY
report $? "same kappa from both files, equal to the prototype's (1e-8)"
$BIN check $C/ibm.ini >$T/ibm.log 2>&1 && grep -q "spheres_file = $C/packing_N200.h5" $T/ibm.log
report $? "ibm.ini accepts the 200 fixed spheres of the same file"
$PY -c "import h5py; f = h5py.File('$T/bad.h5', 'w'); f['position'] = [[1.0, 1, 1]]" &&
    sed "s|^packing = .*|packing = $T/bad.h5|" $C/porenet.ini >$T/bad.ini
out=$($BIN check $T/bad.ini 2>&1 >/dev/null); rc=$?
echo "$out" | grep -Eq "^$T/bad.ini:[0-9]+: porenet.packing: $T/bad.h5: needs the datasets position \[n\]\[3\] and radius \[n\]" && [ $rc = 2 ]
report $? "a packing without radius: status $rc, '$(echo "$out" | tail -1)'"
P=cases/permeameter/permeameter.ini
$BIN run $P --out $T/pm >$T/pm.log 2>&1 && $BIN run $P --set porenet.margin=0.8 --out $T/pm_narrow >$T/pm_narrow.log 2>&1 &&
    $BIN run $P --set porenet.snapshots=on --out $T/pm_snap >$T/pm_snap.log 2>&1
report $? "permeameter.ini runs (default, porenet.margin = 0.8, porenet.snapshots = on)"
ls $T/pm | grep -Eq "porenet_|checkpoint_" && bad=1 || bad=0
ls $T/pm_snap | grep -q "porenet_00000.h5" && grep -q "kappa/d^2 = " $T/pm.log || bad=1
report $bad "a fixed packing writes no snapshot nor checkpoint unless asked ($(ls $T/pm | tr '\n' ' '))"
grep -q "porenet.margin = 0.8 is too narrow for this packing" $T/pm_narrow.log &&
    $PY - $T <<'PY'
import json, sys
a, b = (json.load(open(sys.argv[1] + p + "/summary.json"))["porenet"] for p in ("/pm", "/pm_narrow"))
print("# kappa_z %.12e (default margin), %.12e (margin 0.8, widened), kappa/d^2 %.6e; pores %d and %d"
      % (a["permeability_z"], b["permeability_z"], a["permeability_over_d2_z"], a["pores"], b["pores"]))
sys.exit(0 if abs(b["permeability_z"] / a["permeability_z"] - 1) < 1e-10 and a["pores"] == b["pores"]
         and abs(a["permeability_over_d2_z"] - a["permeability_z"] / a["mean_diameter"] ** 2) < 1e-15 else 1)
PY
report $? "a margin too narrow is widened with a warning: the same pores and kappa (1e-10)"
tap_end $T
