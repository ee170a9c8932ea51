#!/usr/bin/env python3
"""The cost of dimension for greedy training: full runs, modes and accuracy when greedy
trains over one, two and three parameters of the double pendulum with a tip push
(data/models/double_pendulum_push.toml, plus a moment at the pin between the links for the
third parameter, written beside the results).

Each box is trained with `[train] greedy = { tolerance = T, max_runs = 16 }` (no range: the
box of `[parameters]`), then checked by `flexrom sweep --points FILE --validate` at 16
random points of its box that are neither training points nor candidates (seed 7). Prints
one Markdown row per (dimension, tolerance): converged, full runs, candidates, modes,
sampled elements, training wall time, the largest and median rel_error at the held-out
points, how many of them the error estimate covers, and the median and largest
effectivity. Run from the repository after `cargo build --release`:

    python3 benches/greedy_box.py [--out out/greedy_box] [--tolerances 1e-3,1e-2]
"""
import argparse
import json
import os
import random
import statistics
import subprocess
import time

import h5py

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FLEXROM = os.path.join(ROOT, "target", "release", "flexrom")
MODEL = os.path.join(ROOT, "data", "models", "double_pendulum_push.toml")
# the third parameter: a moment at the pin, about a tenth of what gravity exerts there
TWIST = '\n[[loads]]\ntype = "moment"\nbody = "lower"\nnode = "start"\nscaled = "twist"\nfunction = { type = "constant", value = 0.05 }\n'
AXES = [
    ("load_scale", "[0.5, 1.5]", lambda r: 0.5 + r),
    ("push", '{ range = [0.2, 2.0], scale = "log" }', lambda r: 0.2 * 10**r),
    ("twist", "[-1.0, 1.0]", lambda r: -1.0 + 2.0 * r),
]


def held_out(dim, n=16, seed=7):
    rng = random.Random(seed)
    axes = AXES[:dim]
    rows = [[f(rng.random()) for _, _, f in axes] for _ in range(n)]
    return ",".join(a for a, _, _ in axes) + "\n" + "".join(",".join(repr(x) for x in r) + "\n" for r in rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "greedy_box"))
    ap.add_argument("--tolerances", default="1e-3,1e-2")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    model = os.path.join(a.out, "double_pendulum_push_twist.toml")
    with open(MODEL) as f, open(model, "w") as g:
        g.write(f.read() + TWIST)
    print("| parameters | tolerance | converged | full runs | candidates | modes | sampled elements | training | max rel_error | median | covered | effectivity median | max |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for dim in (1, 2, 3):
        points = os.path.join(a.out, f"held_out_{dim}.csv")
        with open(points, "w") as f:
            f.write(held_out(dim))
        box = "".join(f"{n} = {r}\n" for n, r, _ in AXES[:dim])
        for tol in a.tolerances.split(","):
            name = f"d{dim}_t{tol}"
            p = os.path.join(a.out, name + ".toml")
            with open(p, "w") as f:
                f.write(
                    f'model = "{model}"\nbasis = "{name}.h5"\nreport = "report_{name}"\n[parameters]\n{box}'
                    f"[train]\ngreedy = {{ tolerance = {tol}, max_runs = 16 }}\n"
                    f'[reduction]\nvariant = "constraint-preserving"\n'
                )
            t0 = time.perf_counter()
            subprocess.run([FLEXROM, "train", p, "-q"], check=True)
            wall = time.perf_counter() - t0
            with h5py.File(os.path.join(a.out, name + ".h5"), "r") as h:
                t = h["training"]
                converged = "yes" if t.attrs["converged"] else "no"
                runs = int(t.attrs["full_runs"])
                cands = t["estimates"].shape[1]
                modes = int(t["n_modes"][-1])
                elements = int(t["n_elements"][-1])
            out = subprocess.run(
                [FLEXROM, "sweep", p, "--points", points, "--validate", "-o", os.path.join(a.out, name + "_sweep.h5"), "-q", "--json"],
                check=True, capture_output=True, text=True,
            )
            rows = json.loads(out.stdout)
            err = [r["rel_error"] for r in rows]
            est = [r["error_estimate"] for r in rows]
            covered = sum(e >= x for e, x in zip(est, err))
            eff = [e / x for e, x in zip(est, err)]
            print(
                f"| {dim} | {tol} | {converged} | {runs} | {cands} | {modes} | {elements} | {wall:.1f} s | {max(err):.2e} | "
                f"{statistics.median(err):.2e} | {covered}/16 | {statistics.median(eff):.2f} | {max(eff):.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
