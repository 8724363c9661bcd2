"""``tasker day``: run a day protocol (N days x schedulers on a backend) and write its table.

The same as ``python -m experiments.dayreport``; this module holds only the options, so
``tasker --help`` stays clear of numpy and scipy (the handler imports
:mod:`experiments.dayreport` when it runs).  See ``docs/benchmark.md``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from experiments import days

EXAMPLES = """\
examples:
  tasker day --protocol tabsa --days 100 --out out/day
  tasker day --protocol tabsa-short --backend robot --days 20 --out out/day-robot --resume"""


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--protocol", default="tabsa",
                    help=f"a registered protocol ({', '.join(days.names())}) or a protocol file (.toml)")
    ap.add_argument("--backend", default="synthetic", choices=days.BACKENDS)
    ap.add_argument("--days", type=int, default=100, help="days per scheduler (seeds first-seed, first-seed + 1, ...)")
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--schedulers", nargs="+", default=["lookahead", "alg2", "simple", "simple2", "distance"])
    ap.add_argument("--workers", type=int, default=None,
                    help="local processes (default: 2 synthetic, 1 robot: a robot day is long, keep it in one)")
    ap.add_argument("--resume", action="store_true", help="keep OUT/days.jsonl and run only the days it lacks")
    ap.add_argument("--keep-runs", action="store_true", help="keep each day's files in OUT/runs/SCHEDULER/SEED")
    ap.add_argument("--out", required=True, type=Path, help="folder for days.jsonl and table.md")


def _run(args: argparse.Namespace) -> int:
    from experiments import dayreport

    return dayreport.run(args)


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("day", help="run a day protocol: N days x schedulers on a backend, and its table",
                       description="Run N seeded days of a protocol under each scheduler on the synthetic or the "
                                   "robot backend; write OUT/days.jsonl (each day as it ends) and OUT/table.md "
                                   "(95 % CIs, paired comparisons of lookahead against each baseline).",
                       epilog=EXAMPLES)
    add_arguments(p)
    p.set_defaults(func=_run)
