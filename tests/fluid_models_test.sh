#!/bin/bash
# fluid_models_test.sh — the fluid model named by one key, [coupling] fluid (fluid_model.h):
#  1. the dry switch: every shipped case with particles and a fluid (resolved or pore network,
#     found in cases/) runs with --set coupling.fluid=off, as the DEM alone (no fluid, immersed-boundary or
#     pore-network part in summary.json), and its log names the model and notes the keys of
#     the other sections as not used;
#  2. a case without particles has nothing to simulate dry: exit 2, and the message names the
#     key and the sections (not a missing [fluid]);
#  3. the same scene under each model of a case that has sections of several: a [fluid] and a
#     [porenet] section without coupling.fluid is refused (file:line: coupling.fluid: ...), and
#     each named model runs its own parts;
#  4. coupling.fluid = drag on the bouncing sphere (its [fluid] gives rho and nu): the sphere
#     falls at the closure's terminal velocity (Stokes, with the immersed weight) before the
#     wall; coupling.fluid = none leaves the lubrication out ([lubrication] noted unused);
#  5. [fluid] viscous = auto reports its choice in the log and summary.json.
# Prints TAP lines; ~10 s.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_fluid_models.XXXXXX)
Q="--set output.progress=off"

# 1. the dry switch, on every shipped case with particles ([particles] with a source) and a fluid
# ([fluid] or [porenet])
coupled=$(for f in cases/*/*.ini; do
    awk '/^\[/ { sec = $1 } sec == "[particles]" && $1 == "source" && $3 != "none" { p = 1 }
         $1 == "[fluid]" || $1 == "[porenet]" { fl = 1 } END { exit !(p && fl) }' "$f" && echo "${f#cases/}"
done | sed 's/\.ini$//')
[ "$(echo $coupled | wc -w)" -ge 9 ]
report $? "the shipped coupled cases: $(echo $coupled | wc -w) ($(echo $coupled | tr '\n' ' '))"
for c in $coupled; do
    nm=$(echo $c | tr / _)
    $BIN run cases/$c.ini $Q --set coupling.fluid=off --set time.max_steps=20 --set packing.max_time=0.002 --out $T/$nm >$T/$nm.log 2>&1
    rc=$?
    parts=$($PY -c "import json; print(' '.join(k for k in ('fluid', 'ibm', 'porenet') if k in json.load(open('$T/$nm/summary.json'))))" 2>/dev/null)
    grep -q "^fluid model: .*coupling.fluid = off" $T/$nm.log && grep -q "^note: .* not used by this run" $T/$nm.log &&
        [ $rc = 0 ] && [ -z "$parts" ]
    report $? "$c runs dry with --set coupling.fluid=off (the DEM alone; fluid parts: '${parts}'; log notes the unused keys)"
done

# 2. nothing to simulate dry
out=$($BIN check cases/settling_sphere/settling_axi.ini --set coupling.fluid=off 2>&1); rc=$?
echo "$out" | grep -q "nothing to simulate with coupling.fluid = off: the case has no \[particles\] (its \[fluid\] and \[ibm\]" &&
    [ $rc = 2 ]
report $? "a fluid case without particles has nothing to simulate dry (exit $rc): $(echo "$out" | head -1 | cut -c1-80)"

# 3. a scene with sections of two models
sed -e 's/^\[porenet\]/[fluid]\nnu = 0.001\nrho = 1000\n\n[porenet]/' cases/porenet_deposition/coarse.ini >$T/two.ini
out=$($BIN check $T/two.ini 2>&1); rc=$?
echo "$out" | grep -Eq "^$T/two.ini: coupling.fluid: the case has a \[fluid\] and a \[porenet\] section: name its fluid model" &&
    [ $rc = 2 ]
report $? "[fluid] and [porenet] without coupling.fluid: refused, exit $rc"
ok=0
for m in porenet none drag; do
    $BIN run $T/two.ini $Q --set coupling.fluid=$m --set time.max_steps=5 --out $T/two_$m >$T/two_$m.log 2>&1 || ok=1
done
$PY - $T <<'PY' || ok=1
import json, sys
t = sys.argv[1]
p = json.load(open(t + "/two_porenet/summary.json")); n = json.load(open(t + "/two_none/summary.json"))
d = json.load(open(t + "/two_drag/summary.json"))
sys.exit(0 if "porenet" in p and "porenet" not in n and "porenet" not in d and "fluid" not in d else 1)
PY
grep -q "\[fluid\] nu, rho" $T/two_porenet.log && grep -q "\[porenet\]" $T/two_drag.log || ok=1
report $ok "each named model runs its own parts; the other sections are noted unused"

# 4. drag on the bouncing sphere: the settling of the closure (Stokes: the case's Re_p ~ 60 is far from
# it; this checks the keys and the driver), stopped before the wall
$BIN run cases/bouncing_sphere/bounce_axi.ini $Q --set coupling.fluid=drag --set time.t_end=8 --out $T/drag >$T/drag.log 2>&1
rc=$?
$PY - $T/drag/series.csv <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
# rho_p/rho 8, nu 0.0434959 (rho = 1, D = 1, g = 1): v_t = (8 - 1) g D^2 / (18 nu) = 8.941
vt = 7.0 / (18 * 0.0434959)
# from rest: v_t (1 - e^(-t/tau)), tau = 8/(18 nu) = 10.2; by t = 8 the sphere has fallen 22 of its 39.5 D
m = 8 * 3.141592653589793 / 6
ke = float(rows[-1]["dem_kinetic_energy"])
v = (2 * ke / m) ** 0.5
import math
tau = 8 / (18 * 0.0434959)
t = float(rows[-1]["time"])
exact = vt * (1 - math.exp(-t / tau))
print(f"# drag: speed at t = {t:g}: {v:.5f} (closure {exact:.5f}, rel. {abs(v - exact) / exact:.1e})")
# the synced velocity carries half a step of gravity without its drag (drag.c): within g dt_DEM / v ~ 1e-5,
# and the first order of the implicit relaxation, dt/tau ~ 5e-6
sys.exit(0 if abs(v - exact) / exact < 1e-4 else 1)
PY
report $? "coupling.fluid = drag: the closure's settling velocity from the [fluid] section's rho and nu"
$BIN run cases/bouncing_sphere/bounce_axi.ini $Q --set coupling.fluid=none --set time.max_steps=5 --out $T/none >$T/none.log 2>&1 &&
    grep -q "^fluid model: none (the DEM alone)" $T/none.log && grep -q "\[lubrication\] model, roughness, range" $T/none.log
report $? "coupling.fluid = none: the DEM alone, [lubrication] noted unused"

# 5. viscous = auto in the log and summary.json
$BIN run cases/taylor_green/taylor_green.ini $Q --set time.max_steps=3 --out $T/tg >$T/tg.log 2>&1 &&
    grep -q "^fluid: viscous = auto: explicit viscous term from step 1" $T/tg.log &&
    $PY -c "import json, sys; f = json.load(open('$T/tg/summary.json'))['fluid']; sys.exit(0 if f['viscous'] == 'auto' and f['implicit_steps'] == 0 else 1)"
report $? "viscous = auto: the choice in the log and summary.json (taylor_green: explicit)"
tap_end "$T"
