#!/usr/bin/env python3
"""Post-processing of immersed-avalanche runs ([avalanche], docs/theory.md §11).

    avalanche.py RUN_DIR [RUN_DIR ...] [--out PREFIX] [--labels L1,L2,...] [--map] [--compare]

A folder without summary.json (a run not finished) is left out with a note on stderr.

For each run: the profiles of profiles.csv merged into slabs of one mean diameter (the thesis'
averaging, eq. 4.8), the time series of Q_g, h_g and the compacity, and a row of the table
(St, r, T in ms and in sqrt(D/g), T/T_v, T/T_i, T/T_ff, compacity, force shares, cost per part).
Writes PREFIX.md (the table), PREFIX_profiles.png and PREFIX_series.png.  --compare adds, for
every run against the last one listed (the largest box or the finest grid of a study), the ratio
of the flow times and the relative L2 difference of the grains' velocity profiles (slabs of one D
that both beds fill).
"""
import argparse
import csv
import json
import math
import os
import sys


def read_profiles(path):
    rows, D = [], None
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                D = float(line.split("D = ")[1].split()[0])
                continue
            if line.startswith("z,"):
                names = line.strip().split(",")
                continue
            rows.append(dict(zip(names, map(float, line.strip().split(",")))))
    return rows, D


def merge_diameter(rows, D):
    """Slabs of one diameter from the bed plane: solid-volume weighted grain velocity."""
    if not rows:
        return []
    b = rows[1]["z"] - rows[0]["z"] if len(rows) > 1 else D
    per = max(1, int(round(D / b)))
    out = []
    for k in range(0, len(rows) - per + 1, per):
        grp = rows[k:k + per]
        phi = sum(r["phi"] for r in grp) / per
        ug = sum(r["phi"] * r["Ug_x"] for r in grp) / (phi * per) if phi > 0 else 0.0
        pf = sum(r["phi_fluid"] for r in grp) / per
        uf = sum(r["phi_fluid"] * r["Uf_x"] for r in grp) / (pf * per) if pf > 0 else 0.0
        out.append({"z_over_D": (k + 0.5 * per) * b / D, "phi": phi, "Ug": ug, "Uf": uf})
    return out


def inf(x):
    return float("inf") if x is None else x


def summarise(run):
    s = json.load(open(os.path.join(run, "summary.json")))
    a = s["avalanche"]
    tg = a["sqrt_D_over_g"]
    row = {
        "run": os.path.basename(os.path.normpath(run)),
        "ratio": a["density_ratio"], "St": a["St"], "r": a["r"], "Ar": a["Ar"],
        "T_ms": 1e3 * a["T"] if a["T"] is not None else float("inf"),
        "T_g": a["T"] / tg if a["T"] is not None else float("inf"),
        # a bed that did not move over the window has no flow rate: T is infinite
        "T_Tv": inf(a["T_over_Tv"]), "T_Ti": inf(a["T_over_Ti"]), "T_Tff": inf(a["T_over_Tff"]),
        "phi": a["mean"]["phi_bed"], "h_D": a["mean"]["h_g"] / a["D"],
        "St_mean": a["mean"]["St_mean"],
        "share_c": a["share_per_contact"], "share_g": a["share_per_grain"],
        "cost": a["cost"], "wall": s["wall_time"], "t_end_g": s["time"] / tg,
        "window_g": a["averaged_seconds"] / tg, "status": s["status"], "ranks": s["ranks"],
        "rejected": s.get("rejected_steps", 0), "steps": s.get("steps", 0),
    }
    # the largest overlap of the run (series.csv's dem_max_overlap, a fraction of the smaller diameter)
    ov, path = float("nan"), os.path.join(run, "series.csv")
    if os.path.exists(path):
        with open(path) as f:
            vals = [float(r["dem_max_overlap"]) for r in csv.DictReader(f) if r.get("dem_max_overlap")]
        if vals:
            ov = max(vals)
    row["overlap"] = ov
    return row


# Table 4.3 of the thesis: (rho_p/rho, St) -> regime
THESIS = {(4, 0.04): "viscous", (4, 0.31): "viscous", (4, 7.75): "inertial", (4, 75.4): "inertial",
          (100, 0.45): "viscous", (100, 4.5): "free fall", (100, 111.2): "free fall"}


# The band of a plateau: the thesis' viscous plateau scatters up to T/T_v = 1.95 (Table 4.2 read with
# its T_v at rho_p/rho = 40 and 100, reference notes §2.1)
BAND = 2.0
# a bed slower than every time scale by this factor has stopped or creeps (not a regime)
NOFLOW = 20.0


def regime(r):
    """The thesis' method (§2.2 of the reference notes): the regime whose time scale the flow time
    follows, T/T_v ~ 1 (viscous), T/T_i ~ 1 (inertial), T/T_ff ~ 1 (free fall), each within a factor
    BAND; the nearest in log when two fit; "transitional" when none does (the grey points of the
    thesis' Fig. 4.10).  The inertial and free-fall scales differ by T_ff/T_i = 1.55 r only (4 at
    r = 2.58), so at small r both can fit."""
    d = {"viscous": abs(math.log(r["T_Tv"])), "inertial": abs(math.log(r["T_Ti"])),
         "free fall": abs(math.log(r["T_Tff"]))}
    best = min(d, key=d.get)
    if min(r["T_Tv"], r["T_Ti"], r["T_Tff"]) > NOFLOW:
        return "no flow"
    return best if d[best] <= math.log(BAND) else "transitional"


def table(rows):
    out = ["| run | ρ_p/ρ | St | r | T (ms) | T √(g/D) | T/T_v | T/T_i | T/T_ff | regime (thesis) | φ | h_g/D | "
           "shares per contact c/lub/h | shares per grain c/lub/h | window √(D/g) | max overlap (% of d) | "
           "retried steps | wall (s) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        sc, sg = r["share_c"], r["share_g"]
        th = next((v for (q, st), v in THESIS.items() if abs(r["ratio"] - q) < 1e-6 * q and abs(r["St"] / st - 1) < 0.05),
                  None)
        lab = regime(r) + (" (%s)" % th if th else "")
        out.append("| %s | %g | %.3g | %.3g | %.4g | %.4g | %.3g | %.3g | %.3g | %s | %.3f | %.2f | %.2f/%.2f/%.2f | "
                   "%.2f/%.2f/%.2f | %.0f | %.2f | %d | %.0f |" % (
                       r["run"], r["ratio"], r["St"], r["r"], r["T_ms"], r["T_g"], r["T_Tv"], r["T_Ti"], r["T_Tff"], lab,
                       r["phi"], r["h_D"], sc["contact"], sc["lubrication"], sc["hydrodynamic"], sg["contact"],
                       sg["lubrication"], sg["hydrodynamic"], r["window_g"], 100 * r["overlap"], r["rejected"],
                       r["wall"]))
    return "\n".join(out) + "\n"


# Table 4.2 of the thesis (θ = 25°): rho_p/rho -> (St range, T range in ms at D = 5 mm); rows of one run
# give one value.  The St bound 0.03 of rho_p/rho = 2.7 is probably 0.3 (reference notes §3.2).
TABLE42 = {2.7: ((0.03, 95), (25, 130)), 3: ((28, 28), (24, 24)), 4: ((0.05, 155), (24, 605)),
           5: ((0.05, 51), (21, 589)), 6: ((62, 62), (21, 21)), 7: ((0.15, 23), (23, 182)),
           7.5: ((79, 79), (21, 21)), 10: ((0.4, 107), (18, 71)), 15: ((10, 10), (28, 28)),
           16: ((0.7, 0.75), (28, 43)), 20: ((220, 220), (32, 32)), 30: ((20, 330), (28, 32)),
           40: ((0.2, 177), (33, 243)), 75: ((843, 843), (31, 31)), 100: ((0.04, 111), (38, 1200))}


def table42(rows):
    """T in ms for D = 5 mm (T sqrt(g/D) times sqrt(5 mm/g)) against the range of its Table 4.2 row."""
    out = ["| run | St | T (ms, D = 5 mm) | Table 4.2 row: St, T (ms) | T in the row's range |",
           "|---|---|---|---|---|"]
    for r in rows:
        row = next((v for q, v in TABLE42.items() if abs(r["ratio"] / q - 1) < 1e-6), None)
        if row is None:
            continue
        t = r["T_g"] * math.sqrt(0.005 / 9.81) * 1e3
        (s0, s1), (t0, t1) = row
        ins = "yes" if t0 <= t <= t1 else ("below" if t < t0 else "above")
        sin = "" if s0 <= r["St"] * 1.05 and r["St"] <= s1 * 1.05 else " (St outside the row's)"
        ts = "%.1f" % t
        if regime(r) == "no flow":
            ts, ins = "no flow", "no"
        out.append("| %s | %.3g | %s | %g–%g, %g–%g | %s%s |" % (r["run"], r["St"], ts, s0, s1, t0, t1, ins, sin))
    return "\n".join(out) + "\n"


def find(rows, ratio, st):
    """The run of this density ratio whose St is nearest st (within 5 %; the map's St 0.3 and Table 4.3's
    0.31 are both within it), or None."""
    near = [(abs(r["St"] / st - 1), k) for k, r in enumerate(rows)
            if abs(r["ratio"] / ratio - 1) < 1e-6 and abs(r["St"] / st - 1) < 0.05]
    return min(near)[1] if near else None


def profile_targets(runs, rows):
    """Target 4 of the avalanche (Table 4.3 cases): the grains' velocity profiles (slabs of one D)
    compared by their relative L2 difference over the bed, and their maxima."""
    prof = {}

    def ug(k):
        if k not in prof:
            prof[k] = grain_profile(runs[k])
        return prof[k]

    def both(a, b):  # the slabs of one D where both beds hold grains (phi >= 0.1)
        n = min(len(a), len(b))
        keep = [i for i in range(n) if a[i][1] >= 0.1 and b[i][1] >= 0.1]
        return [a[i][0] for i in keep], [b[i][0] for i in keep]

    def l2(a, b):
        return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)) / sum(y ** 2 for y in b))

    out = []
    for ratio, low, pair in ((100, 0.45, (4.5, 111.2)), (4, 0.31, (7.75, 75.4)), (4, 0.04, (0.31, 75.4))):
        k0, k1, k2 = find(rows, ratio, low), find(rows, ratio, pair[0]), find(rows, ratio, pair[1])
        if None in (k1, k2):
            continue
        a, b = both(ug(k1), ug(k2))
        # the shape: each profile over its maximum
        sa, sb = [x / max(a) for x in a], [x / max(b) for x in b]
        line = ("ρ_p/ρ = %g: St %g against %g over the %d slabs of one D both beds fill, relative L2 of ⟨U⟩_g "
                "%.3f (against St %g's), of ⟨U⟩_g/max %.3f (shape), max ⟨U⟩_g/√(gD) %.3f and %.3f" % (
                    ratio, pair[0], pair[1], len(a), l2(a, b), pair[1], l2(sa, sb), max(a), max(b)))
        if k0 is not None:
            c = [x for x, _ in ug(k0)]
            line += "; St %g: max %.3f, ratios %.2f and %.2f" % (low, max(c), max(a) / max(c), max(b) / max(c))
        out.append(line)
    return out


def grain_profile(run):
    """The grains' velocity in slabs of one D, over sqrt(g D), with the slab's solid fraction."""
    p, D = read_profiles(os.path.join(run, "profiles.csv"))
    return [(q["Ug"] / math.sqrt(9.81 * D), q["phi"]) for q in merge_diameter(p, D)]


def rel_l2(a, b):
    """Relative L2 difference of profiles a and b (against b) over the slabs where both hold grains
    (phi >= 0.1), of the profiles and of their shapes (each over its maximum there); returns both,
    the two maxima and the number of slabs."""
    n = min(len(a), len(b))
    keep = [i for i in range(n) if a[i][1] >= 0.1 and b[i][1] >= 0.1]
    if not keep:
        return float("nan"), float("nan"), 0.0, 0.0, 0
    ma, mb = max(a[i][0] for i in keep), max(b[i][0] for i in keep)

    def l2(x, y):
        den = sum(v ** 2 for v in y)
        return math.sqrt(sum((u - v) ** 2 for u, v in zip(x, y)) / den) if den > 0 else float("nan")

    x, y = [a[i][0] for i in keep], [b[i][0] for i in keep]
    shape = l2([u / ma for u in x], [v / mb for v in y]) if ma > 0 and mb > 0 else float("nan")
    return l2(x, y), shape, ma, mb, len(keep)


def compare(runs, rows):
    """Each run against the last one: T ratio and relative L2 of the grain velocity profile."""
    ref, rr = grain_profile(runs[-1]), rows[-1]
    out = []
    for run, r in zip(runs[:-1], rows[:-1]):
        d, shape, ma, mb, n = rel_l2(grain_profile(run), ref)
        out.append("%s against %s: T %.4g against %.4g √(D/g) (ratio %.3f); over the %d slabs of one D both beds "
                   "fill, relative L2 of ⟨U⟩_g %.3f, of its shape (over its maximum) %.3f, max ⟨U⟩_g/√(gD) %.3f "
                   "against %.3f" % (r["run"], rr["run"], r["T_g"], rr["T_g"], r["T_g"] / rr["T_g"], n, d, shape, ma, mb))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--out", default="avalanche")
    ap.add_argument("--labels", default=None)
    ap.add_argument("--map", action="store_true", help="also the regime map (St, r) with the thesis' lines")
    ap.add_argument("--compare", action="store_true",
                    help="each run against the last: flow time ratio, relative L2 of the grain velocity profile")
    a = ap.parse_args()
    runs = []
    for r in a.runs:
        r = os.path.normpath(r)
        if not os.path.exists(os.path.join(r, "summary.json")):
            print("avalanche.py: %s: no summary.json (not finished), left out" % r, file=sys.stderr)
        elif r not in runs:
            runs.append(r)
    if not runs:
        sys.exit("avalanche.py: no finished run")
    # a run stopped (diverged) before its averaging window has no flow time: listed, not tabulated
    stopped, keep = [], []
    for r in runs:
        s = json.load(open(os.path.join(r, "summary.json")))
        av = s["avalanche"]
        note = "%s at %.1f √(D/g) (%s)" % (s["status"], s["time"] / av["sqrt_D_over_g"], s.get("reason", ""))
        if not av.get("averaged_seconds") or (av.get("T") is None and s["status"] != "t_end"):
            stopped.append("%s: no flow time, %s" % (os.path.basename(r), note))
        else:
            keep.append(r)
            if s["status"] != "t_end":
                stopped.append("%s: %s, window shortened" % (os.path.basename(r), note))
    if not keep:
        sys.exit("avalanche.py: no finished run with a flow time:\n  " + "\n  ".join(stopped))
    a.runs = runs = keep
    rows = [summarise(r) for r in a.runs]
    text = table(rows)
    if stopped:
        text += "\nRuns that did not reach their end:\n\n" + "\n".join("- " + x for x in stopped) + "\n"
    text += "\n" + table42(rows)
    extra = profile_targets(a.runs, rows)
    if a.compare and len(a.runs) > 1:
        extra += compare(a.runs, rows)
    if extra:
        text += "\n" + "\n".join("- " + e for e in extra) + "\n"
    with open(a.out + ".md", "w") as f:
        f.write(text)
    sys.stdout.write(text)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    if a.map:
        fig, ax = plt.subplots(figsize=(8.5, 4.5))
        mk = {"viscous": ("o", "tab:blue"), "inertial": ("s", "tab:orange"), "free fall": ("^", "tab:green"),
              "transitional": ("D", "0.6"), "no flow": ("x", "k")}
        for lab, (m, c) in mk.items():
            pts = [(r["St"], r["r"]) for r in rows if regime(r) == lab]
            if pts:
                ax.scatter(*zip(*pts), marker=m, color=c, label=lab)
        ax.plot([1, 1], [4, 20], "k-", lw=1, label="Izard: St = 1 (r ≥ 4), r = 4 St")
        ax.plot([0.25, 1], [1, 4], "k-", lw=1)
        ax.plot([1, 1e3], [4, 4], "k:", lw=1)
        ax.plot([10, 10], [4, 20], "r--", lw=1, label="Courrech du Pont: St = 10, r = 0.4 St, r = 4")
        ax.plot([2.5, 10], [1, 4], "r--", lw=1)
        ax.plot([10, 1e3], [4, 4], "r:", lw=1)
        for r in rows:  # Table 4.3's cases: the thesis' label beside the point
            th = next((v for (q, st), v in THESIS.items() if abs(r["ratio"] - q) < 1e-6 * q and abs(r["St"] / st - 1) < 0.05),
                      None)
            if th:
                ax.annotate("thesis: " + th, (r["St"], r["r"]), textcoords="offset points", xytext=(4, 4), fontsize=6,
                            color="0.3")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(0.02, 1e3)
        ax.set_xlabel("St")
        ax.set_ylabel("r")
        ax.set_title("labels by the flow time's scale (T/T_v, T/T_i, T/T_ff within 2)", fontsize=8)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1))
        fig.tight_layout()
        fig.savefig(a.out + "_map.png", dpi=100)
        # the thesis' classification plots: T/T_v against St (Fig. 4.7), T/T_i and T/T_ff against r
        # for St >= 1 (Fig. 4.8)
        fig, ax = plt.subplots(1, 2, figsize=(9, 4))
        for lab, (m, c) in mk.items():
            if lab == "no flow":
                continue
            pts = [(r["St"], r["T_Tv"]) for r in rows if regime(r) == lab]
            if pts:
                ax[0].scatter(*zip(*pts), marker=m, color=c, label=lab)
        ax[0].plot([1e-2, 1e3], [1, 1], "k:", lw=1)
        ax[0].plot([1, 1e3], [1, 1e3], "k--", lw=1, label="T/T_v = St")
        ax[0].set_xscale("log")
        ax[0].set_yscale("log")
        ax[0].set_xlabel("St")
        ax[0].set_ylabel("T/T_v")
        ax[0].legend(fontsize=7)
        big = [r for r in rows if r["St"] >= 1 and regime(r) != "no flow"]
        if big:
            ax[1].scatter([r["r"] for r in big], [r["T_Ti"] for r in big], marker="s", color="tab:orange", label="T/T_i")
            ax[1].scatter([r["r"] for r in big], [r["T_Tff"] for r in big], marker="^", color="tab:green", label="T/T_ff")
        ax[1].axhline(1, color="k", ls=":", lw=1)
        ax[1].set_xscale("log")
        ax[1].set_yscale("log")
        ax[1].set_xlabel("r (St ≥ 1)")
        ax[1].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(a.out + "_scaling.png", dpi=100)
    labels = a.labels.split(",") if a.labels else [r["run"] for r in rows]
    fig, ax = plt.subplots(1, 2, figsize=(9, 4.5))
    for run, lab in zip(a.runs, labels):
        prof, D = read_profiles(os.path.join(run, "profiles.csv"))
        ug = math.sqrt(9.81 * D)
        m = merge_diameter(prof, D)
        ax[0].plot([p["Ug"] / ug for p in m], [p["z_over_D"] for p in m], "o-", label=lab)
        ax[1].plot([p["phi"] for p in m], [p["z_over_D"] for p in m], "o-", label=lab)
    ax[0].set_xlabel("⟨U⟩_g / √(gD)")
    ax[0].set_ylabel("z / D")
    ax[1].set_xlabel("φ")
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out + "_profiles.png", dpi=120)
    fig, ax = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    for run, lab in zip(a.runs, labels):
        s = json.load(open(os.path.join(run, "summary.json")))["avalanche"]
        tg = s["sqrt_D_over_g"]
        t, q, u, phi = [], [], [], []
        with open(os.path.join(run, "series.csv")) as f:
            for r in csv.DictReader(f):
                if not r["Q_g"]:  # a row still being written (a run in progress)
                    continue
                t.append(float(r["time"]) / tg)
                q.append(float(r["Q_g"]))
                u.append(float(r["U_g"]) / math.sqrt(9.81 * s["D"]))
                phi.append(float(r["phi_bed"]))
        ax[0].plot(t, q, lw=0.7, label=lab)
        ax[1].plot(t, u, lw=0.7, label=lab)
        ax[2].plot(t[1:], phi[1:], lw=0.7, label=lab)
    ax[0].set_ylabel("Q_g (m³/s)")
    ax[1].set_ylabel("mean grain velocity U_g / √(gD)")
    ax[2].set_ylabel("φ (compacity)")
    ax[2].set_xlabel("t / √(D/g)")
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out + "_series.png", dpi=120)


if __name__ == "__main__":
    main()
