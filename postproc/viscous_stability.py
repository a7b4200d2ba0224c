#!/usr/bin/python3
"""viscous_stability.py OUT — the table of scripts/viscous_stability.sh (OUT/map.md, also printed).

For each run: its status (t_end reached, or where it diverged), steps, the fluid step (median and
largest), the largest viscous number dt nu/dx^2 (dx the smallest cell), for coupled runs the
largest dt/tau_S (tau_S = (rho_p + rho/2) D^2/(18 eta), the Stokes relaxation time of the
particles' mean diameter) and the largest overlap (% of the smaller diameter), the step-to-step
oscillation of the particles' kinetic energy (mean of |E_n - (E_n-1 + E_n+1)/2| / E_n over the
second half of the run; 0 for a smooth run), and its result: the squeeze flow's drag over
Brenner's at gaps of 1.5, 1, 0.5 and 0.25 D, the settling velocity (free sphere, one grain), or
the particles' mean kinetic energy over a window against the reference run."""
import configparser
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from squeeze_drag import ratios  # noqa: E402

OUT = sys.argv[1]


def cfg_of(run):
    c = configparser.ConfigParser(inline_comment_prefixes=(";", "#"), strict=False)
    c.read(f"{OUT}/{run}/input.ini")
    return c


def num(c, sec, key, default=None):
    try:
        return float(c[sec][key].split()[0])
    except KeyError:
        return default


def status(run):
    if not os.path.exists(f"{OUT}/{run}.rc"):
        return "not run"
    log = open(f"{OUT}/{run}.log").read()
    m = re.search(r"diverged at step (\d+) \(t = ([0-9.e+-]+)", log)
    if m:
        return f"diverged at step {m.group(1)} (t = {float(m.group(2)):.4g})"
    m = re.search(r"reached t_end at step (\d+)", log)
    return "ran" if m else "failed"


def series(run):
    return np.genfromtxt(f"{OUT}/{run}/series.csv", delimiter=",", names=True)


def hmin(c):
    L = [float(x) for x in c["domain"]["length"].split()]
    n = [int(num(c, "domain", k, 1)) for k in ("nx", "ny", "nz")]
    h = [L[i] / n[i] for i in range(3) if n[i] > 1]
    if c["domain"].get("x_stretch", "uniform").split()[0] == "uniform_arithmetic":
        h.append(num(c, "domain", "x_uniform_length") / num(c, "domain", "x_uniform_cells"))
    return min(h)


def jag(y):
    y = y[len(y) // 2:]
    if len(y) < 4 or not np.all(np.isfinite(y)) or y.max() <= 0:
        return float("nan")
    j = np.abs(y[1:-1] - 0.5 * (y[:-2] + y[2:])) / np.maximum(y[1:-1], 1e-300)
    return j.mean()


def mean_ke(d, t0, t1):
    w = (d["time"] > t0) & (d["time"] <= t1)
    return d["dem_kinetic_energy"][w].mean()


runs = [line.split("|")[0] for line in open(f"{OUT}/runs.list")]
rows = []
for run in runs:
    if not os.path.exists(f"{OUT}/{run}.rc") or not os.path.exists(f"{OUT}/{run}/series.csv"):
        rows.append((run, status(run), "", "", "", "", "", "", "", ""))
        continue
    c, d = cfg_of(run), series(run)
    dt = d["dt"][1:]
    nu = num(c, "fluid", "nu")
    vn = dt.max() * nu / hmin(c) ** 2
    taus, ov, jg, res = "", "", "", ""
    if "particles" in c:
        rho, rp = num(c, "fluid", "rho", 1.0), num(c, "particles", "density", None)
        r = num(c, "particles", "radius", None)
        if r is None or rp is None:  # a list of particles: the first one's
            p1 = c["particles"]["particle1"]
            r = 0.5 * float(p1.split("diameter")[1].split()[0])
            rp = float(p1.split("density")[1].split()[0])
        tau = (rp + 0.5 * rho) * (2 * r) ** 2 / (18 * rho * nu)
        taus = f"{dt.max() / tau:.2g}"
        ov = f"{100 * d['dem_max_overlap'].max():.3f}"
        jg = f"{jag(d['dem_kinetic_energy']):.3f}"
    if run.startswith("sq_"):
        res = " ".join(f"{v:.3f}" for g, v in sorted(ratios(f"{OUT}/{run}").items(), reverse=True))
    elif run.startswith("free_"):
        res = f"V = {abs(d['s1_v'][-1]):.5f}"
    elif run.startswith("single_"):
        ref = series("single_ref")["s1_w"][-1]
        res = f"w = {d['s1_w'][-1]:.5f} m/s ({d['s1_w'][-1] / ref - 1:+.2%} of ref), max |w| {abs(d['s1_w']).max():.4f}"
    elif run.startswith("settle_") and os.path.exists(f"{OUT}/settle_ref/series.csv"):
        ref = series("settle_ref")
        res = f"E(0.05-0.3 s) / ref = {mean_ke(d, 0.05, 0.3) / mean_ke(ref, 0.05, 0.3):.3f}"
    elif "particles" in c:
        res = f"E end {d['dem_kinetic_energy'][-1]:.3g} J, {int(d['dem_contacts'][-1])} contacts"
    rows.append((run, status(run), f"{len(dt)}", f"{np.median(dt):.3g}", f"{dt.max():.3g}", f"{vn:.3g}", taus, ov,
                 jg, res))

head = "| run | status | steps | dt median | dt max | max dt nu/dx^2 | max dt/tau_S | max overlap (% D) | oscillation | result |"
lines = [head, "|" + "---|" * 10]
for r in rows:
    lines.append("| " + " | ".join(str(x) for x in r) + " |")
text = "\n".join(lines) + "\n"
open(f"{OUT}/map.md", "w").write(text)
print(text)
