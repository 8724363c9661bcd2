"""Benchmark: what a ``derived`` suspension costs to build, against ``static`` and ``planned``, in one run.

For every task type loaded (the bundled folders, and ``--path`` folders) with an ``[example]``,
the task's ``exeTsk`` is planned on its example world and the task is interrupted after each
of its stages in turn (the states a real interruption meets).  At each, genSusp builds
``exeSusp`` under the three strategies, rounds interleaved, every cache the call could use
cleared first (the planner's and the estimator's: each suspension meets a state it has not
seen, as in a run).  Printed: the median CPU milliseconds per genSusp of each strategy, and
derived's ratio to static and to planned, per task type and over all.  CPU seconds, so the
figures survive a shared machine (this process's and Fast Downward's search binary's, a child process).

    python benchmarks/bench_derived.py [--rounds N] [--path DIR ...]
"""

from __future__ import annotations

import argparse
import resource
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from planners.bundled import task_types  # noqa: E402
from planners.estimates import estimator_for  # noqa: E402
from planners.examples import StraightLineMotion, example_context  # noqa: E402
from planners.pddl_task import PddlTaskType  # noqa: E402
from tasker.task import Strategy, TaskContext  # noqa: E402

STRATEGIES = ("static", "planned", "derived")


def interruptions(task: PddlTaskType) -> list[TaskContext]:
    """A context per interruption point of the example's exeTsk: after 1, 2, ... stages (suspended)."""
    ctx = example_context(task, motion=StraightLineMotion())
    if ctx is None:
        return []
    exe = task.update_task(ctx)
    out = []
    world = ctx.world
    for n, stage in enumerate(exe.stages[:-1], start=1):
        world = world.updated([tuple(f) for f in stage.data.get("add", ())],
                              [tuple(f) for f in stage.data.get("delete", ())])
        k = example_context(task, motion=StraightLineMotion(), world=world)
        if k is not None:  # the stages it ran: what it made true is its own (a door it opened)
            out.append(replace(k, suspended=True, done=list(exe.stages[:n])))
    return out


def cpu_ms(task: PddlTaskType, ctx: TaskContext, strategy: str) -> float:
    task.planner.clear_cache()
    estimator_for(task).clear()
    c = replace(ctx, strategy=Strategy(update="planned", suspension=strategy))
    t0 = _cpu()
    task.generate_suspension(c)
    return (_cpu() - t0) * 1e3


def _cpu() -> float:
    """CPU seconds of this process and of its finished children (Fast Downward's search binary)."""
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + kids.ru_utime + kids.ru_stime


def _row(name: str, points: int, med: dict[str, float]) -> None:
    print(f"{name:16s} {points:6d} " + " ".join(f"{med[s]:11.2f}" for s in STRATEGIES)
          + f" {med['derived'] / max(med['static'], 1e-6):14.1f}x {med['derived'] / max(med['planned'], 1e-6):15.2f}x")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5, help="interleaved rounds per interruption point (median)")
    ap.add_argument("--path", action="append", default=[], help="also these task folders (repeatable)")
    args = ap.parse_args(argv)
    every: dict[str, list[float]] = {s: [] for s in STRATEGIES}
    print(f"{'task type':16s} {'points':>6s} " + " ".join(f"{s + ' ms':>11s}" for s in STRATEGIES)
          + f" {'derived/static':>15s} {'derived/planned':>16s}")
    for task in task_types(args.path):
        if not isinstance(task, PddlTaskType):
            continue
        points = interruptions(task)
        if not points:
            continue
        times: dict[str, list[float]] = {s: [] for s in STRATEGIES}
        for ctx in points:
            per: dict[str, list[float]] = {s: [] for s in STRATEGIES}
            for _ in range(args.rounds):
                for s in STRATEGIES:
                    per[s].append(cpu_ms(task, ctx, s))
            for s in STRATEGIES:
                times[s].append(statistics.median(per[s]))
                every[s].append(times[s][-1])
        med = {s: statistics.median(times[s]) for s in STRATEGIES}
        _row(task.name, len(points), med)
    if not every["static"]:
        print("no task type with an [example] to measure", file=sys.stderr)
        return 1
    med = {s: statistics.median(every[s]) for s in STRATEGIES}
    _row("all", len(every["static"]), med)
    print("median CPU ms per genSusp, caches cleared before each call; ratios of medians")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
