#!/bin/bash
# DEM section of make validate: the full-size dry granular cases (the coarse
# versions are in make test, tests/test_dem_cases.c).  Prints the measured
# numbers; exits non-zero if a check fails.  Called by scripts/validate.sh (or
# alone: BUILD=build OUT=build/validate bash scripts/validate_dem.sh).
#
#  - column collapse (cases/dem_column_collapse/case.ini, ~2000 grains, a ≈ 1,
#    seed parameters): runs to rest; run-out within 30 % of the law of
#    Lajeunesse et al. (2005), (R∞ − R0)/R0 = 1.2 a (their scatter and the
#    friction μ_c = 1 of the seed set the band);
#  - rough inclined plane (cases/dem_inclined_plane/case.ini, 3300 grains,
#    θ = 24°): steady (mean velocity of the two halves of 3–4 s within 5 %),
#    Bagnold profile fitted within 10 % (L2) and better than a straight line.
# About 15 min on 2 cores.
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
OUT=${OUT:-$BUILD/validate}
PY=/usr/bin/python3
mkdir -p "$OUT"
failed=""
section() { echo; echo "=== validate: $1"; }
fail() { echo "FAILED: $1"; failed="$failed $1"; }

section "dem: dry column collapse, ~2000 grains, a = 1"
d=$OUT/dem_column
rm -rf "$d"
if $MPIRUN -np 1 "$BUILD/ibmdem" run cases/dem_column_collapse/case.ini --out "$d" &&
   $PY postproc/dem_column.py "$d" 0.12 "$d/column.png"; then
    $PY - "$d" <<'EOF' || fail "dem column collapse"
import json, sys
r = json.load(open(sys.argv[1] + "/column.json"))
s = json.load(open(sys.argv[1] + "/summary.json"))
ok = s["status"] == "steady" and abs(r["runout"] / r["lajeunesse"] - 1) < 0.3
print("column: status %s, run-out %.3f vs 1.2 a = %.3f (%+.1f %%)" % (s["status"], r["runout"], r["lajeunesse"],
      100 * (r["runout"] / r["lajeunesse"] - 1)))
sys.exit(0 if ok else 1)
EOF
else
    fail "dem column collapse run"
fi

section "dem: dry flow on a rough inclined plane, 3300 grains, 24 deg"
d=$OUT/dem_incline
rm -rf "$d"
if $MPIRUN -np 1 "$BUILD/ibmdem" run cases/dem_inclined_plane/case.ini --out "$d" &&
   $PY postproc/dem_incline.py "$d" 3 4 0.005 "$d/incline.png"; then
    $PY - "$d" <<'EOF' || fail "dem inclined plane"
import json, sys
r = json.load(open(sys.argv[1] + "/incline.json"))
ok = abs(r["flux_change"]) < 0.05 and r["bagnold_misfit"] < 0.10 and r["bagnold_misfit"] < r["linear_misfit"]
sys.exit(0 if ok else 1)
EOF
else
    fail "dem inclined plane run"
fi

[ -z "$failed" ] && echo "validate dem: all passed" || { echo "validate dem: FAILED:$failed"; exit 1; }
