#!/usr/bin/python3
"""checkpoint_particles.py CHECKPOINT.h5 OUT.h5 — the DEM particles of a checkpoint as a packing
file that `[particles] source = file` reads (positions, velocities, spins, contact springs, lists):
the state of a run, e.g. a flowing bed, as the initial state of another.  Centres a periodic
direction carried past the domain are wrapped back into it (no wall lets a particle out); the
time is set to 0 (the new run starts there)."""
import sys

import h5py
import numpy as np

if len(sys.argv) != 3:
    sys.exit(__doc__)
src_file = h5py.File(sys.argv[1], "r")
if "dem" not in src_file:
    sys.exit(f"{sys.argv[1]}: no /dem group (not a checkpoint of a run with particles)")
src = src_file["dem"]
with h5py.File(sys.argv[2], "w") as dst:
    for k, v in src.attrs.items():
        dst.attrs[k] = v
    for k in src.keys():
        src.copy(src[k], dst, name=k)
    lo, hi = np.asarray(src.attrs["domain_lo"]), np.asarray(src.attrs["domain_hi"])
    p = dst["position"][()]
    for c in range(3):
        out = (p[:, c] < lo[c]) | (p[:, c] >= hi[c])
        if out.any():
            p[:, c] = lo[c] + np.mod(p[:, c] - lo[c], hi[c] - lo[c])
    dst["position"][...] = p
    dst.attrs["time"] = 0.0
print(f"{sys.argv[2]}: {len(p)} particles of {sys.argv[1]} (t = {float(np.ravel(src.attrs['time'])[0]):.9g} s there, 0 here)")
