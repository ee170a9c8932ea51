#!/usr/bin/env python3
"""The SPEC §4 pendulum in Exudyn (solved in-process) and in flexrom (the whole process),
side by side in one run, with the ratio of their median wall times.

    make bench-exudyn                       # installs exudyn 1.13.6 if missing, builds, runs this
    python3 benches/exudyn/pendulum.py [--rounds 15] [--flexrom target/release/flexrom]

Both solve the same problem: one beam of 50 planar ANCF elements (ρ = 5540 kg/m³, L = 1.2 m,
A = 1.8e-3 m², I = 1.215e-8 m⁴, E = 0.7e9 N/m²), pinned to ground at its left end, horizontal
at rest at t = 0, gravity 9.81 m/s² in −y, t ∈ [0, 1.1] s in 220 steps of Δt = 0.005 s,
generalized-α with spectral radius 1 (the trapezoidal rule). Exudyn uses its ANCFCable2D
element (Gerstmayr curvature, axial strain from |r'|), flexrom the Berzeri–Shabana simple model
(SPEC §1), so the two tip curves agree to a small difference from the strain models, which is
printed too (the largest tip distance over the 221 time points).

What is timed:
- Exudyn: only `SolveDynamic` on an assembled system (import, model building and `Assemble`
  excluded), with no solution file, no sensors and no console output; its linear solver is
  the faster of EXUdense (its default) and EigenSparse, chosen by a first timing pass, and
  Newton is its default (modified Newton). This favours Exudyn.
- flexrom: the whole process `flexrom simulate data/models/pendulum.toml -o FILE` (start-up,
  reading the model, the solve, writing the HDF5 result), spawned from this script.
Rounds alternate the two, so a busy spell of a shared machine falls on both; medians are
reported. The ratio printed is Exudyn's median over flexrom's median.
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

try:
    import exudyn as exu
    from exudyn.itemInterface import Cable2D, SensorNode
    from exudyn.beams import GenerateBeamElementsAlongLine
except ImportError:
    sys.exit("error: exudyn is not installed (pip install exudyn==1.13.6, or `make bench-exudyn`)")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MODEL = os.path.join(ROOT, "data", "models", "pendulum.toml")

# SPEC §4, Table 1
RHO, LENGTH, AREA, INERTIA, YOUNG = 5540.0, 1.2, 1.8e-3, 1.215e-8, 0.7e9
ELEMENTS, T_END, STEPS, GRAVITY = 50, 1.1, 220, 9.81


def build(sensor):
    """An assembled Exudyn system and its settings; `sensor` records the tip position at every step."""
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    template = Cable2D(physicsMassPerLength=RHO * AREA, physicsBendingStiffness=YOUNG * INERTIA,
                       physicsAxialStiffness=YOUNG * AREA, useReducedOrderIntegration=0)
    # pin: the first node's two position coordinates fixed to ground, its slope free
    items = GenerateBeamElementsAlongLine(mbs, [0, 0, 0], [LENGTH, 0, 0], ELEMENTS, template,
                                          gravity=[0, -GRAVITY, 0], groundConstraintsStart=[True, True, False, False])
    nodes = items["nodes"]
    tip_sensor = None
    if sensor:
        tip_sensor = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True, writeToFile=False,
                                                  outputVariableType=exu.OutputVariableType.Position))
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.timeIntegration.endTime = T_END
    s.timeIntegration.numberOfSteps = STEPS
    s.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    s.timeIntegration.verboseMode = 0
    s.show.computationTime = False
    s.show.statistics = False
    s.solution.file.write = False
    s.solution.sensors.writePeriod = T_END / STEPS
    return sc, mbs, s, tip_sensor


def solve_exudyn(solver_type):
    """Wall and CPU seconds (user + system, all threads) of one SolveDynamic."""
    sc, mbs, s, _ = build(sensor=False)
    s.linearSolver.solverType = solver_type
    c0, t0 = time.process_time(), time.perf_counter()
    ok = mbs.SolveDynamic(s)
    t1, c1 = time.perf_counter(), time.process_time()
    if not ok:
        sys.exit(f"error: Exudyn's SolveDynamic failed ({solver_type})")
    return t1 - t0, c1 - c0


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_flexrom(exe, out):
    """Wall and CPU seconds (user + system) of one whole `flexrom simulate` process."""
    c0, t0 = children_cpu(), time.perf_counter()
    r = subprocess.run([exe, "simulate", MODEL, "-o", out], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    t1, c1 = time.perf_counter(), children_cpu()
    if r.returncode != 0:
        sys.exit(f"error: {exe} simulate exited with status {r.returncode}: {r.stderr.decode().strip()}")
    return t1 - t0, c1 - c0


def tip_difference(exe, out):
    """Largest distance (m) between the two tip trajectories over the 221 time points."""
    import h5py

    sc, mbs, s, sensor = build(sensor=True)
    if not mbs.SolveDynamic(s):
        sys.exit("error: Exudyn's SolveDynamic failed")
    data = mbs.GetSensorStoredData(sensor)  # columns t, x, y, z
    run_flexrom(exe, out)
    with h5py.File(out, "r") as f:
        t, tip = f["t"][()], f["probes/tip"][()]
    ex_t, ex_xy = data[:, 0], data[:, 1:3]
    if len(ex_t) != len(t) or np.max(np.abs(ex_t - t)) > 1e-9:
        sys.exit(f"error: time grids differ (Exudyn {len(ex_t)} points, flexrom {len(t)})")
    return float(np.max(np.linalg.norm(ex_xy - tip, axis=1))), ex_xy[-1], tip[-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=15, help="timed runs of each (alternating)")
    ap.add_argument("--flexrom", default=os.path.join(ROOT, "target", "release", "flexrom"))
    args = ap.parse_args()
    if not os.access(args.flexrom, os.X_OK):
        sys.exit(f"error: {args.flexrom}: no flexrom executable (cargo build --release)")
    out = os.path.join(tempfile.mkdtemp(prefix="flexrom-exudyn-"), "pendulum.h5")

    # Exudyn's faster linear solver for this system, from a first pass of 3 runs each
    candidates = {"EXUdense": exu.LinearSolverType.EXUdense, "EigenSparse": exu.LinearSolverType.EigenSparse}
    pick = {name: statistics.median(solve_exudyn(k)[1] for _ in range(3)) for name, k in candidates.items()}
    best = min(pick, key=pick.get)
    for _ in range(2):  # warm-up of flexrom's files in the page cache
        run_flexrom(args.flexrom, out)

    ex, fx = [], []
    for _ in range(args.rounds):
        ex.append(solve_exudyn(candidates[best]))
        fx.append(run_flexrom(args.flexrom, out))
    diff, ex_end, fx_end = tip_difference(args.flexrom, out)

    print(f"pendulum, SPEC §4: {ELEMENTS} ANCF elements, {STEPS} steps of {T_END / STEPS} s, spectral radius 1")
    print(f"Exudyn {exu.config.Version()} SolveDynamic, in-process ({best}; first pass, median CPU: "
          + ", ".join(f"{k} {1e3 * v:.1f} ms" for k, v in pick.items()) + ")")
    report(ex)
    print(f"flexrom simulate, whole process ({args.flexrom})")
    report(fx)
    print(f"tip at t = {T_END} s: Exudyn ({ex_end[0]:.5f}, {ex_end[1]:.5f}), flexrom ({fx_end[0]:.5f}, {fx_end[1]:.5f});"
          f" largest tip distance over the run {diff:.2e} m")
    wall = statistics.median(w for w, _ in ex) / statistics.median(w for w, _ in fx)
    cpu = statistics.median(c for _, c in ex) / statistics.median(c for _, c in fx)
    print(f"ratio Exudyn / flexrom: {wall:.1f}x wall time, {cpu:.1f}x CPU time"
          f" (load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs: on a busy machine the CPU ratio is the steadier)")


def report(runs):
    wall, cpu = [w for w, _ in runs], [c for _, c in runs]
    print(f"  wall median {1e3 * statistics.median(wall):8.2f} ms (min {1e3 * min(wall):.2f}, max {1e3 * max(wall):.2f}),"
          f" CPU median {1e3 * statistics.median(cpu):8.2f} ms, {len(runs)} runs")

if __name__ == "__main__":
    main()
