#!/usr/bin/env python3
"""Where Newton starts a step: the full run of each model with each `[time] predictor`.

For every model file given, the script writes four copies that differ only in `[time]
predictor` ("zero-acceleration", "constant-velocity", "constant-position", "adaptive"; any
predictor line of the model is replaced) into a work folder, then runs `flexrom simulate COPY -v --threads 1`
`--rounds` times, the four starts in turn within each round so a busy spell of the host
falls on all four, and prints a markdown table: Newton iterations per step and
factorizations (the same in every round), and the median time per step (the time loop as
`simulate -v` reports it). A run that fails shows its error's first words.

    python3 benches/predictor_starts.py [--rounds 5] [--flexrom EXE] [--load-scale X] MODEL.toml...

e.g. the shipped models and a zoo drawn by `target/release/examples/zoo --draw-only`:

    python3 benches/predictor_starts.py data/models/*.toml out/zoo/models/*/model.toml
"""

import argparse
import os
import re
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STARTS = ["zero-acceleration", "constant-velocity", "constant-position", "adaptive"]
NEWTON = re.compile(r"Newton: ([0-9.]+) iterations per step .*?, (\d+) factorizations.*?; ([0-9.]+) ms per step")


def variant(text, start):
    """The model text with `[time] predictor = start` (any predictor line replaced)."""
    lines = [line for line in text.splitlines() if not re.match(r"\s*predictor\s*=", line)]
    out, done = [], False
    for line in lines:
        out.append(line)
        if not done and re.match(r"\s*\[time\]\s*$", line):
            out.append(f'predictor = "{start}"')
            done = True
    if not done:
        raise SystemExit("no [time] table in the model")
    return "\n".join(out) + "\n"


def run(exe, model, scale):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", HDF5_USE_FILE_LOCKING="FALSE")
    with tempfile.TemporaryDirectory() as d:
        cmd = [exe, "simulate", model, "-o", os.path.join(d, "r.h5"), "-v", "--threads", "1"]
        if scale is not None:
            cmd += ["--load-scale", str(scale)]
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    m = NEWTON.search(p.stderr)
    if p.returncode != 0 or not m:
        first = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else f"exit {p.returncode}"
        return None, first[:60]
    return (float(m.group(1)), int(m.group(2)), float(m.group(3))), None


def main():
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("models", nargs="+")
    a.add_argument("--rounds", type=int, default=5)
    a.add_argument("--flexrom", default=os.path.join(ROOT, "target", "release", "flexrom"))
    a.add_argument("--load-scale", type=float, default=None)
    args = a.parse_args()
    work = tempfile.mkdtemp(prefix="predictor_starts_")
    copies = {}
    for i, path in enumerate(args.models):
        with open(path) as f:
            text = f.read()
        name = os.path.relpath(path, ROOT) if path.startswith(ROOT) else path
        for s in STARTS:
            c = os.path.join(work, f"{i}_{s}.toml")
            with open(c, "w") as f:
                f.write(variant(text, s))
            copies[(name, s)] = c
    names = list(dict.fromkeys(n for n, _ in copies))
    times = {k: [] for k in copies}
    counts, failed = {}, {}
    for _ in range(args.rounds):
        for n in names:
            for s in STARTS:
                r, why = run(args.flexrom, copies[(n, s)], args.load_scale)
                if r is None:
                    failed[(n, s)] = why
                    continue
                counts[(n, s)] = r[:2]
                times[(n, s)].append(r[2])
    print("| model | " + " | ".join(f"{s}: its/step, fact., ms/step" for s in STARTS) + " |")
    print("|---" * (len(STARTS) + 1) + "|")
    for n in names:
        cells = []
        for s in STARTS:
            if (n, s) in failed:
                cells.append(f"failed: {failed[(n, s)]}")
            else:
                its, fact = counts[(n, s)]
                cells.append(f"{its:.2f}, {fact}, {statistics.median(times[(n, s)]):.3f}")
        print(f"| {n} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
