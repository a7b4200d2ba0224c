#!/usr/bin/pvpython
"""check_porenet_paraview.py DIR/porenet.xmf — ParaView opens the pore-network
snapshot index: three unstructured grids (pore tetrahedra, throat segments,
sphere points) whose pressure and force arrays equal the HDF5 data."""
import sys
from paraview.simple import XDMFReader, MergeBlocks
from vtk.util.numpy_support import vtk_to_numpy
import h5py, numpy as np, os
r = XDMFReader(FileNames=[sys.argv[1]])
r.UpdatePipeline()
d = r.GetClientSideObject().GetOutputDataObject(0)
f = h5py.File(os.path.join(os.path.dirname(sys.argv[1]), "porenet_00000.h5"))
names = []
ok = True
it = d.NewIterator(); it.InitTraversal()
while not it.IsDoneWithTraversal():
    b = it.GetCurrentDataObject()
    names.append((b.GetClassName(), b.GetNumberOfPoints(), b.GetNumberOfCells()))
    if b.GetCellData().GetArray("pressure") is not None:
        ok &= np.array_equal(vtk_to_numpy(b.GetCellData().GetArray("pressure")), f["pores/pressure"][...])
        ok &= b.GetNumberOfCells() == f["pores/tets"].shape[0]
    if b.GetPointData().GetArray("force") is not None:
        ok &= np.array_equal(vtk_to_numpy(b.GetPointData().GetArray("force")), f["spheres/force"][...])
    it.GoToNextItem()
print("paraview:", names, "equal:", ok)
sys.exit(0 if ok and len(names) == 3 else 1)
