#!/usr/bin/python3
"""compare_runs.py A B — are two output folders of ibmdem the same run?

Every file the runs wrote must be in both folders and identical: HDF5 files
(snapshots, checkpoints) dataset by dataset and attribute by attribute, bit
for bit; CSV files line by line (series.csv without its wall_per_step
column); XDMF indexes, input.ini and the other text files byte for byte;
summary.json key by key without the entries that measure the machine (cost, wall
and CPU times, speeds, memory) or say how the run went (restarted_from,
steps_this_run).  log.txt, which records how the run went, is not compared.
The name of the folder (in the resolved input, the summary) is the only
allowed difference: A's path is read as B's.
Prints the differences; exit status 0 when there are none.

    compare_runs.py A B --checkpoint-groups   (two checkpoint files: only the
                                               groups of the parts, without the
                                               list of the snapshots written)
    compare_runs.py A B --skip NAME           (a dataset, attribute, summary key
                                               or file NAME.* not compared, e.g.
                                               input)
"""
import json
import os
import sys

import h5py
import numpy as np

NOT_COMPARED = {"log.txt", ".ibmdem.lock"}
# the checkpoints' hash of series.csv covers its wall_per_step column
ALWAYS_SKIPPED = ("series_hash",)
# summary.json entries that measure the machine or the way the run went
MACHINE = ("wall", "per_second", "rss", "restarted_from", "steps_this_run", "time_", "bytes_per", "cost.")


RENAME = [None, None]  # folder A's path, read as B's


def renamed(v):
    if RENAME[0] is None:
        return v
    if isinstance(v, bytes):
        return v.replace(RENAME[0].encode(), RENAME[1].encode())
    if isinstance(v, str):
        return v.replace(RENAME[0], RENAME[1])
    return v


def same_value(x, y):
    x = renamed(x)
    if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
        x, y = np.asarray(x), np.asarray(y)
        if x.shape != y.shape or x.dtype != y.dtype:
            return False
        if x.dtype.kind == "f":  # bit for bit (NaN == NaN, -0 != +0)
            return x.tobytes() == y.tobytes()
        return np.array_equal(x, y)
    return x == y


def diff_h5(a, b, only_groups=False, skip=()):
    out = []
    skip = tuple(skip) + ALWAYS_SKIPPED
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        def attrs(name, oa, ob):
            for k in set(oa.attrs) | set(ob.attrs):
                if k in skip:
                    continue
                if k not in oa.attrs or k not in ob.attrs:
                    out.append(f"{a}: attribute {name}@{k} in one file only")
                elif not same_value(oa.attrs[k], ob.attrs[k]):
                    out.append(f"{a}: attribute {name}@{k} differs")

        names = []
        fa.visit(names.append)
        namesb = []
        fb.visit(namesb.append)
        if only_groups:
            names = [n for n in names if "/" in n or isinstance(fa[n], h5py.Group)]
            namesb = [n for n in namesb if "/" in n or isinstance(fb[n], h5py.Group)]
        names = [n for n in names if n.split("/")[-1] not in skip]
        namesb = [n for n in namesb if n.split("/")[-1] not in skip]
        for n in sorted(set(names) ^ set(namesb)):
            out.append(f"{a}: /{n} in one file only")
        if not only_groups:
            attrs("/", fa, fb)
        for n in sorted(set(names) & set(namesb)):
            oa, ob = fa[n], fb[n]
            attrs("/" + n, oa, ob)
            if isinstance(oa, h5py.Dataset) and not same_value(oa[()], ob[()]):
                out.append(f"{a}: dataset /{n} differs")
    return out


def diff_csv(a, b):
    la, lb = open(a).read().splitlines(), open(b).read().splitlines()
    drop = None
    if la and "wall_per_step" in la[0].split(","):
        drop = la[0].split(",").index("wall_per_step")
    def cut(line):
        if drop is None:
            return line
        f = line.split(",")
        return ",".join(f[:drop] + f[drop + 1:])
    la, lb = [cut(x) for x in la], [cut(x) for x in lb]
    if la == lb:
        return []
    for i, (x, y) in enumerate(zip(la, lb)):
        if x != y:
            return [f"{a}: line {i + 1} differs:\n    {x}\n    {y}"]
    return [f"{a}: {len(la)} lines, the other {len(lb)}"]


def flat(d, prefix=""):
    for k, v in d.items():
        if isinstance(v, dict):
            yield from flat(v, prefix + k + ".")
        else:
            yield prefix + k, v


def diff_summary(a, b, skip=()):
    keep = lambda k: not any(m in k for m in MACHINE) and k.split(".")[-1] not in skip
    da = {k: renamed(v) for k, v in flat(json.load(open(a))) if keep(k)}
    db = {k: v for k, v in flat(json.load(open(b))) if keep(k)}
    return [f"{a}: {k}: {da.get(k)} and {db.get(k)}" for k in sorted(set(da) | set(db)) if da.get(k) != db.get(k)]


def diff_dirs(a, b, skip=()):
    fa = {f for f in os.listdir(a) if f not in NOT_COMPARED}
    fb = {f for f in os.listdir(b) if f not in NOT_COMPARED}
    out = [f"{f}: in one folder only ({a if f in fa else b})" for f in sorted(fa ^ fb)]
    for f in sorted(fa & fb):
        pa, pb = os.path.join(a, f), os.path.join(b, f)
        if f.split(".")[0] in skip:
            continue
        if f.endswith(".h5"):
            out += diff_h5(pa, pb, skip=skip)
        elif f.endswith(".csv"):
            out += diff_csv(pa, pb)
        elif f == "summary.json":
            out += diff_summary(pa, pb, skip)
        elif renamed(open(pa, "rb").read()) != open(pb, "rb").read():
            out.append(f"{pa}: differs")
    return out


def main():
    argv = sys.argv[1:]
    skip = []
    while "--skip" in argv:
        i = argv.index("--skip")
        skip.append(argv[i + 1])
        del argv[i:i + 2]
    args = [x for x in argv if not x.startswith("--")]
    if os.path.isdir(args[0]):
        RENAME[:] = [args[0].rstrip("/"), args[1].rstrip("/")]
        out = diff_dirs(args[0], args[1], tuple(skip))
    else:
        # two checkpoints: the state (the groups of the parts), not the
        # bookkeeping of the outputs written before them
        if "--checkpoint-groups" in argv:
            skip += ["snapshots", "snapshot_times", "snapshot_counts", "csv_last_step", "csv_hash"]
        out = diff_h5(args[0], args[1], only_groups="--checkpoint-groups" in argv, skip=tuple(skip))
    for line in out[:20]:
        print("#  ", line)
    if len(out) > 20:
        print(f"#   ... {len(out) - 20} more")
    sys.exit(1 if out else 0)


if __name__ == "__main__":
    main()
