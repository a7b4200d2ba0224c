#!/bin/bash
# make demo:
#  1. the lid-driven cavity at Re = 100 on 2 ranks, run to a steady state, then the centreline
#     velocities against Ghia et al. (1982) and a map of the velocity magnitude in a PNG
#     (postproc/plot_cavity.py), ~20 s;
#  2. the bouncing sphere of Izard (2014) Fig. 3.3 (cases/bouncing_sphere/bounce_axi.ini:
#     axisymmetric, D/dx = 20, rho_p/rho = 8, Ar = 3700, lubrication eta_e/R = 4e-4) on one
#     rank until the rebound is measured (~40 s), then its velocity history and restitution
#     point against the seed's model in bounce.png and the numbers in bounce.json
#     (postproc/plot_bounce.py).
set -e
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
OUT=${OUT:-$BUILD/demo}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
rm -rf "$OUT/cavity" "$OUT/bounce"
echo "demo 1/2: lid-driven cavity, Re = 100, 64 x 64, 2 ranks -> $OUT/cavity"
mpirun --allow-run-as-root --oversubscribe -np 2 "$BUILD/ibmdem" run cases/cavity/cavity.ini --out "$OUT/cavity"
/usr/bin/python3 postproc/plot_cavity.py "$OUT/cavity" "$OUT/cavity/cavity.png"
echo "demo 2/2: sphere bouncing on a wall (Izard 2014 Fig. 3.3), axisymmetric 80 x 880, 1 rank -> $OUT/bounce"
"$BUILD/ibmdem" run cases/bouncing_sphere/bounce_axi.ini --out "$OUT/bounce" --set coupling.stop_after_rebound=true
/usr/bin/python3 postproc/plot_bounce.py "$OUT/bounce" "$OUT/bounce/bounce.png" "$OUT/bounce/bounce.json"
echo "demo: outputs in $OUT/cavity (fields.xmf opens in ParaView; cavity.png) and $OUT/bounce (series.csv, summary.json, bounce.png, bounce.json)"
