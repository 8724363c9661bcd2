"""``tasker plan``, ``tasker domains`` and ``tasker fsm``: the planning side of the command line.

:func:`register` adds the subcommands to an ``argparse`` sub-parser set; each sets
``func`` to a handler ``(args) -> int`` returning the exit status: 0 success, 1 no plan
(unsolvable or time-out), 2 bad input, with the message on stderr and never a traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from typing import Any

from planners.checks import DefinitionError, load_problem
from planners.engine import ENGINE_NAME
from planners.examples import StraightLineMotion, example_context
from planners.pddl_task import PddlTaskType
from planners.planner import DEFAULT_PLANNER, PddlText, Planner
from planners.results import PlanResult, PlanStatus
from tasker.errors import TaskerError
from tasker.stage import Purpose, Stage, StagePlan
from tasker.task import Strategy, TaskType

Handler = Callable[[argparse.Namespace], int]


def _guard(handler: Handler) -> Handler:
    """Run a handler; turn every error into a one-line message and exit status 2."""

    def run(args: argparse.Namespace) -> int:
        try:
            return handler(args)
        except TaskerError as exc:
            print(f"error: {exc}", file=sys.stderr)
        except OSError as exc:
            print(f"error: {exc}", file=sys.stderr)
        except Exception as exc:  # noqa: BLE001 - a command line never shows a traceback
            print(f"error: internal: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 2

    run.__name__ = handler.__name__
    run.__doc__ = handler.__doc__
    return run


def _task_types(extra: list[str]) -> list[TaskType]:
    from planners.bundled import task_types

    return task_types(extra)


def _find_task(name: str, extra: list[str]) -> TaskType:
    from tasker.errors import UnknownName

    types = {t.name: t for t in _task_types(extra)}
    if name not in types:
        raise UnknownName("task type", name, list(types))
    return types[name]


def _stages_for(domain_name: str, result: PlanResult, extra: list[str]) -> tuple[Stage, ...]:
    """Stages of a plan: the task type's skills when the domain is a registered task's."""
    assert result.plan is not None
    try:
        task = next((t for t in _task_types(extra) if isinstance(t, PddlTaskType)
                     and t.domain.name == domain_name), None)
    except TaskerError:
        task = None
    if task is not None:
        return task.builder.from_steps(result.plan, {}, {})
    return tuple(Stage(s[0], tuple(s[1:])) for s in result.plan)


@_guard
def plan_command(args: argparse.Namespace) -> int:
    """Solve DOMAIN + PROBLEM; print the plan, its cost and its stages (or JSON)."""
    domain, text, model = load_problem(args.domain, args.problem)
    planner = Planner(args.planner, timeout=args.timeout, cache_size=0)
    result = planner.solve(PddlText(domain.text, text) if planner.name == ENGINE_NAME else model)
    if result.status is PlanStatus.ERROR and result.message.startswith("translator"):
        # FD's own PDDL reader is stricter than UP's (e.g. an empty ``(:goal ())``): let UP write it.
        result = planner.solve(model)
    if result.status is PlanStatus.ERROR:
        print(f"error: planner {result.planner} failed on {args.problem}: {result.message}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(result.to_json()))
    elif result.solved:
        assert result.plan is not None
        print(f"plan ({len(result.plan)} steps, cost {result.cost:g}, {result.planner}, "
              f"{result.wall_time_s * 1000:.0f} ms):")
        for k, step in enumerate(result.plan, 1):
            print(f"  {k:3d}. ({' '.join(step)})")
        print("stages:")
        for k, s in enumerate(_stages_for(domain.name, result, []), 1):
            print(f"  {k:3d}. {s.label} [{s.kind.value}, skill={s.skill or '-'}, {s.duration:g} s]")
    else:
        print(f"{result.status.value}: {result.message or 'no plan'} ({result.planner})")
    return 0 if result.solved else 1


@_guard
def domains_command(args: argparse.Namespace) -> int:
    """List the registered task types."""
    for t in _task_types(args.path):
        arg_list = ", ".join(a.name + ("" if a.required else "?") for a in t.arg_specs)
        print(f"{t.name}({arg_list}): {t.description}")
    return 0


def example_plan(task: TaskType, purpose: Purpose, strategy: str, after: int | None) -> StagePlan:
    """``exeTsk`` of the task's example, or ``exeSusp`` after ``after`` stages of it ran."""
    if not isinstance(task, PddlTaskType):
        raise DefinitionError(task.name, "fsm needs a task type built from a task folder")
    ctx = example_context(task, strategy=Strategy(strategy, strategy), motion=StraightLineMotion())
    if ctx is None:
        raise DefinitionError(task.spec.folder / "task.toml", "no [example] world to show an FSM for")
    exe = task.update_task(ctx)
    if purpose is Purpose.UP_TSK:
        return exe
    k = len(exe.stages) // 2 if after is None else max(0, min(after, len(exe.stages)))
    for s in exe.stages[:k]:
        ctx.world = ctx.world.updated([tuple(f) for f in s.data.get("add", ())],
                                      [tuple(f) for f in s.data.get("delete", ())])
    ctx.plan, ctx.stage_index, ctx.done = exe, k, list(exe.stages[:k])
    ctx.interrupted = exe.stages[k] if k < len(exe.stages) else None
    return task.generate_suspension(ctx)


@_guard
def fsm_command(args: argparse.Namespace) -> int:
    """Print a task's exeTsk or exeSusp FSM for its example world."""
    task = _find_task(args.task_type, args.path)
    plan = example_plan(task, Purpose(args.purpose), args.strategy, args.after)
    print(plan.to_dot() if args.format == "dot" else plan.to_mermaid(), end="")
    if plan.note:
        print(f"%% note: {plan.note}" if args.format == "mermaid" else f"// note: {plan.note}")
    return 0


def register(subparsers: Any) -> None:
    """Add ``plan``, ``domains`` and ``fsm`` to an argparse sub-parser set."""
    p = subparsers.add_parser("plan", help="solve a PDDL domain + problem")
    p.add_argument("domain", metavar="DOMAIN", help="domain.pddl")
    p.add_argument("problem", metavar="PROBLEM", help="problem.pddl")
    p.add_argument("--planner", default=DEFAULT_PLANNER, help=f"UP one-shot engine (default {DEFAULT_PLANNER})")
    p.add_argument("--timeout", type=float, default=60.0, metavar="S", help="seconds (default 60)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=plan_command)

    d = subparsers.add_parser("domains", help="list registered task types")
    d.add_argument("--path", action="append", default=[], help="also load task folders from here")
    d.set_defaults(func=domains_command)

    f = subparsers.add_parser("fsm", help="print a task's exeTsk/exeSusp FSM for its example world")
    f.add_argument("task_type", metavar="TASK_TYPE")
    f.add_argument("--purpose", choices=[p.value for p in Purpose], default=Purpose.UP_TSK.value)
    f.add_argument("--format", choices=["mermaid", "dot"], default="mermaid")
    f.add_argument("--strategy", choices=["planned", "static"], default="planned")
    f.add_argument("--after", type=int, default=None, metavar="K",
                   help="genSusp: interrupt after K stages of exeTsk (default: half way)")
    f.add_argument("--path", action="append", default=[], help="also load task folders from here")
    f.set_defaults(func=fsm_command)


def main(argv: list[str] | None = None) -> int:
    """Stand-alone entry (the lead wires :func:`register` into ``tasker``)."""
    parser = argparse.ArgumentParser(prog="tasker")
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    raise SystemExit(main())
