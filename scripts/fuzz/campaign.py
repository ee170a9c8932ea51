#!/usr/bin/env python3
"""A mutation campaign against the release binary, driving it as a user's files and command
lines reach it: model and pipeline TOML mutated line by line and value by value, basis, sweep
and part files mutated with h5py (datasets shortened, shapes declared huge, attributes given
newlines) and, with --bytes, byte by byte; option values and environment variables mutated.
Each process runs with a time limit and a 4 GiB address space.

A case is bad when the process panics (exit 101), aborts (134), dies by a signal, outlives
its time limit, prints an error of more than two lines, or leaves a temporary file
(`.*.flexrom-tmp-*`) beside its output. Bad cases are copied with their command line into
--keep (default fuzz-findings/) and the script exits 1; each one found so far is a
regression test in tests/hostile_files.rs.

    scripts/fuzz/campaign.py --cases 60 --seed 1 --bytes  the short run of CI (.ci/run)
    scripts/fuzz/campaign.py --cases 3000 --bytes          a campaign (hours)

--bytes adds byte-level mutation of the HDF5 files: the statically linked libhdf5 1.10.8
trusts a damaged file's global heap (variable-length strings) and crashed on one
(tests/fuzz_cases/heap_object_size); flexrom checks the heaps before it reads a text
(io::h5::check_global_heaps), and other damage of that kind is what --bytes looks for.

Needs python3 with h5py and numpy, and target/release/flexrom built.
"""

import argparse
import os
import random
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
BIN = ROOT / "target" / "release" / "flexrom"
LIMIT_S = 20
ADDRESS_SPACE = 4 << 30

EDGE_VALUES = ["0", "-1", "1e300", "-1e300", "1e-300", "nan", "inf", "-inf", "9223372036854775807",
               '"x"', "[]", "{}", "true", '"\\u0000"', '"a\\nb"', "1.5", "100000"]
OPTION_VALUES = ["0", "-1", "1e300", "nan", "100000", "4294967297", "", "x", "1:2:0", "1,,2", "\n"]
ENV_VARS = ["RAYON_NUM_THREADS", "SLURM_CPUS_PER_TASK", "FLEXROM_MAX_MEMORY", "FLEXROM_MAX_STEPS",
            "FLEXROM_MAX_ELEMENTS"]


def limits():
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def run(args, cwd, env=None):
    """(exit code or -signal or None for a time-out, stderr)."""
    e = dict(os.environ, HDF5_USE_FILE_LOCKING="FALSE", **(env or {}))
    try:
        p = subprocess.run([str(BIN), *args], cwd=cwd, env=e, capture_output=True, timeout=LIMIT_S,
                           preexec_fn=limits)
        return p.returncode, p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired as t:
        return None, (t.stderr or b"").decode(errors="replace")


def setup(base):
    """A coarse pendulum pipeline, its basis, a sweep and two parts: the files mutated."""
    model = (ROOT / "data/models/pendulum.toml").read_text()
    model = model.replace("elements = 50", "elements = 8").replace("t_end = 1.1", "t_end = 0.1")
    (base / "model.toml").write_text(model)
    (base / "pipe.toml").write_text(
        'model = "model.toml"\nbasis = "basis.h5"\nreport = "report"\n[train]\nload_scales = [0.9, 1.1]\n'
        '[reduction]\nvariant = "galerkin"\nmodes = { count = 4 }\n[online]\nload_scales = "0.9:1.1:3"\n'
        '[validate]\nload_scales = [1.0]\n')
    steps = [["train", "-q", "pipe.toml"],
             ["sweep", "-q", "pipe.toml", "--load-scales", "0.9:1.1:3", "-o", "sweep.h5"],
             ["sweep", "-q", "pipe.toml", "--load-scales", "0.9:1.1:3", "--shard", "1/2", "-o", "part1.h5"],
             ["sweep", "-q", "pipe.toml", "--load-scales", "0.9:1.1:3", "--shard", "2/2", "-o", "part2.h5"]]
    for s in steps:
        code, err = run(s, base)
        if code != 0:
            sys.exit(f"setup failed: flexrom {' '.join(s)}: {err}")


def mutate_toml(text, rng):
    lines = text.splitlines()
    i = rng.randrange(len(lines))
    kind = rng.choice(["value", "drop", "dup", "swap"])
    if kind == "value" and "=" in lines[i]:
        key = lines[i].split("=", 1)[0]
        lines[i] = f"{key}= {rng.choice(EDGE_VALUES)}"
    elif kind == "drop":
        del lines[i]
    elif kind == "dup":
        lines.insert(i, lines[i])
    else:
        j = rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    return "\n".join(lines) + "\n"


def datasets(f):
    out = []
    f.visititems(lambda n, o: out.append(n) if isinstance(o, h5py.Dataset) else None)
    return out


def mutate_h5(path, rng):
    with h5py.File(path, "r+") as f:
        names = datasets(f)
        name = rng.choice(names)
        d = f[name]
        kind = rng.choice(["short", "huge", "attr", "nan"])
        if kind == "short" and d.shape and d.shape[0] > 0 and d.dtype.kind in "fiu":
            data = d[()][1:]
            del f[name]
            f[name] = data
        elif kind == "huge" and d.dtype.kind in "fiu":
            shape = ((1 << 31),) + tuple(d.shape[1:]) if d.shape else (1 << 31,)
            chunk = (1024,) + tuple(max(1, s) for s in d.shape[1:]) if d.shape else (1024,)
            del f[name]
            f.create_dataset(name, shape=shape, dtype="f8", chunks=chunk)
        elif kind == "nan" and d.dtype.kind == "f" and d.size:
            data = d[()]
            data.flat[rng.randrange(data.size)] = np.nan
            d[...] = data
        else:
            obj = rng.choice([f, d])
            keys = [k for k in obj.attrs if isinstance(obj.attrs[k], (str, bytes))]
            if keys:
                k = rng.choice(keys)
                obj.attrs[k] = rng.choice(["", "a\nb", "\x1b[31m", "x" * 1000, "none\n"])
    return path


def mutate_bytes(path, rng):
    b = bytearray(path.read_bytes())
    for _ in range(rng.randint(1, 4)):
        i = rng.randrange(len(b))
        b[i] ^= 1 << rng.randrange(8)
    path.write_bytes(b)
    return path


def case(base, work, rng, bytes_too):
    """One mutated command in `work` (a copy of `base`): (argv, env)."""
    for p in base.iterdir():
        if p.is_file():
            shutil.copy(p, work / p.name)
    kinds = ["model", "pipeline", "h5", "option", "env"] + (["bytes"] * 2 if bytes_too else [])
    kind = rng.choice(kinds)
    env = {}
    argv = ["-q"] + rng.choice([
        ["simulate", "model.toml", "-o", "out.h5"],
        ["online", "pipe.toml", "--load-scale", "1", "-o", "out.h5"],
        ["validate", "pipe.toml", "--load-scale", "1", "--no-dense"],
        ["sweep", "pipe.toml", "--load-scales", "0.9:1.1:3", "--resume", "-o", "sweep.h5"],
        ["merge", "part1.h5", "part2.h5", "-o", "merged.h5"],
        ["train", "pipe.toml", "--basis", "new.h5"],
    ])
    if kind == "model":
        (work / "model.toml").write_text(mutate_toml((work / "model.toml").read_text(), rng))
    elif kind == "pipeline":
        (work / "pipe.toml").write_text(mutate_toml((work / "pipe.toml").read_text(), rng))
    elif kind in ("h5", "bytes"):
        target = {"online": "basis.h5", "validate": "basis.h5", "sweep": "sweep.h5", "merge": "part2.h5"}
        name = target.get(argv[1], "basis.h5")
        (mutate_h5 if kind == "h5" else mutate_bytes)(work / name, rng)
    elif kind == "option":
        opt = rng.choice(["--threads", "--max-memory", "--max-steps", "--dt", "--t-end", "--load-scale"])
        argv = argv + [opt, rng.choice(OPTION_VALUES)]
    else:
        env[rng.choice(ENV_VARS)] = rng.choice(OPTION_VALUES)
    return argv, env, kind


def verdict(code, err, work):
    if code is None:
        return f"no exit within {LIMIT_S} s"
    if code < 0:
        return f"killed by signal {-code}"
    if code in (101, 134):
        return f"exit {code} (panic or abort)"
    lines = err.strip().splitlines()
    # one error line, and the last: a message split by a newline leaves a line after it
    # (a usage error, exit 2, is clap's own several-line message)
    if code not in (0, 2) and (sum(l.startswith("error:") for l in lines) != 1 or not lines[-1].startswith("error:")):
        if not (code in (129, 130, 143) or lines and lines[-1].startswith("flexrom: ")):
            return "an error not on one line of its own"
    left = [p.name for p in work.iterdir() if ".flexrom-tmp-" in p.name]
    if left:
        return f"temporary files left: {left}"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--bytes", action="store_true", help="also flip bytes of HDF5 files")
    ap.add_argument("--keep", default="fuzz-findings")
    a = ap.parse_args()
    if not BIN.exists():
        sys.exit(f"{BIN} missing: cargo build --release first")
    rng = random.Random(a.seed)
    bad = 0
    codes = {}
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp) / "base"
        base.mkdir()
        setup(base)
        for n in range(a.cases):
            work = Path(tmp) / f"case{n}"
            work.mkdir()
            argv, env, kind = case(base, work, rng, a.bytes)
            code, err = run(argv, work, env)
            why = verdict(code, err, work)
            codes[code] = codes.get(code, 0) + 1
            if why:
                bad += 1
                keep = Path(a.keep) / f"seed{a.seed}-case{n}"
                shutil.copytree(work, keep, dirs_exist_ok=True)
                (keep / "command.txt").write_text(f"{env} flexrom {' '.join(argv)}\n{why}\n{err}")
                print(f"case {n} ({kind}): {why}: {env} flexrom {' '.join(argv)}\n  {err.strip()[:300]}")
            shutil.rmtree(work, ignore_errors=True)
    print(f"{a.cases} cases, {bad} bad; exit codes: {dict(sorted(codes.items(), key=str))}")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
