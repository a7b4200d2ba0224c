#!/bin/bash
# ibm_bad_input_test.sh — bad [ibm] input stops before the run with status 2 and
# "file:line: ibm.key: reason" (docs/user-guide.md, Bad input).  TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_ibm_bad.XXXXXX)
base3d='[domain]\nnx = 16\nny = 16\nnz = 16\nlength = 1 1 1\n[fluid]\nnu = 1\n[time]\nt_end = 1\n[ibm]\n'
axi='[domain]\ngeometry = axisymmetric\nnx = 8\nny = 8\nlength = 1 1 1\n[boundary]\nx_lo = axis\nx_hi = freeslip\n[fluid]\nnu = 1\n[time]\nt_end = 1\n[ibm]\n'
check() { # name, file text, expected message (regex)
    printf "$2" >$T/$1.ini
    out=$($BIN check $T/$1.ini 2>&1 >/dev/null); rc=$?
    echo "$out" | grep -Eq "^$T/$1.ini:[0-9]+: $3" && [ $rc = 2 ]
    report $? "$1: status $rc, '$(echo "$out" | tail -1)'"
}
check outside "${base3d}sphere1 = free center 2 0.5 0.5 radius 0.1 density 2\n" "ibm.sphere1: the centre is outside the domain"
check tag "${base3d}sphere1 = free center 0.5 0.5 0.5 radis 0.1\n" "ibm.sphere1: 'radis' is not one of"
check kind "${base3d}sphere1 = floating center 0.5 0.5 0.5 radius 0.1\n" "ibm.sphere1: 'floating': the first word must be the kind"
check density "${base3d}sphere1 = free center 0.5 0.5 0.5 radius 0.1\n" "ibm.sphere1: a free sphere needs density"
check number "${base3d}sphere1 = fixed center 0.5 x 0.5 radius 0.1\n" "ibm.sphere1: center: 'x' is not a number"
check noradius "${base3d}sphere1 = fixed center 0.5 0.5 0.5\n" "ibm.sphere1: no radius"
check period "${base3d}sphere1 = fixed center 0.5 0.5 0.5 radius 0.4\n" "ibm.sphere1: sphere 1 \(radius 0.4\) and its band"
check axis "${axi}sphere1 = free center 0.2 0.5 0 radius 0.1 density 2\n" "ibm.sphere1: an axisymmetric sphere must be on the axis"
check swirl "${axi}sphere1 = prescribed center 0 0.5 0 radius 0.1 omega 0 1 0\n" "ibm.sphere1: an axisymmetric sphere cannot rotate"
check rigid1 "${base3d}force_model = rigid\nsphere1 = free center 0.5 0.5 0.5 radius 0.1 density 1\n" "ibm.force_model: rigid divides by"
check history "${base3d}sphere1 = fixed center 0.5 0.5 0.5 radius 0.1 history h.csv\n" "ibm.sphere1: a velocity history needs the kind prescribed"
check calkappa "${base3d}radius_correction = calibrated\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n" "ibm.radius_correction: calibrated needs forcing_time in \\[0.1, 0.3\\]"
check caliter "${base3d}radius_correction = calibrated\nforcing_time = 0.2\nforcing_iterations = 1\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n" "ibm.radius_correction: calibrated needs forcing_iterations = 0"
check nofluid '[domain]\nnx = 8\nny = 8\nnz = 8\nlength = 1 1 1\n[time]\nt_end = 1\n[ibm]\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n' "ibm.sphere1: an immersed boundary needs a fluid"
printf 'x,y,z,radius\n0.5,0.5,0.5,0.1\n0.2,0.2\n' >$T/s.csv
check csv "${base3d}spheres_file = $T/s.csv\ndensity = 2\n" "ibm.spheres_file: $T/s.csv:3: 2 values for 4 columns"
tap_end $T
