#!/usr/bin/env python3
"""Accuracy of a basis trained at sampled points of a parameter box, against the number of
points and modes, in one dimension (gravity's scale) and two (and a tip push), on the
double pendulum with a tip push (data/models/double_pendulum_push.toml).

Each basis is trained with `[train] points = { count = N, sampling = "sobol" }` and checked
by `flexrom sweep --points FILE --validate` at 16 held-out random points of its box (seed 7;
the 1-D box keeps the push at the model file's value). Prints one line per basis: the
largest and median rel_error, how many of the 16 the error estimate covers, and the median
effectivity. Run from the repository after `cargo build --release`:

    python3 benches/box_points.py [--out out/box_points]
"""
import argparse
import json
import os
import random
import statistics
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FLEXROM = os.path.join(ROOT, "target", "release", "flexrom")
MODEL = os.path.join(ROOT, "data", "models", "double_pendulum_push.toml")
BOXES = {
    1: 'load_scale = [0.5, 1.5]\n',
    2: 'load_scale = [0.5, 1.5]\npush = { range = [0.2, 2.0], scale = "log" }\n',
}


def held_out(dim, n=16, seed=7):
    rng = random.Random(seed)
    pts = [(0.5 + rng.random(), 0.2 * 10 ** rng.random()) for _ in range(n)]
    head = "load_scale,push\n" if dim == 2 else "load_scale\n"
    return head + "".join(("%r,%r\n" % p) if dim == 2 else ("%r\n" % p[0]) for p in pts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "box_points"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for dim, box in BOXES.items():
        points = os.path.join(a.out, f"held_out_{dim}.csv")
        with open(points, "w") as f:
            f.write(held_out(dim))
        for modes in (4, 8):
            for n in (2, 4, 8, 16, 32):
                name = f"d{dim}_m{modes}_n{n}"
                p = os.path.join(a.out, name + ".toml")
                with open(p, "w") as f:
                    f.write(
                        f'model = "{MODEL}"\nbasis = "{name}.h5"\nreport = "report_{name}"\n[parameters]\n{box}'
                        f'[train]\npoints = {{ count = {n}, sampling = "sobol", seed = 1 }}\n'
                        f'[reduction]\nvariant = "constraint-preserving"\nmodes = {{ count = {modes} }}\n'
                    )
                subprocess.run([FLEXROM, "train", p, "-q"], check=True)
                out = subprocess.run(
                    [FLEXROM, "sweep", p, "--points", points, "--validate", "-o", os.path.join(a.out, name + "_sweep.h5"), "-q", "--json"],
                    check=True, capture_output=True, text=True,
                )
                rows = json.loads(out.stdout)
                err = [r["rel_error"] for r in rows]
                est = [r["error_estimate"] for r in rows]
                covered = sum(e >= x for e, x in zip(est, err))
                eff = statistics.median(e / x for e, x in zip(est, err))
                print(f"| {dim} | {modes} | {n} | {max(err):.2e} | {statistics.median(err):.2e} | {covered}/16 | {eff:.2f} |", flush=True)


if __name__ == "__main__":
    main()
