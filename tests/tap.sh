# tap.sh — sourced by the shell tests: MPI environment, the binary, TAP reporting.
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
BIN=$PWD/$BUILD/ibmdem
PY=/usr/bin/python3
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# start-up: a run started without mpirun stays a singleton (no daemon), and the ranks talk
# through the ob1 layer (shared memory) instead of initialising UCX: 0.3 s against 0.9 s for
# a singleton's MPI_Init, 0.9 s against 1.2 s for mpirun -np 2 (the suite starts hundreds of runs)
export OMPI_MCA_ess_singleton_isolated=1 OMPI_MCA_pml=ob1
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
n=0; failed=0
# report STATUS NAME: one TAP line, ok when STATUS is 0
report() {
    n=$((n + 1))
    if [ "$1" = 0 ]; then echo "ok $n - $2"; else echo "not ok $n - $2"; failed=$((failed + 1)); fi
}
# side_start ID COMMAND...: run a check in the background, beside the next one (the tests run
# one after the other and the CI machine has two cores); its output and status are kept in $T
side_start() {
    local id=$1; shift
    ("$@") >"$T/.side_$id.out" 2>&1 &
    eval "side_pid_$id=$!"
}
# side_report ID NAME: wait for check ID, print its output and one TAP line
side_report() {
    local pid rc
    eval "pid=\$side_pid_$1"
    wait "$pid"; rc=$?
    cat "$T/.side_$1.out"
    report $rc "$2"
}
# tap_end TMPDIR: the plan line; keep TMPDIR when something failed
tap_end() {
    [ "$failed" = 0 ] && rm -rf "$1"
    echo "1..$n"
    exit $((failed > 0))
}
