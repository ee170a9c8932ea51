#!/usr/bin/env python3
"""Scaling with the mesh: the four-bar and the pendulum refined, each trained greedily, reduced
against full.

For each size the script writes a model (the shipped data/models/fourbar.toml or pendulum.toml
with every body's `elements` multiplied or set, nothing else changed) and a pipeline (the
shipped pipelines/fourbar.toml or pendulum.toml with `model`, `basis` and `report` pointing
into the work folder: the same greedy range, tolerance, max_runs and [reduction]) into a
work folder, then

* times `flexrom train P.toml` (wall and CPU of the whole process),
* reads from the basis: full runs, converged or not, POD modes + joint coordinates, sampled
  elements,

then, once every size is trained, runs `flexrom validate P.toml --load-scale X --json
--no-dense` at each pipeline's [validate] loads (neither training loads nor greedy
candidates), `--rounds` times, every size and load in turn, round after round, so a busy
spell of the host falls on all sizes. Each `validate` times the full and the reduced time
loop interleaved in one process (up to 7 pairs within 0.25 s, one pair where a full run
alone takes longer) and the estimate once; the table gives medians over all rounds and
loads: reduced without the estimate = `rom_seconds`, with it = `rom_seconds +
estimate_seconds`; rel_error and the estimate (the same in every round) at their largest
over the loads.

It writes one JSON file per size into the work folder (a later run trains only sizes that
have none, unless --force, and times them all again), prints the markdown table, the
break-even sizes and log-log slopes and draws the figure (matplotlib, if installed).

    python3 benches/scaling.py [--work DIR] [--fourbar 1,2,5,10,20] [--pendulum 50,200,500,1000,2000,5000]
                               [--rounds 3] [--flexrom EXE] [--figure docs/img/scaling.png]

Run it on one core of a quiet machine, e.g. `taskset -c 1 python3 benches/scaling.py`: every
flexrom process gets `--threads 1`, OPENBLAS_NUM_THREADS=1 and HDF5_USE_FILE_LOCKING=FALSE.
Only ratios measured in one run compare: the host's speed may drift by 2× within a day.
"""

import argparse
import json
import math
import os
import re
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FAMILIES = {
    "fourbar": {"bodies": 3, "base_elements": 110},
    "pendulum": {"bodies": 1, "base_elements": 50},
}


def coordinates(elements, bodies):
    """4 coordinates per node (x, y, x', y'), one node more than elements per body."""
    return 4 * (elements + bodies)


def fourbar_model(factor):
    text = open(os.path.join(ROOT, "data", "models", "fourbar.toml")).read()
    if factor == 1:
        return text, 110
    total = 0

    def times(m):
        nonlocal total
        n = int(m.group(1)) * factor
        total += n
        return f"elements = {n}"

    text = re.sub(r"(?m)^elements = (\d+)", times, text)
    n_dof = coordinates(total, 3)
    text = text.replace(
        "# Flexible four-bar mechanism, thesis §4 Table 2 (SPEC §4).",
        f"# The thesis four-bar (SPEC §4, Table 2) with every body meshed {factor}× finer: the scaling study of docs/benchmarks.md.",
        1,
    )
    text = re.sub(r"(?m)^# 452 coordinates", f"# {n_dof} coordinates", text, count=1)
    text = re.sub(
        r'(?m)^description = .*$',
        f'description = "Flexible four-bar (Kim 2016, Table 2), every body refined {factor}×: {total} ANCF elements, {n_dof} coordinates"',
        text,
        count=1,
    )
    return text, total


def pendulum_model(elements):
    text = open(os.path.join(ROOT, "data", "models", "pendulum.toml")).read()
    if elements == 50:
        return text, 50
    n_dof = coordinates(elements, 1)
    text = re.sub(r"(?m)^elements = 50$", f"elements = {elements}", text, count=1)
    text = text.replace(
        "# Free-falling flexible pendulum, thesis §4 Table 1 (SPEC §4).",
        f"# The thesis pendulum (SPEC §4, Table 1) meshed with {elements} elements: the scaling study of docs/benchmarks.md.",
        1,
    )
    text = re.sub(
        r'(?m)^description = .*$',
        f'description = "Flexible pendulum (Kim 2016, Table 1) refined: {elements} ANCF elements, {n_dof} coordinates"',
        text,
        count=1,
    )
    return text, elements


def pipeline(family, name):
    """The shipped pipeline with model, basis and report in the work folder (paths relative
    to the pipeline, which sits in WORK/pipelines/)."""
    text = open(os.path.join(ROOT, "pipelines", f"{family}.toml")).read()
    text = re.sub(r'(?m)^model = .*$', f'model = "../models/{name}.toml"', text, count=1)
    text = re.sub(r'(?m)^basis = .*$', f'basis = "../bases/{name}.h5"', text, count=1)
    text = re.sub(r'(?m)^report = .*$', f'report = "../reports/{name}"', text, count=1)
    text = re.sub(r'(?m)^description = .*$',
                  f'description = "pipelines/{family}.toml (its [train], [reduction], [online], [validate]) on {name}"',
                  text, count=1)
    return text


def validate_loads(text):
    m = re.search(r"(?ms)^\[validate\].*?^load_scales = \[([^\]]*)\]", text)
    return [float(x) for x in m.group(1).split(",")]


def run(cmd, env):
    """Runs `cmd`; returns (wall s, CPU s of the child, exit code, stdout, stderr)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, p.returncode, p.stdout, p.stderr


def read_basis(path):
    import h5py

    out = {}
    with h5py.File(path) as f:
        out["reduced_coordinates"] = int(f["basis/modes"].shape[1])
        out["joint_coordinates"] = int(f["basis/kept_dofs"].shape[0]) if "basis/kept_dofs" in f else 0
        out["pod_modes"] = out["reduced_coordinates"] - out["joint_coordinates"]
        out["block_modes"] = [int(x) for x in f["basis/block_modes"][:]] if "basis/block_modes" in f else []
        out["sampled_elements"] = int(f["hyper/elements"].shape[0]) if "hyper/elements" in f else None
        if "training" in f:
            t = f["training"]
            out["converged"] = bool(t.attrs.get("converged", 0))
            out["full_runs"] = int(t.attrs.get("full_runs", len(t["load_scales"])))
            out["training_loads"] = [float(x) for x in t["load_scales"][:]]
            out["worst_estimate"] = [float(x) for x in t["worst_estimate"][:]]
        if "timing" in f:
            g = f["timing"]
            out["train_timing"] = {k: float(g[k][()]) for k in ("full_seconds", "reduced_seconds", "estimate_seconds")}
        est = f.get("estimator")
        if est is not None:
            m = est.attrs.get("default_method")
            out["estimate_method"] = m.decode() if isinstance(m, bytes) else (str(m) if m is not None else None)
    return out


def case(family, size, work):
    """Writes the model and pipeline of one size; returns (name, pipeline path, result stub)."""
    if family == "fourbar":
        text, elements = fourbar_model(size)
        name = f"fourbar_{size}x"
    else:
        text, elements = pendulum_model(size)
        name = f"pendulum_{size}"
    for sub in ("models", "pipelines", "bases", "logs"):
        os.makedirs(os.path.join(work, sub), exist_ok=True)
    with open(os.path.join(work, "models", f"{name}.toml"), "w") as f:
        f.write(text)
    pfile = os.path.join(work, "pipelines", f"{name}.toml")
    with open(pfile, "w") as f:
        f.write(pipeline(family, name))
    stub = {"family": family, "name": name, "elements": elements,
            "coordinates": coordinates(elements, FAMILIES[family]["bodies"]), "pipeline": pfile,
            "basis": os.path.join(work, "bases", f"{name}.h5")}
    return name, pfile, stub


def train(r, args, env):
    """`flexrom train` of one size, timed; what the basis holds."""
    name, work = r["name"], args.work
    print(f"{name}: train ...", file=sys.stderr, flush=True)
    wall, cpu, code, out, err = run([args.flexrom, "train", r["pipeline"], "--threads", "1"], env)
    with open(os.path.join(work, "logs", f"{name}.train.log"), "w") as f:
        f.write(out + err)
    r["train_date"] = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    if code != 0:
        print(f"{name}: train exit {code}\n{err}", file=sys.stderr)
        r["train_exit"] = code
        if not os.path.exists(r["basis"]):
            return r
    r["train_wall"], r["train_cpu"] = wall, cpu
    r["train_warnings"] = [l for l in err.splitlines() if l.startswith("warning: greedy training") and "above its tolerance" in l]
    r.update(read_basis(r["basis"]))
    print(f"{name}: trained in {wall:.1f} s, {r.get('full_runs')} full runs, converged {r.get('converged')}",
          file=sys.stderr, flush=True)
    return r


def time_all(results, args, env):
    """`flexrom validate` at every held-out load of every size, round after round (sizes and
    loads in turn, so a busy spell of the host falls on all of them); medians per size."""
    todo = [r for r in results if "train_wall" in r]
    per = {r["name"]: {x: [] for x in validate_loads(open(r["pipeline"]).read())} for r in todo}
    for k in range(args.rounds):
        print(f"timing round {k + 1} of {args.rounds} ...", file=sys.stderr, flush=True)
        for r in todo:
            for x in per[r["name"]]:
                cmd = [args.flexrom, "validate", r["pipeline"], "--load-scale", str(x), "--json", "--no-dense",
                       "--threads", "1"]
                _, _, code, out, err = run(cmd, env)
                if code != 0:
                    print(f"{r['name']}: validate {x} exit {code}: {err}", file=sys.stderr)
                    per[r["name"]][x].append({"exit": code, "stderr": err[-2000:]})
                else:
                    per[r["name"]][x].append(json.loads(out))
    for r in todo:
        per_load = per[r["name"]]
        for key in ("full_ms", "rom_ms", "rom_est_ms", "speedup", "speedup_est", "rel_error_max", "estimate_max",
                    "covered", "held_out", "timings"):
            r.pop(key, None)
        r["validate"] = {str(x): v for x, v in per_load.items()}
        r["timed_date"] = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
        r["loadavg"] = os.getloadavg()
        ok = [v for vs in per_load.values() for v in vs if "exit" not in v]
        r["failed_validations"] = sum(1 for vs in per_load.values() for v in vs if "exit" in v)
        if not ok:
            continue
        est = lambda v: v["rom_seconds"] + (v["estimate_seconds"] or 0.0)
        r["full_ms"] = 1e3 * statistics.median([v["full_seconds"] for v in ok])
        r["rom_ms"] = 1e3 * statistics.median([v["rom_seconds"] for v in ok])
        r["rom_est_ms"] = 1e3 * statistics.median([est(v) for v in ok])
        r["speedup"] = statistics.median([v["full_seconds"] / v["rom_seconds"] for v in ok])
        r["speedup_est"] = statistics.median([v["full_seconds"] / est(v) for v in ok])
        firsts = [vs[0] for vs in per_load.values() if vs and "exit" not in vs[0]]
        r["rel_error_max"] = max(v["rel_error"] for v in firsts)
        r["estimate_max"] = max((v["error_estimate"] or float("nan")) for v in firsts)
        r["covered"] = sum(1 for v in firsts if (v["error_estimate"] or 0.0) >= v["rel_error"])
        r["held_out"] = len(firsts)
        r["timings"] = len(ok)
        print(f"{r['name']}: full {r['full_ms']:.2f} ms, reduced {r['rom_ms']:.2f} ms (+ estimate "
              f"{r['rom_est_ms']:.2f} ms), rel_error ≤ {r['rel_error_max']:.2e}", file=sys.stderr, flush=True)


def num(x):
    """3 significant digits, without an exponent up to 99 999."""
    return f"{x:.0f}" if x >= 100 else f"{x:.3g}"


def fmt_time(s):
    m, s = divmod(s, 60)
    return f"{int(m)} min {s:.0f} s" if m else f"{s:.1f} s"


def table(results):
    lines = [
        "| model | elements | coordinates | training (wall) | full runs | reduced coordinates | sampled elements "
        "| full (ms) | reduced + estimate (ms) | reduced (ms) | speedup with / without estimate "
        "| rel_error max | estimate max |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        if "full_ms" not in r:
            lines.append(f"| {r['name']} | {r['elements']} | {r['coordinates']} | failed | | | | | | | | | |")
            continue
        red = f"{r['reduced_coordinates']}"
        if r.get("joint_coordinates"):
            red = f"{r['pod_modes']} + {r['joint_coordinates']}"
        conv = "" if r.get("converged", True) else " (not converged)"
        lines.append(
            f"| {r['family']} | {r['elements']} | {r['coordinates']} | {fmt_time(r['train_wall'])}{conv} "
            f"| {r.get('full_runs', '')} | {red} | {r.get('sampled_elements', '')} "
            f"| {num(r['full_ms'])} | {num(r['rom_est_ms'])} | {num(r['rom_ms'])} "
            f"| {num(r['speedup_est'])} / {num(r['speedup'])} | {r['rel_error_max']:.2e} | {r['estimate_max']:.2e} |"
        )
    return "\n".join(lines)


def loglog_slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = statistics.mean(lx), statistics.mean(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def break_even(rs, key):
    """Elements where the speedup (`key`: "speedup" or "speedup_est") crosses 1, log-log
    interpolated between sizes (None: no crossing)."""
    pts = [(r["elements"], r[key]) for r in rs]
    for (e0, s0), (e1, s1) in zip(pts, pts[1:]):
        if (s0 - 1) * (s1 - 1) <= 0 and s0 != s1:
            f = math.log(s0) / (math.log(s0) - math.log(s1))
            return math.exp(math.log(e0) + f * (math.log(e1) - math.log(e0)))
    return None


def newton(r):
    """Median over the held-out loads of the full and the reduced run's Newton iterations."""
    firsts = [vs[0] for vs in r.get("validate", {}).values() if vs and "exit" not in vs[0]]
    if not firsts:
        return None
    return (int(statistics.median(v["full_newton_iterations"] for v in firsts)),
            int(statistics.median(v["rom_newton_iterations"] for v in firsts)))


def summary(results):
    out = []
    for fam in FAMILIES:
        rs = sorted([r for r in results if r["family"] == fam and "full_ms" in r], key=lambda r: r["elements"])
        if len(rs) < 2:
            continue
        e = [r["elements"] for r in rs]
        parts = [f"{fam}: full time ∝ elements^{loglog_slope(e, [r['full_ms'] for r in rs]):.2f}",
                 f"reduced ∝ elements^{loglog_slope(e, [r['rom_ms'] for r in rs]):.2f}",
                 f"reduced + estimate ∝ elements^{loglog_slope(e, [r['rom_est_ms'] for r in rs]):.2f}",
                 f"training ∝ elements^{loglog_slope(e, [r['train_wall'] for r in rs]):.2f}"]
        its = [newton(r) for r in rs]
        if all(its):
            parts.append("Newton iterations full / reduced (median over the loads): " +
                         ", ".join(f"{r['elements']}: {f} / {m}" for r, (f, m) in zip(rs, its)))
        for key, what in (("speedup", "without estimate"), ("speedup_est", "with estimate")):
            b = break_even(rs, key)
            if b is not None:
                parts.append(f"break-even {what} at ≈ {b:.0f} elements")
            elif rs[0][key] > 1:
                parts.append(f"reduced faster {what} at every size from {rs[0]['elements']}")
            else:
                parts.append(f"reduced slower {what} at every size up to {rs[-1]['elements']}")
        out.append("; ".join(parts))
    return "\n".join(out)


def figure(results, path):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no figure", file=sys.stderr)
        return
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    colors = {"fourbar": "tab:red", "pendulum": "tab:blue"}
    for fam, c in colors.items():
        rs = sorted([r for r in results if r["family"] == fam and "full_ms" in r], key=lambda r: r["elements"])
        if not rs:
            continue
        e = [r["elements"] for r in rs]
        ax.loglog(e, [r["full_ms"] for r in rs], "o-", color=c, label=f"{fam}: full (banded)")
        ax.loglog(e, [r["rom_est_ms"] for r in rs], "s--", color=c, label=f"{fam}: reduced + estimate")
        ax.loglog(e, [r["rom_ms"] for r in rs], "^:", color=c, label=f"{fam}: reduced, no estimate")
        bx.loglog(e, [r["speedup_est"] for r in rs], "s--", color=c, label=f"{fam}: with estimate")
        bx.loglog(e, [r["speedup"] for r in rs], "^:", color=c, label=f"{fam}: without estimate")
        for r in rs:
            if r.get("converged") is False:
                bx.annotate("greedy not converged", (r["elements"], r["speedup_est"]), textcoords="offset points",
                            xytext=(6, -16), ha="right", fontsize=8, color=c)
    ax.set(xlabel="elements", ylabel="time loop [ms] (median, one core)", title="Full and reduced time loop")
    bx.axhline(1.0, color="k", lw=0.8)
    bx.set(xlabel="elements", ylabel="full / reduced (median)", title="Speedup (below 1: the full model is faster)")
    from matplotlib.ticker import FuncFormatter, NullFormatter

    for a in (ax, bx):
        for axis in (a.xaxis, a.yaxis):
            axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(NullFormatter())
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=8)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=120)
    print(f"figure: {path}", file=sys.stderr)


def main():
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("--work", default=os.path.join(ROOT, "out", "scaling"), help="work folder (models, bases, results)")
    a.add_argument("--fourbar", default="1,2,5,10,20", help="refinement factors of the four-bar ('' for none)")
    a.add_argument("--pendulum", default="50,200,500,1000,2000,5000", help="pendulum element counts ('' for none)")
    a.add_argument("--rounds", type=int, default=3, help="validate rounds over the held-out loads")
    a.add_argument("--flexrom", default=os.path.join(ROOT, "target", "release", "flexrom"))
    a.add_argument("--figure", default=os.path.join(ROOT, "docs", "img", "scaling.png"))
    a.add_argument("--force", action="store_true", help="train sizes again that have a result file")
    a.add_argument("--report-only", action="store_true", help="no runs: the table and figure of the result files")
    args = a.parse_args()
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", HDF5_USE_FILE_LOCKING="FALSE", RAYON_NUM_THREADS="1")
    cases = [("fourbar", int(x)) for x in args.fourbar.split(",") if x] + \
            [("pendulum", int(x)) for x in args.pendulum.split(",") if x]
    os.makedirs(args.work, exist_ok=True)
    results = []
    for fam, size in cases:
        name, pfile, stub = case(fam, size, args.work)
        rfile = os.path.join(args.work, f"{name}.json")
        if os.path.exists(rfile) and not args.force:
            r = json.load(open(rfile))
            r.update({k: stub[k] for k in ("pipeline", "basis")})
        elif args.report_only:
            continue
        else:
            r = train(stub, args, env)
            with open(rfile, "w") as f:
                json.dump(r, f, indent=1)
        results.append(r)
    if not args.report_only:
        time_all(results, args, env)
        for r in results:
            with open(os.path.join(args.work, f"{r['name']}.json"), "w") as f:
                json.dump(r, f, indent=1)
    results.sort(key=lambda r: (r["family"] != "fourbar", r["elements"]))
    print(table(results))
    print()
    print(summary(results))
    figure(results, args.figure)


if __name__ == "__main__":
    main()
