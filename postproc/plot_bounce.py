#!/usr/bin/python3
"""Velocity history and restitution point of a bouncing-sphere run (cases/bouncing_sphere).

usage: plot_bounce.py RUN_DIR OUT.png [OUT.json]

Reads RUN_DIR/series.csv (columns s1_v or approach_speed) and RUN_DIR/summary.json (the coupling
results), plots u/V_T against t (units of the case) with V_T, V_C and V_R marked, and, on a
second panel, the measured eps/eps_max against St with the seed's model (eq. 3.30, for the
run's eta_e/R) and Legendre et al.'s exp(-35/St).  The JSON gets the measured values, the model
value at the measured St and the seed's numbers for the case of Fig. 3.3.
"""
import csv, json, math, sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def izard_model(St, r):
    """eq. 3.30: eps/eps_max = beta exp(-(pi/2)/sqrt(beta St)), beta = 1 + ln(eta_e/R)/St"""
    b = 1 + math.log(r) / St
    return 0.0 if b <= 0 else b * math.exp(-(math.pi / 2) / math.sqrt(b * St))


def main():
    run, png = sys.argv[1], sys.argv[2]
    out_json = sys.argv[3] if len(sys.argv) > 3 else None
    s = json.load(open(f"{run}/summary.json"))
    c = s["coupling"]
    rows = list(csv.DictReader(open(f"{run}/series.csv")))
    t = [float(r["time"]) for r in rows]
    u = [-float(r["approach_speed"]) for r in rows]  # upward positive
    roughness = 4e-4
    try:
        for line in open(f"{run}/input.ini"):
            k = line.split(";")[0].split("=")
            if len(k) == 2 and k[0].strip() == "roughness":
                roughness = float(k[1])
    except OSError:
        pass
    VT = c["V_T"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1.6, 1]})
    a1.plot(t, [x / VT for x in u], "k-", lw=1)
    a1.axhline(-1, color="0.6", ls=":", lw=0.8)
    if c.get("t_contact", -1) > 0:
        a1.axvline(c["t_contact"], color="C3", ls="--", lw=0.8, label="contact")
        a1.plot([c["t_contact"]], [-c["V_C"] / VT], "o", color="C0", label=f"V_C/V_T = {c['V_C_over_V_T']:.3f}")
        a1.plot([c["t_release"]], [c["V_R"] / VT], "s", color="C2", label=f"ε = V_R/V_T = {c['epsilon']:.3f}")
        t0 = c["t_contact"]
        a1.set_xlim(max(t[0], t0 - 1.5), max(t[-1], t0 + 0.2))
    a1.set_xlabel("t √(g/D)")
    a1.set_ylabel("u / V_T (upward positive)")
    a1.set_title(f"{s['case']}: St = {c['St']:.1f}, Re_p = {c['Re_p']:.1f}")
    a1.legend(loc="best", fontsize=8)
    St = [10 ** (0.5 + 3.0 * i / 200) for i in range(201)]
    a2.semilogx(St, [izard_model(x, roughness) for x in St], "k-", lw=1, label=f"model eq. 3.30, η_e/R = {roughness:g}")
    a2.semilogx(St, [math.exp(-35 / x) for x in St], "k--", lw=0.8, label="Legendre et al. exp(−35/St)")
    a2.plot([c["St"]], [c["epsilon_over_max"]], "o", color="C3", label="this run")
    a2.plot([55], [0.65], "^", color="C0", mfc="none", label="seed, Fig. 3.3 (0.65)")
    a2.set_xlabel("St")
    a2.set_ylabel("ε / ε_max")
    a2.set_ylim(0, 1.05)
    a2.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    if out_json:
        res = {k: c[k] for k in ("V_T", "V_C", "V_C_onset", "V_R", "V_C_over_V_T", "epsilon", "epsilon_max",
                                 "epsilon_over_max", "St", "Re_p", "t_contact") if k in c}
        res["model_eq_3_30_at_St"] = izard_model(c["St"], roughness)
        res["roughness"] = roughness
        res["seed_fig_3_3"] = {"St": "53-56", "Re_p": "~60", "V_C_over_V_T": 0.88, "epsilon_over_max": 0.65}
        res["wall_time_s"] = s.get("wall_time")
        json.dump(res, open(out_json, "w"), indent=2)
    print(f"{png}: eps/eps_max = {c['epsilon_over_max']:.3f} at St = {c['St']:.1f} "
          f"(model 3.30: {izard_model(c['St'], roughness):.3f}; seed 0.65 at St ~ 55)")


if __name__ == "__main__":
    main()
