"""``tasker run``: run a scenario and write its trace.

For now a scenario is a synthetic one (:mod:`experiments.synthetic`); robot
scenarios plug in here too.
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

from experiments import synthetic
from tasker import schedulers


def register(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser("run", help="run a scenario; write DIR/trace.jsonl",
                       description="Run a scenario file on the simulated clock and write its trace.")
    p.add_argument("scenario", help="scenario file (.toml or .json)")
    p.add_argument("--out", default="out", help="output folder (default: out)")
    p.add_argument("--seed", type=int, default=None, help="seed (default: the scenario's)")
    p.add_argument("--scheduler", default=None, help=f"schedule algorithm: {', '.join(schedulers.names())}")
    p.add_argument("--mode", choices=("IT", "CT"), default=None, help="interruptible or constant-task harmonisation")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    scenario = synthetic.load(args.scenario)
    if args.scheduler is not None and args.scheduler not in schedulers.names():
        schedulers.create(args.scheduler)  # raises the error that lists the known names
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    trace = synthetic.run(scenario, seed=args.seed, scheduler=args.scheduler, mode=args.mode)
    trace.write(out / "trace.jsonl")
    ends = trace.of("end")
    causes = Counter(e["cause"] for e in ends)
    last = trace.events[-1]["t"] if trace.events else 0.0
    print(f"{scenario.name}: {len(trace.of('request'))} tasks, {len(ends)} ended "
          f"({', '.join(f'{n} {c}' for c, n in sorted(causes.items()))}) in {last:.1f} s simulated; "
          f"{sum(1 for e in trace.of('command') if e['flag'] == 'susp')} suspensions")
    print(f"trace: {out / 'trace.jsonl'}", file=sys.stderr)
    return 0
