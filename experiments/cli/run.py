"""``tasker run``: run a scenario and write its trace, metrics and pictures.

Every argument is checked before the simulation starts (the seed's range, the
scheduler's name, that ``--out`` can be written, that every ``--path`` holds task
folders), so a long run is never lost to a typo.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from experiments import facade
from experiments.cli.args import (
    EXIT_FAILED,
    EXIT_INTERRUPTED,
    EXIT_OK,
    UsageError,
    did_you_mean,
    note,
    seed,
    show_progress,
    writable_dir,
)
from experiments.inputs.strategy import SUSPENSION_VALUES
from tasker.errors import RunInterrupted
from tasker.support.reader import InputWarning
from tasker.trace import FAILED

EXAMPLES = """\
examples:
  tasker run paper --out out/paper                 # the paper's verification scenario (Appendix B)
  tasker run household --suspension static --seed 3
  tasker run experiments/inputs/scenarios/synthetic_demo.toml --no-pictures
  tasker run my.toml --path ~/my_tasks --strict    # with your own task folders; exit 1 if a task failed"""


def add_path_option(p: argparse.ArgumentParser) -> None:
    """``--path DIR`` (repeatable): task folders to load besides the bundled ones and ``$TASKER_TASKS``."""
    p.add_argument("--path", action="append", default=[], metavar="DIR",
                   help="also load task types from this task folder or folder of task folders (repeatable; "
                        "also $TASKER_TASKS, os.pathsep-separated)")


def task_paths(args: argparse.Namespace) -> list[str]:
    """The ``--path`` folders, absolute (so they mean the same in a worker process or on another host)."""
    out = []
    for p in getattr(args, "path", []) or []:
        path = Path(p).expanduser()
        if not path.is_dir():
            raise UsageError("--path", f"{p}: no such folder")
        out.append(str(path.resolve()))
    return out


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("run", help="run a scenario: trace.jsonl, metrics.json, run.json and pictures in DIR",
                       description="Run a scenario (a shipped name such as 'paper', or a .toml file) on the "
                                   "simulated clock and write trace.jsonl, run.json, metrics.json, problems/ (the "
                                   "PDDL of every planning call, for 'tasker explain'), report.html, timeline.png, "
                                   "gantt.png and (robot scenarios) trajectory.jsonl and world.png.",
                       epilog=EXAMPLES)
    p.add_argument("scenario", help="shipped scenario name or scenario file")
    p.add_argument("--out", default=None, metavar="DIR", help="output folder (default: out/NAME)")
    p.add_argument("--seed", type=seed, default=None, help="seed, 0 <= N < 2**32 (default: the scenario's)")
    p.add_argument("--suspension", choices=SUSPENSION_VALUES, default=None,
                   help="genSusp strategy for every task: static (the tree's stages), planned (plan to the tree's "
                        "goal), derived (plan to the goal the folder's declarations give), fallback (the tree "
                        "where it can run, a plan to the derived goal where it cannot); default: the scenario's")
    p.add_argument("--tree", default=None, metavar="[TYPE:]NAME",
                   help="the decision tree genSusp reads: NAME in every task folder that declares [[trees.NAME]], "
                        "or TYPE:NAME in one (default: each folder's [[suspension]])")
    p.add_argument("--update", choices=("static", "planned"), default=None,
                   help="upTsk strategy for every task (default: the scenario's)")
    p.add_argument("--scheduler", default=None,
                   help="schedule algorithm (tasker.schedulers: alg2, lookahead, priority, fifo, sjf, srtf, edf, "
                        "simple, simple2, distance; lookahead-cpsat and any other entry point of tasker.schedulers)")
    p.add_argument("--policy", choices=("strict", "conditional"), default=None,
                   help="suspension policy for both strategies: conditional branches (e.g. leave the cooker on for "
                        "a short interruption) are eligible only under 'conditional' (default: the scenario's)")
    p.add_argument("--hazard-waiting", action="store_true",
                   help="a waiting task secures its declared hazard before its budget runs out (docs/model.md)")
    p.add_argument("--mode", choices=("IT", "CT"), default=None, help="interruptible or constant-task harmonisation")
    p.add_argument("--randomize", action="store_true", help="draw a randomised variant of the scenario from --seed")
    p.add_argument("--no-pictures", action="store_true", help="skip report.html and the PNG figures")
    p.add_argument("--strict", action="store_true", help="exit 1 when a task failed (default: 0 once the run ends)")
    add_path_option(p)
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from experiments.inputs import scenario as scenarios
    from experiments.run.options import RunOptions
    from tasker import schedulers

    if args.tree is not None and not all(p.isidentifier() for p in args.tree.split(":", 1)):
        raise UsageError("--tree", f"expected a tree's NAME or TYPE:NAME (identifiers), got {args.tree!r}")
    if args.scheduler is not None and args.scheduler not in schedulers.names():
        raise UsageError("--scheduler", f"unknown scheduler {args.scheduler!r}"
                                        f"{did_you_mean(args.scheduler, schedulers.names())}; "
                                        f"known: {', '.join(schedulers.names())}")
    paths = task_paths(args)
    path = scenarios.resolve(args.scenario)
    label = scenarios.name_of(path)
    ignored = [f"--{name.replace('_', '-')}" for name in ("update", "suspension", "policy", "hazard_waiting")
               if getattr(args, name)]
    if ignored and scenarios.kind_of(path) == "synthetic":  # its timed stages have no plans, policy or hazards
        warnings.warn(InputWarning(f"{path}: a synthetic scenario's timed stages ignore {', '.join(ignored)}: "
                                   "the run is the static one (run.json records it); compare strategies on a "
                                   "robot scenario"), stacklevel=1)
    want = Path(args.out) if args.out else Path("out") / label
    made = not want.exists()
    out = writable_dir(want, "--out")
    try:
        options = RunOptions(seed=args.seed, update=args.update, suspension=args.suspension, scheduler=args.scheduler,
                             mode=args.mode, randomize=args.randomize, task_paths=tuple(paths), policy=args.policy,
                             hazard_waiting=args.hazard_waiting, tree=args.tree)
        # every task folder is checked before the run (experiments.facade.run_scenario)
        result = facade.run_scenario(path, options, out=out, progress=show_progress(args),
                                     pictures=not args.no_pictures)
    except RunInterrupted as exc:  # stopped while running: what ran is written (experiments.run.runner)
        print(f"tasker run: {exc.reason}; the trace so far, run.json and metrics.json are in {out}/",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception:  # bad input refused before the run: no empty output folder left behind
        if made and out.is_dir() and not any(out.iterdir()):
            out.rmdir()
        raise
    from experiments.report import summary
    from experiments.trace.timeline import Timeline

    tl = Timeline(result.trace.typed)
    print(summary.headline(label, tl, result.metrics, result.record.wall_time_s))
    if not args.quiet:
        for line in summary.ends(tl) + summary.safety(tl, result.metrics):
            print(line)
    note(args, f"wrote {out}/")
    failed = [a.end for a in tl.agents.values() if a.end is not None and a.end.cause in FAILED]
    if args.strict and failed:
        print(f"tasker run: {len(failed)} task(s) failed: "
              + "; ".join(f"{e.agent}: {e.reason}" for e in failed), file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK
