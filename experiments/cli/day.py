"""``tasker day``: run a day protocol (N days x schedulers on a backend) and write its table.

The same as ``python -m experiments.days.report``; this module holds only the options, so
``tasker --help`` stays clear of numpy and scipy (the handler imports
:mod:`experiments.days.report` when it runs).  See ``docs/benchmark.md``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from experiments.days import pipeline as days
from tasker.support.cliargs import EXIT_INTERRUPTED, seed

EXAMPLES = """\
examples:
  tasker day --protocol tabsa --days 100 --out out/day
  tasker day --protocol tabsa-short --backend robot --days 20 --out out/day-robot --resume
  tasker day --protocol tabsa-short --backend robot --days 10 --schedulers lookahead alg2 \\
      --strategies suspension=static suspension=planned --out out/day-susp"""


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--protocol", default="tabsa",
                    help=f"a registered protocol ({', '.join(days.names())}) or a protocol file (.toml); default tabsa")
    ap.add_argument("--backend", default="synthetic", choices=days.BACKENDS,
                    help="timed stages or TIAGo in MuJoCo (default synthetic)")
    ap.add_argument("--days", type=int, default=100,
                    help="days per scheduler (seeds first-seed, first-seed + 1, ...; default 100)")
    ap.add_argument("--first-seed", type=seed, default=1, help="seed of the first day (default 1)")
    ap.add_argument("--schedulers", nargs="+", default=["lookahead", "alg2", "simple", "simple2", "distance"],
                    help="registered schedulers to compare (default: lookahead alg2 simple simple2 distance)")
    ap.add_argument("--workers", type=int, default=None,
                    help="local processes (default: 2 synthetic, 1 robot: a robot day is long, keep it in one)")
    ap.add_argument("--strategies", nargs="+", default=None, metavar="STRATEGY",
                    help="robot backend: strategies to compare under every scheduler, e.g. 'suspension=static' "
                         "'suspension=planned' (factors update, suspension, policy, hazard_waiting; default: the "
                         "day's own settings)")
    ap.add_argument("--scheduler-address", default=None, metavar="ADDRESS",
                    help="run the days on this Dask scheduler (e.g. tcp://host:8786) instead of local processes, "
                         "as tasker sweep does")
    ap.add_argument("--resume", action="store_true",
                    help="keep OUT/days.db and run only the days it lacks (an older OUT/days.jsonl is read in)")
    ap.add_argument("--retry-errors", action="store_true", help="with --resume: run again the days stored as errors")
    ap.add_argument("--keep-runs", action="store_true",
                    help="keep each day's files in OUT/runs/[STRATEGY/]SCHEDULER/SEED")
    ap.add_argument("--out", required=True, type=Path,
                    help="folder for days.db (the results database), days.jsonl (its days, one per line) and "
                         "table.md")


def _run(args: argparse.Namespace) -> int:
    from experiments.days import report as dayreport

    try:
        return dayreport.run(args)
    except KeyboardInterrupt:  # every day that ended is already in days.db
        db = Path(args.out) / "days.db"
        if db.is_file():
            print(f"tasker day: interrupted; the days that ended are in {db}: run the same command with --resume "
                  "to go on", file=sys.stderr)
            return EXIT_INTERRUPTED
        raise


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("day", help="run a day protocol: N days x schedulers on a backend, and its table",
                       description="Run N seeded days of a protocol under each scheduler on the synthetic or the "
                                   "robot backend (and, there, each strategy), on local processes or Dask; store each "
                                   "day in OUT/days.db as it ends (--resume goes on), write OUT/days.jsonl and "
                                   "OUT/table.md (95 % CIs, paired comparisons of lookahead against each baseline, "
                                   "and of strategies under each scheduler).",
                       epilog=EXAMPLES)
    add_arguments(p)
    p.set_defaults(func=_run)
