#!/usr/bin/env python3
"""The shipped four-bar's 100-load sweep (0.8:1.2:100) by each route, as whole processes:
the full model (`sweep --full`), the reduced model with its estimate, and without it.

The three commands run in turn, round after round (a busy spell of a shared machine falls
on all three), and the table gives each route's median and range of wall time and of CPU
time (user + system of the process), with the load average before and after. Without
--basis the basis is trained first (greedy, about half a minute on 2 cores) into a
temporary folder; its `/timing` (what `train` measured) is printed too.

    python3 benches/sweep_routes.py [--rounds 5] [--flexrom EXE] [--basis B.h5] [--threads N]
"""

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PIPELINE = os.path.join(ROOT, "pipelines", "fourbar.toml")
LOADS = "0.8:1.2:100"


def timed(cmd):
    """Runs `cmd` (exit 0 required); returns (wall s, CPU s of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main():
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("--rounds", type=int, default=5)
    a.add_argument("--flexrom", default=os.path.join(ROOT, "target", "release", "flexrom"))
    a.add_argument("--basis", help="a basis of pipelines/fourbar.toml (default: trained here)")
    a.add_argument("--threads", type=int, help="worker threads (default: flexrom's, every core)")
    args = a.parse_args()
    threads = ["--threads", str(args.threads)] if args.threads else []
    with tempfile.TemporaryDirectory() as d:
        basis = args.basis
        if basis is None:
            basis = os.path.join(d, "fourbar.h5")
            print(f"training {basis} ...", file=sys.stderr)
            timed([args.flexrom, "train", PIPELINE, "--basis", basis, "-q"] + threads)
        try:
            import h5py

            with h5py.File(basis) as f:
                g = f["timing"]
                print(
                    f"basis /timing at load scale {g.attrs['load_scale']}: full {1e3 * g['full_seconds'][()]:.2f} ms, "
                    f"reduced {1e3 * g['reduced_seconds'][()]:.2f} ms, estimate {1e3 * g['estimate_seconds'][()]:.2f} ms"
                )
        except (ImportError, KeyError):
            print("(no h5py, or a basis without /timing: its stored times are not shown)")
        out = os.path.join(d, "sweep.h5")
        sweep = [args.flexrom, "sweep", PIPELINE, "--load-scales", LOADS, "-o", out, "-q"] + threads
        routes = {
            "full (`--full`)": sweep + ["--full"],
            "reduced, with its estimate": sweep + ["--basis", basis],
            "reduced, `--no-estimate`": sweep + ["--basis", basis, "--no-estimate"],
        }
        times = {r: [] for r in routes}
        load_before = os.getloadavg()[0]
        for _ in range(args.rounds):
            for r, cmd in routes.items():
                times[r].append(timed(cmd))
        load_after = os.getloadavg()[0]
    print(f"\n{args.rounds} rounds, load average {load_before:.1f} before, {load_after:.1f} after\n")
    print("| route | wall, median (s) | wall, range (s) | CPU, median (s) | CPU, range (s) |")
    print("|---|---|---|---|---|")
    for r, t in times.items():
        w, c = [x[0] for x in t], [x[1] for x in t]
        print(
            f"| {r} | {statistics.median(w):.2f} | {min(w):.2f}–{max(w):.2f} "
            f"| {statistics.median(c):.2f} | {min(c):.2f}–{max(c):.2f} |"
        )


if __name__ == "__main__":
    main()
