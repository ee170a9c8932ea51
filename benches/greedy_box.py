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

With `--zoo DIR` (a folder written by `cargo run --release --example zoo -- --out DIR`) it
instead takes each generated model with at least two loads, gives its last load a
parameter of its own (`scaled = "p2"`) beside the load scale of the others, and trains
greedily over load_scale × p2 = [0.5, 1.5]² (`--max-seconds` skips models whose line
training took longer in the zoo's own run, from DIR/zoo.json).
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
FLEXROM = os.environ.get("FLEXROM", os.path.join(ROOT, "target", "release", "flexrom"))
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


def two_parameters(text):
    """The model text with its last load scaled by `p2`, or None when no other load follows
    the load scale (gravity's default is unscaled, moments' and forces' scaled)."""
    blocks = text.split("[[loads]]")
    if len(blocks) < 3:
        return None

    def follows_load_scale(block):
        head = block.split("\n[")[0]
        scaled = [ln.split("=", 1)[1].strip() for ln in head.splitlines() if ln.strip().startswith("scaled")]
        if scaled:
            return scaled[0] == "true"
        return 'type = "gravity"' not in head

    if not any(follows_load_scale(b) for b in blocks[1:-1]):
        return None
    last = blocks[-1]
    head, sep, tail = last.partition("\n[")
    lines = [ln for ln in head.splitlines() if not ln.strip().startswith("scaled")]
    lines.insert(1, 'scaled = "p2"')
    blocks[-1] = "\n".join(lines) + sep + tail
    return "[[loads]]".join(blocks)


def train(out, name, pipeline_text):
    """Writes the pipeline `name`.toml in `out`, trains it, and returns its path, the
    training's wall time and what /training says: converged, full runs, candidates, modes,
    sampled elements."""
    p = os.path.join(out, name + ".toml")
    with open(p, "w") as f:
        f.write(pipeline_text)
    t0 = time.perf_counter()
    subprocess.run([FLEXROM, "train", p, "-q"], check=True)
    wall = time.perf_counter() - t0
    with h5py.File(os.path.join(out, name + ".h5"), "r") as h:
        t = h["training"]
        record = ("yes" if t.attrs["converged"] else "no", int(t.attrs["full_runs"]), t["estimates"].shape[1],
                  int(t["n_modes"][-1]), int(t["n_elements"][-1]))
    return p, wall, record


def validate_points(flexrom_args, points, out):
    rows = json.loads(subprocess.run(flexrom_args + ["--points", points, "--validate", "-o", out, "-q", "--json"],
                                     check=True, capture_output=True, text=True).stdout)
    err = [r["rel_error"] for r in rows]
    est = [r["error_estimate"] for r in rows]
    eff = [e / x for e, x in zip(est, err)]
    return err, est, eff


def zoo(a):
    with open(os.path.join(a.zoo, "zoo.json")) as f:
        z = json.load(f)
    seconds = {}
    for e in z["entries"]:
        seconds[e["model"]] = max(seconds.get(e["model"], 0.0), e["wall_seconds"])
    rng = random.Random(7)
    pts = [(0.5 + rng.random(), 0.5 + rng.random()) for _ in range(8)]
    points = os.path.join(a.out, "held_out_zoo.csv")
    with open(points, "w") as f:
        f.write("load_scale,p2\n" + "".join("%r,%r\n" % p for p in pts))
    print("| model | tolerance | converged | full runs | modes | sampled elements | training | max rel_error | covered | effectivity median | max |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for m in sorted(os.listdir(os.path.join(a.zoo, "models"))):
        src = os.path.join(a.zoo, "models", m, "model.toml")
        if not os.path.exists(src) or seconds.get(m, 1e9) > a.max_seconds:
            continue
        with open(src) as f:
            text = two_parameters(f.read())
        if text is None:
            continue
        model = os.path.join(a.out, m + ".toml")
        with open(model, "w") as f:
            f.write(text)
        for tol in a.tolerances.split(","):
            name = f"{m}_t{tol}"
            p, wall, (converged, runs, _, modes, elements) = train(
                a.out,
                name,
                f'model = "{model}"\nbasis = "{name}.h5"\nreport = "report_{name}"\n'
                f"[parameters]\nload_scale = [0.5, 1.5]\np2 = [0.5, 1.5]\n"
                f"[train]\ngreedy = {{ tolerance = {tol}, max_runs = 10 }}\n",
            )
            err, est, eff = validate_points([FLEXROM, "sweep", p], points, os.path.join(a.out, name + "_sweep.h5"))
            covered = sum(e >= x for e, x in zip(est, err))
            print(
                f"| {m} | {tol} | {converged} | {runs} | {modes} | {elements} | {wall:.1f} s | {max(err):.2e} | "
                f"{covered}/{len(err)} | {statistics.median(eff):.2f} | {max(eff):.2f} |",
                flush=True,
            )


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "greedy_box"))
    ap.add_argument("--tolerances", default="1e-3,1e-2")
    ap.add_argument("--zoo", help="a folder of generated models (examples/zoo.rs) to train over two parameters")
    ap.add_argument("--max-seconds", type=float, default=60.0, help="with --zoo: skip models slower than this")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.zoo:
        return zoo(a)
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
            p, wall, (converged, runs, cands, modes, elements) = train(
                a.out,
                name,
                f'model = "{model}"\nbasis = "{name}.h5"\nreport = "report_{name}"\n[parameters]\n{box}'
                f"[train]\ngreedy = {{ tolerance = {tol}, max_runs = 16 }}\n"
                f'[reduction]\nvariant = "constraint-preserving"\n',
            )
            err, est, eff = validate_points([FLEXROM, "sweep", p], points, os.path.join(a.out, name + "_sweep.h5"))
            covered = sum(e >= x for e, x in zip(est, err))
            print(
                f"| {dim} | {tol} | {converged} | {runs} | {cands} | {modes} | {elements} | {wall:.1f} s | {max(err):.2e} | "
                f"{statistics.median(err):.2e} | {covered}/16 | {statistics.median(eff):.2f} | {max(eff):.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
