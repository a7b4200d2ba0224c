#!/usr/bin/python3
"""Called by the LIGGGHTS/LAMMPS benchmark inputs through `shell` around the
timed loop: appends "<label> <wall time> <cpu time of the simulation process>"
to a file.  The simulation calls system(), i.e. `sh -c`, which may exec this
script in place of the shell (dash does): the simulation process is the first
ancestor that is not a shell.

usage: cpustamp.py LABEL FILE
"""
import os
import sys
import time


def cpu_seconds(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    ticks = os.sysconf("SC_CLK_TCK")
    return (int(fields[11]) + int(fields[12])) / ticks  # utime + stime


def parent_of(pid):
    with open("/proc/%d/stat" % pid) as f:
        return int(f.read().rsplit(")", 1)[1].split()[1])


def name_of(pid):
    with open("/proc/%d/stat" % pid) as f:
        text = f.read()
    return text[text.index("(") + 1:text.rindex(")")]


def main():
    label, out = sys.argv[1], sys.argv[2]
    sim = os.getppid()
    while name_of(sim) in ("sh", "dash", "bash") and sim > 1:
        sim = parent_of(sim)
    with open(out, "a") as f:
        f.write("%s %.6f %.3f\n" % (label, time.time(), cpu_seconds(sim)))


if __name__ == "__main__":
    main()
