#!/bin/bash
# The dry switch's cost: every shipped case with particles and a fluid (a
# [particles] section and a [fluid] or [porenet] one) run three ways, one
# after the other, the same number of steps (STEPS, default 20; the coupled
# run's steps are its own, fluid or DEM steps):
#   coupled   the case as shipped;
#   dry       --set coupling.fluid=off;
#   DEM       the case with its fluid sections removed ([fluid], [ibm],
#             [poisson], [porenet], [oedometer], [drag]) and the lubrication's
#             viscosity written out (the ρν the dry run takes from [fluid]):
#             the DEM alone as a user would write it.
# CPU time of each child process (the machine is shared), its DEM steps and
# peak memory from summary.json; dry/DEM is the switch's overhead (1: the dry
# run costs the DEM's).  Prints "RESULT dry_switch ..." lines and a table.
#
# Environment: BUILD (default build), WORK (default $BUILD/bench_dry_switch),
# STEPS, REPS (runs of the dry and DEM variants, the smallest CPU time kept;
# default 3).
set -e
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
WORK=${WORK:-$BUILD/bench_dry_switch}
mkdir -p "$WORK"
BIN=$BUILD/ibmdem STEPS=${STEPS:-20} REPS=${REPS:-3} WORK=$WORK /usr/bin/python3 - <<'PY'
import glob, json, os, re, resource, subprocess
B, W, steps, reps = os.environ["BIN"], os.environ["WORK"], int(os.environ["STEPS"]), int(os.environ["REPS"])

def sections(path):
    secs, cur = {}, None
    for line in open(path):
        m = re.match(r"\s*\[([a-z_0-9]+)\]", line)
        if m:
            cur = m.group(1)
            secs.setdefault(cur, {})
            continue
        m = re.match(r"\s*([a-z_0-9]+)\s*=\s*(.*?)\s*(#.*)?$", line)
        if m and cur:
            secs[cur][m.group(1)] = m.group(2)
    return secs

def strip(path, out):
    """the case without its fluid sections, the lubrication's viscosity written out"""
    s = sections(path)
    drop = {"fluid", "ibm", "poisson", "porenet", "oedometer", "drag"}
    lub = s.get("lubrication", {})
    if lub.get("model", "none") != "none" and float(lub.get("viscosity", "-1")) < 0 and "fluid" in s:
        f = s["fluid"]
        rho = float(f.get("rho", "1"))
        mu = float(f["mu"]) if "mu" in f else rho * float(f["nu"])
        lub["viscosity"] = repr(mu)
    with open(out, "w") as o:
        for sec, kv in s.items():
            if sec in drop:
                continue
            o.write("[%s]\n" % sec)
            for k, v in kv.items():
                if sec == "coupling" and k == "fluid":
                    continue
                o.write("%s = %s\n" % (k, v))
            o.write("\n")

def run(ini, tag, extra):
    out = os.path.join(W, tag)
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run([B, "run", ini, "--set", "output.progress=off", "--set", "time.max_steps=%d" % steps,
                        "--out", out] + extra, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise SystemExit("%s %s failed:\n%s" % (ini, tag, r.stdout[-2000:]))
    s = json.load(open(os.path.join(out, "summary.json")))
    cpu = (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)
    return cpu, s.get("dem", {}).get("dem_steps", 0), s.get("peak_rss_bytes_rank0", 0)

cases = []
for ini in sorted(glob.glob("cases/*/*.ini")):
    s = sections(ini)
    if "particles" in s and s["particles"].get("source", "none") != "none" and ("fluid" in s or "porenet" in s):
        cases.append(ini)
rows = []
for ini in cases:
    tag = ini[len("cases/"):-len(".ini")].replace("/", "_")
    dem_ini = os.path.join(W, tag + "_dem.ini")
    strip(ini, dem_ini)
    cpl = run(ini, tag + "_coupled", [])
    dry = min((run(ini, tag + "_dry", ["--set", "coupling.fluid=off"]) for _ in range(reps)), key=lambda t: t[0])
    dem = min((run(dem_ini, tag + "_dem", []) for _ in range(reps)), key=lambda t: t[0])
    print("RESULT dry_switch case= %s steps= %d coupled_cpu_s= %.4g coupled_dem_steps= %d coupled_rss_MB= %.1f "
          "dry_cpu_s= %.4g dry_dem_steps= %d dry_rss_MB= %.1f dem_cpu_s= %.4g dem_dem_steps= %d dem_rss_MB= %.1f "
          "dry_over_dem= %.3f" % (ini, steps, cpl[0], cpl[1], cpl[2] / 2**20, dry[0], dry[1], dry[2] / 2**20, dem[0],
                                  dem[1], dem[2] / 2**20, dry[0] / dem[0]), flush=True)
    rows.append((ini, cpl, dry, dem))
print("\n| case | coupled: CPU s (DEM steps, MB) | dry: CPU s (DEM steps, MB) | DEM alone: CPU s (DEM steps, MB) | dry / DEM |")
print("|---|---|---|---|---|")
for ini, c, d, e in rows:
    print("| `%s` | %.3g (%d, %.0f) | %.3g (%d, %.0f) | %.3g (%d, %.0f) | %.2f |"
          % (ini, c[0], c[1], c[2] / 2**20, d[0], d[1], d[2] / 2**20, e[0], e[1], e[2] / 2**20, d[0] / e[0]))
PY
