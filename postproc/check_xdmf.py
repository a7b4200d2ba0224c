#!/usr/bin/python3
"""check_xdmf.py FILE.xmf — check an XDMF 2 index written by ibmdem against the
XDMF 2 model (Xdmf.dtd and the XDMF 2 documentation of Domain, Grid, Topology,
Geometry, Attribute and DataItem) and against the HDF5 files it points to:

- Xdmf Version 2.x > Domain > Grid (Collection, Temporal) > Grids (Uniform) with
  increasing Time values;
- Topology 3DRectMesh / 2DRectMesh with Dimensions = node counts (slowest first),
  Geometry VXVYVZ / VXVY with one DataItem per direction, of the matching length;
- Attribute Scalar / Vector, Center Cell or Node, DataItem Dimensions = cell (or
  node) counts, plus 3 components for a vector;
- every HDF DataItem "file.h5:/path" names an existing dataset of exactly that
  shape, of the NumberType and Precision given.
Prints one line per problem and exits 1 if there is any."""
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

problems = []


def bad(msg):
    problems.append(msg)
    print("check_xdmf:", msg)


def dims_of(item):
    return [int(x) for x in item.get("Dimensions", "").split()]


def check_dataitem(item, base, want_dims, where):
    d = dims_of(item)
    if want_dims is not None and d != list(want_dims):
        bad("%s: Dimensions %s, expected %s" % (where, d, list(want_dims)))
    fmt = item.get("Format", "XML")
    if fmt != "HDF":
        bad("%s: Format %s (ibmdem writes HDF)" % (where, fmt))
        return
    ref = (item.text or "").strip()
    if ":" not in ref:
        bad("%s: '%s' is not file.h5:/path" % (where, ref))
        return
    fname, path = ref.split(":", 1)
    full = os.path.join(base, fname)
    if not os.path.exists(full):
        bad("%s: %s does not exist" % (where, full))
        return
    with h5py.File(full, "r") as f:
        if path not in f:
            bad("%s: no dataset %s in %s" % (where, path, fname))
            return
        ds = f[path]
        if list(ds.shape) != d:
            bad("%s: %s:%s has shape %s, the XDMF says %s" % (where, fname, path, list(ds.shape), d))
        nt, prec = item.get("NumberType", "Float"), int(item.get("Precision", "4"))
        want = {("Float", 8): np.float64, ("Float", 4): np.float32, ("Int", 4): np.int32, ("Int", 8): np.int64}
        if (nt, prec) not in want or ds.dtype != want[(nt, prec)]:
            bad("%s: %s:%s is %s, the XDMF says %s/%d" % (where, fname, path, ds.dtype, nt, prec))


def main(path):
    base = os.path.dirname(os.path.abspath(path))
    root = ET.parse(path).getroot()
    if root.tag != "Xdmf" or not root.get("Version", "").startswith("2"):
        bad("root element is %s version %s, expected Xdmf 2.x" % (root.tag, root.get("Version")))
    dom = root.find("Domain")
    if dom is None:
        bad("no Domain")
        return
    coll = dom.find("Grid")
    if coll is None or coll.get("GridType") != "Collection" or coll.get("CollectionType") != "Temporal":
        bad("the Domain's Grid is not a temporal collection")
        return
    times = []
    grids = coll.findall("Grid")
    if not grids:
        bad("empty collection")
    for g in grids:
        name = g.get("Name", "?")
        if g.get("GridType", "Uniform") != "Uniform":
            bad("%s: GridType %s" % (name, g.get("GridType")))
        t = g.find("Time")
        if t is None:
            bad("%s: no Time" % name)
        else:
            times.append(float(t.get("Value")))
        topo, geo = g.find("Topology"), g.find("Geometry")
        if topo is None or geo is None:
            bad("%s: Topology or Geometry missing" % name)
            continue
        ttype = topo.get("TopologyType")
        nodes = dims_of(topo)
        ndim = {"3DRectMesh": 3, "2DRectMesh": 2}.get(ttype)
        if ndim is None or len(nodes) != ndim:
            bad("%s: TopologyType %s with Dimensions %s" % (name, ttype, nodes))
            continue
        gtype = geo.get("GeometryType")
        if gtype != {3: "VXVYVZ", 2: "VXVY"}[ndim]:
            bad("%s: GeometryType %s for a %s" % (name, gtype, ttype))
        items = geo.findall("DataItem")
        if len(items) != ndim:
            bad("%s: %d geometry arrays for %d directions" % (name, len(items), ndim))
        # VX is the fastest (last) dimension
        for q, item in enumerate(items):
            check_dataitem(item, base, [nodes[ndim - 1 - q]], "%s/Geometry[%d]" % (name, q))
        for a in g.findall("Attribute"):
            an = "%s/%s" % (name, a.get("Name"))
            center, atype = a.get("Center", "Node"), a.get("AttributeType", "Scalar")
            if center not in ("Cell", "Node"):
                bad("%s: Center %s" % (an, center))
            if atype not in ("Scalar", "Vector"):
                bad("%s: AttributeType %s" % (an, atype))
            want = [n - 1 for n in nodes] if center == "Cell" else list(nodes)
            if atype == "Vector":
                want = want + [3]
            check_dataitem(a.find("DataItem"), base, want, an)
    if any(b <= a for a, b in zip(times, times[1:])):
        bad("times are not increasing: %s" % times)
    print("check_xdmf: %s: %d snapshots, t = %s .. %s, %s" % (
        path, len(grids), times[0] if times else "?", times[-1] if times else "?",
        "OK" if not problems else "%d problems" % len(problems)))


if __name__ == "__main__":
    main(sys.argv[1])
    sys.exit(1 if problems else 0)
