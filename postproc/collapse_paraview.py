#!/usr/bin/pvpython
"""The pore pressure of a column-collapse run as ParaView shows it: fields.xmf opened with
ParaView's XDMF reader, the snapshot nearest to a time, a slice through the middle of the width,
the pressure relative to probes.reference over Delta rho g H0 in colour (range twice the basal extremes of column.json) and the grains' outlines (solid_fraction = 0.5) in black.

usage: xvfb-run -a pvpython postproc/collapse_paraview.py RUN_DIR OUT.png [TIME]
  RUN_DIR  a resolved run of cases/column_collapse with its column.json
           (postproc/column_collapse.py: Delta rho g H0, the time of the basal pressure's minimum)
  TIME     simulated time (s) of the snapshot; default the time of p_b's extreme of the sign of its
           first excursion (column.json: t_pb_min, or t_pb_max when pb_first > 0)
Checks on the way that the reader gives the pressure, velocity and solid_fraction cell arrays of
the snapshot on the grid of fields_00000.h5 (exit 1 otherwise).  ParaView needs an X display:
run it under xvfb-run (scripts/collapse.sh does, when both are installed).
"""
import configparser
import json
import os
import sys

import h5py
from paraview.simple import (Calculator, ColorBy, Contour, CreateView, GetColorTransferFunction, GetScalarBar, ResetCamera,
                             CellDatatoPointData,
                             SaveScreenshot, Show, Slice, XDMFReader)

run, png = sys.argv[1], sys.argv[2]
with open(os.path.join(run, "column.json")) as f:
    col = json.load(f)
ini = configparser.ConfigParser(inline_comment_prefixes=(";", "#"))
ini.read(os.path.join(run, "input.ini"))
rho = float(ini["fluid"].get("rho", "1000"))
# default: p_b's extreme of the sign it first leaves hydrostatic with (dense: the minimum; loose: the maximum)
t_want = float(sys.argv[3]) if len(sys.argv) > 3 else col["t_pb_max" if col.get("pb_first", -1) > 0 else "t_pb_min"]

r = XDMFReader(FileNames=[os.path.join(run, "fields.xmf")])
r.UpdatePipelineInformation()
times = list(r.TimestepValues) or [0.0]
t = min(times, key=lambda v: abs(v - t_want))
r.UpdatePipeline(t)
# what the reader gives, from its data information (the grid itself stays on the server)
info = r.GetDataInformation()
arrays = set(r.CellData.keys())
ext = info.GetExtent()
dims = (ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1)
need = {"pressure", "velocity", "solid_fraction"}
if not need <= arrays:
    print(f"collapse_paraview: {run}: arrays {sorted(arrays)} lack {sorted(need - arrays)}")
    sys.exit(1)
bounds = info.GetBounds()
print(f"collapse_paraview: {info.GetDataSetTypeAsString()} {dims} points, {len(times)} snapshots; "
      f"t = {t:.4f} s ({t / col['T_visq']:.0f} T_visq)")

with h5py.File(os.path.join(run, "fields_00000.h5"), "r") as f:  # the grid the run wrote
    yf, shape = f["y"][...], f["pressure"].shape
if shape != (dims[2] - 1, dims[1] - 1, dims[0] - 1):
    print(f"collapse_paraview: {run}: ParaView's grid {dims} points, the HDF5 pressure {shape} cells")
    sys.exit(1)
# the slice through the cell centre nearest to the middle of the width (not through a face)
ymid = float(min(0.5 * (yf[1:] + yf[:-1]), key=lambda y: abs(y - 0.5 * (bounds[2] + bounds[3]))))
sl = Slice(Input=r)
sl.SliceType = "Plane"
sl.SliceType.Origin = [bounds[0], ymid, bounds[4]]
sl.SliceType.Normal = [0, 1, 0]
pp = Calculator(Input=sl)
pp.AttributeType = "Cell Data"
pp.ResultArrayName = "p_over_drho_g_H0"
# relative to the clear fluid at probes.reference (as p_b): the solver's pressure has a zero mean
pref = 0.0
if ini.has_option("probes", "reference"):
    xr = [float(v) for v in ini["probes"]["reference"].split()]
    with h5py.File(os.path.join(run, f"fields_{times.index(t):05d}.h5"), "r") as f:
        ijk = [int(abs(f[c][...] - v).argmin()) for c, v in zip(("xc", "yc", "zc"), xr)]
        pref = float(f["pressure"][ijk[2], ijk[1], ijk[0]])
pp.Function = f"(pressure - {pref!r})*{rho}/{col['drho_g_H0']}"
pts = CellDatatoPointData(Input=sl)
ct = Contour(Input=pts)
ct.ContourBy = ["POINTS", "solid_fraction"]
ct.Isosurfaces = [0.5]

v = CreateView("RenderView")
v.ViewSize = [1600, 520]
v.OrientationAxesVisibility = 0
v.Background = [1, 1, 1]
try:
    v.UseColorPaletteForBackground = 0
except AttributeError:
    pass
v.ViewTime = t
d = Show(pp, v)
d.Ambient, d.Diffuse = 1.0, 0.0  # flat colours
ColorBy(d, ("CELLS", "p_over_drho_g_H0"))
lut = GetColorTransferFunction("p_over_drho_g_H0")
lut.ApplyPreset("Cool to Warm", True)
prange = 2 * max(abs(col["pb_min"]), abs(col["pb_max"]), 0.01)  # twice the basal extremes
lut.RescaleTransferFunction(-prange, prange)
d.SetScalarBarVisibility(v, True)
c = Show(ct, v)
c.DiffuseColor = [0, 0, 0]
c.AmbientColor = [0, 0, 0]
c.ColorArrayName = ["POINTS", ""]
c.LineWidth = 1.0
# the column's region: x up to 3 R0 (or the box), z up to 1.6 H0 (or the box)
R0 = col["R_inf"] / col["R_inf_over_R0"]
x1 = min(bounds[1], 3.0 * R0)
z1 = min(bounds[5], 1.6 * col["H0"] + 0.02)
xc, zc = 0.5 * (bounds[0] + x1), 0.5 * (bounds[4] + z1)
v.CameraParallelProjection = 1
v.CameraPosition = [xc, ymid - 1.0, zc]
v.CameraFocalPoint = [xc, ymid, zc]
v.CameraViewUp = [0, 0, 1]
ResetCamera(v)  # the clipping range
v.CameraPosition = [xc, ymid - 1.0, zc]
v.CameraFocalPoint = [xc, ymid, zc]
v.CameraParallelScale = 0.55 * max(z1 - bounds[4], (x1 - bounds[0]) * 520 / 1600)
sb = GetScalarBar(lut, v)
sb.Title = "p / (drho g H0)"
sb.ComponentTitle = ""
sb.TitleColor = sb.LabelColor = [0, 0, 0]
SaveScreenshot(png, v, ImageResolution=[1600, 520])
print(f"collapse_paraview: {png}")
