#!/usr/bin/python3
"""Write packing_N200.h5, the packing that both the resolved solver ([ibm] spheres_file) and
the pore network ([porenet] packing) read: the reference prototype's periodic packing
tests/data/porenet/proto_N200_phi0.60_pd0.05.txt (catalano_pfv.md section 6: 200 spheres,
radii 1 +- 5 %, solid fraction 0.60, overlaps relaxed below 2e-4 r), in the DEM's HDF5 layout:
position [n][3], radius [n], fixed [n] (= 1: the immersed spheres are held at rest); the
attribute L is the period of the cube.
Usage (from the repository root): /usr/bin/python3 cases/permeability_crosscheck/make_packing.py"""
import numpy as np
import h5py

src = "tests/data/porenet/proto_N200_phi0.60_pd0.05.txt"
L = None
for line in open(src):
    if line.startswith("# L = "):
        L = float(line[6:])
a = np.loadtxt(src)
with h5py.File("cases/permeability_crosscheck/packing_N200.h5", "w") as f:
    f["position"] = a[:, :3]
    f["radius"] = a[:, 3]
    f["fixed"] = np.ones(len(a), dtype=np.int32)
    f.attrs["L"] = L
    f.attrs["source"] = src
print(f"{len(a)} spheres, L = {L!r}, mean radius {a[:, 3].mean():.6f}, "
      f"solid fraction {(4 / 3 * np.pi * a[:, 3] ** 3).sum() / L ** 3:.6f}")
