#!/bin/bash
# fuzz_test.sh — the quick fuzz subset: mutants of every case file in cases/
# through `ibmdem check` and a few steps of `ibmdem run`, clean outcomes only
# (tests/fuzz.py; the long series is `make fuzz`, a section of make validate).
# The seed is fixed (17) so that a failure reproduces; FUZZ_SEED=N make test
# draws others, FUZZ_CHECKS / FUZZ_RUNS set the mutants per case file.  Then
# the harness itself is tested: a binary that dies of a signal in every run
# must be reported.  TAP lines, one per case file and one for the harness.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_fuzz_test.XXXXXX)
# Cases D and E of the column collapse are left out here: they have case A's keys (case.ini,
# fuzzed here) on grids that cannot be shrunk (their periodic width is 22 cells, the least the
# immersed band allows), so each mutant runs their whole 3.9 or 5.4 M-cell grid (case E's two
# steps: 11.6 s); `make fuzz` covers them.
$PY tests/fuzz.py --bin "$BIN" --seed "${FUZZ_SEED:-17}" --checks "${FUZZ_CHECKS:-1}" --runs "${FUZZ_RUNS:-1}" \
    --skip column_collapse/case_D.ini --skip column_collapse/case_E.ini --jobs 4 >$T/fuzz.out 2>&1
rc=$?
grep -v '^1\.\.' $T/fuzz.out
n=$(grep -c '^\(not \)\?ok ' $T/fuzz.out)
report $rc "fuzz.py exits 0 (status $rc)"
# the harness can fail: every run of this binary is killed by SIGSEGV
printf '#!/bin/bash\n[ "$1" = run ] && kill -SEGV $$\nexec %s "$@"\n' "$BIN" >$T/crashing
chmod +x $T/crashing
$PY tests/fuzz.py --bin $T/crashing --seed 17 --case cavity/cavity.ini --checks 0 --runs 1 --work $T/w >$T/crash.out 2>&1
rc=$?
[ $rc = 1 ] && grep -q '^not ok 1 - cases/cavity/cavity.ini' $T/crash.out && grep -q '^#   run mutant 0: status -11' $T/crash.out
report $? "a run killed by a signal is reported (fuzz.py status $rc, want 1)"
tap_end $T
