#!/bin/bash
# Run every test program (tests/test_*.c) on the rank counts given by its
# "RANKS:" line, and every shell test (tests/*_test.sh).  Prints the cmocka
# reports and a closing line "tests: N passed, M failed".
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# ranks may share cores with other jobs: yield instead of busy-polling
export OMPI_MCA_mpi_yield_when_idle=1
# start-up: a run started without mpirun stays a singleton (no daemon), and the ranks talk
# through the ob1 layer (shared memory) instead of initialising UCX: 0.3 s against 0.9 s for
# a singleton's MPI_Init, 0.9 s against 1.2 s for mpirun -np 2 (the suite starts hundreds of runs)
export OMPI_MCA_ess_singleton_isolated=1 OMPI_MCA_pml=ob1
export BUILD
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
if [ "$BUILD" = build-san ]; then
    # Open MPI's dlopen'ed components leak at exit in frames LeakSanitizer
    # cannot name or suppress; leak checking is off, bounds/use-after-free
    # (ASan) and undefined behaviour (UBSan, fatal) stay on.
    export ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
    MPIRUN="$MPIRUN -x ASAN_OPTIONS -x UBSAN_OPTIONS"
fi
pass=0; fail=0; failed_names=""
log=$(mktemp)
filter="${TESTS:-}"
for src in tests/test_*.c; do
    name=$(basename "$src" .c)
    [ -n "$filter" ] && [[ ! "$name" =~ $filter ]] && continue
    ranks=$(grep -m1 -o 'RANKS:[ 0-9]*' "$src" | sed 's/RANKS://')
    [ -z "$ranks" ] && ranks=1
    for np in $ranks; do
        echo "=== $name (np=$np)"
        t0=$(date +%s.%N)
        timeout 900 $MPIRUN -np "$np" "$BUILD/tests/$name" >"$log" 2>&1
        rc=$?
        cat "$log"
        p=$(grep -o '\[  PASSED  \] [0-9]*' "$log" | awk '{s+=$NF} END {print s+0}')
        f=$(grep -o '\[  FAILED  \] [0-9]*' "$log" | awk '{s+=$NF} END {print s+0}')
        if [ "$rc" != 0 ] && [ "$f" = 0 ]; then f=1; echo "!!! $name (np=$np) exited with status $rc"; fi
        pass=$((pass + p)); fail=$((fail + f))
        [ "$f" != 0 ] && failed_names="$failed_names $name/np$np"
        awk -v a="$t0" -v b="$(date +%s.%N)" -v n="$name" -v p="$np" 'BEGIN{printf "=== %s (np=%s): %.1f s\n", n, p, b-a}'
    done
done
for sh in tests/*_test.sh; do
    [ -e "$sh" ] || continue
    name=$(basename "$sh" .sh)
    [ -n "$filter" ] && [[ ! "$name" =~ $filter ]] && continue
    echo "=== $name"
    t0=$(date +%s.%N)
    if timeout 900 bash "$sh" >"$log" 2>&1; then
        cat "$log"; p=$(grep -c '^ok ' "$log"); f=$(grep -c '^not ok ' "$log")
    else
        cat "$log"; p=$(grep -c '^ok ' "$log"); f=$(grep -c '^not ok ' "$log"); [ "$f" = 0 ] && f=1
    fi
    pass=$((pass + p)); fail=$((fail + f))
    [ "$f" != 0 ] && failed_names="$failed_names $name"
    awk -v a="$t0" -v b="$(date +%s.%N)" -v n="$name" 'BEGIN{printf "=== %s: %.1f s\n", n, b-a}'
done
rm -f "$log"
[ -n "$failed_names" ] && echo "failed:$failed_names"
echo "tests: $pass passed, $fail failed"
[ "$fail" = 0 ]
