#!/usr/bin/env python3
"""Post-processing of immersed-avalanche runs ([avalanche], docs/theory.md §11).

    avalanche.py RUN_DIR [RUN_DIR ...] [--out PREFIX] [--labels L1,L2,...]

For each run: the profiles of profiles.csv merged into slabs of one mean diameter (the thesis'
averaging, eq. 4.8), the time series of Q_g, h_g and the compacity, and a row of the table
(St, r, T in ms and in sqrt(D/g), T/T_v, T/T_i, T/T_ff, compacity, force shares, cost per part).
Writes PREFIX.md (the table), PREFIX_profiles.png and PREFIX_series.png.
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


def summarise(run):
    s = json.load(open(os.path.join(run, "summary.json")))
    a = s["avalanche"]
    tg = a["sqrt_D_over_g"]
    row = {
        "run": os.path.basename(os.path.normpath(run)),
        "ratio": a["density_ratio"], "St": a["St"], "r": a["r"], "Ar": a["Ar"],
        "T_ms": 1e3 * a["T"] if a["T"] is not None else float("nan"),
        "T_g": a["T"] / tg if a["T"] is not None else float("nan"),
        "T_Tv": a["T_over_Tv"], "T_Ti": a["T_over_Ti"], "T_Tff": a["T_over_Tff"],
        "phi": a["mean"]["phi_bed"], "h_D": a["mean"]["h_g"] / a["D"],
        "St_mean": a["mean"]["St_mean"],
        "share_c": a["share_per_contact"], "share_g": a["share_per_grain"],
        "cost": a["cost"], "wall": s["wall_time"], "t_end_g": s["time"] / tg,
        "window_g": a["averaged_seconds"] / tg, "status": s["status"], "ranks": s["ranks"],
    }
    return row


# Table 4.3 of the thesis: (rho_p/rho, St) -> regime
THESIS = {(4, 0.04): "viscous", (4, 0.31): "viscous", (4, 7.75): "inertial", (4, 75.4): "inertial",
          (100, 0.45): "viscous", (100, 4.5): "free fall", (100, 111.2): "free fall"}


def regime(r):
    """The thesis' method (§2.2 of the reference notes): the regime whose time scale the flow time
    follows, T/T_v ~ 1 (viscous), T/T_i ~ 1 (inertial), T/T_ff ~ 1 (free fall): the nearest in log."""
    d = {"viscous": abs(math.log(r["T_Tv"])), "inertial": abs(math.log(r["T_Ti"])),
         "free fall": abs(math.log(r["T_Tff"]))}
    return min(d, key=d.get)


def table(rows):
    out = ["| run | ρ_p/ρ | St | r | T (ms) | T √(g/D) | T/T_v | T/T_i | T/T_ff | regime (thesis) | φ | h_g/D | "
           "shares per contact c/lub/h | shares per grain c/lub/h | window √(D/g) | wall (s) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        sc, sg = r["share_c"], r["share_g"]
        th = next((v for (q, st), v in THESIS.items() if abs(r["ratio"] - q) < 1e-6 * q and abs(r["St"] / st - 1) < 0.05),
                  None)
        lab = regime(r) + (" (%s)" % th if th else "")
        out.append("| %s | %g | %.3g | %.3g | %.4g | %.4g | %.3g | %.3g | %.3g | %s | %.3f | %.2f | %.2f/%.2f/%.2f | "
                   "%.2f/%.2f/%.2f | %.0f | %.0f |" % (
                       r["run"], r["ratio"], r["St"], r["r"], r["T_ms"], r["T_g"], r["T_Tv"], r["T_Ti"], r["T_Tff"], lab,
                       r["phi"], r["h_D"], sc["contact"], sc["lubrication"], sc["hydrodynamic"], sg["contact"],
                       sg["lubrication"], sg["hydrodynamic"], r["window_g"], r["wall"]))
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--out", default="avalanche")
    ap.add_argument("--labels", default=None)
    ap.add_argument("--map", action="store_true", help="also the regime map (St, r) with the thesis' lines")
    a = ap.parse_args()
    rows = [summarise(r) for r in a.runs]
    with open(a.out + ".md", "w") as f:
        f.write(table(rows))
    sys.stdout.write(table(rows))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    if a.map:
        fig, ax = plt.subplots(figsize=(6, 4.5))
        mk = {"viscous": ("o", "tab:blue"), "inertial": ("s", "tab:orange"), "free fall": ("^", "tab:green")}
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
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("St")
        ax.set_ylabel("r")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(a.out + "_map.png", dpi=120)
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
    fig, ax = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for run, lab in zip(a.runs, labels):
        s = json.load(open(os.path.join(run, "summary.json")))["avalanche"]
        tg = s["sqrt_D_over_g"]
        t, q, phi = [], [], []
        with open(os.path.join(run, "series.csv")) as f:
            for r in csv.DictReader(f):
                t.append(float(r["time"]) / tg)
                q.append(float(r["Q_g"]))
                phi.append(float(r["phi_bed"]))
        ax[0].plot(t, q, lw=0.7, label=lab)
        ax[1].plot(t[1:], phi[1:], lw=0.7, label=lab)
    ax[0].set_ylabel("Q_g (m³/s)")
    ax[1].set_ylabel("φ (compacity)")
    ax[1].set_xlabel("t / √(D/g)")
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out + "_series.png", dpi=120)


if __name__ == "__main__":
    main()
