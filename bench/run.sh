#!/bin/bash
# Run every benchmark program present ($BUILD/bench/bench_*) on 1 and 2
# ranks and print its report.  Builds nothing (`make bench` builds first).
# Extra arguments are passed to every program (e.g. a grid size: 64).
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
status=0
for prog in "$BUILD"/bench/bench_*; do
    [ -x "$prog" ] || continue
    for np in 1 2; do
        echo "=== $(basename "$prog") (np=$np)"
        $MPIRUN -np "$np" "$prog" "$@" || { echo "!!! $(basename "$prog") (np=$np) failed"; status=1; }
    done
done
exit $status
