"""``tasker plan``, ``domains``, ``fsm`` and ``new``: the planning side of the command line.

:func:`register` adds the subcommands to an ``argparse`` sub-parser set; each sets
``func`` to a handler ``(args) -> int`` returning the exit status (0 success, 1 no
plan, 2 bad input; :mod:`experiments.cli.args`).  Handlers raise on bad input and the caller
(:func:`experiments.cli.args.run_handler`) prints one line, never a traceback.

Heavy modules are imported inside the handlers.  ``tasker plan`` is
:func:`planners.plan_files.plan_files`: with a search schedule it goes to Fast Downward
without unified-planning's engine framework, skips UP's PDDL reader when the same domain
and problem passed its checks before, and UP's validator when the same plan passed it
(:mod:`planners.cache`).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from experiments.cli.args import EXIT_FAILED, EXIT_OK, UsageError, non_negative_int, note, positive_seconds
from planners.scaffold import scaffold
from tasker.support import reader

if TYPE_CHECKING:
    from planners.pddl_task import PddlTaskType
    from planners.results import PlanResult
    from tasker.stage import Purpose, Stage, StagePlan
    from tasker.task import TaskType

ENV_VAR = "TASKER_TASKS"  # as planners.bundled.ENV_VAR, which would import the loader (and UP's reader)

"""The folder ``tasker new`` copies: ``domain.pddl``, ``task.toml``, ``scenario.toml``."""

_DOMAIN_NAME = re.compile(r"\(\s*domain\s+([^\s()]+)\s*\)", re.IGNORECASE)


def _path_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--path", action="append", default=[], metavar="DIR",
                   help="also load task types from this task folder or folder of task folders (repeatable; "
                        "also $TASKER_TASKS)")


def _paths(args: argparse.Namespace) -> list[str]:
    out = []
    for p in getattr(args, "path", []) or []:
        if not Path(p).expanduser().is_dir():
            raise UsageError("--path", f"{p}: no such folder")
        out.append(str(Path(p).expanduser().resolve()))
    return out


def _task_types(extra: list[str]) -> list[TaskType]:
    from planners.bundled import task_types

    return task_types(extra)


def _find_task(name: str, extra: list[str]) -> TaskType:
    from tasker.errors import UnknownName

    types = {t.name: t for t in _task_types(extra)}
    if name not in types:
        raise UnknownName("task type", name, list(types))
    return types[name]


def _task_folders(extra: list[str]) -> list[Path]:
    """Every task folder tasker would load (bundled, ``$TASKER_TASKS``, ``--path``), without loading any."""
    from domains import BUNDLED

    roots = [BUNDLED, *(Path(p) for p in os.environ.get(ENV_VAR, "").split(os.pathsep) if p),
             *(Path(p) for p in extra)]
    out: list[Path] = []
    for r in roots:
        if (r / "task.toml").is_file():
            out.append(r)
        elif r.is_dir():
            out += [q for q in sorted(r.iterdir()) if (q / "task.toml").is_file()]
    return out


def _task_for_domain(domain_text: str, extra: list[str], beside: Path | None = None) -> PddlTaskType | None:
    """The task whose domain has this domain's name — a registered one, or the task folder the
    domain file sits in (``beside``) — or ``None``; only that folder is loaded."""
    m = _DOMAIN_NAME.search(domain_text)
    if not m:
        return None
    own = [beside] if beside is not None and (beside / "task.toml").is_file() else []
    for folder in [*own, *_task_folders(extra)]:
        dm = _DOMAIN_NAME.search((folder / "domain.pddl").read_text(encoding="utf-8", errors="replace")) \
            if (folder / "domain.pddl").is_file() else None
        if dm and dm.group(1).lower() == m.group(1).lower():
            from planners.loader import load_task

            return load_task(folder)
    return None


def _stages_for(domain_text: str, result: PlanResult, extra: list[str],
                beside: Path | None = None) -> tuple[Stage, ...] | str:
    """Stages of a plan: the task type's skills, kinds and durations when the domain is a task
    folder's ``domain.pddl`` (the folder it sits in, or a registered one with its name and text);
    else why there are none — a stage without its task folder has no skill, kind or duration, and
    printing "suspendable, 0 s" for each would say what nobody declared."""
    from tasker.errors import TaskerError

    assert result.plan is not None
    m = _DOMAIN_NAME.search(domain_text)
    name = m.group(1) if m else "?"
    try:
        task = _task_for_domain(domain_text, extra, beside)
    except TaskerError as exc:
        print(f"tasker plan: warning: the stages have no skills or durations: the domain's task folder does "
              f"not load: {exc}", file=sys.stderr)
        return "the domain's task folder does not load (see the warning)"
    if task is None:
        return (f"domain {name!r} is no task folder's: stages (skill, kind, duration) come from a task folder's "
                "task.toml; give its folder with --path")
    unknown = sorted({s[0] for s in result.plan if s[0] not in task.spec.actions or s[0] not in task.domain.actions
                      or len(s) - 1 != len(task.domain.actions[s[0]].params)})
    if unknown:  # a domain of the same name with other actions: its stages would be guessed
        return (f"the plan's action(s) {', '.join(unknown)} are not those of {task.spec.domain_file} (task "
                f"{task.name!r}, whose domain has this name)")
    try:
        return task.builder.from_steps(result.plan, {}, {})
    except (KeyError, ValueError, TaskerError) as exc:
        return f"the plan does not fit task {task.name!r}'s task.toml: {type(exc).__name__}: {exc}"


def _read_arg(path: str, argument: str) -> str:
    p = Path(path)
    if not p.exists():
        raise UsageError(argument, f"{path}: no such file")
    try:  # a folder, a device, a huge or binary file: named by the reader
        return reader.read_text(p)
    except reader.InputError as exc:
        raise UsageError(argument, str(exc)) from None


def plan_command(args: argparse.Namespace) -> int:
    """Solve DOMAIN + PROBLEM; print the plan, its cost, whether it is optimal and its stages (or JSON)."""
    from experiments.cli.temporal import plan_temporal
    from planners.plan_files import Reader, plan_files
    from planners.planner import Planner
    from planners.results import Failure, PlanStatus
    from planners.temporal.reading import is_temporal

    domain_text, problem_text = _read_arg(args.domain, "DOMAIN"), _read_arg(args.problem, "PROBLEM")
    extra = _paths(args)
    if is_temporal(domain_text):  # PDDL 2.1: durative actions (experiments.cli.temporal)
        return plan_temporal(args, domain_text, problem_text,
                             lambda r: _stages_for(domain_text, r, extra, Path(args.domain).parent))
    planner = Planner(args.planner, timeout=args.timeout, cache_size=0)
    answer = plan_files(Path(args.domain), Path(args.problem), domain_text, problem_text, planner)
    result = answer.result
    if result.failure is Failure.INPUT:
        raise UsageError("PROBLEM", f"planner {result.planner} refuses {args.problem}: {result.message}")
    if args.json:
        print(json.dumps(answer.to_json()))
    elif result.solved:
        assert result.plan is not None and result.cost is not None
        print(f"plan ({len(result.plan)} steps, cost {result.cost:g}, {result.planner}, "
              f"{result.wall_time_s * 1000:.0f} ms):")
        for k, step in enumerate(result.plan, 1):
            print(f"  {k:3d}. ({' '.join(step)})")
        print(f"optimal: {'proven' if result.optimal else 'not proven'} ({result.search}'s plan"
              + (f"; {result.message})" if result.message else ")"))
        if answer.reader is Reader.FAST_DOWNWARD:
            print(f"read by Fast Downward's translator; {answer.validation}")
        elif answer.validation:
            print(f"plan {answer.validation}")
        if not getattr(args, "quiet", False):
            stages = _stages_for(domain_text, result, extra, Path(args.domain).parent)
            if isinstance(stages, str):
                print(f"stages: none shown: {stages}")
            else:
                print("stages:")
                for k, s in enumerate(stages, 1):
                    print(f"  {k:3d}. {s.label} [{s.kind.value}, skill={s.skill or '-'}, {s.duration:g} s]")
    elif result.status is not PlanStatus.ERROR:
        print(f"{result.status.value}: {result.message or 'no plan'} ({result.planner})")
        if result.attempts:
            print("tried: " + "; ".join(a.describe(timed=True) for a in result.attempts))
    if result.status is PlanStatus.ERROR:  # the engine's failure (or memory), not the input: exit 1
        print(f"tasker plan: error: {result.message}", file=sys.stderr)
    return EXIT_OK if result.solved else EXIT_FAILED


def domains_command(args: argparse.Namespace) -> int:
    """List the registered task types."""
    for t in _task_types(_paths(args)):
        arg_list = ", ".join(a.name + ("" if a.required else "?") for a in t.arg_specs)
        print(f"{t.name}({arg_list}): {t.description}")
    return EXIT_OK


def example_plan(task: TaskType, purpose: Purpose, strategy: str, after: int | None) -> StagePlan:
    """``exeTsk`` of the task's example, or ``exeSusp`` after ``after`` stages of it ran.

    ``after`` must lie in ``0 … len(exeTsk)`` (``None``: half way)."""
    from planners.checks import DefinitionError
    from planners.examples import StraightLineMotion, example_context
    from planners.pddl_task import PddlTaskType
    from tasker.stage import Purpose
    from tasker.task import Strategy

    if not isinstance(task, PddlTaskType):
        raise DefinitionError(task.name, "fsm needs a task type built from a task folder")
    ctx = example_context(task, strategy=Strategy(strategy, strategy), motion=StraightLineMotion())
    if ctx is None:
        raise DefinitionError(task.spec.folder / "task.toml", "no [example] world to show an FSM for")
    exe = task.update_task(ctx)
    if purpose is Purpose.UP_TSK:
        return exe
    n = len(exe.stages)
    if after is not None and not 0 <= after <= n:
        raise UsageError("--after", f"expected 0 <= K <= {n} (the example's exeTsk has {n} stages), got {after}")
    k = n // 2 if after is None else after
    for s in exe.stages[:k]:
        ctx.world = ctx.world.updated([tuple(f) for f in s.data.get("add", ())],
                                      [tuple(f) for f in s.data.get("delete", ())])
    ctx.plan, ctx.stage_index, ctx.done = exe, k, list(exe.stages[:k])
    ctx.interrupted = exe.stages[k] if k < len(exe.stages) else None
    return task.generate_suspension(ctx)


def fsm_command(args: argparse.Namespace) -> int:
    """Print a task's exeTsk or exeSusp FSM for its example world."""
    from tasker.stage import Purpose

    if args.after is not None and args.purpose != "genSusp":
        raise UsageError("--after", "applies to --purpose genSusp (the exeSusp FSM after K stages of exeTsk); "
                                    "the exeTsk FSM has no K")
    task = _find_task(args.task_type, _paths(args))
    plan = example_plan(task, Purpose(args.purpose), args.strategy, args.after)
    text = plan.to_dot() if args.format == "dot" else plan.to_mermaid()
    if plan.note:  # one comment line, whatever the label it comes from holds
        note = " ".join(plan.note.split())
        text = text.rstrip("\n") + "\n" + (f"%% note: {note}" if args.format == "mermaid" else f"// note: {note}")
    sys.stdout.write(text.rstrip("\n") + "\n")  # a file that ends with its last line, as diagram tools expect
    return EXIT_OK


def new_command(args: argparse.Namespace) -> int:
    """Scaffold a task folder that loads, plans and runs at once."""
    folder = Path(args.dir if args.dir else args.task)
    existed = folder.exists()
    try:
        files = scaffold(args.task, folder, temporal=getattr(args, "temporal", False))
    except BaseException:
        if not existed and folder.is_dir():
            shutil.rmtree(folder)  # leave nothing half-written behind
        raise
    print(f"wrote task folder {folder}/: " + ", ".join(p.name for p in files))
    note(args, "next:\n"
               f"  tasker check {folder}                                   # all the load-time checks\n"
               f"  tasker plan {folder}/domain.pddl {folder}/problem.pddl   # solve its example\n"
               f"  tasker fsm {args.task} --path {folder}                  # its exeTsk FSM\n"
               f"  tasker run {folder}/scenario.toml --path {folder}       # run it on TIAGo in the flat world")
    return EXIT_OK


def register(subparsers: Any) -> None:
    """Add ``plan``, ``domains``, ``fsm`` and ``new`` to an argparse sub-parser set."""
    from planners.schedules import CLI_PLANNER, SCHEDULES

    p = subparsers.add_parser(
        "plan", help="solve a PDDL domain + problem with Fast Downward (or any UP one-shot engine)",
        description="Check a PDDL domain and problem, solve them and print the plan, its cost, whether it is "
                    "proven optimal and, when the domain is a registered task's, the stages it becomes. The default "
                    "planner finds a plan at once and improves it within --timeout. Where unified-planning's reader "
                    "refuses the task, Fast Downward's own translator reads it (said so; the plan is then not "
                    "validated). No plan exits 1; an engine's own failure exits 1 naming it.",
        epilog="examples:\n"
               "  tasker plan domains/cook/domain.pddl problem.pddl\n"
               "  tasker plan domain.pddl problem.pddl --json --timeout 5\n"
               "  tasker plan domain.pddl problem.pddl --planner tasker-opt          # optimal or nothing\n"
               "  tasker plan domain.pddl problem.pddl --planner fast-downward-opt   # any UP one-shot engine\n"
               "planners (--planner):\n" + "\n".join(f"  {s.name:15s} {s.summary}" for s in SCHEDULES.values())
               + "\n  (any other name: a unified-planning one-shot engine)")
    p.add_argument("domain", metavar="DOMAIN", help="domain.pddl")
    p.add_argument("problem", metavar="PROBLEM", help="problem.pddl")
    p.add_argument("--planner", default=CLI_PLANNER,
                   help=f"a search schedule or a unified-planning one-shot engine by name (default {CLI_PLANNER}: "
                        "a plan at once, improved within --timeout; tasker-fd, tasker-opt, tasker-first; "
                        "e.g. fast-downward, fast-downward-opt)")
    p.add_argument("--timeout", type=positive_seconds, default=60.0, metavar="S", help="seconds (default 60)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    _path_option(p)
    p.set_defaults(func=plan_command)

    d = subparsers.add_parser(
        "domains", help="list the registered task types",
        description="List every task type tasker loads: the bundled ones, those in $TASKER_TASKS and --path. "
                    "Each is checked as it loads (an error names the file and line).",
        epilog="examples:\n  tasker domains\n  tasker domains --path ~/my_tasks")
    _path_option(d)
    d.set_defaults(func=domains_command)

    f = subparsers.add_parser(
        "fsm", help="print a task's exeTsk/exeSusp FSM for its example world",
        description="Plan the task's [example] request and print the FSM of its stages (exeTsk, purpose upTsk), "
                    "or the suspension FSM (exeSusp, purpose genSusp) after K stages ran, as Mermaid or Graphviz.",
        epilog="examples:\n"
               "  tasker fsm guide_human\n"
               "  tasker fsm cook --purpose genSusp --after 3 --format dot | dot -Tpng > cook.png\n"
               "  tasker fsm my_task --path ~/my_tasks --strategy static")
    f.add_argument("task_type", metavar="TASK_TYPE", help="a task type with an [example] (tasker domains lists them)")
    f.add_argument("--purpose", choices=["upTsk", "genSusp"], default="upTsk",
                   help="upTsk: the exeTsk FSM; genSusp: the exeSusp FSM after --after stages (default upTsk)")
    f.add_argument("--format", choices=["mermaid", "dot"], default="mermaid",
                   help="Mermaid or Graphviz (default mermaid)")
    f.add_argument("--strategy", choices=["planned", "static"], default="planned",
                   help="build the stages by planning or from the task.toml templates (default planned)")
    f.add_argument("--after", type=non_negative_int, default=None, metavar="K",
                   help="genSusp: interrupt after K stages of exeTsk, 0 <= K <= its length (default: half way)")
    _path_option(f)
    f.set_defaults(func=fsm_command)

    n = subparsers.add_parser(
        "new", help="write a new task folder that loads, plans and runs at once",
        description="Scaffold a task folder: domain.pddl, a task.toml with every key present and commented and an "
                    "[example], the example's problem.pddl, and a scenario.toml that runs the task on TIAGo.",
        epilog="examples:\n"
               "  tasker new fetch_cup                # into ./fetch_cup\n"
               "  tasker new fetch_cup ~/my_tasks/fetch_cup && tasker check ~/my_tasks/fetch_cup")
    n.add_argument("task", metavar="TASK", help="the task type's name (a lower-case identifier)")
    n.add_argument("dir", metavar="DIR", nargs="?", default=None, help="folder to create (default: ./TASK)")
    n.add_argument("--temporal", action="store_true",
                   help="a PDDL 2.1 domain with durative actions (planned by LPG, Aries, Kairos; docs/planners.md)")
    n.set_defaults(func=new_command)
