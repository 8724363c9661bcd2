"""``tasker day``: run a day protocol (N days x schedulers on a backend) and write its table.

The days run through :mod:`experiments.days.runner` and their table is
:mod:`experiments.days.table`; this module checks the options and writes ``OUT``.  The
heavy modules (numpy, scipy, the runner) are imported when the command runs, so
``tasker --help`` stays fast.  See ``docs/benchmark.md``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from experiments import facade
from experiments.cli.args import (
    EXIT_INTERRUPTED,
    SEED_LIMIT,
    UsageError,
    positive_int,
    seed,
    show_progress,
    shown,
    workers,
    writable_dir,
    writable_file,
)
from experiments.days import pipeline as days
from tasker.errors import ConfigError

DEFAULT_SCHEDULERS = ("lookahead", "alg2", "edf", "wspt", "atc", "tabsa-simple", "tabsa-simple2", "tabsa-distance",
                      "tabsa-scheduler", "simple", "simple2", "distance")
"""The look-ahead, the paper's Alg. 2, the scheduling baselines, TaBSA's agents, and our priority-first ones."""

EXAMPLES = """\
examples:
  tasker day --protocol tabsa --days 100 --out out/day
  tasker day --protocol tabsa-original --days 20 --schedulers tabsa-simple tabsa-simple2 tabsa-distance \\
      tabsa-scheduler edf lookahead --out out/day-original
  tasker day --protocol tabsa-original --days 100 --schedulers lookahead tabsa-simple:hesitance=* --out out/sweep
  tasker day --protocol tabsa-short --backend robot --days 20 --out out/day-robot   # again: goes on
  tasker day --protocol tabsa-short --days 20 --out out/day --overwrite             # afresh
  tasker day --protocol tabsa-short --backend robot --days 10 --schedulers lookahead alg2 \\
      --strategies suspension=static suspension=planned --out out/day-susp"""


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--protocol", default="tabsa",
                    help=f"a registered protocol ({', '.join(days.names())}) or a protocol file (.toml); default tabsa")
    ap.add_argument("--backend", default="synthetic", choices=days.BACKENDS,
                    help="timed stages or TIAGo in MuJoCo (default synthetic)")
    ap.add_argument("--days", type=positive_int, default=100,
                    help="days per scheduler (seeds first-seed, first-seed + 1, ...; default 100)")
    ap.add_argument("--first-seed", type=seed, default=1, help="seed of the first day (default 1)")
    ap.add_argument("--schedulers", nargs="+", default=list(DEFAULT_SCHEDULERS), metavar="SCHEDULER",
                    help="schedulers to compare: a registered name, with options as NAME:OPTION=VALUE "
                         "(e.g. tabsa-simple:hesitance=0.25; OPTION=* sweeps the scheduler's grid, e.g. "
                         f"tabsa-distance:ratio=*); default: {' '.join(DEFAULT_SCHEDULERS)}")
    ap.add_argument("--workers", type=workers, default=None,
                    help="local processes (default: 2 synthetic, 1 robot: a robot day is long, keep it in one)")
    ap.add_argument("--strategies", nargs="+", default=None, metavar="STRATEGY",
                    help="robot backend: strategies to compare under every scheduler, e.g. 'suspension=static' "
                         "'suspension=planned' (factors update, suspension, policy, hazard_waiting; default: the "
                         "day's own settings)")
    ap.add_argument("--scheduler-address", default=None, metavar="ADDRESS",
                    help="run the days on this Dask scheduler (e.g. tcp://host:8786) instead of local processes, "
                         "as tasker sweep does")
    ap.add_argument("--resume", action="store_true",
                    help="the default, kept for older scripts: OUT/days.db is kept and only the days it lacks run "
                         "(an older OUT/days.jsonl is read in)")
    ap.add_argument("--overwrite", action="store_true",
                    help="delete OUT/days.db and OUT/days.jsonl first and run every day afresh (nothing stored is "
                         "ever deleted without it)")
    ap.add_argument("--retry-errors", action="store_true",
                    help="run again the days stored as errors (the days stored as ok are kept)")
    ap.add_argument("--keep-runs", action="store_true",
                    help="keep each day's files in OUT/runs/[STRATEGY/]SCHEDULER/SEED")
    ap.add_argument("--no-pictures", action="store_true",
                    help="write no PNG pictures and no report.html beside table.md")
    ap.add_argument("--out", required=True, type=Path,
                    help="folder for days.db (the results database), days.jsonl (its days, one per line) and "
                         "table.md")


def _days(a: argparse.Namespace) -> int:
    """Run the days into ``OUT/days.db``; write ``days.jsonl`` and ``table.md``; print the table.

    Bad input raises :class:`experiments.cli.args.UsageError` (or the protocol's
    :class:`tasker.support.reader.InputError`) before the first day runs.  Returns 1 if a day failed
    to run (it is listed under the table), else 0."""

    from experiments.cli.sweep import dask_scheduler
    from experiments.days.resume import check_resumable, import_log, scenario_key
    from experiments.inputs.strategy import Strategy
    from experiments.metrics.store import holds_results
    from experiments.metrics.store import remove as remove_store
    from experiments.sweep.driver import lease
    from experiments.sweep.spec import MAX_JOBS

    a.schedulers = _scheduler_specs(a.schedulers)
    if a.first_seed + a.days > SEED_LIMIT:
        raise UsageError("--days", f"the last day's seed would be {shown(a.first_seed + a.days - 1)}: seeds are "
                                   "< 2**32")
    strategies = []
    for text in a.strategies or ["default"]:
        try:
            st = Strategy.parse(text)
        except ValueError as exc:
            raise UsageError("--strategies", str(exc)) from exc
        if st.scheduler is not None:
            raise UsageError("--strategies", f"{text!r} names a scheduler: schedulers are --schedulers")
        strategies.append(st)
    if len({st.label for st in strategies}) != len(strategies):
        raise UsageError("--strategies", "a strategy is given twice")
    n_jobs = a.days * len(a.schedulers) * len(strategies)
    if n_jobs > MAX_JOBS:  # as a sweep refuses: a typo such as --days 1000000 would fill memory before any day
        raise UsageError("--days", f"{shown(a.days)} days x {len(a.schedulers)} schedulers x {len(strategies)} "
                                   f"strategies = {shown(n_jobs)} days to run, more than the {MAX_JOBS} a run may have")
    for st in strategies:
        try:
            days.check_settings(a.backend, dict(st.items()))
        except ConfigError as exc:
            raise UsageError("--strategies", str(exc)) from exc
    try:
        proto = days.load(a.protocol)
    except ConfigError as exc:
        raise UsageError("--protocol", str(exc)) from exc
    if a.backend == "robot" and proto.robot is None:
        raise UsageError("--backend", f"{proto.source} has no [robot_backend]: it runs on the synthetic backend only")
    for name in a.schedulers:  # what only a drawn day shows (more people than the world has, a scheduler's
        try:  # options): for each scheduler, before any day runs
            days.make(a.protocol, a.first_seed, backend=a.backend, scheduler=name)
        except ConfigError as exc:
            raise UsageError("--protocol", str(exc)) from exc
    n_workers = a.workers if a.workers is not None else (2 if a.backend == "synthetic" else 1)
    writable_dir(a.out, "--out")
    db, log = a.out / "days.db", a.out / "days.jsonl"
    for written in (db, log, a.out / "table.md"):  # now, not after hours of days: their table would be lost
        writable_file(written, "--out")
    if a.overwrite and a.resume:
        raise UsageError("--overwrite", "and --resume contradict each other: --overwrite deletes the stored days, "
                                        "--resume (the default) keeps them")
    if a.overwrite:
        with lease(db):  # a run still writing into OUT keeps its days: this one stops instead
            remove_store(db)
            log.unlink(missing_ok=True)
    if not holds_results(db) and log.is_file():
        import_log(log, db, a.protocol, a.backend)  # days of a tasker before days.db: kept, as any stored day
    try:
        check_resumable(db, scenario_key(a.protocol, a.backend), proto)
    except ConfigError as exc:
        raise UsageError("--out", f"{exc}; give --overwrite to delete them and start afresh, or another --out") \
            from None
    backend = "" if a.backend == "synthetic" else f" --backend {a.backend}"
    chosen = "" if not a.strategies else " --strategies " + " ".join(st.label for st in strategies)
    cmd = (f"tasker day --protocol {a.protocol}{backend} --days {a.days} "
           f"--first-seed {a.first_seed} --schedulers {' '.join(a.schedulers)}{chosen} --out {a.out}")
    with dask_scheduler(a.scheduler_address):
        done = facade.day(a.protocol, a.days, a.schedulers, out=a.out, first_seed=a.first_seed, backend=a.backend,
                          strategies=strategies, workers=n_workers, keep_runs=a.keep_runs,
                          retry_errors=a.retry_errors, scheduler_address=a.scheduler_address,
                          progress=show_progress(a), command=cmd)
    if not a.no_pictures:
        _pictures(a.out, done.table, list(done.results))
    print(done.table)
    return 1 if done.failed else 0


def _scheduler_specs(texts: list[str]) -> list[str]:
    """``--schedulers`` as canonical scheduler specs (:mod:`experiments.days.specs`), ``=*`` expanded."""
    from experiments.days.specs import expand

    try:
        return [s.label for s in expand(texts)]
    except ConfigError as exc:
        raise UsageError("--schedulers", str(exc)) from None


def _pictures(out: Path, text: str, results: list[dict[str, object]]) -> None:
    """The PNGs and report.html beside table.md (:mod:`experiments.days.pictures`)."""
    from experiments.days.pictures import write

    write(out, text, results)


def _run(args: argparse.Namespace) -> int:
    try:
        return _days(args)
    except KeyboardInterrupt:  # every day that ended is already in days.db
        db = Path(args.out) / "days.db"
        if db.is_file():
            print(f"tasker day: interrupted; the days that ended are in {db}: run the same command again to go on "
                  "(without --overwrite)", file=sys.stderr)
            return EXIT_INTERRUPTED
        raise


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("day", help="run a day protocol: N days x schedulers on a backend, and its table",
                       description="Run N seeded days of a protocol under each scheduler on the synthetic or the "
                                   "robot backend (and, there, each strategy), on local processes or Dask; store each "
                                   "day in OUT/days.db as it ends (run again, it goes on: days.db is never "
                                   "emptied without --overwrite), write OUT/days.jsonl and "
                                   "OUT/table.md (95 % CIs, paired comparisons of lookahead against each baseline, "
                                   "and of strategies under each scheduler).",
                       epilog=EXAMPLES)
    add_arguments(p)
    p.set_defaults(func=_run)
