#!/usr/bin/python3
"""fuzz.py — mutated case files through `ibmdem check` and a few steps of
`ibmdem run`, asserting clean outcomes only (docs/user-guide.md, "What the
code refuses"):

  check  exit 0 (the resolved input, "; check: valid"), or exit 2 with a
         message `FILE:LINE: ...` / `FILE: section.key: ...` naming the case file;
  run    the same, or exit 0 with finite numbers in series.csv and a valid
         summary.json, exit 3 (diverged: a message and its checkpoint), exit 1
         (a part halted the run: a message and summary status "halted");

never a signal, a sanitizer report, a hang (timeouts) or another status.
Each process gets --memory GB of address space (4 by default; under the
sanitizers their allocations are capped instead): input that passes the
checks but needs more (the checks refuse what exceeds the machine's memory)
ends with "out of memory", status 1, which counts as clean.

Every case file of cases/ is the start of its mutants (its grid shrunk to a
few cells for speed): lines deleted, duplicated, swapped, indented or cut;
numbers made extreme, non-finite, hexadecimal or of the wrong type; values
and comments thousands of bytes long; bytes that are not UTF-8 text or are
control characters; section headers broken; impossible geometry (a sphere
1000 times larger, two at the same centre, a centre far outside, speeds of
1e200).  Runs take `time.max_steps` steps at most (--set) and mutate values
only (syntax errors are for check).

Reproducible: mutant M of case C depends on the seed, C and M only.
  tests/fuzz.py --bin build/ibmdem --seed 17 --checks 1 --runs 1   (make test)
  make fuzz                          (--checks 40 --runs 8; FUZZ_SEED, FUZZ_ARGS)
  FUZZ_SEED=5 make test              (tests/fuzz_test.sh reads FUZZ_SEED)
  tests/fuzz.py --bin build/ibmdem --seed 17 --case cavity/cavity.ini --only check:2 --keep
A failure prints the mutant's mutations and the command that reproduces it;
--keep (or any failure) keeps the mutant files in the work folder.

Output: TAP lines, one per case file (tests/run.sh counts them).
"""
import argparse
import concurrent.futures
import glob
import json
import math
import os
import random
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import zlib

EXTREME = ["0", "-0", "-1", "1", "2", "3", "1e308", "-1e308", "1e-308", "4.9e-324", "1e309", "-1e309", "nan", "-nan",
           "inf", "-inf", "Infinity", "0x10", "0X1p3", "1e999", "2147483647", "2147483648", "-2147483648",
           "9223372036854775808", "1.5", "1e100", "1e200", "-1e200", "1e-200", "00", "+5", "1e+", "1,5", "1..2",
           "١"]
WRONG = ["abc", "true", "", "1 2", "1 2 3 4", "[x]", "=", "x = y", "e5", "+-1", ".", "-", "; 1", "1 ; 2", "\"1\"",
         "NULL", "none", "0 0 0 0 0 0 0 0", "é", "🙂"]
BAD_BYTES = [b"\x00", b"\xff", b"\xe9", b"\xc3", b"\x1b", b"\r", b"\x7f", b"\x80", b"\xed\xa0\x80", b"\xc0\xaf",
             b"\xf4\x90\x80\x80", b"\x01", b"\x0c"]
NUM = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
# keys the runs hold small: they set the cost of a step, not what is tested
RUN_SET = ["time.max_steps=2", "time.wall_limit=30", "dem.substeps=5", "packing.max_time=0.002", "output.progress=off",
           "output.fields_every=0"]


def shrink(text, cap):
    """The case with its grid scaled down so that no direction has more than cap cells."""
    n = {k: int(v) for k, v in re.findall(r"(?m)^(n[xyz])\s*=\s*(\d+)\s*$", text)}
    if not n or max(n.values()) <= cap:
        return text
    f = cap / max(n.values())

    def sub(m):
        v = int(m.group(2))
        return "%s = %d" % (m.group(1), max(4 if v >= 4 else v, 2 * round(v * f / 2)) if v > 1 else v)
    return re.sub(r"(?m)^(n[xyz])\s*=\s*(\d+)\s*$", sub, text)


class Mutant:
    """Lines of a case file (bytes) and the list of what was done to them."""

    def __init__(self, lines, rng):
        self.lines = list(lines)
        self.rng = rng
        self.what = []

    def keyed(self):
        return [i for i, l in enumerate(self.lines) if re.match(rb"^[A-Za-z_0-9]+\s*=", l)]

    def numeric(self):
        return [i for i in self.keyed() if NUM.search(self.lines[i].split(b"=", 1)[1].decode("utf-8", "replace"))]

    def pick(self, idx):
        return self.rng.choice(idx) if idx else None

    def set_value(self, i, value):
        key = self.lines[i].split(b"=", 1)[0].rstrip()
        self.lines[i] = key + b" = " + value

    # ---- mutations of the structure
    def delete(self):
        i = self.pick([i for i, l in enumerate(self.lines) if l.strip()])
        if i is not None:
            self.what.append("delete line %d: %r" % (i + 1, self.lines[i][:60]))
            del self.lines[i]

    def duplicate(self):
        i = self.pick([i for i, l in enumerate(self.lines) if l.strip()])
        if i is not None:
            j = self.rng.randrange(len(self.lines) + 1)
            self.what.append("copy line %d to %d" % (i + 1, j + 1))
            self.lines.insert(j, self.lines[i])

    def swap(self):
        if len(self.lines) > 1:
            i, j = self.rng.sample(range(len(self.lines)), 2)
            self.what.append("swap lines %d and %d" % (i + 1, j + 1))
            self.lines[i], self.lines[j] = self.lines[j], self.lines[i]

    def syntax(self):
        i = self.pick([i for i, l in enumerate(self.lines) if l.strip() and not l.startswith((b";", b"#"))])
        if i is None:
            return
        l = self.lines[i]
        kind = self.rng.choice(["indent", "no ]", "no =", "rename", "cut", "empty key", "two =", "colon"])
        if kind == "indent":
            l = b"  " + l
        elif kind == "no ]":
            l = l.replace(b"]", b"") if l.startswith(b"[") else b"[" + l
        elif kind == "no =":
            l = l.replace(b"=", b" ")
        elif kind == "rename":
            l = l[:len(l) // 2] + b"x" + l[len(l) // 2:]
        elif kind == "cut":
            l = l[:self.rng.randrange(len(l) + 1)]
        elif kind == "empty key":
            l = b"=" + l.split(b"=", 1)[-1]
        elif kind == "two =":
            l = l + b" = 1"
        else:
            l = l.replace(b"=", b":", 1)
        self.what.append("line %d %s: %r" % (i + 1, kind, l[:60]))
        self.lines[i] = l

    def long(self):
        kind = self.rng.choice(["comment", "value", "key", "number", "blanks"])
        n = self.rng.choice([200, 201, 1000, 5000, 100000])
        i = self.pick(self.keyed())
        if kind == "comment" or i is None:
            j = self.rng.randrange(len(self.lines) + 1)
            tail = self.lines[i] if i is not None else b"nu = 1"
            self.lines.insert(j, b"; " + b"c" * n + b" " + tail)
            self.what.append("a comment of %d bytes at line %d" % (n, j + 1))
        elif kind == "value":
            self.set_value(i, b"v" * n)
            self.what.append("line %d: a value of %d bytes" % (i + 1, n))
        elif kind == "key":
            self.lines[i] = b"k" * n + self.lines[i]
            self.what.append("line %d: a key of %d bytes" % (i + 1, n))
        elif kind == "number":
            self.set_value(i, b"1" + b"0" * n)
            self.what.append("line %d: a number of %d digits" % (i + 1, n))
        else:
            v = self.lines[i].split(b"=", 1)[1].strip()
            self.set_value(i, v + b" " * n + b"\t")
            self.what.append("line %d: %d trailing blanks" % (i + 1, n))

    def bytes_(self):
        kind = self.rng.choice(["insert", "bom", "crlf", "utf16"])
        if kind == "bom":
            self.lines[0] = b"\xef\xbb\xbf" + self.lines[0]
        elif kind == "crlf":
            self.lines = [l + b"\r" for l in self.lines]
        elif kind == "utf16":
            i = self.rng.randrange(len(self.lines))
            self.lines[i] = self.lines[i].decode("utf-8", "replace").encode("utf-16")
        else:
            i = self.rng.randrange(len(self.lines))
            l = self.lines[i]
            b = self.rng.choice(BAD_BYTES)
            k = self.rng.randrange(len(l) + 1)
            self.lines[i] = l[:k] + b + l[k:]
            kind = "byte %r at line %d column %d" % (b, i + 1, k + 1)
        self.what.append("bytes: " + kind)

    # ---- mutations of the values
    def number(self):
        i = self.pick(self.numeric())
        if i is None:
            return
        key, val = self.lines[i].split(b"=", 1)
        val = val.decode("utf-8", "replace")
        nums = list(NUM.finditer(val))
        m = self.rng.choice(nums)
        x = float(m.group())
        new = self.rng.choice(EXTREME + ["scale"] * 4)
        if new == "scale":
            new = repr(x * self.rng.choice([1e3, 1e6, 1e-3, 1e-6, -1, 0.5, 2, 10]))
        val = val[:m.start()] + new + val[m.end():]
        self.lines[i] = key + b"=" + val.encode()
        self.what.append("line %d: %s" % (i + 1, self.lines[i][:80]))

    def wrong(self):
        i = self.pick(self.keyed())
        if i is not None:
            self.set_value(i, self.rng.choice(WRONG).encode())
            self.what.append("line %d: %r" % (i + 1, self.lines[i][:80]))

    def geometry(self):
        """Spheres and particles: larger, at the same centre, outside, too fast; smaller boxes."""
        sph = [i for i, l in enumerate(self.lines) if re.search(rb"\b(center|centre|position)\b", l)]
        i = self.pick(sph)
        kind = self.rng.choice(["big", "same", "outside", "fast", "box", "radius"])
        if kind in ("big", "same", "outside", "fast") and i is not None:
            l = self.lines[i].decode("utf-8", "replace")
            if kind == "big":
                l = re.sub(r"\b(radius|diameter)\s+(\S+)", lambda m: "%s %s" % (m.group(1), self.rng.choice(
                    ["1000", "1e6", "0", "-1", "1e-9"])), l)
            elif kind == "same" and len(sph) > 1:
                other = self.lines[self.rng.choice([j for j in sph if j != i])].decode("utf-8", "replace")
                c = re.search(r"\b(?:center|centre|position)((?:\s+\S+){3})", other)
                if c:
                    l = re.sub(r"\b(center|centre|position)((?:\s+\S+){3})", lambda m: m.group(1) + c.group(1), l)
            elif kind == "outside":
                l = re.sub(r"\b(center|centre|position)((?:\s+\S+){3})", lambda m: m.group(1) + " " + self.rng.choice(
                    ["1e6 1e6 1e6", "-5 0 0", "0 -1e-3 0", "1e300 0 0"]), l)
            else:
                l = re.sub(r"\bvelocity((?:\s+\S+){3})", "", l) + " velocity " + self.rng.choice(
                    ["1e200 0 0", "1e308 0 0", "0 -1e5 0", "1e3 1e3 1e3"])
            self.lines[i] = l.encode()
            self.what.append("geometry %s, line %d: %r" % (kind, i + 1, self.lines[i][:100]))
        elif kind == "box":
            j = self.pick([j for j, l in enumerate(self.lines) if re.match(rb"^length\s*=", l)])
            if j is not None:
                f = self.rng.choice([0.01, 0.1, 0.5])
                nums = [float(x) * f for x in NUM.findall(self.lines[j].split(b"=", 1)[1].decode())]
                self.set_value(j, " ".join(repr(x) for x in nums).encode())
                self.what.append("geometry box x %g, line %d" % (f, j + 1))
        else:
            j = self.pick([j for j, l in enumerate(self.lines) if re.match(rb"^(radius|diameter)\s*=", l)])
            if j is not None:
                self.set_value(j, self.rng.choice([b"1000", b"1e-9", b"0.5", b"1e6"]))
                self.what.append("geometry radius, line %d: %r" % (j + 1, self.lines[j]))

    STRUCTURE = ["delete", "duplicate", "swap", "syntax", "long", "bytes_"]
    VALUES = ["number", "number", "wrong", "geometry", "geometry", "delete", "duplicate"]

    def mutate(self, kinds, count):
        for _ in range(count):
            getattr(self, self.rng.choice(kinds))()

    def text(self):
        return b"\n".join(self.lines) + b"\n"


def seeded(seed, case, kind, m):
    return random.Random("%d/%s/%s/%d" % (seed, case, kind, m))


def limit_memory(limit):
    def f():
        if limit:
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return f


# Open MPI failing to start (MPI_Init aborts before ibmdem's code runs), seen once in a few hundred
# starts on a loaded machine: the environment's, not the input's; such a start is tried again
MPI_START = re.compile(r"before MPI_INIT completed|It looks like (opal|orte|MPI)_init failed")


def run(cmd, timeout, mem, env):
    for attempt in range(3):
        try:
            p = subprocess.run(cmd, capture_output=True, timeout=timeout, preexec_fn=limit_memory(mem), env=env)
            rc, out, err = p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")
        except subprocess.TimeoutExpired as e:
            return "timeout", (e.stdout or b"").decode("utf-8", "replace"), (e.stderr or b"").decode("utf-8", "replace")
        if rc == 0 or not MPI_START.search(err):
            break
    return rc, out, err


CRASH = re.compile(r"Sanitizer|runtime error:|Segmentation|\*\*\* Process received signal|core dumped|HDF5-DIAG")


def input_error(path, err):
    """exit 2: a line naming the case file, with a line number, a key, or the file's own problem."""
    p = re.escape(path)
    return any(re.match(r"^%s(:\d+)?: \S" % p, l) for l in err.splitlines())


def finite_csv(path):
    with open(path) as f:
        rows = f.read().splitlines()
    if len(rows) < 2:
        return "series.csv has no rows"
    for r in rows[1:]:
        for v in r.split(","):
            try:
                if not math.isfinite(float(v)):
                    return "series.csv: %r" % r[:100]
            except ValueError:
                return "series.csv: not a number in %r" % r[:100]
    return None


def strict_json(path):
    def bad(x):
        raise ValueError("non-finite %s" % x)
    with open(path, encoding="utf-8") as f:
        return json.load(f, parse_constant=bad)


def judge(kind, rc, out, err, path, outdir):
    """None when the outcome is clean, else why not."""
    if rc == "timeout":
        return "no answer within the timeout (a hang?)"
    if CRASH.search(err) or CRASH.search(out):
        return "crash or sanitizer report: %s" % CRASH.search(err + out).group()
    if rc == 2:
        return None if input_error(path, err) else "status 2 without a message naming %s" % path
    if rc == 1 and re.search(r"^error \(rank 0\): out of memory", err, re.M):
        return None  # the address-space limit of this harness (--memory), with its message
    if kind == "check":
        if rc == 0:
            return None if "; check: valid on" in out else "status 0 without the resolved input"
        return "status %s" % rc
    summary = os.path.join(outdir, "summary.json")
    try:
        status = strict_json(summary)["status"] if rc in (0, 1, 3) else None
    except Exception as e:  # noqa: BLE001 -- any unreadable summary is the finding
        return "status %s and summary.json unreadable: %s" % (rc, e)
    if rc == 0:
        if status not in ("t_end", "max_steps", "wall_limit", "steady", "done"):
            return "status 0 and summary status %s" % status
        return finite_csv(os.path.join(outdir, "series.csv"))
    if rc == 3:
        if status != "diverged" or not re.search(r"^error: the run (diverged|cannot go on)", err, re.M):
            return "status 3 without the divergence message (summary status %s)" % status
        ck = re.search(r"saved in (\S+)", err)
        return None if ck and os.path.exists(ck.group(1)) else "status 3 without its checkpoint"
    if rc == 1:
        return None if status == "halted" and "error: the run stopped at step" in err else "status 1: %s" % (
            err.strip().splitlines() or ["(no message)"])[-1][:200]
    return "status %s" % rc


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--seed", type=int, default=int(os.environ.get("FUZZ_SEED", "17")))
    ap.add_argument("--checks", type=int, default=3, help="check mutants per case file")
    ap.add_argument("--runs", type=int, default=1, help="run mutants per case file")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60, help="s per check (a run: twice this)")
    ap.add_argument("--memory", type=float, default=4, help="GB of address space per process (0: no limit)")
    ap.add_argument("--case", default="", help="only the case files whose path contains this")
    ap.add_argument("--skip", action="append", default=[], help="leave out the case files whose path contains this")
    ap.add_argument("--only", default="", help="one mutant: check:M or run:M")
    ap.add_argument("--keep", action="store_true", help="keep the work folder")
    ap.add_argument("--work", default="")
    a = ap.parse_args()

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    os.chdir(root)  # the cases name their data files from the repository root
    work = a.work or tempfile.mkdtemp(prefix="ibmdem_fuzz.")
    os.makedirs(work, exist_ok=True)
    env = dict(os.environ)
    # a process alone needs no daemon: without one Open MPI starts in half the time
    env.setdefault("OMPI_MCA_ess_singleton_isolated", "1")
    sanitized = "ASAN_OPTIONS" in env or "build-san" in a.bin
    mem = 0 if sanitized else int(a.memory * 2**30)
    if sanitized:  # ASan needs its address space: cap its allocations instead
        env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":allocator_may_return_null=1:max_allocation_size_mb=%d" % (
            a.memory * 1024)
    cases = sorted(c for c in glob.glob("cases/*/*.ini") if a.case in c and not any(k in c for k in a.skip))
    print("# fuzz: seed %d, %d case files, %d check and %d run mutants each, work folder %s" % (
        a.seed, len(cases), a.checks, a.runs, work), flush=True)

    # the starting point of each case: its grid shrunk as far as it stays valid
    def base(case):
        text = open(case).read()
        for cap in (16, 24, 32, 48, 64, 10**9):
            t = shrink(text, cap)
            path = os.path.join(work, "base_" + case.replace("/", "_"))
            with open(path, "w") as f:
                f.write(t)
            rc, _, _ = run([a.bin, "check", path], a.timeout, mem, env)
            if rc == 0:
                return t
        return None

    jobs = []
    for ci, case in enumerate(cases):
        if a.only:
            kind, m = a.only.split(":")
            jobs.append((ci, case, kind, int(m)))
            continue
        for kind, count in (("check", a.checks), ("run", a.runs)):
            for m in range(count):
                jobs.append((ci, case, kind, m))

    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        bases = dict(zip(cases, pool.map(base, cases)))

        def one(job):
            ci, case, kind, m = job
            rng = seeded(a.seed, case, kind, m)
            name = "%s_%s_%d" % (case.replace("/", "_").replace(".ini", ""), kind, m)
            path = os.path.join(work, name + ".ini")
            outdir = os.path.join(work, name + "_out")
            # a run mutant is drawn again (up to 4 times) while it is bad input: the runs are for valid input
            for attempt in range(1 if kind == "check" else 4):
                mu = Mutant(bases[case].encode().split(b"\n"), rng)
                if kind == "check":
                    mu.mutate(Mutant.STRUCTURE + Mutant.VALUES, 1 + (rng.random() < 0.4) + (rng.random() < 0.2))
                else:
                    mu.mutate(Mutant.VALUES, 1 + (rng.random() < 0.3))
                with open(path, "wb") as f:
                    f.write(mu.text())
                cmd = [a.bin, kind, path]
                if kind == "run":
                    shutil.rmtree(outdir, ignore_errors=True)
                    cmd += ["--out", outdir] + sum((["--set", s] for s in RUN_SET), [])
                rc, out, err = run(cmd, a.timeout * (2 if kind == "run" else 1), mem, env)
                why = judge(kind, rc, out, err, path, outdir)
                if why is not None or rc != 2:
                    break
            if why is None and not a.keep:
                os.remove(path)
                shutil.rmtree(outdir, ignore_errors=True)
            else:
                with open(os.path.join(work, name + ".err"), "w") as f:
                    f.write(err)
            return job, rc, why, mu.what, err

        results = list(pool.map(one, [j for j in jobs if bases[j[1]] is not None]))

    failed = 0
    for ci, case in enumerate(cases):
        mine = [r for r in results if r[0][1] == case]
        if bases[case] is None:
            print("not ok %d - %s: the case itself does not pass check" % (ci + 1, case))
            failed += 1
            continue
        bad = [r for r in mine if r[2] is not None]
        tally = {}
        for (_, _, kind, _), rc, _, _, _ in mine:
            tally["%s %s" % (kind, rc)] = tally.get("%s %s" % (kind, rc), 0) + 1
        print("%s %d - %s: %s" % ("not ok" if bad else "ok", ci + 1, case,
                                  ", ".join("%d %s" % (v, k) for k, v in sorted(tally.items())) or "nothing run"))
        for (_, _, kind, m), rc, why, what, err in bad:
            failed += 1
            print("#   %s mutant %d: %s" % (kind, m, why))
            for w in what:
                print("#     %s" % w)
            for l in err.strip().splitlines()[-4:]:
                print("#     | %s" % l[:200])
            print("#     reproduce: tests/fuzz.py --bin %s --seed %d --case %s --only %s:%d --keep" % (
                a.bin, a.seed, case, kind, m))
    print("1..%d" % len(cases))
    if failed or a.keep:
        print("# mutants kept in %s" % work)
    else:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
