#!/bin/bash
# Install the Debian packages ibmdem needs, only those that are missing.
# DEPS_PKGS replaces the list (bench/deps_bench.sh: the codes the benchmarks compare with).
set -e
PKGS=${DEPS_PKGS:-"make gcc g++ pkg-config libopenmpi-dev openmpi-bin libfftw3-dev libfftw3-mpi-dev libhdf5-openmpi-dev
      hdf5-tools libgsl-dev libcmocka-dev libqhull-dev libcgal-dev libsuitesparse-dev libopenblas0-serial
      python3-numpy python3-matplotlib python3-h5py"}
missing=""
for p in $PKGS; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "deps: installing$missing"
SUDO=""; [ "$(id -u)" != 0 ] && SUDO=sudo
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
