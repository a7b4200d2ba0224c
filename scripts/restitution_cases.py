#!/usr/bin/python3
"""Run list of the restitution sweep (issue 5): writes one shell script per run.

Wall runs: cases/bouncing_sphere/bounce_axi.ini (the seed's Fig. 3.3 set-up, units D = g = rho = 1)
with rho_p/rho and Ar chosen so that the Schiller-Naumann terminal velocity gives the target
St = (rho_p/rho + 1/2) Re_p / 9 (eq. 3.19); the measured St is what is plotted.
Binary runs: cases/binary_collision/binary_axi.ini (units D = U_o = rho = 1), nu chosen so that
St_B = (rho_p/rho) Re_rel / 9 (eq. 3.34) hits the target with the measured U_i/U_o.

Further arguments key=value override (or add) a case-file key in every run, after the run list's own
settings (e.g. lubrication.overlap=saturated); they are recorded in each run's meta.json.

usage: restitution_cases.py OUT full|coarse [key=value ...]
"""
import json
import math
import os
import shlex
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROUGHNESS = 2e-4          # eta_e/R of Table 3.2
# [ibm] forcing_time = kappa: the time-step independent forcing of docs/theory.md §6b instead of the
# seed's beta = alpha.  The sweep's fluid step varies 20-fold from run to run (dt ~ 1/V_T), and with
# beta = alpha the result depends on it: at D/dx = 10, rho_p/rho = 8, St ~ 40, a fluid step of 0.0195
# and 0.001 gives V_C/V_T = 0.81 and 0.20, eps/eps_max = 0.57 and 0.10 (the band of partly covered
# nodes grows more rigid as dt decreases and closes the gap early); at rho_p/rho = 32, St ~ 1 the
# terminal velocity is 0.909, 0.696, 0.603, 0.574 at dt = 0.075, 0.01, 0.002, 0.001.  With kappa = 0.2:
# V_C/V_T = 0.89 and 0.81, eps/eps_max = 0.65 and 0.71, the same V_T (2.09) at both steps.
FORCING_TIME = 0.2
# [coupling] align_contacts: a fluid step ends where a contact starts, so that the contact (t_c is
# 0.1-0.2 of the fluid step) lies inside one fluid step.  Without it, a fluid step that ends during
# the contact samples the reversed velocity, and the fluid's reaction to that reversal (computed in
# the next fluid step) brakes the released sphere before V_R is sampled: dry, rho_p/rho = 8,
# St 21.7: eps = 0.680 (split contact) against 0.890 aligned (docs/validation.md).
ALIGN_CONTACTS = "true"


def re_terminal(ar):
    """Schiller-Naumann: C_D Re^2 = 4/3 Ar with C_D = 24/Re (1 + 0.15 Re^0.687) (note §8)."""
    lo, hi = 1e-8, 1e5
    for _ in range(200):
        m = (lo + hi) / 2
        lo, hi = (lo, m) if 24 * m * (1 + 0.15 * m ** 0.687) > 4 / 3 * ar else (m, hi)
    return m


def wall_parameters(ratio, st):
    """Ar, nu and V_T (Schiller-Naumann, units D = g = rho = 1) for a target St."""
    re = 9 * st / (ratio + 0.5)
    ar = 18 * re * (1 + 0.15 * re ** 0.687)          # 3/4 C_D Re^2
    nu = math.sqrt((ratio - 1) / ar)
    return ar, nu, re * nu


def relaxation_distance(ratio, nu, vt, frac=0.98):
    """Fall from rest until u = frac V_T: (r + C_M) du/dt = (r - 1) - 3/4 C_D(Re) u^2, C_M = 1/2
    (quasi-steady drag and added mass, no history force: a lower bound of the real distance)."""
    u = x = 0.0
    dt = 1e-3 * min(1.0, vt)
    while u < frac * vt:
        re = max(u / nu, 1e-12)
        cd = 24 / re * (1 + 0.15 * re ** 0.687)
        u += ((ratio - 1) - 0.75 * cd * u * u) / (ratio + 0.5) * dt
        x += u * dt
    return x


def fluid_dt_max(n, nu, v):
    """Largest fluid step: a displacement of 0.05 D per step (the seed's dt sqrt(g/D) ~ 0.02 at
    V_T ~ 2.5 and D/dx = 10), and a viscous diffusion number nu dt/dx^2 <= 0.5 (with the
    Crank-Nicolson viscous term the forcing of FORCING_TIME still drifts by a few % above 1,
    docs/theory.md §6b)."""
    return min(0.1, 0.05 / v, 0.5 / (n * n * nu))


def wall_run(out, n, ratio, st, lub, launch_above=30.0):
    """One wall run at D/dx = n.  Release from rest at 1.25 x98 + 3 D above the wall (6 <= fall <= 36,
    36 D is the seed's fall); when the quasi-steady distance to 98 % of V_T exceeds `launch_above`,
    the sphere is launched at the Schiller-Naumann V_T from 30 D instead (the fall from rest to
    terminal velocity would need 50-120 D at St >= 120, rho_p/rho = 32)."""
    ar, nu, vt = wall_parameters(ratio, st)
    x98 = relaxation_distance(ratio, nu, vt)
    launch = x98 > launch_above
    fall = 30.0 if launch else min(36.0, max(6.0, math.ceil(1.25 * x98 + 3)))
    y0 = fall + 0.5                    # centre; the wall is at y = 0
    length = math.ceil(y0 + 4)         # the seed: the sphere starts 4 D below the top
    v0 = vt if launch else 0.0
    name = f"wall_r{ratio:g}_St{st:g}_{lub}"
    d = os.path.join(out, name)
    p = f"center 0 {y0:g} 0 diameter 1 density {ratio:g}"
    if launch: p += f" velocity 0 {-v0:.6g} 0"
    sets = {
        "domain.nx": 4 * n, "domain.ny": length * n, "domain.x_uniform_cells": 5 * n // 2,
        "domain.length": f"10.4 {length} 1",
        "fluid.nu": f"{nu:.8g}",
        "fluid.dt_max": f"{fluid_dt_max(n, nu, vt):.6g}",
        "particles.particle1": p,
        "lubrication.model": lub, "lubrication.roughness": ROUGHNESS,
        "ibm.forcing_time": FORCING_TIME,
        "coupling.align_contacts": ALIGN_CONTACTS,
        "dem.max_overlap": 0.05,
        "time.t_end": f"{(fall + 2) / vt * 2 + 20 / vt:.4g}",
        "coupling.stop_after_rebound": "true",
        "output.series_every": 1, "output.progress": "off",
    }
    steps = ((fall + 3) / vt + 2) / float(sets["fluid.dt_max"])
    meta = dict(kind="wall", name=name, ratio=ratio, St_target=st, lubrication=lub, Ar=ar, nu=nu,
                V_SN=vt, fall=fall, launched=launch, d_over_dx=n, cost=steps * length * n)
    return name, d, os.path.join(ROOT, "cases/bouncing_sphere/bounce_axi.ini"), sets, meta


def binary_run(out, n, ratio, st_b, lub="brenner", ui_over_uo=0.90):
    """One binary run: nu such that St_B = ratio Re_rel / 9 with U_i ~ ui_over_uo U_o (U_o = 1; the
    impulsive start loses part of U_o to the added mass of the fluid)."""
    nu = ratio * ui_over_uo / (9 * st_b)
    name = f"binary_r{ratio:g}_StB{st_b:g}_{lub}"
    d = os.path.join(out, name)
    sets = {
        "domain.nx": 4 * n, "domain.ny": 44 * n, "domain.x_uniform_cells": 5 * n // 2,
        "fluid.nu": f"{nu:.8g}",
        "fluid.dt_max": f"{fluid_dt_max(n, nu, 1.0):.6g}",
        "time.t_end": 3.5 if st_b >= 20 else 6,
        "particles.particle1": f"center 0 22 0 diameter 1 density {ratio:g} velocity 0 -1 0",
        "particles.particle2": f"center 0 20 0 diameter 1 density {ratio:g}",
        "lubrication.model": lub,
        "ibm.forcing_time": FORCING_TIME,
        "coupling.align_contacts": ALIGN_CONTACTS,
        "coupling.stop_after_rebound": "true",
        "output.series_every": 1, "output.progress": "off",
    }
    meta = dict(kind="binary", name=name, ratio=ratio, St_target=st_b, lubrication=lub, nu=nu, d_over_dx=n,
                cost=sets["time.t_end"] / float(sets["fluid.dt_max"]) * 44 * n * 1.5)
    return name, d, os.path.join(ROOT, "cases/binary_collision/binary_axi.ini"), sets, meta


def runs(out, mode):
    r = []
    if mode == "full":
        n = 10
        # 12 targets per ratio, log-spaced from 1.15 (the measured St is ~7 % below the
        # Schiller-Naumann target at Re < 1) to Re_p ~ 270; rho_p/rho = 32 gets a 13th above 1000
        for ratio, st_hi in ((2.5, 100), (8, 280), (16, 540), (32, 900)):
            lo = math.log10(1.15)
            sts = [10 ** (lo + (math.log10(st_hi) - lo) * k / 11) for k in range(12)] + ([1100] if ratio == 32 else [])
            for st in sts:
                for lub in ("brenner", "none"):
                    r.append(wall_run(out, n, ratio, float(f"{st:.3g}"), lub))
        # the seed's Re ~ 100 series (Table 3.2, second-last row marked like the first): St ~ 700 and 1400
        for ratio, st in ((64, 717), (128, 1430)):
            for lub in ("brenner", "none"):
                r.append(wall_run(out, n, ratio, st, lub))
        for st_b in (7, 12, 20, 35, 60, 100, 135, 160):
            for lub in ("brenner", "none"):
                r.append(binary_run(out, 20, 8, st_b, lub))
        r.append(binary_run(out, 20, 2.3, 7))
        r.append(binary_run(out, 20, 90, 1352))
    elif mode == "coarse":
        n = 10
        r.append(wall_run(out, n, 8, 5, "brenner"))
        r.append(wall_run(out, n, 8, 55, "brenner"))
        r.append(wall_run(out, n, 8, 55, "none"))
        r.append(binary_run(out, 10, 8, 135))
    else:
        sys.exit(f"unknown mode {mode}")
    return r


def overrides(args):
    """key=value arguments as a dict (section.key = value, as for --set)."""
    sets = {}
    for a in args:
        key, eq, value = a.partition("=")
        if not eq or "." not in key:
            sys.exit(f"override {a!r}: expected section.key=value")
        sets[key.strip()] = value.strip()
    return sets


def main():
    out, mode = sys.argv[1], sys.argv[2]
    extra = overrides(sys.argv[3:])
    os.makedirs(os.path.join(out, "jobs"), exist_ok=True)
    exe = os.environ.get("IBMDEM", os.path.join(ROOT, "build/ibmdem"))
    listing = []
    total = 0.0
    for name, d, ini, sets, meta in sorted(runs(out, mode), key=lambda r: -r[4]["cost"]):
        total += meta["cost"]
        sets.update(extra)
        if extra: meta["overrides"] = extra
        os.makedirs(d, exist_ok=True)
        with open(os.path.join(d, "meta.json"), "w") as f: json.dump(meta, f, indent=1)
        cmd = [exe, "run", ini, "--out", d] + [a for k, v in sets.items() for a in ("--set", f"{k}={v}")]
        job = os.path.join(out, "jobs", name + ".sh")
        with open(job, "w") as f:
            # /usr/bin/time: the CPU seconds of the run (the wall time depends on the machine's load)
            f.write("#!/bin/bash\n/usr/bin/time -f '%U %S' -o " + shlex.quote(d) + ".time " +
                    " ".join(shlex.quote(str(c)) for c in cmd) + f" > {shlex.quote(d)}.log 2>&1\n"
                    f"echo \"$?\" > {shlex.quote(d)}.rc\n")
        listing.append(job)
    # longest first (by the estimated cell-steps) so that the cores stay busy until the end
    with open(os.path.join(out, "jobs.list"), "w") as f:
        f.write("\n".join(listing) + "\n")
    print(f"{len(listing)} runs, about {total:.3g} cell-row steps")


if __name__ == "__main__":
    main()
