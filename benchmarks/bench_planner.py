"""Benchmark: our default planner against ``fast-downward-opt``, measured in the same run.

For each bundled task domain, the problems are those its task type really solves on its
example world: ``upTsk`` from the start and after every plan prefix, and ``genSusp``
at every interruption point that needs a plan.  Each is solved by

* ``Planner()`` (``tasker-fd`` on PDDL text, cache off) — what task types call;
* ``OneshotPlanner(name="tasker-fd")`` on UP's model — the registered engine;
* ``OneshotPlanner(name="fast-downward-opt")`` on UP's model — the baseline;

the plan costs must be equal (both optimal).  Then a repeated identical problem is
answered from the cache.  Last, the translator alone, in CPU seconds over all the
problems: the library's own ``main()`` on files (the baseline, what every call ran before
:mod:`planners.translate`) against the reuse path, rounds interleaved, the SAS output of
the two compared byte for byte.  Run: ``python benchmarks/bench_planner.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from unified_planning.shortcuts import OneshotPlanner  # noqa: E402

from planners.bundled import task_types  # noqa: E402
from planners.checks import load_problem_text  # noqa: E402
from planners.examples import StraightLineMotion, example_context  # noqa: E402
from planners.pddl_task import PddlTaskType  # noqa: E402
from planners.planner import PddlText, Planner, plan_cost  # noqa: E402
from planners.registration import register_engine  # noqa: E402
from planners.translate import translate  # noqa: E402
from tasker.stage import Purpose  # noqa: E402

TARGET_SPEEDUP = 5.0
TARGET_CACHE_S = 1e-3
TRANSLATE_ROUNDS = 5


def problems_of(task: PddlTaskType) -> list[tuple[str, PddlText]]:
    """The distinct problems the task type plans on its example world."""
    ctx = example_context(task, motion=StraightLineMotion())
    assert ctx is not None
    exe = task.update_task(ctx)
    out: dict[str, tuple[str, PddlText]] = {}
    world0 = ctx.world
    for k in range(len(exe.stages)):
        world = world0
        for s in exe.stages[:k]:
            world = world.updated([tuple(f) for f in s.data["add"]], [tuple(f) for f in s.data["delete"]])
        ctx_k = example_context(task, motion=StraightLineMotion(), world=world)
        assert ctx_k is not None
        for purpose in Purpose:
            label = f"{purpose.value}@{k}"
            plan = task.generate_suspension(ctx_k) if purpose is Purpose.GEN_SUSP else task.update_task(ctx_k)
            if plan.stages and plan.strategy == "planned":
                text = task.planning_problem(ctx_k, purpose)
                out.setdefault(text.problem, (label, text))
    return list(out.values())


def timed(fn: Callable[[], float | None], repeat: int) -> tuple[float, float | None]:
    """Median seconds of ``repeat`` calls, and the last call's plan cost."""
    times, cost = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        cost = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), cost


def up_solver(name: str, problem: object) -> Callable[[], float | None]:
    register_engine()  # "tasker-fd" is known to UP's factory once registered (idempotent)
    def run() -> float | None:
        with warnings.catch_warnings(), OneshotPlanner(name=name) as engine:
            warnings.simplefilter("ignore")
            engine.skip_checks = True
            res = engine.solve(problem)
        return plan_cost(problem, res.plan) if res.plan is not None else None  # type: ignore[arg-type]

    return run


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="solves per problem and planner (median)")
    ap.add_argument("--temporal", action="store_true", help="only the temporal engines (benchmarks/bench_temporal.py)")
    args = ap.parse_args(argv)
    if args.temporal:  # time to first and best plan per temporal engine, against the commit before them
        import bench_temporal

        return bench_temporal.main([])
    ours = Planner(cache_size=0)
    ratios: list[float] = []
    mismatches = 0
    translated: list[PddlText] = []
    print(f"{'domain':14s} {'problem':12s} {'Planner ms':>10s} {'tasker-fd ms':>12s} {'fd-opt ms':>10s} "
          f"{'ratio':>6s} {'cost':>6s}")
    for task in task_types():
        assert isinstance(task, PddlTaskType)
        dom_ratios = []
        for label, text in problems_of(task):
            translated.append(text)
            model = load_problem_text(task.domain.checked, text.problem)
            t_ours, c_ours = timed(lambda text=text: ours.solve(text).cost, args.repeat)
            t_engine, c_engine = timed(up_solver("tasker-fd", model), args.repeat)
            t_base, c_base = timed(up_solver("fast-downward-opt", model), args.repeat)
            ok = c_ours == c_base == c_engine
            mismatches += not ok
            ratio = t_base / t_ours
            dom_ratios.append(ratio)
            print(f"{task.name:14s} {label:12s} {t_ours * 1e3:10.1f} {t_engine * 1e3:12.1f} {t_base * 1e3:10.1f} "
                  f"{ratio:6.1f} {c_ours:6g}{'' if ok else f'  COST MISMATCH: fd-opt {c_base}, engine {c_engine}'}")
        print(f"{task.name:14s} median speed-up over fast-downward-opt: {statistics.median(dom_ratios):.1f}x "
              f"({len(dom_ratios)} problems)")
        ratios += dom_ratios

    cached = Planner()
    task = task_types()[0]
    assert isinstance(task, PddlTaskType)
    label, text = problems_of(task)[0]
    cached.solve(text)
    hits = []
    for _ in range(1000):
        t0 = time.perf_counter()
        res = cached.solve(PddlText(text.domain, text.problem))
        hits.append(time.perf_counter() - t0)
        assert res.cached
    cache_s = statistics.median(hits)
    overall = statistics.median(ratios)
    print(f"\noverall median speed-up of Planner() over fast-downward-opt: {overall:.1f}x over {len(ratios)} problems "
          f"(target >= {TARGET_SPEEDUP:g}x) {'OK' if overall >= TARGET_SPEEDUP else 'MISSED'}")
    print(f"repeated identical problem from the cache: median {cache_s * 1e6:.1f} us, max {max(hits) * 1e6:.1f} us "
          f"(target <= {TARGET_CACHE_S * 1e3:g} ms) {'OK' if cache_s <= TARGET_CACHE_S else 'MISSED'}")
    print(f"plan costs equal on every problem: {'yes' if mismatches == 0 else f'NO ({mismatches} mismatches)'}")
    same = translator(translated, max(args.repeat, TRANSLATE_ROUNDS))
    return 0 if mismatches == 0 and same and overall >= TARGET_SPEEDUP and cache_s <= TARGET_CACHE_S else 1


def translator(problems: list[PddlText], rounds: int) -> bool:
    """CPU seconds of the translator over ``problems``: the library's ``main()`` on files against
    the reuse path (each domain read once per process), rounds interleaved; True if every SAS
    output is byte-identical."""
    same = all(translate(t.domain, t.problem) == translate(t.domain, t.problem, reuse=False) for t in problems)
    cpu: dict[bool, list[float]] = {False: [], True: []}
    for _ in range(rounds):
        for reuse in (False, True):
            t0 = time.process_time()
            for t in problems:
                translate(t.domain, t.problem, reuse=reuse)
            cpu[reuse].append(time.process_time() - t0)
    base, now = statistics.median(cpu[False]), statistics.median(cpu[True])
    print(f"translator, CPU s over {len(problems)} problems (median of {rounds} rounds): library main() on files "
          f"{base:.3f}, reuse path {now:.3f} = {base / now:.2f}x; SAS identical on every problem: "
          f"{'yes' if same else 'NO'}")
    return same


if __name__ == "__main__":
    raise SystemExit(main())
