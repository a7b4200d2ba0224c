#!/usr/bin/python3
"""Write bed30.csv, the random fixed bed of the cross-check (crosscheck.py, cases bed30_*):
N = 30 spheres of diameter D = 1 in a triply periodic cube of side L = (N pi / (6 phi))^(1/3)
at the solid fraction phi = 0.40, every pair of surfaces (periodic images included) at least
gap_min = 0.1 D apart.

Generated, not cut from a DEM packing (a settled DEM packing is at phi ~ 0.6 and not periodic):
numpy's default_rng(seed) draws the centres uniformly in the cube; the overlaps of spheres of
diameter D + gap_min (the hard core) are relaxed by repeated pairwise pushes (minimum image)
until none is left; then 500 Metropolis sweeps of hard-core moves (the same generator) shuffle
the configuration (a hard-sphere fluid of hard-core fraction phi (1 + gap_min)^3 = 0.53).
The output: a CSV for [ibm] spheres_file (x,y,z,diameter,fixed), centres wrapped into [0, L),
and a header comment with N, L, phi, seed and the smallest surface gap.

Usage (from the repository root): /usr/bin/python3 bench/crosscheck/make_bed.py [--check]
(--check: regenerate and compare with the committed file, exit 1 if they differ)."""
import math
import sys

import numpy as np

N, PHI, D, GAP, SEED, SWEEPS = 30, 0.40, 1.0, 0.1, 20211, 500
OUT = "bench/crosscheck/bed30.csv"


def min_image(d, L):
    return d - L * np.round(d / L)


def pair_dist(x, L):
    d = min_image(x[:, None, :] - x[None, :, :], L)
    r = np.sqrt((d ** 2).sum(-1))
    np.fill_diagonal(r, np.inf)
    return d, r


def generate():
    L = (N * math.pi * D ** 3 / (6 * PHI)) ** (1.0 / 3.0)
    core = D + GAP
    rng = np.random.default_rng(SEED)
    x = rng.uniform(0, L, size=(N, 3))
    # relax the overlaps of the hard cores (pushed to 1.0005 core, so that none is left)
    for it in range(200000):
        d, r = pair_dist(x, L)
        ov = np.clip(1.0005 * core - r, 0, None)
        if r.min() >= core:
            break
        push = (d / np.where(np.isfinite(r), r, 1.0)[..., None] * ov[..., None]).sum(1) * 0.5
        x = (x + push) % L
    else:
        sys.exit("make_bed: the overlaps were not relaxed")
    # Metropolis sweeps of the hard-core fluid
    step, acc = 0.04, 0
    for sw in range(SWEEPS):
        for i in range(N):
            trial = (x[i] + rng.uniform(-step, step, 3)) % L
            dd = min_image(x - trial, L)
            rr = np.sqrt((dd ** 2).sum(-1))
            rr[i] = np.inf
            if rr.min() >= core:
                x[i] = trial
                acc += 1
    _, r = pair_dist(x, L)
    return L, x, r.min() - D, acc / (SWEEPS * N)


def main():
    L, x, gmin, acc = generate()
    phi = N * math.pi / 6 / L ** 3
    text = ("# random fixed bed (bench/crosscheck/make_bed.py): N = %d, D = %g, L = %.17g, phi = %.6f, "
            "seed %d, smallest surface gap %.6f D (periodic images included), Metropolis acceptance %.3f\n"
            % (N, D, L, phi, SEED, gmin, acc))
    text += "x,y,z,diameter,fixed\n" + "".join("%.12f,%.12f,%.12f,%g,1\n" % (a, b, c, D) for a, b, c in x)
    if "--check" in sys.argv:
        if open(OUT).read() != text:
            sys.exit("make_bed: %s differs from the regenerated bed" % OUT)
        print("make_bed: %s reproduced" % OUT)
        return
    open(OUT, "w").write(text)
    print(text.splitlines()[0])


if __name__ == "__main__":
    main()
