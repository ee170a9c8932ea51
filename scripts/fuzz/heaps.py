#!/usr/bin/env python3
"""Byte-level mutation of each kind of HDF5 file flexrom reads (basis, sweep, part, result,
snapshot), aimed at where libhdf5 1.10.8 trusts the file: its global heap collections (the
`GCOL` blocks holding variable-length strings) and, for comparison, anywhere. A mutation
writes a 4- or 8-byte value (0, 1, 8, 15, 16, all ones, random) or flips bits. Each process
runs with a 20 s limit, a 4 GiB address space and no core file.

Counts exit codes per file kind; a time-out (124 here), an abort (134) or a signal (shown as
128 + signal, 139 a segfault) is a bug, and its file is copied into --keep.

    scripts/fuzz/heaps.py --cases 300 --seed 1 [--bin target/release/flexrom]
"""

import argparse
import collections
import os
import random
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LIMIT_S = 20
ADDRESS_SPACE = 4 << 30
VALUES = [0, 1, 8, 15, 16, 0xFFFFFFFF, None]


def limits():
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def run(binary, args, cwd):
    """The exit code, 128 + signal for a signal, 124 for a time-out."""
    env = dict(os.environ, HDF5_USE_FILE_LOCKING="FALSE", OPENBLAS_NUM_THREADS="1")
    try:
        p = subprocess.run([str(binary), *args, "--threads", "1"], cwd=cwd, env=env, capture_output=True,
                           timeout=LIMIT_S, preexec_fn=limits)
        return (128 - p.returncode if p.returncode < 0 else p.returncode), p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        return 124, ""


def setup(binary, base):
    """A coarse pendulum pipeline and one file of each kind."""
    model = (ROOT / "data/models/pendulum.toml").read_text()
    model = model.replace("elements = 50", "elements = 8").replace("t_end = 1.1", "t_end = 0.1")
    (base / "model.toml").write_text(model)
    (base / "pipe.toml").write_text(
        'model = "model.toml"\nbasis = "basis.h5"\nreport = "report"\n[train]\nload_scales = [0.9, 1.1]\n'
        '[reduction]\nvariant = "galerkin"\nmodes = { count = 4 }\n[validate]\nload_scales = [1.0]\n')
    steps = [["train", "-q", "pipe.toml"],
             ["train", "-q", "pipe.toml", "--snapshots-only", "--shard", "1/1", "-o", "snaps.h5"],
             ["online", "-q", "pipe.toml", "--load-scale", "1", "-o", "result.h5"],
             ["sweep", "-q", "pipe.toml", "--load-scales", "0.9:1.1:3", "-o", "sweep.h5"],
             ["sweep", "-q", "pipe.toml", "--load-scales", "0.9:1.1:3", "--shard", "1/2", "-o", "part1.h5"],
             ["sweep", "-q", "pipe.toml", "--load-scales", "0.9:1.1:3", "--shard", "2/2", "-o", "part2.h5"]]
    for s in steps:
        code, err = run(binary, s, base)
        if code != 0:
            sys.exit(f"setup failed: flexrom {' '.join(s)}: {err}")


# file kind: (the file mutated, the commands reading it)
KINDS = {
    "basis": ("basis.h5", [["online", "-q", "pipe.toml", "--load-scale", "1", "-o", "o.h5"],
                           ["validate", "-q", "pipe.toml", "--load-scale", "1", "--no-dense"]]),
    "sweep": ("sweep.h5", [["sweep", "-q", "pipe.toml", "--load-scales", "0.9:1.1:3", "--resume", "-o", "sweep.h5"]]),
    "part": ("part2.h5", [["merge", "-q", "part1.h5", "part2.h5", "-o", "merged.h5"]]),
    "result": ("result.h5", [["animate", "-q", "result.h5", "-o", "a.gif"]]),
    "snapshot": ("snaps.h5", [["train", "-q", "pipe.toml", "--from-snapshots", "snaps.h5", "--basis", "new.h5"]]),
}


def heaps(b):
    """(start, end) of each global heap collection."""
    out, i = [], b.find(b"GCOL\x01")
    while i >= 0:
        size = int.from_bytes(b[i + 8:i + 16], "little")
        out.append((i, min(len(b), i + max(16, size))))
        i = b.find(b"GCOL\x01", i + 8)
    return out


def fields(b, lo, hi):
    """Offsets of the collection's size and of each object's index and size fields."""
    out, p = [lo + 8], lo + 16
    while p + 16 <= hi:
        out += [p, p + 8]
        index, size = int.from_bytes(b[p:p + 2], "little"), int.from_bytes(b[p + 8:p + 16], "little")
        need = size if index == 0 else 16 + (size + 7) // 8 * 8
        if index == 0 or need <= 0:
            break
        p += need
    return out


def mutate(b, rng):
    b = bytearray(b)
    spans = heaps(b)
    where = "heap" if spans and rng.random() < 0.8 else "anywhere"
    lo, hi = rng.choice(spans) if where == "heap" else (0, len(b))
    if rng.random() < 0.3:
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(lo, hi)
            b[i] ^= 1 << rng.randrange(8)
        return bytes(b), where + " bits"
    width = rng.choice([4, 8])
    if where == "heap" and rng.random() < 0.7:
        # a header field: the collection's size or an object's index or size
        i = rng.choice(fields(b, lo, hi))
    else:
        i = lo + rng.randrange(max(1, (hi - lo - width) // 4)) * 4
    v = rng.choice(VALUES)
    v = rng.getrandbits(8 * width) if v is None else v & ((1 << (8 * width)) - 1)
    b[i:i + width] = v.to_bytes(width, "little")
    return bytes(b), f"{where} {width}-byte {v:#x} at {i}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=300)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--bin", default=str(ROOT / "target/release/flexrom"))
    ap.add_argument("--keep", default="fuzz-findings-heaps")
    a = ap.parse_args()
    binary = Path(a.bin).resolve()
    rng = random.Random(a.seed)
    counts = collections.defaultdict(collections.Counter)
    bad = 0
    with tempfile.TemporaryDirectory() as t:
        base, work = Path(t) / "base", Path(t) / "work"
        base.mkdir()
        setup(binary, base)
        for n in range(a.cases):
            kind = list(KINDS)[n % len(KINDS)]
            name, commands = KINDS[kind]
            argv = rng.choice(commands)
            data, how = mutate((base / name).read_bytes(), rng)
            shutil.rmtree(work, ignore_errors=True)
            shutil.copytree(base, work)
            (work / name).write_bytes(data)
            code, err = run(binary, argv, work)
            counts[kind][code] += 1
            if code in (124, 134) or code > 128:
                bad += 1
                keep = Path(a.keep) / f"{n:04d}-{kind}-{code}"
                keep.mkdir(parents=True, exist_ok=True)
                shutil.copy(work / name, keep / name)
                (keep / "case.txt").write_text(f"flexrom {' '.join(argv)}\n{how}\nexit {code}\n{err}")
                print(f"case {n}: {kind}: exit {code}: {how}", flush=True)
    for kind, c in counts.items():
        print(kind, dict(sorted(c.items())))
    print(f"{bad} bad of {a.cases}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
