#!/usr/bin/python3
"""Called by the LIGGGHTS/LAMMPS benchmark inputs through `shell` around the
timed loop: appends "<label> <wall time> <cpu time of the simulation process>"
to a file.  The simulation runs `sh -c` which runs this script, so the
simulation process is the grandparent.

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


def main():
    label, out = sys.argv[1], sys.argv[2]
    sim = parent_of(os.getppid())
    with open(out, "a") as f:
        f.write("%s %.6f %.3f\n" % (label, time.time(), cpu_seconds(sim)))


if __name__ == "__main__":
    main()
