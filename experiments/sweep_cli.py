"""``tasker sweep`` and ``tasker report``: run a sweep spec into a results database; report on it.

``register(subparsers)`` adds both subcommands; each handler returns the exit
status.  See ``docs/sweeps.md``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("sweep", help="run scenarios × seeds × strategies into a results database (resumable)",
                       description="Run every job of a sweep spec (TOML) that the results database does not hold "
                                   "yet, in parallel; each result is stored as it finishes, so an interrupted "
                                   "sweep resumes where it stopped.")
    p.add_argument("spec", help="sweep spec (.toml): scenarios, seeds, strategies")
    p.add_argument("--db", required=True, help="results database (SQLite; created if missing)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: CPU count)")
    p.add_argument("--scheduler-address", default=None,
                   help="run on this Dask scheduler (e.g. tcp://host:8786) instead of local processes")
    p.add_argument("--retry-errors", action="store_true", help="run again the jobs stored with status error")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=_sweep)

    r = sub.add_parser("report", help="tables, CSV and plots from a results database",
                       description="Compare the strategies of a sweep: mean and 95 %% CI per metric, paired "
                                   "planned vs static differences, bar charts.")
    r.add_argument("--db", required=True, help="results database written by 'tasker sweep'")
    r.add_argument("--out", required=True, help="output folder (report.md, summary.csv, paired.csv, plots/)")
    r.add_argument("--no-plots", action="store_true", help="tables only")
    r.set_defaults(func=_report)


def _sweep(args: argparse.Namespace) -> int:
    from experiments.sweep import SweepError, load_spec, run_sweep

    spec = load_spec(args.spec)
    if args.workers is not None and args.workers < 1:
        raise SweepError(f"--workers: expected a positive number, got {args.workers}")
    summary = run_sweep(spec, args.db, workers=args.workers, scheduler_address=args.scheduler_address,
                        retry_errors=args.retry_errors, progress=not args.no_progress)
    print(f"{spec.name}: {summary.total} jobs; {summary.skipped} already stored, {summary.ran} run "
          f"({summary.ok} ok, {summary.errors} errors) in {summary.wall:.1f} s on {summary.backend} workers")
    if summary.errors:
        print(f"{summary.errors} runs failed; see 'tasker report --db {args.db}' (rerun with --retry-errors)",
              file=sys.stderr)
    return 1 if summary.errors else 0


def _report(args: argparse.Namespace) -> int:
    from experiments.report import build_report

    files = build_report(args.db, args.out, plots=not args.no_plots)
    print(f"report: {files.markdown}")
    print(f"tables: {files.summary_csv}, {files.paired_csv}; {len(files.plots)} plots in {Path(args.out) / 'plots'}",
          file=sys.stderr)
    return 0
