#!/usr/bin/env python3
"""The fluid of an avalanche run for a density ratio and a Stokes number (Izard 2014 ch. 4).

The sweep varies rho_p/rho and eta_f only, as the thesis does: the grains keep rho_p (2500 kg/m^3,
D = 5 mm, the bed of cases/avalanche/bed.ini); the fluid density is rho_p/ratio and its viscosity
the one that gives St = sqrt(rho_p (rho_p - rho) g sin(theta) D^3) / (18 sqrt(2) eta).

    avalanche_set.py RATIO ST [--theta DEG] [--rho-p KG_M3] [--d M]
prints the --set options of ibmdem (fluid.rho, fluid.nu) and, on stderr, St, r, Ar, T_v, T_i, T_ff.
"""
import argparse
import math
import sys


def fluid_for(ratio, st, theta_deg=25.0, rho_p=2500.0, d=0.005006, g=9.81):
    rho = rho_p / ratio
    drho = rho_p - rho
    gs = g * math.sin(math.radians(theta_deg))
    eta = math.sqrt(rho_p * drho * gs * d ** 3) / (18 * math.sqrt(2) * st)
    nums = {
        "St": st,
        "r": math.sqrt(5 * rho_p / (3 * rho)),
        "Ar": rho * drho * g * d ** 3 / eta ** 2,
        "T_v": 18 * eta / (drho * gs * d) / math.sqrt(d / g),
        "T_i": math.sqrt(rho * d / (2 * drho * gs)) / math.sqrt(d / g),
        "T_ff": math.sqrt(2 * rho_p * d / (drho * gs)) / math.sqrt(d / g),
    }
    return rho, eta / rho, nums


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("ratio", type=float)
    ap.add_argument("st", type=float)
    ap.add_argument("--theta", type=float, default=25.0)
    ap.add_argument("--rho-p", type=float, default=2500.0)
    ap.add_argument("--d", type=float, default=0.005006, help="mean diameter of the mobile grains (m)")
    a = ap.parse_args()
    rho, nu, nums = fluid_for(a.ratio, a.st, a.theta, a.rho_p, a.d)
    print("--set fluid.rho=%.9g --set fluid.nu=%.9g" % (rho, nu))
    print("rho_p/rho = %g: " % a.ratio + ", ".join("%s = %.4g" % kv for kv in nums.items())
          + " (times in sqrt(D/g))", file=sys.stderr)


if __name__ == "__main__":
    main()
