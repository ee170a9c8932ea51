#!/usr/bin/env python3
"""The four-bar's 100-load reduced sweep (0.8:1.2:100, estimates on) from Python against the
command line, interleaved round after round, medians:

- `flexrom sweep` as a whole process (writes its sweep file),
- a whole Python process doing the same (`import flexrom`, `Basis.load`, `Basis.sweep`),
- `Basis.sweep` alone, in a process that loaded the basis once (what a notebook pays per
  sweep), against the command's own sweep time (`wall_seconds` of its file).

Without --basis the basis is trained first (about 20 s) into a temporary folder.

    python3 benches/python_sweep.py [--rounds 5] [--flexrom EXE] [--basis B.h5]
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

import flexrom

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PIPELINE = os.path.join(ROOT, "pipelines", "fourbar.toml")
LOADS = (0.8, 1.2, 100)

WHOLE_PYTHON = """
import sys, numpy as np, flexrom
b = flexrom.Basis.load(sys.argv[1], pipeline=sys.argv[2])
s = b.sweep(np.linspace({a}, {b}, {n}))
""".format(a=LOADS[0], b=LOADS[1], n=LOADS[2])


def wall(cmd):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr}")
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--flexrom", default=os.path.join(ROOT, "target", "release", "flexrom"))
    ap.add_argument("--basis")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="flexrom-pybench-")
    basis = a.basis or os.path.join(tmp, "fourbar.h5")
    if not a.basis:
        subprocess.run([a.flexrom, "-q", "train", PIPELINE, "--basis", basis], check=True)
    b = flexrom.Basis.load(basis, pipeline=PIPELINE)
    loads = np.linspace(*LOADS)
    out = os.path.join(tmp, "sweep.h5")
    cli = [a.flexrom, "-q", "sweep", PIPELINE, "--basis", basis, "--load-scales", "{}:{}:{}".format(*LOADS), "-o", out]
    rows = {k: [] for k in ["cli process", "python process", "cli sweep", "python sweep"]}
    for _ in range(a.rounds):
        if os.path.exists(out):
            os.remove(out)
        rows["cli process"].append(wall(cli))
        with h5py.File(out, "r") as f:
            rows["cli sweep"].append(float(f.attrs["wall_seconds"]))
        rows["python process"].append(wall([sys.executable, "-c", WHOLE_PYTHON, basis, PIPELINE]))
        t0 = time.perf_counter()
        s = b.sweep(loads)
        rows["python sweep"].append(time.perf_counter() - t0)
        assert all(x is None for x in s["failed"])
    med = {k: statistics.median(v) for k, v in rows.items()}
    print(f"four-bar, {LOADS[2]} loads, {a.rounds} rounds, {os.cpu_count()} cores; median (min-max) s")
    for k, v in rows.items():
        print(f"  {k:15s} {med[k]:.3f} ({min(v):.3f}-{max(v):.3f})")
    print(f"  python / cli: whole process {med['python process'] / med['cli process']:.2f}, sweep alone {med['python sweep'] / med['cli sweep']:.2f}")


if __name__ == "__main__":
    main()
