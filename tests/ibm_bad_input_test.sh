#!/bin/bash
# ibm_bad_input_test.sh — bad [ibm] input and impossible geometry of spheres
# and particles stop before the run with status 2 and "file:line: section.key:
# reason" (docs/user-guide.md, Bad input and What the code refuses); a free
# sphere reaching a wall stops the run with status 1.  TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_ibm_bad.XXXXXX)
base3d='[domain]\nnx = 16\nny = 16\nnz = 16\nlength = 1 1 1\n[fluid]\nnu = 1\n[time]\nt_end = 1\n[ibm]\n'
axi='[domain]\ngeometry = axisymmetric\nnx = 8\nny = 8\nlength = 1 1 1\n[boundary]\nx_lo = axis\nx_hi = freeslip\n[fluid]\nnu = 1\n[time]\nt_end = 1\n[ibm]\n'
check() { # name, file text, expected message (regex) [, ok: the input is valid]
    printf "$2" >$T/$1.ini
    out=$($BIN check $T/$1.ini 2>&1 >/dev/null); rc=$?
    if [ "$4" = ok ]; then [ $rc = 0 ]; else echo "$out" | grep -Eq "^$T/$1.ini:[0-9]+: $3" && [ $rc = 2 ]; fi
    report $? "$1: status $rc, '$(echo "$out" | tail -1)'"
}
check outside "${base3d}sphere1 = free center 2 0.5 0.5 radius 0.1 density 2\n" "ibm.sphere1: the centre is outside the domain"
check tag "${base3d}sphere1 = free center 0.5 0.5 0.5 radis 0.1\n" "ibm.sphere1: 'radis' is not one of"
check kind "${base3d}sphere1 = floating center 0.5 0.5 0.5 radius 0.1\n" "ibm.sphere1: 'floating': the first word must be the kind"
check density "${base3d}sphere1 = free center 0.5 0.5 0.5 radius 0.1\n" "ibm.sphere1: a free sphere needs density"
check number "${base3d}sphere1 = fixed center 0.5 x 0.5 radius 0.1\n" "ibm.sphere1: center: 'x' is not a number"
check noradius "${base3d}sphere1 = fixed center 0.5 0.5 0.5\n" "ibm.sphere1: no radius"
check period "${base3d}sphere1 = fixed center 0.5 0.5 0.5 radius 0.4\n" "ibm.sphere1: sphere 1 \(radius 0.4\) and its band"
# cells longer in x than in y and z: the band is counted in the largest spacing at the sphere, so the sphere
# fits x (walls) but its band does not fit the periodic y (a run stopped with status 1 at the first step before)
flat='[domain]\nnx = 4\nny = 32\nnz = 32\nlength = 1 1 1\n[boundary]\nx_lo = noslip\nx_hi = noslip\n[fluid]\nnu = 1\n[time]\nt_end = 1\n[ibm]\n'
check flatcells "${flat}sphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n" "ibm.sphere1: sphere 1 \(radius 0.1\) and its band of [0-9.]+ cells of 0.25 do not fit in the periodic y length 1"
check axis "${axi}sphere1 = free center 0.2 0.5 0 radius 0.1 density 2\n" "ibm.sphere1: an axisymmetric sphere must be on the axis"
check swirl "${axi}sphere1 = prescribed center 0 0.5 0 radius 0.1 omega 0 1 0\n" "ibm.sphere1: an axisymmetric sphere cannot rotate"
check rigid1 "${base3d}force_model = rigid\nsphere1 = free center 0.5 0.5 0.5 radius 0.1 density 1\n" "ibm.force_model: rigid divides by"
check history "${base3d}sphere1 = fixed center 0.5 0.5 0.5 radius 0.1 history h.csv\n" "ibm.sphere1: a velocity history needs the kind prescribed"
check calkappa "${base3d}radius_correction = calibrated\nforcing_time = 0\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n" "ibm.radius_correction: calibrated needs forcing_time in \\[0.1, 0.3\\]"
check caliter "${base3d}radius_correction = calibrated\nforcing_time = 0.2\nforcing_iterations = 1\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n" "ibm.radius_correction: calibrated needs forcing_iterations = 0"
check calband "${base3d}radius_correction = gaps\nband_width = 0.5\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n" "ibm.radius_correction: gaps is fitted on the seed's band: it needs band_width = 1, not 0.5"
check bandrange "${base3d}band_width = 0.2\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n" "ibm.band_width: "
check gaps2d "${axi}radius_correction = gaps\nsphere1 = fixed center 0 0.5 0 radius 0.1\n" "ibm.radius_correction: gaps is fitted on 3-D arrays"
check gapsiter "${base3d}radius_correction = gaps\nforcing_iterations = 2\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n" "ibm.radius_correction: gaps needs forcing_iterations = 0"
check nofluid '[domain]\nnx = 8\nny = 8\nnz = 8\nlength = 1 1 1\n[time]\nt_end = 1\n[ibm]\nsphere1 = fixed center 0.5 0.5 0.5 radius 0.1\n' "ibm.sphere1: an immersed boundary needs a fluid"
printf 'x,y,z,radius\n0.5,0.5,0.5,0.1\n0.2,0.2\n' >$T/s.csv
check csv "${base3d}spheres_file = $T/s.csv\ndensity = 2\n" "ibm.spheres_file: $T/s.csv:3: 2 values for 4 columns"
# impossible geometry of immersed spheres (walls on every face of walled3d)
walled3d='[domain]\nnx = 16\nny = 16\nnz = 16\nlength = 6 6 6\n[boundary]\nx_lo = noslip\nx_hi = noslip\ny_lo = noslip\ny_hi = noslip\nz_lo = noslip\nz_hi = noslip\n[fluid]\nnu = 1\n[time]\nt_end = 1\n[ibm]\n'
check larger "${walled3d}sphere1 = fixed center 3 3 3 diameter 1000\n" "ibm.sphere1: sphere 1 \(diameter 1000\) is larger than the domain in x \(6\)"
check samecentre "${walled3d}sphere1 = free center 3 3 3 diameter 1 density 2\nsphere2 = free center 3 3 3 diameter 1 density 2\n" "ibm.sphere2: spheres 1 and 2 \(radii 0.5 and 0.5\) overlap by 100 % of the smaller diameter, and one is free"
check overlap70 "${walled3d}sphere1 = free center 3 3 3 diameter 1 density 2\nsphere2 = fixed center 3 3.3 3 diameter 1\n" "ibm.sphere2: spheres 1 and 2 .* overlap by 70 %"
check inside "${walled3d}sphere1 = fixed center 3 3 3 diameter 2\nsphere2 = fixed center 3 3.2 3 diameter 1\n" "ibm.sphere2: sphere 2 \(radius 0.5\) lies inside sphere 1 \(radius 1\)"
check wallcut "${walled3d}sphere1 = free center 3 0.4 3 diameter 1 density 2\n" "ibm.sphere1: free sphere 1 \(radius 0.5, centre y = 0.4\) crosses the y_lo face"
printf 'x,y,z,radius\n3,3,3,0.5\n3,3,3,0.5\n' >$T/two.csv
check csvsame "${walled3d}spheres_file = $T/two.csv\ndensity = 2\n" "ibm.spheres_file: spheres 1 and 2 .* overlap by 100 %"
check hexcentre "${walled3d}sphere1 = fixed center 0x3 3 3 radius 0.1\n" "ibm.sphere1: center: '0x3' is not a number"

# DEM particles: overlaps beyond dem.max_overlap, outside the domain, too fast to resolve a contact
dem='[domain]\nlength = 6 6 6\n[boundary]\nx_lo = noslip\nx_hi = noslip\ny_lo = noslip\ny_hi = noslip\nz_lo = noslip\nz_hi = noslip\n[contact]\nrestitution = 0.9\ncontact_time = 1e-3\nfriction = 0.3\n[time]\nt_end = 0.01\n[particles]\nsource = list\nparticle1 = center 3 3 3 diameter 1 density 2500\n'
check demok "${dem}particle2 = center 3 4.5 3 diameter 1 density 2500\n[dem]\ngravity = 0 0 0\n" "" ok
check demsame "${dem}particle2 = center 3 3 3 diameter 1 density 2500\n" "particles.particle2: particle 2 \(radius 0.5, centre 3 3 3\) overlaps particle 1 \(particles.particle1; .*\) by 100 % of the smaller diameter, more than dem.max_overlap = 1 %"
check dem70 "${dem}particle2 = center 3 3.3 3 diameter 1 density 2500\n" "particles.particle2: particle 2 .* by 70 % of the smaller"
check demfast "${dem}particle2 = center 3 4.5 3 diameter 1 density 2500 velocity 1e200 0 0\n" "particles.particle2: particle 2: a speed of 1e\+200 m/s .* moves it more than its radius"
check demfast308 "${dem}particle2 = center 3 4.5 3 diameter 1 density 2500 velocity 1e308 0 0\n" "particles.particle2: particle 2: a speed of 1e\+308 m/s"
check demwall "${dem}particle2 = center 3 4.5 3 diameter 1 density 2500\n[walls]\nwall1_point = 0 4.3 0\nwall1_normal = 0 1 0\n" "particles.particle2: particle 2 \(radius 0.5\) overlaps the wall wall1 by 30 %"
printf "${dem}" | sed 's/^source = list$/source = insert/; /^particle1/d' >$T/demregion.ini
printf 'count = 5\nradius = 0.1\nregion_lo = 1 1 1\nregion_hi = 9 2 2\n' >>$T/demregion.ini
out=$($BIN check $T/demregion.ini 2>&1 >/dev/null); rc=$?
echo "$out" | grep -Eq "^$T/demregion.ini:[0-9]+: particles.region_lo: particle [0-9]+: the centre .* is outside the domain \[0, 6\] in x" && [ $rc = 2 ]
report $? "demregion: an insertion region outside the domain: status $rc, '$(echo "$out" | tail -1)'"
periodic='[domain]\nlength = 6 6 6\n[contact]\nrestitution = 0.9\ncontact_time = 1e-3\nfriction = 0.3\n[time]\nt_end = 0.01\n[particles]\nsource = list\nparticle1 = center 3 3 3 diameter 1000 density 2500\n'
check demperiod "$periodic" "particles.particle1: particle 1: its diameter \(1000 m\) is more than half the periodic length in x \(6 m\)"

# a coupled particle too fast for its DEM step (a crash of the advection kernel with dt = 0 before)
coupled='[domain]\nnx = 16\nny = 32\nnz = 16\nlength = 4 8 4\n[boundary]\nx_lo = freeslip\nx_hi = freeslip\ny_lo = noslip\ny_hi = freeslip\nz_lo = freeslip\nz_hi = freeslip\n[fluid]\nnu = 0.05\n[particles]\nsource = list\nparticle1 = center 2 6 2 diameter 1 density 8 velocity 1e200 0 0\n[contact]\nrestitution = 0.97\ncontact_time = 2.5e-3\nfriction = 0.25\n[walls]\nfaces = y_lo\n[dem]\ngravity = 0 -1 0\n[time]\nt_end = 1\n'
check coupledfast "$coupled" "particles.particle1: particle 1: a speed of 1e\+200 m/s"

# the pore network: YADE's wall throats with no-slip walls conduct more than with slip ones
check yadenoslip '[domain]\nlength = 13.455325682746873 13.455325682746873 13.455325682746873\n[porenet]\nviscosity = 1\npacking = cases/permeameter/packing_walled_300.txt\nwall_throats = yade\nx_lo = noslip\nx_hi = noslip\ny_lo = slip\ny_hi = slip\nz_lo_flow = pressure\nz_lo_value = 1\nz_hi_flow = pressure\n[time]\nt_end = 0\n' "porenet.wall_throats: yade reproduces YADE's slip walls only, and face x_lo is noslip"

# run time: a prescribed sphere at 1e300 m/s, no crash from a zero step: with the seed's forcing
# (forcing_time = 0, u <- U in the solid) the fluid's energy is not finite and the run stops cleanly
# (status 3); with the default forcing_time the relaxation over the step (about 2e-301 s) gives the
# nodes a finite fraction of U, and the three steps end normally with finite values
printf "${walled3d}sphere1 = prescribed center 3 3 3 diameter 1 velocity 1e300 0 0\n" >$T/fast.ini
timeout 120 $BIN run $T/fast.ini --set time.max_steps=3 --set ibm.forcing_time=0 --out $T/ofast >$T/fast.out 2>&1
rc=$?
[ $rc = 3 ] && grep -q "^error: the run diverged at step 1" $T/fast.out
report $? "a sphere at 1e300 m/s, the seed's forcing: a clean divergence (status $rc, want 3)"
timeout 120 $BIN run $T/fast.ini --set time.max_steps=3 --out $T/ofast2 >$T/fast2.out 2>&1
rc=$?
[ $rc = 0 ] && $PY -c "
import csv, math, sys
r = list(csv.DictReader(open('$T/ofast2/series.csv')))[-1]
sys.exit(not (r['step'] == '3' and math.isfinite(float(r['kinetic_energy'])) and 0 < float(r['time']) < 1e-299))"
report $? "a sphere at 1e300 m/s, the default forcing: three steps of ~2e-301 s, finite energy (status $rc)"

# a free sphere settling onto the bottom of a closed box stops there (no contact model), status 1
settle='[domain]\ngeometry = 2d\nnx = 16\nny = 32\nlength = 2 4 1\n[boundary]\nx_lo = freeslip\nx_hi = freeslip\ny_lo = noslip\ny_hi = freeslip\n[fluid]\nnu = 0.05\nviscous = implicit\ndt = 0.02\n[ibm]\ngravity = 0 -1 0\nsphere1 = free center 1 1.0 0 diameter 1 density 4\n[time]\nt_end = 5\n'
printf "$settle" >$T/settle.ini
timeout 300 $BIN run $T/settle.ini --out $T/osettle >$T/settle.out 2>&1; rc=$?
[ $rc = 1 ] && grep -q "^error: the run stopped at step [0-9]* (t = .*): ibm: free sphere 1 touched the y_lo wall" $T/settle.out &&
    $PY -c "import json,sys; d=json.load(open('$T/osettle/summary.json')); sys.exit(d['status']!='halted' or d['time']>=5)"
report $? "a free sphere reaching the bottom wall stops the run there (status $rc, want 1; summary status halted)"
# the same for a particle of a coupled scene settling onto a face with no DEM wall
printf "$coupled" | sed 's/velocity 1e200 0 0//; s/center 2 6 2/center 2 0.8 2/; s/^faces = y_lo$/faces = x_lo/' >$T/unwalled.ini
timeout 300 $BIN run $T/unwalled.ini --out $T/ounwalled >$T/unwalled.out 2>&1; rc=$?
[ $rc = 1 ] && grep -q "^error: the run stopped at step [0-9]* .*coupling: particle 1 touched the y_lo face of the fluid's domain, which has no DEM wall" $T/unwalled.out
report $? "a coupled particle reaching a face without a DEM wall stops the run there (status $rc, want 1)"
tap_end $T
