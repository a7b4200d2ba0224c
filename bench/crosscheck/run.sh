#!/bin/bash
# make crosscheck: ibmdem against OpenFOAM on the simple cubic array of spheres
# (bench/crosscheck/crosscheck.py says how both cases are built from one geometry).
# Installs OpenFOAM from Debian when simpleFoam is missing (an optional dependency: make test
# never needs it).  Every run is serial (one core) and keeps its result.json under $OUT/CASE/:
# a second call only runs what is missing (remove $OUT to start again).  Writes $OUT/table.md,
# $OUT/table.json and $OUT/speed_error.png (CPU seconds against |error of K|, both codes).
#
#   CASES="sc064_stokes sc064_re10"   the cases, in this order (default: all five: sc064_stokes,
#                                     sc064_re10, sc064_re50, sc216_stokes, sc343_stokes)
#                                     also the random bed: bed30_stokes, bed30_re20, and the
#                                     sphere in a duct: duct_re20, duct_re100, duct_re250, and the
#                                     sphere oscillating in a box: osc_sphere, osc_sphere_dt2,
#                                     osc_sphere_small (not in the default; bench/crosscheck/README.md)
#   METHODS="calibrated none"         ibmdem's methods (also: gaps, narrow; common.IBM_METHODS)
#   BUILD (default build), OUT (default $BUILD/crosscheck)
# Cost: 25 min of CPU (43 min wall on the shared 2-core machine) for the five cases, 9 min of CPU
# (11 min wall) for sc064_stokes alone.
set -e
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
OUT=${OUT:-$BUILD/crosscheck}
CASES=${CASES:-"sc064_stokes sc064_re10 sc064_re50 sc216_stokes sc343_stokes"}
METHODS=${METHODS:-"calibrated none"}
if ! command -v simpleFoam >/dev/null || ! command -v snappyHexMesh >/dev/null; then
    echo "crosscheck: OpenFOAM is missing, installing the Debian package openfoam"
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y openfoam
fi
mkdir -p "$OUT"
for c in $CASES; do
    echo "=== $c"
    BUILD=$BUILD /usr/bin/python3 bench/crosscheck/crosscheck.py run "$c" "$OUT" --methods "${METHODS// /,}"
done
/usr/bin/python3 bench/crosscheck/crosscheck.py report "$OUT"
echo "crosscheck: $OUT/table.md, $OUT/speed_error.png"
