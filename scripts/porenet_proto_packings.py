#!/usr/bin/python3
"""Write the packings of the reference prototype (catalano_pfv.md section 6) to
tests/data/porenet/ so that the C pore network is compared with the prototype
on the SAME packings, and print the prototype's permeability for each.
Usage: /usr/bin/python3 scripts/porenet_proto_packings.py PROTO_DIR OUT_DIR
(the prototype itself is not copied into the repository)."""
import sys, os, importlib.util
import numpy as np
spec = importlib.util.spec_from_file_location("proto", os.path.join(sys.argv[1], "catalano_pfv_proto.py"))
proto = importlib.util.module_from_spec(spec); spec.loader.exec_module(proto)
out = sys.argv[2]
cases = [(1000, 0.55, 0.05), (1000, 0.58, 0.05), (1000, 0.60, 0.05), (1000, 0.62, 0.05),
         (200, 0.60, 0.05), (500, 0.60, 0.5)]
for N, phi, polyd in cases:
    x, r, L, it, ov = proto.make_packing(N, phi, polyd=polyd, seed=3)
    m = proto.build(x, r, L); rows, st = proto.network(m)
    kap, F = proto.permeability(m, rows)
    d = 2*np.mean(r)
    name = f"proto_N{N}_phi{phi:.2f}_pd{polyd:g}.txt"
    with open(os.path.join(out, name), "w") as f:
        f.write(f"# catalano_pfv_proto.py make_packing(N={N}, phi={phi}, polyd={polyd}, seed=3)\n")
        f.write(f"# prototype: kappa_z/d^2 = {kap/d**2:.10e} (d = 2 mean r, alpha = 1/2, mu = 1, periodic)\n")
        f.write(f"# L = {L:.17g}\n")
        for p, rr in zip(x, r):
            f.write(f"{p[0]:.17g} {p[1]:.17g} {p[2]:.17g} {rr:.17g}\n")
    print(name, f"kappa/d^2 = {kap/d**2:.6e}", flush=True)
