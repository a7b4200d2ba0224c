#!/usr/bin/python3
"""Speed against error of the bouncing sphere (scripts/bounce_resolution.sh).

usage: bounce_resolution.py resolution.csv OUT.png

Prints a markdown table (D/dx, cells, steps, wall time, V_T, eps/eps_max, and their change
from the finest run) and plots |change of V_T| and |change of eps/eps_max| from the finest run
against the wall time.
"""
import csv, sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

rows = list(csv.DictReader(open(sys.argv[1])))
rows.sort(key=lambda r: float(r["d_over_dx"]))
fine = rows[-1]
VT0, E0 = float(fine["V_T"]), float(fine["epsilon_over_max"])
print("| D/Δx | cells | steps | wall time (s) | V_T/√(gD) | ΔV_T from finest | ε/ε_max | Δ(ε/ε_max) from finest | St |")
print("|---|---|---|---|---|---|---|---|---|")
W, dV, dE = [], [], []
for r in rows:
    vt, e, w = float(r["V_T"]), float(r["epsilon_over_max"]), float(r["wall_s"])
    cells = int(r["nx"]) * int(r["ny"])
    print(f"| {r['d_over_dx']} | {cells} | {r['steps']} | {w:.1f} | {vt:.4f} | {100 * (vt - VT0) / VT0:+.2f} % | "
          f"{e:.3f} | {e - E0:+.3f} | {float(r['St']):.1f} |")
    if r is not fine:
        W.append(w); dV.append(abs(vt - VT0) / VT0); dE.append(abs(e - E0))
fig, ax = plt.subplots(figsize=(5.5, 4))
ax.loglog(W, dV, "o-", label="|V_T − V_T,finest| / V_T,finest")
ax.loglog(W, [max(x, 1e-4) for x in dE], "s--", label="|ε/ε_max − finest| (floor 1e-4)")
for r, w, v in zip(rows[:-1], W, dV):
    ax.annotate(f"D/Δx={r['d_over_dx']}", (w, v), fontsize=7, xytext=(3, 3), textcoords="offset points")
ax.set_xlabel("wall time of the run (s, one core)")
ax.set_ylabel(f"change from D/Δx = {fine['d_over_dx']}")
ax.set_title("Bouncing sphere (Izard Fig. 3.3): error against cost", fontsize=9)
ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
