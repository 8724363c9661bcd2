"""``tasker sweep`` and ``tasker report``: run a sweep spec into a results database; report on it.

``register(subparsers)`` adds both subcommands; each handler returns the exit
status.  Every argument is checked before the first job starts: the spec (seeds in
range), that the database can be written, that every ``--path`` holds task folders,
and that a Dask scheduler answers.  See ``docs/sweeps.md`` and ``docs/cli.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import socket
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import urlsplit

from experiments import facade
from experiments.cli.args import (
    EXIT_FAILED,
    EXIT_OK,
    UsageError,
    note,
    positive_int,
    show_progress,
    workers,
    writable_dir,
    writable_file,
)
from experiments.cli.run import add_path_option, task_paths

if TYPE_CHECKING:
    from experiments.sweep.driver import SweepSummary

SWEEP_EXAMPLES = """\
examples:
  tasker sweep experiments/sweep/specs/suspension.toml --db out/suspension.db --workers 2
  tasker sweep my_sweep.toml --db out/my.db --path ~/my_tasks          # with your own task folders
  tasker sweep my_sweep.toml --db out/my.db --scheduler-address tcp://head:8786   # on a Dask cluster
  tasker sweep experiments/sweep/specs/strategies.toml --db out/s.db --seeds 1-20  # a pilot: seeds 1..20
  tasker sweep experiments/sweep/specs/strategies.toml --db out/s.db --limit 30    # 30 more runs, then stop
  tasker sweep my_sweep.toml --db out/my.db --overwrite                  # delete what out/my.db holds, run all"""

REPORT_EXAMPLES = """\
examples:
  tasker report --db out/suspension.db --out out/suspension-report
  tasker report --db out/suspension.db --out out/tables --no-plots"""

CONNECT_TIMEOUT_S = 5.0
"""How long ``--scheduler-address`` may take to accept a connection."""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("sweep", help="run scenarios × seeds × strategies into a results database (resumable)",
                       description="Run every job of a sweep spec (TOML) that the results database does not hold "
                                   "yet, in parallel; each result is stored as it finishes, so an interrupted "
                                   "sweep resumes where it stopped. A stored run is never deleted unless asked "
                                   "by name: --retry-errors (the errors only) or --overwrite (all).",
                       epilog=SWEEP_EXAMPLES)
    p.add_argument("spec", help="sweep spec (.toml): scenarios, seeds, strategies")
    p.add_argument("--db", required=True, help="results database (SQLite; created if missing)")
    p.add_argument("--workers", type=workers, default=None,
                   help="local worker processes, at most 1024 (default: CPU count)")
    p.add_argument("--scheduler-address", default=None, metavar="ADDRESS",
                   help="run on this Dask scheduler (e.g. tcp://host:8786) instead of local processes")
    p.add_argument("--retry-errors", action="store_true",
                   help="run again the jobs stored with status error (the jobs stored as ok are kept)")
    p.add_argument("--overwrite", action="store_true",
                   help="delete the results database first and run every job afresh (a stored run is never "
                        "deleted without it)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar (also --quiet, or not a terminal)")
    p.add_argument("--seeds", default=None, metavar="A-B",
                   help="only these seeds of the spec: A-B, A,B,C or a mix (e.g. 1-20); the rest stay missing")
    p.add_argument("--limit", type=positive_int, default=None, metavar="N",
                   help="run at most N of the missing jobs (in the spec's order), then stop and say how long the "
                        "rest would take")
    add_path_option(p)
    p.set_defaults(func=_sweep)

    r = sub.add_parser("report", help="tables, CSV and plots from a results database",
                       description="Compare the strategies of a sweep: mean and 95 % CI per metric, paired "
                                   "planned vs static differences, bar charts.",
                       epilog=REPORT_EXAMPLES)
    r.add_argument("--db", required=True, help="results database written by 'tasker sweep'")
    r.add_argument("--out", required=True, metavar="DIR",
                   help="output folder (report.md, summary.csv, paired.csv, plots/, report.html)")
    r.add_argument("--no-plots", action="store_true", help="tables only: no plots/, no report.html")
    r.set_defaults(func=_report)


def check_scheduler(address: str, timeout: float = CONNECT_TIMEOUT_S) -> None:
    """Fail now, with a clear message, when the Dask scheduler at ``address`` does not answer.

    A ``tcp://host:port`` (or ``host:port``) address is probed with a plain TCP connection,
    which fails in milliseconds when nothing listens, rather than Dask's 30 s of retries.
    """
    parts = urlsplit(address if "://" in address else f"tcp://{address}")
    if parts.scheme not in ("tcp", "tls", "ws", "wss", "ucx", "inproc"):
        raise UsageError("--scheduler-address", f"{address!r}: expected tcp://HOST:PORT")
    if parts.scheme != "tcp":
        return  # other transports: Dask's own error is caught when connecting
    try:
        host, port = parts.hostname, parts.port
    except ValueError:
        host, port = None, None
    if not host or port is None:
        raise UsageError("--scheduler-address", f"{address!r}: expected tcp://HOST:PORT (e.g. tcp://head:8786)")
    try:
        with socket.create_connection((host, port), timeout=timeout):
            pass
    except OSError as exc:
        raise UsageError("--scheduler-address", f"cannot reach a Dask scheduler at {address}: "
                                                f"{exc.strerror or type(exc).__name__}") from None


@contextmanager
def dask_scheduler(address: str | None) -> Iterator[None]:
    """Around a run on the Dask scheduler at ``address`` (``None``: local workers, nothing to do):
    probe it first (:func:`check_scheduler`), and word losing it as bad ``--scheduler-address``."""
    if not address:
        yield
        return
    check_scheduler(address)
    try:
        yield
    except (OSError, TimeoutError) as exc:
        raise UsageError("--scheduler-address", f"lost the Dask scheduler at {address}: {exc}") from None


def _sweep(args: argparse.Namespace) -> int:
    from experiments.sweep.spec import load_spec

    spec = load_spec(args.spec)
    if args.seeds is not None:
        from experiments.sweep.spec import select_seeds

        try:
            spec = select_seeds(spec, args.seeds)
        except ValueError as exc:
            raise UsageError("--seeds", str(exc)) from None
    paths = [*spec.task_paths, *(p for p in task_paths(args) if p not in spec.task_paths)]
    if paths:
        facade.check_task_paths(paths)  # every task folder checked here, before any job
        spec = dataclasses.replace(spec, task_paths=tuple(paths))
    writable_file(args.db, "--db")
    with dask_scheduler(args.scheduler_address):
        summary = facade.run_sweep(spec, args.db, workers=args.workers, scheduler_address=args.scheduler_address,
                               retry_errors=args.retry_errors, overwrite=args.overwrite, limit=args.limit,
                               progress=show_progress(args) and not args.no_progress)
    print(f"{spec.name}: {summary.total} jobs; {summary.skipped} already stored, {summary.ran} run "
          f"({summary.ok} ok, {summary.errors} errors) in {summary.wall:.1f} s on {summary.backend} workers")
    if summary.not_run:
        print(f"{summary.not_run} jobs not run yet; {_rest(summary, args.db)} (run the same command again to go on)")
    if summary.errors:
        print(f"{summary.errors} runs failed; see 'tasker report --db {args.db}' (rerun with --retry-errors)",
              file=sys.stderr)
    return EXIT_FAILED if summary.errors else EXIT_OK


def _rest(summary: SweepSummary, db: str) -> str:
    """How long the jobs not run should take: at this call's mean job time, or else the database's."""
    per = summary.job_wall / summary.ran if summary.ran else None
    source = "this run's"
    if per is None:
        from experiments.metrics.store import ResultStore

        with ResultStore(db, readonly=True) as store:
            walls = [r.wall for r in store.rows() if r.wall]
        per, source = (sum(walls) / len(walls), "the stored runs'") if walls else (None, "")
    left = summary.remaining_s(per)
    if left is None:
        return "no run time known yet to estimate the rest"
    return (f"at {source} mean of {per:.1f} s a job on {summary.workers} worker(s), about "
            f"{_duration(left)} more")


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _report(args: argparse.Namespace) -> int:
    if not Path(args.db).is_file():
        raise UsageError("--db", f"{args.db}: no such results database (write one with 'tasker sweep')")
    writable_dir(args.out, "--out")
    files = facade.sweep_report(args.db, args.out, plots=not args.no_plots)
    print(f"report: {files.markdown}")
    note(args, f"tables: {files.summary_csv}, {files.paired_csv}; {len(files.plots)} plots in "
               f"{Path(args.out) / 'plots'}")
    return EXIT_OK
