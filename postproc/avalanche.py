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


def table(rows):
    out = ["| run | ρ_p/ρ | St | r | T (ms) | T √(g/D) | T/T_v | T/T_i | T/T_ff | φ | h_g/D | "
           "shares per contact c/lub/h | shares per grain c/lub/h | window √(D/g) | wall (s) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        sc, sg = r["share_c"], r["share_g"]
        out.append("| %s | %g | %.3g | %.3g | %.4g | %.4g | %.3g | %.3g | %.3g | %.3f | %.2f | %.2f/%.2f/%.2f | "
                   "%.2f/%.2f/%.2f | %.0f | %.0f |" % (
                       r["run"], r["ratio"], r["St"], r["r"], r["T_ms"], r["T_g"], r["T_Tv"], r["T_Ti"], r["T_Tff"],
                       r["phi"], r["h_D"], sc["contact"], sc["lubrication"], sc["hydrodynamic"], sg["contact"],
                       sg["lubrication"], sg["hydrodynamic"], r["window_g"], r["wall"]))
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--out", default="avalanche")
    ap.add_argument("--labels", default=None)
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
    labels = a.labels.split(",") if a.labels else [r["run"] for r in rows]
    fig, ax = plt.subplots(1, 2, figsize=(9, 4.5))
    for run, lab in zip(a.runs, labels):
        prof, D = read_profiles(os.path.join(run, "profiles.csv"))
        s = json.load(open(os.path.join(run, "summary.json")))["avalanche"]
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
