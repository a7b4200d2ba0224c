#!/bin/bash
# fuzz_test.sh — the quick fuzz subset: mutants of every case file in cases/
# through `ibmdem check` and a few steps of `ibmdem run`, clean outcomes only
# (tests/fuzz.py; the long series is a section of make validate).  The seed is
# fixed (17) so that a failure reproduces; FUZZ_SEED=N make test draws others.
# Prints TAP lines, one per case file.
. "$(dirname "$0")/tap.sh"
exec $PY tests/fuzz.py --bin "$BIN" --seed "${FUZZ_SEED:-17}" --checks "${FUZZ_CHECKS:-3}" --runs "${FUZZ_RUNS:-1}"
