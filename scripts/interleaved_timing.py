#!/usr/bin/env python3
"""Whole-process wall times of several commands, interleaved, reported as medians.

    scripts/interleaved_timing.py [--rounds R] [--runs K] 'LABEL=[VAR=value ...] COMMAND' ...

Each round runs every command K times, in a fresh random order per round, so that a slow
spell of a shared machine falls on all commands alike (hyperfine runs one command's whole
series before the next). Each run is posix_spawn → waitpid, output to /dev/null, timed with
a monotonic clock; the spawn's own cost is in every figure alike and cancels against
`/bin/true`, the first command when given. A command that exits non-zero stops the script.
"""
import argparse
import os
import random
import shlex
import statistics
import sys
import time


def run_once(argv, env):
    devnull = os.open(os.devnull, os.O_WRONLY)
    actions = [(os.POSIX_SPAWN_DUP2, devnull, 1), (os.POSIX_SPAWN_DUP2, devnull, 2)]
    t0 = time.perf_counter_ns()
    pid = os.posix_spawn(argv[0], argv, env, file_actions=actions)
    _, status = os.waitpid(pid, 0)
    t1 = time.perf_counter_ns()
    os.close(devnull)
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"error: `{shlex.join(argv)}` exited with status {os.waitstatus_to_exitcode(status)}")
    return (t1 - t0) / 1e6


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--runs", type=int, default=10, help="runs of each command per round")
    ap.add_argument("--warmup", type=int, default=3, help="untimed runs of each command first")
    ap.add_argument("commands", nargs="+", help="LABEL=COMMAND (the command split as a shell would)")
    args = ap.parse_args()
    cmds = []
    for c in args.commands:
        label, sep, cmd = c.partition("=")
        if not sep:
            sys.exit(f"error: command `{c}`: expected LABEL=COMMAND")
        argv = shlex.split(cmd)
        env = dict(os.environ)
        while argv and "=" in argv[0]:  # leading VAR=value words set the environment, as in a shell
            var, _, value = argv.pop(0).partition("=")
            env[var] = value
        if not argv:
            sys.exit(f"error: command `{c}`: no program")
        if "/" not in argv[0]:
            argv[0] = next((os.path.join(d, argv[0]) for d in os.environ["PATH"].split(":")
                            if os.access(os.path.join(d, argv[0]), os.X_OK)), argv[0])
        cmds.append((label, argv, env))
    times = {label: [] for label, _, _ in cmds}
    for label, argv, env in cmds:
        for _ in range(args.warmup):
            run_once(argv, env)
    for _ in range(args.rounds):
        order = cmds[:]
        random.shuffle(order)
        for label, argv, env in order:
            for _ in range(args.runs):
                times[label].append(run_once(argv, env))
    base_label = cmds[0][0]
    base = statistics.median(times[base_label])
    print(f"{'command':<28} {'median ms':>10} {'over ' + base_label:>16} {'q1–q3 ms':>16}  runs")
    for label, _, _ in cmds:
        t = sorted(times[label])
        q = statistics.quantiles(t, n=4)
        med = statistics.median(t)
        print(f"{label:<28} {med:>10.2f} {med - base:>16.2f} {q[0]:>7.2f}–{q[2]:<8.2f}  {len(t)}")


if __name__ == "__main__":
    main()
