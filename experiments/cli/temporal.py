"""``tasker plan`` for a temporal (PDDL 2.1) domain: :mod:`planners.temporal`'s engines in turn.

:func:`experiments.cli.plan.plan_command` hands a domain here when
:func:`planners.temporal.reading.is_temporal` says it is temporal.  ``--planner`` names one
temporal engine or several, comma-separated, tried in that order (default: every installed
engine of :data:`planners.temporal.engines.DEFAULT_ORDER`).  Exit 0 with a plan UP's validator
accepted; 1 without one — unsolvable, out of time, or every engine failed (each named with what
it said); 2 for bad input (the PDDL, an unknown or uninstalled engine).
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from typing import TYPE_CHECKING

from experiments.cli.args import EXIT_FAILED, EXIT_OK, UsageError

if TYPE_CHECKING:
    from planners.results import PlanResult
    from tasker.stage import Stage


def engines_of(option: str, default: str) -> list[str] | None:
    """The engines ``--planner`` names (None: the default order); a classical engine is refused."""
    from planners.temporal import engines

    if option == default:
        return None
    names = [n.strip() for n in option.split(",") if n.strip()]
    unknown = [n for n in names if n not in engines.ENGINES]
    if unknown or not names:
        raise UsageError("--planner", f"{unknown[0] if unknown else option!r} is not a temporal engine; this domain "
                                      f"has durative actions: choose among {', '.join(engines.ENGINES)} (several, "
                                      f"comma-separated, are tried in turn; default {','.join(engines.DEFAULT_ORDER)})")
    return names


def plan_temporal(args: argparse.Namespace, domain_text: str, problem_text: str,
                  stages_of: Callable[[PlanResult], tuple[Stage, ...] | str]) -> int:
    """Solve a temporal DOMAIN + PROBLEM; print the timed plan (or JSON) and, for a task folder's domain,
    its stages (``stages_of``: ``tasker plan``'s own, the stages or why there are none)."""
    from planners.schedules import CLI_PLANNER
    from planners.temporal.portfolio import TemporalPlanner
    from planners.temporal.reading import parse

    names = engines_of(args.planner, CLI_PLANNER)
    problem = parse(domain_text, problem_text, args.domain, args.problem)
    result = TemporalPlanner(names, timeout=args.timeout).solve(problem)
    if args.json:
        print(json.dumps(result.to_json()))
    elif result.solved:
        assert result.plan is not None and result.makespan is not None
        print(f"plan ({len(result.plan)} steps, makespan {float(result.makespan):g}, {result.engine}, "
              f"{result.wall_time_s * 1000:.0f} ms):")
        for k, step in enumerate(result.plan, 1):
            print(f"  {k:3d}. {step}")
        if not getattr(args, "quiet", False):
            print("engines: " + result.message)
            stages = stages_of(result.to_plan_result())
            if isinstance(stages, str):
                print(f"stages: none shown: {stages}")
            else:
                print("stages:")
                for k, s in enumerate(stages, 1):
                    print(f"  {k:3d}. {s.label} [{s.kind.value}, skill={s.skill or '-'}, {s.duration:g} s]")
    else:
        print(f"{result.status.value}: no valid plan ({result.message})")
    return EXIT_OK if result.solved else EXIT_FAILED
