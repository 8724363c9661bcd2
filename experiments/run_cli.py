"""``tasker run``: run a scenario and write its trace, metrics and pictures."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tasker import schedulers


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("run", help="run a scenario: trace.jsonl, metrics.json, run.json and pictures in DIR",
                       description="Run a scenario (a shipped name such as 'paper', or a .toml file) on the "
                                   "simulated clock and write trace.jsonl, run.json, metrics.json, timeline.png, "
                                   "gantt.png and (robot scenarios) world.png.")
    p.add_argument("scenario", help="shipped scenario name or scenario file")
    p.add_argument("--out", default=None, help="output folder (default: out/NAME)")
    p.add_argument("--seed", type=int, default=None, help="seed (default: the scenario's)")
    p.add_argument("--suspension", choices=("static", "planned"), default=None,
                   help="genSusp strategy for every task (default: the scenario's)")
    p.add_argument("--update", choices=("static", "planned"), default=None,
                   help="upTsk strategy for every task (default: the scenario's)")
    p.add_argument("--scheduler", default=None, help=f"schedule algorithm: {', '.join(schedulers.names())}")
    p.add_argument("--mode", choices=("IT", "CT"), default=None, help="interruptible or constant-task harmonisation")
    p.add_argument("--randomize", action="store_true", help="draw a randomised variant of the scenario from --seed")
    p.add_argument("--no-pictures", action="store_true", help="skip the PNG figures")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from experiments import scenario as scenarios
    from experiments.runner import run_scenario

    path = scenarios.resolve(args.scenario)
    if args.scheduler is not None and args.scheduler not in schedulers.names():
        schedulers.create(args.scheduler)  # raises the error that lists the known names
    out = Path(args.out) if args.out else Path("out") / path.stem
    result = run_scenario(path, seed=args.seed, update=args.update, suspension=args.suspension,
                          scheduler=args.scheduler, mode=args.mode, out=out, randomize=args.randomize,
                          progress=sys.stderr.isatty(), pictures=not args.no_pictures)
    ends = result.trace.of("end")
    causes: dict[str, int] = {}
    for e in ends:
        causes[e["cause"]] = causes.get(e["cause"], 0) + 1
    last = result.trace.events[-1]["t"] if result.trace.events else 0.0
    suspensions = sum(1 for e in result.trace.of("command") if e["flag"] == "susp")
    print(f"{path.stem}: {len(result.trace.of('request'))} tasks, {len(ends)} ended "
          f"({', '.join(f'{n} {c}' for c, n in sorted(causes.items()))}), {suspensions} suspensions, "
          f"{last:.1f} s simulated in {result.record['wall_time_s']:.1f} s")
    for e in ends:
        print(f"  {e['agent']} {e['task_type']}: {e['reason']} at t={e['t']:.1f}")
    print(f"wrote {out}/", file=sys.stderr)
    return 0
