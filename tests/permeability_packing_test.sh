#!/bin/bash
# permeability_packing_test.sh — the packing file of cases/permeability_crosscheck is read
# identically by both fluid models: the pore network on the HDF5 packing gives the
# permeability of the same packing given as text (tests/data/porenet/, the reference
# prototype's kappa_z/d^2 = 1.2539188e-3), to the last bit; the resolved solver reads the
# same 200 fixed spheres (ibmdem check); a malformed HDF5 packing is refused with
# "file:line: porenet.packing: reason".  TAP lines; about 1 s.
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
tap_end $T
