#!/usr/bin/python3
"""Release height of a sphere settling onto a wall, for a target impact speed.

usage: bounce_release.py --D D --rho-p RHO_P --rho RHO --mu MU [--g G] (--speed V | --fraction F)

SI units.  The fall from rest is integrated with the quasi-steady Schiller-Naumann drag and the added mass of a
sphere in unbounded fluid (C_M = 1/2), no history force:
    (rho_p + rho/2) V_p du/dt = (rho_p - rho) V_p g - 1/2 rho u^2 (pi D^2/4) C_D(Re),
    C_D = 24/Re (1 + 0.15 Re^0.687)
(scipy's solve_ivp, an event where u reaches the target).  --speed gives the impact speed, --fraction a fraction
of the terminal velocity (the terminal velocity itself is reached only asymptotically: use 0.99-0.995).  The
history force slows the approach to the terminal velocity, so the resolved fall needs more than this estimate:
the script also prints the release gap the restitution sweep uses (scripts/restitution_cases.py: 1.25 times
the estimate plus 3 D).  The wall's own influence (within about one diameter)
is not in the model: release 1 D more than the printed fall, or measure the impact speed of the run
(summary.json coupling.V_T and V_in) and correct.  Prints the Schiller-Naumann terminal velocity, Re, Ga, St and
the fall heights in m and in D.
"""
import argparse
import math
import sys

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    p.add_argument("--D", type=float, required=True, help="diameter (m)")
    p.add_argument("--rho-p", type=float, required=True, help="particle density (kg/m^3)")
    p.add_argument("--rho", type=float, required=True, help="fluid density (kg/m^3)")
    p.add_argument("--mu", type=float, required=True, help="dynamic viscosity (Pa s)")
    p.add_argument("--g", type=float, default=9.81, help="gravity (m/s^2)")
    q = p.add_mutually_exclusive_group(required=True)
    q.add_argument("--speed", type=float, help="target impact speed (m/s)")
    q.add_argument("--fraction", type=float, help="target speed as a fraction of the terminal velocity")
    a = p.parse_args()
    D, rp, rf, mu, g = a.D, a.rho_p, a.rho, a.mu, a.g
    if rp <= rf:
        sys.exit("the particle must be denser than the fluid")
    nu = mu / rf
    Vp, A = math.pi * D ** 3 / 6, math.pi * D * D / 4

    def cd(re):
        return 24 / re * (1 + 0.15 * re ** 0.687)

    ar = (rp / rf - 1) * g * D ** 3 / nu ** 2
    re_t = brentq(lambda re: cd(re) * re * re - 4 / 3 * ar, 1e-12, ar / 18 + 1)
    vt = re_t * nu / D
    target = a.speed if a.speed is not None else a.fraction * vt
    if not 0 < target < vt:
        sys.exit(f"the target {target:.6g} m/s must be between 0 and the terminal velocity {vt:.6g} m/s")

    def rhs(t, y):
        u = max(y[1], 1e-300)
        drag = 0.5 * rf * u * u * A * cd(u * D / nu)
        return [u, ((rp - rf) * Vp * g - drag) / ((rp + 0.5 * rf) * Vp)]

    hit = lambda t, y: y[1] - target
    hit.terminal, hit.direction = True, 1
    tmax = 200 * (rp + 0.5 * rf) * D * D / (18 * mu) + 100 * D / vt
    sol = solve_ivp(rhs, (0, tmax), [0.0, 0.0], events=hit, rtol=1e-10, atol=[1e-14, 1e-14], max_step=tmax / 1e4)
    if not sol.t_events[0].size:
        sys.exit("the target speed was not reached")
    fall = sol.y_events[0][0][0]
    st = rp * target * D / (9 * mu)
    print(f"Schiller-Naumann terminal velocity {vt:.6g} m/s (Re {re_t:.4g}); Ga = {math.sqrt(ar):.4g}, "
          f"rho_p/rho = {rp / rf:.4g}")
    print(f"impact speed {target:.6g} m/s = {target / vt:.4f} V_T: Re {target * D / nu:.4g}, "
          f"St = rho_p V D/(9 mu) = {st:.4g}, (rho_p + rho/2) V D/(9 mu) = {(rp + 0.5 * rf) * target * D / (9 * mu):.4g}")
    print(f"quasi-steady fall from rest: {fall:.6g} m = {fall / D:.4g} D in {sol.t_events[0][0]:.4g} s")
    print(f"suggested release gap (history force and wall margin: 1.25 x + 3 D): {1.25 * fall + 3 * D:.6g} m = "
          f"{1.25 * fall / D + 3:.4g} D")


if __name__ == "__main__":
    main()
