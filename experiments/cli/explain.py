"""``tasker explain RUN_DIR --agent dN [--at T]``: what an agent planned from, and what moved it.

The reading is :mod:`experiments.report.explain`; this module holds the options and prints.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from experiments.cli.args import UsageError, non_negative_seconds
from experiments.report.explain import explain, load_index, write
from tasker.errors import TaskerError


def _planned_in(run_dir: str) -> str:
    """``"; agents that planned in RUN: d1, d2"`` when ``run_dir`` is a run that planned, else ``""``."""
    try:
        index = load_index(Path(run_dir))
    except TaskerError:
        return ""
    agents = sorted({str(e["agent"]) for e in index}, key=lambda a: (len(a), a))
    return f"; agents that planned in {run_dir}: {', '.join(agents)}" if agents else ""


EXAMPLES = """\
examples:
  tasker explain out/paper --agent d3                 # d3's last problem, plan and what moved it
  tasker explain out/paper --agent d1 --at 60         # the problem d1 planned from at t = 60 s
  tasker explain out/carry --agent d1 --at 40         # the suspension d1 planned when help was asked at 40 s
  tasker explain out/run --agent d2 --out /tmp/d2     # domain.pddl, problem.pddl, plan, explain.txt"""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("explain", help="the PDDL an agent planned from, its plan and what moved it",
                       description="Print (or write with --out) the domain and problem an agent of a run planned "
                                   "from at a time (default: its last planning call), the plan, and the decisions, "
                                   "commands and transitions of the trace that moved it. The PDDL is read by any "
                                   "planner and by unified-planning's PDDLReader.",
                       epilog=EXAMPLES)
    _arguments(p)
    p.set_defaults(func=_command)


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run_dir", metavar="RUN_DIR", help="the output folder of `tasker run`")
    p.add_argument("--agent", default=None, help="agent id: d1, d2, ... (required; without it the error lists the "
                                                 "run's agents that planned)")
    p.add_argument("--at", type=non_negative_seconds, default=None,
                   help="simulated time in s, with what the loop did at once in answer to what happened then "
                        "(default: the agent's last plan)")
    p.add_argument("--out", default=None, help="write domain.pddl, problem.pddl, plan and explain.txt here")


def _command(args: argparse.Namespace) -> int:
    if args.agent is None:
        raise UsageError("--agent", f"which agent? an id such as d1{_planned_in(args.run_dir)}")
    ex = explain(args.run_dir, args.agent, args.at)
    if args.out:
        files = write(ex, Path(args.out))
        print(f"wrote {', '.join(str(f) for f in files)}", file=sys.stderr)
    else:
        sys.stdout.write(ex.text())
    return 0
