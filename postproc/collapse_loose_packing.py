#!/usr/bin/python3
"""The loose column of case F on the bed of the collapse's box (cases/column_collapse/README.md).

usage: collapse_loose_packing.py SETTLED BED R0 OUT
  SETTLED  the last particle snapshot of case_settle.ini: the grains settled in the fluid in the
           column's own box (x <= R0) and the fixed bed grains under them
  BED      a packing, snapshot or checkpoint of the collapse's box (e.g. case A's column_packing.h5)
           whose fixed grains are the bed
  R0       the gate's position (m)
  OUT      the packing written (HDF5, the particle-snapshot layout that [particles] source = file
           reads): the settled grains and their bed, and the fixed grains of BED that lie wholly
           beyond the gate (x - r >= R0); every velocity and spin set to zero (grains and fluid
           at rest at t = 0, as the thesis starts the collapse); time 0; ids renumbered
Prints the counts, the largest speed the settled grains had (how far from rest the settling
ended) and the column's top in bins of 2 D (the flatness of the settled surface).
"""
import sys

import h5py
import numpy as np


def read(path):
    with h5py.File(path, "r") as f:
        return {k: f[k][...] for k in ("position", "radius", "density", "fixed")} | {
            "velocity": f["velocity"][...]}


def main():
    settled, bed, R0, out = read(sys.argv[1]), read(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    mob = settled["fixed"] == 0
    if settled["position"][:, 0].max() > R0 * (1 + 1e-9):
        sys.exit(f"collapse_loose_packing: {sys.argv[1]} has a centre beyond R0 = {R0}")
    beyond = (bed["fixed"] != 0) & (bed["position"][:, 0] - bed["radius"] >= R0)
    pos = np.concatenate([settled["position"], bed["position"][beyond]])
    rad = np.concatenate([settled["radius"], bed["radius"][beyond]])
    rho = np.concatenate([settled["density"], bed["density"][beyond]])
    fix = np.concatenate([settled["fixed"], bed["fixed"][beyond]]).astype(np.int32)
    n = len(rad)
    with h5py.File(out, "w") as f:
        f.create_dataset("position", data=pos)
        f.create_dataset("velocity", data=np.zeros((n, 3)))
        f.create_dataset("omega", data=np.zeros((n, 3)))
        f.create_dataset("radius", data=rad)
        f.create_dataset("density", data=rho)
        f.create_dataset("id", data=np.arange(n, dtype=np.int64))
        f.create_dataset("fixed", data=fix)
        f.attrs["time"] = np.array([0.0])
        f.attrs["step"] = np.int64(0)
    D = 2 * settled["radius"][mob].mean()
    x, top = settled["position"][mob, 0], settled["position"][mob, 2] + settled["radius"][mob]
    bins = [top[(x >= b) & (x < b + 2 * D)].max() / D for b in np.arange(0, R0 - 1e-9, 2 * D)
            if ((x >= b) & (x < b + 2 * D)).any()]
    vmax = np.abs(settled["velocity"][mob]).max()
    print(f"collapse_loose_packing: {mob.sum()} grains, {(~mob).sum()} bed grains under them, "
          f"{beyond.sum()} bed grains beyond the gate -> {out}; largest speed at the end of the settling "
          f"{vmax:.3g} m/s; top in bins of 2 D from the wall: " + " ".join(f"{b:.1f}" for b in bins) + " D")


if __name__ == "__main__":
    main()
