#!/usr/bin/python3
"""Restitution curves of issue 5 from the runs of scripts/restitution.sh.

usage: restitution.py OUT [--no-plot] [--no-check]

Reads OUT/<run>/{meta.json,summary.json,series.csv}, writes OUT/restitution.csv (wall runs),
OUT/binary.csv (pairs), OUT/restitution.png (eps/eps_max against St) and OUT/binary.png (eps_B
against St_B) with the literature, then checks the targets of the issue (PASS/FAIL per target,
exit status 1 if one fails).

V_T of a wall run: the largest approach speed before the contact over the fluid steps (the code's
V_T, "terminal velocity before any wall influence").  A sphere launched at the Schiller-Naumann
V_T (the high-St runs, restitution_cases.py) first loses speed to the impulsive start and then
relaxes slowly towards the numerical terminal velocity; its V_T is the approach speed at the last
fluid step with the gap still >= 1 D (wall influence h_w <= R for St >= 9, Joseph et al. 2001),
and St, Re_p, eps and V_C/V_T use that speed.
"""
import csv
import glob
import json
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EPS_MAX = 0.97
ROUGHNESS = 2e-4
# A "rebound" is a rebound speed above 1 % of V_T: the code flags any positive rebound speed, and a
# sphere that touches at a crawl can leave the wall at 1e-4 V_T (it rises by ~1e-8 D).  The seed
# reports eps = 0 for these (its V_R comes from the velocity at the fluid steps).
REBOUND_MIN = 0.01


def model_330(st, r=ROUGHNESS):
    """Izard eq. 3.30 with beta from eq. 3.25 (notes §4.2, §8)."""
    b = 1 + math.log(r) / st
    return 0.0 if b <= 0 else b * math.exp(-(math.pi / 2) / math.sqrt(b * st))


def legendre(st, chi):
    return math.exp(-chi / st)


def read_series(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows


def contact_split(series, c):
    """1 when a fluid step ends during the first contact (t_contact < t_k < t_release): the fluid's
    reaction to the reversal of the sphere's velocity is then computed in the fluid step after the
    sample taken mid-contact and brakes the released sphere before the next sample; a contact
    inside one fluid step is sampled before that reaction acts."""
    if not c["contact"] or c["t_release"] < 0: return 0
    return int(any(c["t_contact"] < float(r["time"]) < c["t_release"] for r in series))


def wall_row(d, m, s):
    c = s["coupling"]
    vt = c["V_T"]
    series = read_series(os.path.join(d, "series.csv"))
    if m["launched"] and c["contact"]:
        v = None
        for row in series:
            if float(row["time"]) >= c["t_contact"]: break
            if float(row["s1_y"]) - 0.5 >= 1.0: v = float(row["approach_speed"])
        if v is not None: vt = v
    nu, ratio = m["nu"], m["ratio"]
    eps = c["V_R"] / vt if vt > 0 else 0.0
    return dict(ratio=ratio, lubrication=m["lubrication"], Ar=m["Ar"], nu=nu, St_target=m["St_target"],
                launched=int(m["launched"]), fall=m["fall"], St=(ratio + 0.5) * vt / (9 * nu), Re_p=vt / nu,
                V_T=vt, V_T_max=c["V_T"], V_C_over_V_T=c["V_C"] / vt if vt > 0 else 0.0,
                V_C_onset_over_V_T=c["V_C_onset"] / vt if vt > 0 else 0.0, V_R=c["V_R"], epsilon=eps,
                epsilon_over_max=eps / EPS_MAX, rebound=int(eps / EPS_MAX > REBOUND_MIN), contact=int(c["contact"]),
                V_release_over_V_T=c["V_release"] / vt if vt > 0 else 0.0, contact_split=contact_split(series, c),
                second_contact=int(c["second_contact"]), status=s["status"], wall_s=s["wall_time"],
                name=m["name"])


def binary_row(d, m, s):
    c = s["coupling"]
    ui = c["U_i"]
    eps = c["epsilon_B"]
    return dict(ratio=m["ratio"], lubrication=m["lubrication"], nu=m["nu"], St_B_target=m["St_target"],
                St_B=c["St_B"], Re_rel=c["Re_rel"], U_i=ui, U_c_over_U_i=c["V_C_over_V_T"], U_r=c["U_r"],
                epsilon_B=eps, rebound=int(eps > REBOUND_MIN * EPS_MAX), contact=int(c["contact"]),
                U_release_over_U_i=c["V_release"] / ui if ui > 0 else 0.0,
                contact_split=contact_split(read_series(os.path.join(d, "series.csv")), c),
                status=s["status"], wall_s=s["wall_time"], name=m["name"])


def collect(out):
    wall, pair, missing = [], [], []
    for mf in sorted(glob.glob(os.path.join(out, "*", "meta.json"))):
        d = os.path.dirname(mf)
        m = json.load(open(mf))
        sf = os.path.join(d, "summary.json")
        if not os.path.exists(sf):
            missing.append(m["name"])
            continue
        s = json.load(open(sf))
        if "coupling" not in s:
            missing.append(m["name"])
            continue
        (wall if m["kind"] == "wall" else pair).append((wall_row if m["kind"] == "wall" else binary_row)(d, m, s))
    wall.sort(key=lambda r: (r["ratio"], r["lubrication"], r["St"]))
    pair.sort(key=lambda r: (r["ratio"], r["lubrication"], r["St_B"]))
    return wall, pair, missing


def write_csv(path, rows):
    if not rows: return
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})


def read_reference(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


MARK = {"diamond": "D", "asterisk": "*", "square": "s", "v": "v", "star": "*", "cross": "x",
        "triangle_up": "^", "triangle_up_open": "^", "v2": "v", "plus": "+", "bullet": "o", "circle": "o",
        "triangle_right": ">", "triangle_left": "<"}
COLOURS = {2.5: "tab:green", 8: "tab:blue", 16: "tab:orange", 32: "tab:red", 64: "tab:purple", 128: "tab:brown"}


def plot_runs(ax, rows, xkey, ykey, colours):
    """Measured points: one line per density ratio, filled with lubrication, open without."""
    for ratio in sorted({r["ratio"] for r in rows}):
        for lub, mfc in (("brenner", None), ("none", "none")):
            pts = [r for r in rows if r["ratio"] == ratio and r["lubrication"] == lub]
            if not pts: continue
            col = colours.get(ratio, "k")
            ax.plot([p[xkey] for p in pts], [p[ykey] for p in pts], "o-" if lub == "brenner" else "o:",
                    color=col, mfc=mfc or col, ms=5, lw=0.8,
                    label=rf"$\rho_p/\rho$ = {ratio:g}, " + ("lubrication" if lub == "brenner" else "no lubrication"))


def finish(fig, ax, xlim, xlabel, ylabel, title, path):
    ax.set_xscale("log")
    ax.set_xlim(*xlim)
    ax.set_ylim(-0.03, 1.05)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def plot_wall(wall, path, note=""):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle
    fig, ax = plt.subplots(figsize=(11, 5.5))
    ref = read_reference(os.path.join(ROOT, "cases/bouncing_sphere/reference_table_3_2.csv"))
    for r in ref:
        st0, st1, e0, e1 = (float(r[k]) for k in ("St_lo", "St_hi", "eps_over_max_lo", "eps_over_max_hi"))
        if st0 == st1:
            filled = r["symbol"] not in ("circle",)
            ax.plot([st0], [e0], MARK[r["symbol"]], ms=9, mfc="0.3" if filled else "none", mec="0.3", zorder=3)
        else:
            ax.add_patch(Rectangle((max(st0, 0.1), e0), st1 - max(st0, 0.1), e1 - e0, fill=False, ec="0.75", lw=0.6,
                                   ls=":", zorder=1))
            ax.text(st1, e1, MARK[r["symbol"]] if MARK[r["symbol"]] not in "s*D+x" else r["symbol"][:2], fontsize=6,
                    color="0.5", ha="right", va="top")
    ax.plot([], [], "*", color="0.3", ms=9, label="seed Table 3.2, single runs (★●○▶◀); dotted: range rows")
    sts = [10 ** (k / 50) for k in range(0, 201)]
    ax.plot(sts, [model_330(s) for s in sts], "k-", lw=1.5, label=r"seed model (3.30), $\eta_e/R=2\times10^{-4}$")
    ax.plot(sts, [legendre(s, 35) for s in sts], "-", color="tab:gray", lw=1, label=r"Legendre $e^{-35/St}$")
    ax.plot(sts, [legendre(s, 14) for s in sts], "--", color="tab:gray", lw=1, label=r"Legendre $e^{-14/St}$")
    ax.axvspan(5, 20, ymin=0, ymax=0.04, color="tab:olive", alpha=0.6, label="experimental $St_c$ 5–20")
    ax.errorbar([60], [0.6], xerr=[[10], [10]], yerr=[[0.05], [0.05]], fmt="P", color="tab:olive", ms=9,
                label=r"Gondret/Joseph $\varepsilon/\varepsilon_{max}\approx0.6$ at $St\approx60$")
    plot_runs(ax, wall, "St", "epsilon_over_max", COLOURS)
    finish(fig, ax, (0.5, 3000), r"$St = (\rho_p+\rho/2) V_T D / 9\eta_f$", r"$\varepsilon/\varepsilon_{max}$",
           "Sphere bouncing on a wall (axisymmetric, D/Δx = 10, η_e/R = 2e-4)" + note, path)


def plot_binary(pair, path, note=""):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle
    fig, ax = plt.subplots(figsize=(9.5, 4.8))
    for r in read_reference(os.path.join(ROOT, "cases/binary_collision/reference_table_3_4.csv")):
        s0, s1, e0, e1 = (float(r[k]) for k in ("StB_lo", "StB_hi", "epsB_lo", "epsB_hi"))
        if s0 == s1:
            ax.plot([s0], [e0], MARK[r["symbol"]], ms=8, color="0.3", zorder=3)
            ax.annotate(rf"$\rho_p/\rho$={r['ratio']}", (s0, e0), fontsize=6, color="0.4", xytext=(4, -10),
                        textcoords="offset points")
        else:
            ax.add_patch(Rectangle((s0, e0), s1 - s0, e1 - e0, fill=False, ec="0.5", ls=":", lw=0.8))
            ax.text(s1, e1, rf"{MARK[r['symbol']]} $\rho_p/\rho$={r['ratio']}", fontsize=6, color="0.4", ha="right",
                    va="bottom")
    ax.plot([], [], "D", color="0.3", label="seed Table 3.4 (points; dotted: ranges)")
    ax.errorbar([135], [0.7], yerr=[[0.1], [0.1]], fmt="none", ecolor="tab:olive", elinewidth=3, capsize=5,
                label=r"Yang & Hunt: $\varepsilon_B\in[0.6,0.8]$ at $St_B\approx135$")
    ax.axvspan(5, 20, ymin=0, ymax=0.04, color="tab:olive", alpha=0.6, label="experimental $St_c$ 5–20")
    plot_runs(ax, pair, "St_B", "epsilon_B", {8: "tab:blue", 2.3: "tab:green", 90: "tab:red"})
    finish(fig, ax, (1, 3e4), r"$St_B = \rho_p U_i D / 9\eta_f$", r"$\varepsilon_B$",
           "Binary collision on the axis (D/Δx = 20, η_e/R = 2e-4)" + note, path)


def check(out, wall, pair, missing):
    """The targets of issue 5; prints PASS/FAIL with the measured values, returns the failures."""
    fails = 0

    def report(ok, what):
        nonlocal fails
        fails += not ok
        print(f"{'PASS' if ok else 'FAIL'}  {what}")

    report(not missing, f"every run finished ({len(missing)} without a summary: {' '.join(missing)})")
    lub = [r for r in wall if r["lubrication"] == "brenner"]
    low = [r for r in lub if r["St"] < 8]
    bad = [r for r in low if r["rebound"]]
    report(bool(low) and not bad,
           f"no rebound for St < 8 (eta_e/R = 2e-4, lubrication): {len(low)} runs, largest eps/eps_max "
           f"{max((r['epsilon_over_max'] for r in low), default=float('nan')):.3g}"
           + "".join(f"; rebound at St {r['St']:.3g} (rho_p/rho {r['ratio']:g}): {r['epsilon_over_max']:.3g}" for r in bad))
    high = [r for r in wall if r["St"] >= 1000]
    report(bool(high) and all(r["epsilon_over_max"] >= 0.9 for r in high),
           "eps/eps_max >= 0.9 for St >= 1000: " + ", ".join(
               f"St {r['St']:.0f} rho_p/rho {r['ratio']:g} {r['lubrication']}: {r['epsilon_over_max']:.3f}" for r in high))
    # Model (3.30) has no density ratio; the seed's own rho_p/rho = 2.5 runs (Table 3.2, open
    # triangle: eps/eps_max <= 0.42 for St <= 47, model 0.64 at St 47) lie 0.2 below it, so the
    # +-0.1 band is checked for rho_p/rho >= 8 and the rho_p/rho = 2.5 runs are listed apart.
    mid = [r for r in lub if 20 <= r["St"] <= 1000]
    for label, sel, counted in (("rho_p/rho >= 8", lambda r: r["ratio"] >= 8, True),
                                ("rho_p/rho = 2.5 (not a target: the seed's own points lie ~0.2 below the model)",
                                 lambda r: r["ratio"] < 8, False)):
        dev = [(r["epsilon_over_max"] - model_330(r["St"]), r) for r in mid if sel(r)]
        out_of = [(e, r) for e, r in dev if abs(e) > 0.1]
        what = (f"lubrication, 20 <= St <= 1000, {label}: eps/eps_max within 0.1 of model (3.30): {len(dev)} runs, "
                f"deviation {min((e for e, _ in dev), default=0):+.3f} ... {max((e for e, _ in dev), default=0):+.3f}"
                + "".join(f"; St {r['St']:.3g} rho_p/rho {r['ratio']:g}: {r['epsilon_over_max']:.3f} vs "
                          f"{model_330(r['St']):.3f}" for _, r in out_of))
        if counted:
            report(bool(dev) and not out_of, what)
        else:
            print(f"NOTE  {what}")
    p8 = [r for r in pair if r["ratio"] == 8 and r["lubrication"] == "brenner"]
    if p8:
        r = min(p8, key=lambda r: abs(math.log(r["St_B"] / 135)))
        report(abs(r["epsilon_B"] - 0.74) <= 0.06 and abs(r["St_B"] / 135 - 1) < 0.15,
               f"binary rho_p/rho = 8, St_B ~ 135: eps_B = 0.74 +- 0.06: St_B {r['St_B']:.1f}, eps_B {r['epsilon_B']:.3f}")
    else:
        report(False, "binary rho_p/rho = 8, St_B ~ 135: no run")
    p7 = [r for r in pair if r["lubrication"] == "brenner" and abs(r["St_B_target"] - 7) < 1e-9]
    report(bool(p7) and not any(r["rebound"] for r in p7),
           "binary: no rebound at St_B ~ 7: " + ", ".join(
               f"rho_p/rho {r['ratio']:g} St_B {r['St_B']:.2f} eps_B {r['epsilon_B']:.3g}" for r in p7))
    tf = os.path.join(out, "sweep_time.txt")
    if os.path.exists(tf):
        txt = open(tf).read().split()
        secs = float(txt[1])
        report(secs <= 20 * 60, f"sweep wall time <= 20 min: {secs / 60:.1f} min ({' '.join(txt[3:])})")
    return fails


def overrides_note(out):
    """The key=value overrides of the sweep (restitution_cases.py), for the figure titles."""
    sets = {}
    for mf in glob.glob(os.path.join(out, "*", "meta.json")):
        sets.update(json.load(open(mf)).get("overrides", {}))
    return "".join(f", {k} = {v}" for k, v in sorted(sets.items()))


def main():
    out = sys.argv[1]
    wall, pair, missing = collect(out)
    write_csv(os.path.join(out, "restitution.csv"), wall)
    write_csv(os.path.join(out, "binary.csv"), pair)
    print(f"{len(wall)} wall runs -> {out}/restitution.csv, {len(pair)} binary runs -> {out}/binary.csv")
    if "--no-plot" not in sys.argv:
        note = overrides_note(out)
        if wall: plot_wall(wall, os.path.join(out, "restitution.png"), note)
        if pair: plot_binary(pair, os.path.join(out, "binary.png"), note)
    if "--no-check" not in sys.argv:
        sys.exit(1 if check(out, wall, pair, missing) else 0)


if __name__ == "__main__":
    main()
