# tap.sh — sourced by the shell tests: MPI environment, the binary, TAP reporting.
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
BIN=$PWD/$BUILD/ibmdem
PY=/usr/bin/python3
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
n=0; failed=0
# report STATUS NAME: one TAP line, ok when STATUS is 0
report() {
    n=$((n + 1))
    if [ "$1" = 0 ]; then echo "ok $n - $2"; else echo "not ok $n - $2"; failed=$((failed + 1)); fi
}
# tap_end TMPDIR: the plan line; keep TMPDIR when something failed
tap_end() {
    [ "$failed" = 0 ] && rm -rf "$1"
    echo "1..$n"
    exit $((failed > 0))
}
