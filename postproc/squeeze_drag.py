#!/usr/bin/python3
"""squeeze_drag.py OUT [OUT...] — drag of the sphere of cases/squeeze_flow against Brenner's
exact result for a sphere moving towards a plane wall in Stokes flow (Brenner 1961, Chem. Eng.
Sci. 16, 242, eq. 2.19):

    F = 6 pi mu a U lambda,  lambda = 4/3 sinh(al) sum_n n(n+1)/((2n-1)(2n+3))
            [ (2 sinh((2n+1)al) + (2n+1) sinh(2al)) / (4 sinh^2((n+1/2)al) - (2n+1)^2 sinh^2(al)) - 1 ],
    cosh(al) = h/a (h: centre-to-wall distance).

Prints F/F_Brenner at gaps (h - a)/D = 1.5, 1.0, 0.5 and 0.25 (the force averaged over one time
unit around the instant the gap is reached), for each run directory; exit status 1 when a run
has no such sample.  The sphere's motion and the fluid's viscosity are read from input.ini."""
import configparser
import math
import sys

import numpy as np


def brenner(h, a):
    al = math.acosh(h / a)
    s = 0.0
    for n in range(1, 400):
        if (2 * n + 1) * al > 700:  # sinh overflows: the terms have converged long before
            break
        num = 2 * math.sinh((2 * n + 1) * al) + (2 * n + 1) * math.sinh(2 * al)
        den = 4 * math.sinh((n + 0.5) * al) ** 2 - (2 * n + 1) ** 2 * math.sinh(al) ** 2
        s += n * (n + 1) / ((2 * n - 1) * (2 * n + 3)) * (num / den - 1)
    return 4.0 / 3.0 * math.sinh(al) * s


def ratios(out):
    cfg = configparser.ConfigParser(inline_comment_prefixes=(";", "#"), strict=False)
    cfg.read(out + "/input.ini")
    nu = float(cfg["fluid"]["nu"].split()[0])
    rho = float(cfg["fluid"].get("rho", "1").split()[0])
    words = cfg["ibm"]["sphere1"].split()
    a = 0.5 * float(words[words.index("diameter") + 1])
    U = abs(float(words[words.index("velocity") + 2]))
    d = np.genfromtxt(out + "/series.csv", delimiter=",", names=True)
    t, y, f = d["time"], d["s1_y"], d["s1_fy"]
    res = {}
    for gap in (1.5, 1.0, 0.5, 0.25):
        h = a + gap * 2 * a
        k = int(np.argmin(abs(y - h)))
        if abs(y[k] - h) > 0.05 * a:
            continue
        w = abs(t - t[k]) <= 0.5
        res[gap] = f[w].mean() / (6 * math.pi * rho * nu * a * U * brenner(h, a))
    return res


if __name__ == "__main__":
    bad = 0
    for out in sys.argv[1:]:
        r = ratios(out)
        print(out, " ".join("gap %.2g D: %.4f" % (g, v) for g, v in sorted(r.items(), reverse=True)))
        bad |= len(r) == 0
    sys.exit(bad)
