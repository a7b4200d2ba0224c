#!/usr/bin/python3
"""Terzaghi consolidation (cases/consolidation, `ibmdem run` with [oedometer]): for each run folder,
the excess pore pressure at mid-height and at the sealed base and the degree of consolidation U
(series.csv: oedo_Tv, oedo_p_mid, oedo_p_base, oedo_U, oedo_U_marker) against Terzaghi's series
(catalano_pfv.md §2.2) at the heights the run reports (summary.json: oedometer.zeta_mid,
zeta_base, zeta_marker), and the pressure profiles p(z) at T_v = 0.1, 0.2, 0.5, 1
(pressure_profile.csv).  U is shown raw (settlement from the instant of loading) and corrected for
the initial compression by Taylor's square-root-of-time method (ASTM D2435): the straight part of
U against sqrt(T_v), fitted on taylor_lo <= T_v <= taylor_hi ([oedometer]), extrapolated to t = 0
gives the corrected zero d_s (summary.json oedometer.taylor_zero); U_corr = (U - d_s)/(1 - d_s).
The marker layer (the grains below the first layer under the piston, centres at z_m in S0): its
settlement over its dry settlement against the degree of consolidation of the sub-layer z < z_m of
Terzaghi's layer (docs/validation.md), no correction.  Prints the values at the T_v points and,
with two runs or more, the largest differences of each run from the first (e.g. the run
re-triangulating at every step, or with two DEM steps per coupled step).

usage: plot_consolidation.py OUT.png RUN_DIR [RUN_DIR ...]
"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def series_terms(T):
    m = np.arange(200)[:, None]
    M = (2 * m + 1) * np.pi / 2
    return M, np.exp(-M * M * np.atleast_1d(T)[None, :])


def terzaghi_p(zeta, T):
    """p/dsigma at height zeta = z/L above the sealed base, drained at z = L."""
    M, e = series_terms(T)
    return np.sum(2 / M * np.sin(M * (1 - zeta)) * e, axis=0)


def terzaghi_U_sub(zeta_m, T):
    """Degree of consolidation of the sub-layer 0 <= z <= zeta_m L: 1 - (1/zeta_m) int_0^zeta_m p/dsigma."""
    M, e = series_terms(T)
    return 1 - np.sum(2 * np.cos(M * (1 - zeta_m)) / (M * M * zeta_m) * e, axis=0)


def terzaghi_U(T):
    return terzaghi_U_sub(1.0, T)


def load(d):
    rows = list(csv.DictReader(open(os.path.join(d, "series.csv"))))
    s = {k: np.array([float(r[k]) for r in rows]) for k in ("step", "oedo_Tv", "oedo_p_mid", "oedo_p_base", "oedo_U", "oedo_U_marker")}
    keep = s["step"] > 0
    s = {k: v[keep] for k, v in s.items()}
    o = json.load(open(os.path.join(d, "summary.json")))["oedometer"]
    prof = list(csv.DictReader(open(os.path.join(d, "pressure_profile.csv"))))
    return s, o, prof


TVS = (0.1, 0.2, 0.5, 1.0)
out = sys.argv[1]
runs = [(d, *load(d)) for d in sys.argv[2:]]
fig, ax = plt.subplots(1, 4, figsize=(20, 4.5))
T = np.linspace(1e-4, 1.05, 400)
_, _, o0, _ = runs[0]
ax[0].plot(T, terzaghi_p(o0["zeta_mid"], T), "k-", label="Terzaghi, mid-height")
ax[0].plot(T, terzaghi_p(o0["zeta_base"], T), "k--", label="Terzaghi, base")
ax[1].plot(T, terzaghi_U(T), "k-", label="Terzaghi")
ax[1].plot(T, terzaghi_U_sub(o0["zeta_marker"], T), "k-.", label="Terzaghi, sub-layer $z < z_m$ ($z_m/L$ = %.3f)" % o0["zeta_marker"])
ax[2].plot(np.sqrt(T), terzaghi_U(T), "k-", label="Terzaghi")
z = np.linspace(0, 1, 100)
for k, t in enumerate(TVS):
    ax[3].plot(terzaghi_p(z, t), z, "k-", lw=0.8, label="Terzaghi" if k == 0 else None)
ref = None
for c, (d, s, o, prof) in enumerate(runs):
    col = "C%d" % c
    name = os.path.basename(os.path.normpath(d))
    ds = o["taylor_zero"]
    ax[0].plot(s["oedo_Tv"], s["oedo_p_mid"], color=col, lw=1, label="%s, mid-height" % name)
    ax[0].plot(s["oedo_Tv"], s["oedo_p_base"], color=col, lw=1, ls="--", label="%s, base" % name)
    ax[1].plot(s["oedo_Tv"], s["oedo_U"], color=col, lw=1, ls=":", label="%s, raw" % name)
    ax[1].plot(s["oedo_Tv"], (s["oedo_U"] - ds) / (1 - ds), color=col, lw=1, label="%s, corrected (Taylor)" % name)
    ax[1].plot(s["oedo_Tv"], s["oedo_U_marker"], color=col, lw=1, ls="-.", label="%s, marker layer" % name)
    ax[2].plot(np.sqrt(s["oedo_Tv"]), s["oedo_U"], color=col, lw=1, label="%s, raw U" % name)
    x = np.linspace(0, np.sqrt(0.2) * 1.3, 2)
    ax[2].plot(x, o["taylor_slope"] * x + ds, color=col, lw=0.8, ls="--", label="%s: Taylor's line, $d_s$ = %.3f" % (name, ds))
    for k, t in enumerate(TVS):
        pr = [r for r in prof if abs(float(r["Tv_target"]) - t) < 1e-9]
        if pr:
            ax[3].plot([float(r["p_over_dsigma"]) for r in pr], [float(r["z_over_L"]) for r in pr], "o", color=col, ms=3,
                       label=name if k == 0 else None)
    print("%s: E_oed = %.5g Pa, kappa/d^2 = %.4g, C_v = %.4g m^2/s, L/H = %.4f, %d coupled steps, coupled/dry step %.1f; "
          "Taylor d_s = %.4f dH, slope %.4f (Terzaghi %.4f); largest deviation %.4f (p_mid, p_base, U_corr), marker %.4f, raw U %.4f"
          % (name, o["E_oed"], o["kappa_over_d2"], o["C_v"], o["drained_face_over_H"], o["coupled_steps"],
             o.get("coupled_over_dry", float("nan")), ds, o["taylor_slope"], 2 / np.sqrt(np.pi), o["deviation"],
             o["deviation_marker"], o["deviation_raw_U"]))
    vals = {}
    for t, key in zip(TVS, ("Tv_0_1", "Tv_0_2", "Tv_0_5", "Tv_1")):
        if key not in o:
            continue
        r = o[key]
        vals[t] = (r["p_mid"], r["p_base"], r["U"], r["U_marker"])
        print("  T_v = %.1f: p_mid %.4f (Terzaghi %.4f), p_base %.4f (%.4f), U %.4f, U_corr %.4f (%.4f), U_marker %.4f (%.4f)"
              % (t, r["p_mid"], r["p_mid_terzaghi"], r["p_base"], r["p_base_terzaghi"], r["U"], r["U_corrected"],
                 r["U_terzaghi"], r["U_marker"], r["U_marker_terzaghi"]))
    if ref is None:
        ref = vals
    else:
        common = [t for t in vals if t in ref]
        worst = max(max(abs(a - b) for a, b in zip(vals[t], ref[t])) for t in common) if common else float("nan")
        print("  largest difference from %s at T_v = %s (p/dsigma, U, U_marker): %.2e"
              % (os.path.basename(os.path.normpath(runs[0][0])), ", ".join("%g" % t for t in common), worst))
for t in TVS:
    for a in ax[:2]:
        a.axvline(t, color="0.85", lw=0.8, zorder=0)
ax[0].set_xlabel("$T_v = C_v t/L^2$")
ax[0].set_ylabel(r"$p/\Delta\sigma$")
ax[1].set_xlabel("$T_v$")
ax[1].set_ylabel("U = settlement / dry settlement")
for a in ax[:2]:
    a.set_xlim(0, 1.05)
ax[2].set_xlim(0, np.sqrt(0.5))
ax[2].set_ylim(0, 0.9)
ax[2].set_xlabel(r"$\sqrt{T_v}$")
ax[2].set_ylabel("raw U")
ax[2].set_title("Taylor's construction", fontsize=9)
ax[3].set_xlabel(r"$p/\Delta\sigma$")
ax[3].set_ylabel("z/L")
ax[3].set_title("pressure profiles at $T_v$ = 0.1, 0.2, 0.5, 1", fontsize=9)
for a in ax:
    a.legend(fontsize=7)
fig.suptitle("DEM-PFV oedometer against Terzaghi (cases/consolidation)")
fig.tight_layout()
fig.savefig(out, dpi=120)
print("wrote", out)
