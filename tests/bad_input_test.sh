#!/bin/bash
# bad_input_test.sh — every kind of bad input stops the run before it starts
# with the exit status 2 and a message `file:line: section.key: reason`
# (no line when the key is absent or given by --set); a diverging run stops
# with status 3, a message and a checkpoint that --restart accepts.
# Prints TAP lines (ok N - ... / not ok N - ...).
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_bad_input.XXXXXX)

# The base case: a small lid-driven cavity.  Line numbers matter below.
base() {
cat <<'INI'
[domain]
geometry = 2d
nx = 8
ny = 8
length = 1 1 1
[boundary]
x_lo = noslip
x_hi = noslip
y_lo = noslip
y_hi = noslip
y_hi_velocity = 1 0 0
[fluid]
nu = 0.01
[time]
t_end = 0.1
INI
}
# line numbers of the base case:  nx 3, x_lo 7, x_hi 8, nu 13, [time] 14

# check NAME STATUS REGEX -- COMMAND...: run, then assert status and stderr
check() {
    local name=$1 want=$2 regex=$3; shift 4
    "$@" >"$T/out" 2>"$T/err"
    local rc=$?
    if [ "$rc" = "$want" ] && { [ -z "$regex" ] || grep -Eq -- "$regex" "$T/err"; }; then
        report 0 "$name"
    else
        report 1 "$name (status $rc, want $want; stderr below, want /$regex/)"
        sed 's/^/#   /' "$T/err" | head -5
    fi
}

# edit the base case: sed expression -> $T/NAME.ini
mk() { base | sed "$2" >"$T/$1.ini"; echo "$T/$1.ini"; }

f=$(mk ok 's/^//')
check "the base case is valid" 0 "" -- $BIN check "$f"

f=$(mk unknown_key 's/^nu = 0.01$/nuu = 0.01/')
check "unknown key" 2 "^$f:13: fluid.nuu: unknown key$" -- $BIN check "$f"

f=$(mk unknown_section 's/^\[time\]$/[times]/')
check "unknown section" 2 "^$f:15: \[times\]: unknown section$" -- $BIN check "$f"

f=$(mk missing_key '/^ny = /d')
check "missing required key" 2 "^$f: domain.ny: missing key" -- $BIN check "$f"

f=$(mk wrong_type 's/^nx = 8$/nx = eight/')
check "wrong type" 2 "^$f:3: domain.nx: 'eight' is not an integer$" -- $BIN check "$f"

f=$(mk out_of_range 's/^nu = 0.01$/nu = 0.01\ncfl = 5/')
check "out-of-range value" 2 "^$f:14: fluid.cfl: 5 is out of range \[1e-06, 1.7\]$" -- $BIN check "$f"

f=$(mk periodic_one_face '/^x_hi = /d')
check "periodic on one face only" 2 "^$f:7: boundary.x_lo: periodic on one x face only" -- $BIN check "$f"

f=$(mk negative_viscosity 's/^nu = 0.01$/nu = -0.01/')
check "negative viscosity" 2 "^$f:13: fluid.nu: -0.01 is out of range" -- $BIN check "$f"

f=$(mk odd_nx 's/^nx = 8$/nx = 9/')
check "grid not dividing among 2 ranks (mpirun -np 2, nx = 9)" 2 \
    "^$f:3: domain.nx: 9 cells do not divide among 2 ranks" -- $MPIRUN -np 2 $BIN check "$f"

f=$(mk syntax 's/^\[fluid\]$/[fluid]\nthis line is not ini/')
check "syntax error" 2 "^$f:13: syntax error" -- $BIN check "$f"

f=$T/ok.ini
check "bad --set (no section.key=value)" 2 "^--set nu: expected section.key=value$" -- $BIN check "$f" --set nu
check "bad --set (wrong type)" 2 "^--set fluid.nu: 'abc' is not a real number$" -- $BIN check "$f" --set fluid.nu=abc
check "bad --set (unknown key)" 2 "^--set fluid.eta: unknown key$" -- $BIN check "$f" --set fluid.eta=1

check "unreadable file" 2 "^$T/nope.ini: cannot open: No such file or directory$" -- $BIN check "$T/nope.ini"
cp "$f" "$T/noperm.ini"; chmod 000 "$T/noperm.ini"
if [ "$(id -u)" != 0 ]; then
    check "unreadable file (no permission)" 2 "^$T/noperm.ini: cannot open: Permission denied$" -- $BIN check "$T/noperm.ini"
fi
check "unknown option" 2 "unknown option '--frobnicate'" -- $BIN run "$f" --frobnicate
check "restart from a file that is not a checkpoint" 1 "$f: cannot open the checkpoint" -- \
    $BIN run "$f" --out "$T/o1" --restart "$f"

# The reader: lines of any length, every byte of the file read as written.
long=$(printf '%0300d' 0)
# a folder of 301 bytes in two names (a name is at most NAME_MAX = 255 bytes); lps: for sed
lp=$(printf '%0150d/%0149d' 0 0); lps=${lp//\//\\/}
f=$(mk long_comment "\$a; $long cfl = 5")
check "a 300-byte comment line hides no key" 0 "" -- $BIN check "$f"
f=$(mk long_value "s/^\\[time\\]\$/[output]\\ndir = n$lps\\n[time]/")
check "a 300-byte value is read whole" 0 "" -- $BIN check "$f"
grep -q "^dir = n$lp\$" "$T/out"
report $? "the resolved input holds the whole 301-byte value"
f=$(mk long_value_line "s/^\\[time\\]\$/[output]\\ndir = n$lps\\nnam = x\\n[time]/")
check "an error after a long line has its own line number" 2 "^$f:16: output.nam: unknown key\$" -- $BIN check "$f"
f=$(mk hex 's/^t_end = 0.1$/t_end = 0x10/')
check "a hexadecimal number is refused" 2 "^$f:15: time.t_end: '0x10' is not a real number" -- $BIN check "$f"
f=$(mk hex_vec 's/^length = 1 1 1$/length = 0x1 1 1/')
check "a hexadecimal component is refused" 2 "^$f:5: domain.length: '0x1 1 1' is not three real numbers" -- $BIN check "$f"
f=$(mk nan 's/^t_end = 0.1$/t_end = nan/')
check "nan is refused" 2 "^$f:15: time.t_end: 'nan' is not a real number" -- $BIN check "$f"
f=$(mk latin1 "s/^\\[time\\]\$/[output]\\nname = caf\\xe9\\n[time]/")
check "a name that is not UTF-8 is refused" 2 "^$f:15: column 11: byte 0xE9 is not UTF-8 text" -- $BIN check "$f"
check "/dev/zero is not a case file (and check returns)" 2 "^/dev/zero:1: column 1: a NUL byte" -- \
    timeout 20 $BIN check /dev/zero
check "a folder is not a case file" 2 "^$T: cannot open: Is a directory\$" -- $BIN check "$T"
f=$(mk bracket 's/^\[time\]$/[time/')
check "a header without its ]" 2 "^$f:14: syntax error: '\\[' without '\\]'" -- $BIN check "$f"
grep -q "unknown" "$T/err"
[ $? = 1 ]; report $? "the keys under that header are not reported as unknown"
f=$(mk indented 's/^nu = 0.01$/nu = 0.01\n  cfl = 0.5/')
check "an indented key" 2 "^$f:14: an indented line" -- $BIN check "$f"
f=$(mk before_section '1s/^/nu = 1\n/')
check "a key before the first section" 2 "^$f:1: nu: a key before the first \\[section\\] header" -- $BIN check "$f"
f=$T/ok.ini
check "a 600-byte --set value is read whole" 0 "" -- $BIN check "$f" --set "output.dir=n$lp/$lp"
grep -q "^dir = n$lp/$lp ; --set\$" "$T/out"
report $? "the resolved input holds the whole --set value"
check "a name longer than 255 bytes is refused" 2 "^--set output.name: longer than 255 bytes" -- \
    $BIN run "$f" --set "output.name=n$long" --out "$T/o_name"
deep=$(printf "$T/%0200d/%0200d/%0200d" 1 2 3)
# (only input.ini, written first, is looked at: the files after it are the output's own tests)
(timeout 120 $BIN run "$f" --set time.max_steps=1 --out "$deep" >/dev/null 2>&1; true) 2>/dev/null
grep -q "^dir = $deep ; --set\$" "$deep/input.ini"
report $? "--out of 600 bytes makes that folder (its input.ini holds the whole path)"
check "an output folder longer than the path limit is refused" 2 "^--set output.dir: the path is longer than 4095 bytes" -- \
    $BIN run "$f" --out "$T/$(printf '%04200d' 0)"

# A diverging run: a fixed time step 16 times the convective limit of the lid
# (CFL = U dt / dx = 1 x 0.5 x 8 = 4 at the first step, above the hard limit
# 1.5) must stop with status 3 and a checkpoint of the state it started from.
out=$T/diverge
check "a diverging run stops with a message" 3 \
    "^error: the run diverged at step 1 .*CFL = [0-9.]+ is above the hard limit 1.5 \(time.cfl_abort\)" -- \
    $BIN run "$f" --set fluid.dt=0.5 --set time.t_end=10 --out "$out"
[ -f "$out/checkpoint_00000000.h5" ] && grep -q "is saved in $out/checkpoint_00000000.h5" "$T/err" &&
    $PY -c "import json,sys; d=json.load(open('$out/summary.json')); sys.exit(d['status']!='diverged')"
report $? "the diverged run left checkpoint_00000000.h5 and summary.json status = diverged"
check "--restart accepts that checkpoint (with a stable dt)" 0 "fluid.dt: 0.5 in the checkpoint, 0.01 now" -- \
    $BIN run "$f" --set fluid.dt=0.01 --set time.max_steps=3 --out "$out" --restart "$out/checkpoint_00000000.h5"
grep -q "reached max_steps at step 3" "$T/out"
report $? "the restarted run advanced to step 3"

chmod 600 "$T/noperm.ini"
# particles from a file that do not fit the scene: bad input before anything is built
C=cases/column_collapse/coarse_loose.ini
l=$(grep -n '^file = ' $C | cut -d: -f1)
check "particles of a file: periodic length below twice the largest diameter" 2 \
    "^$C:$l: particles.file: .*needs a periodic length in y of at least twice its diameter" -- \
    $BIN check $C --set "domain.length=0.304 0.02 0.152"
check "particles of a file: a centre outside the domain" 2 "^$C:$l: particles.file: .*is outside the domain in x" -- \
    $BIN check $C --set "domain.length=0.1 0.03648 0.152" --set domain.nx=40 --set "walls.wall1_point=0.09 0 0" \
    --set "probes.point1=0.05 0.01 0.01" --set "probes.point2=0.05 0.01 0.01" --set "probes.point3=0.05 0.01 0.01" \
    --set "probes.point4=0.05 0.01 0.01" --set "probes.reference=0.05 0.01 0.1"

tap_end "$T"
