"""The calls a notebook needs: run a scenario, load a run, sweep, report, compare, run days.

Named so as not to shadow the sub-packages ``experiments.run``, ``experiments.sweep`` and
``experiments.report``.

These are the stable entry points of :mod:`experiments` (house style 14); ``import experiments``
exports them (lazily: importing the package costs nothing).  The ``tasker`` command's handlers call
them too, after checking their arguments, so a notebook and the command line run the same code::

    import experiments
    result = experiments.run_scenario("experiments/inputs/scenarios/synthetic_demo.toml", seed=3)
    run = experiments.load_run("out/paper")           # a run folder `tasker run` wrote
    summary = experiments.run_sweep("my_sweep.toml", "out/my.db", workers=2)
    analysis = experiments.compare("out/my.db")          # summaries and paired comparisons
    days = experiments.day("experiments/days/protocols/tabsa.toml", 3, ["edf", "lookahead"], out="out/day")

Everything else in :mod:`experiments` is a helper of these, free to change.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from experiments.run.options import RunOptions
from experiments.run.records import RunRecord
from tasker.errors import InputError
from tasker.support import reader

if TYPE_CHECKING:
    from experiments.analysis.compare import Analysis
    from experiments.inputs.robot_scenario import RobotScenario
    from experiments.inputs.strategy import Strategy
    from experiments.run.runner import RunResult
    from experiments.sweep.driver import SweepSummary
    from experiments.sweep.report import ReportFiles
    from experiments.sweep.spec import SweepSpec
    from experiments.trace.timeline import Timeline

__all__ = ["DayReport", "LoadedRun", "compare", "day", "load_run", "run_scenario", "run_sweep", "sweep_report"]


def check_task_paths(paths: Sequence[str]) -> None:
    """Load every task folder under ``paths`` now (a bad folder fails here, before any run)."""
    if paths:
        from planners.bundled import task_types

        task_types(list(paths))


def run_scenario(scenario: str | Path | RobotScenario, options: RunOptions | None = None, *,
                 out: str | Path | None = None, pictures: bool = True, progress: bool = False,
                 **changes: Any) -> RunResult:
    """Run a scenario — a shipped name (``"paper"``), a file, or a loaded robot scenario — and return its
    record, metrics and trace (:class:`~experiments.run.runner.RunResult`).

    ``options`` (:class:`~experiments.run.options.RunOptions`), or its fields as keywords
    (``run("carry", suspension="planned", seed=2)``), choose the seed, the strategies, the scheduler,
    a randomised variant and the task folders besides the bundled ones (each checked before the run).
    ``out``: a folder for ``trace.jsonl``, ``run.json``, ``metrics.json``, ``problems/`` and (``pictures``)
    the figures and ``report.html``; None writes nothing."""
    from experiments.run import runner

    opts = dataclasses.replace(options or RunOptions(), **changes)
    check_task_paths(opts.task_paths)
    return runner.run_scenario(scenario, opts, out=None if out is None else Path(out), progress=progress,
                        pictures=pictures)


@dataclass(frozen=True)
class LoadedRun:
    """A run folder read back: its record (``run.json``), metrics (``metrics.json``) and timeline
    (``trace.jsonl``, read once by :class:`~experiments.trace.timeline.Timeline`)."""

    folder: Path
    record: RunRecord
    metrics: Mapping[str, Any]
    timeline: Timeline


def load_run(folder: str | Path) -> LoadedRun:
    """The run ``tasker run --out FOLDER`` (or :func:`run_scenario` with ``out``) wrote; an
    :class:`~tasker.errors.InputError` names the file, line and field of what is missing or damaged."""
    from experiments.trace.timeline import Timeline

    root = Path(folder)
    if not root.is_dir():
        raise InputError(str(root), "no such run folder (give the --out folder of `tasker run`)")
    files = {name: root / name for name in ("run.json", "metrics.json", "trace.jsonl")}
    for name, path in files.items():
        if not path.is_file():
            raise InputError(str(path), f"the run folder has no {name}")
    record = RunRecord.from_json(reader.parse_json(reader.read_text(files["run.json"]), files["run.json"]),
                                 str(files["run.json"]))
    metrics = reader.parse_json(reader.read_text(files["metrics.json"]), files["metrics.json"])
    if not isinstance(metrics, dict):
        raise InputError(str(files["metrics.json"]), "expected the run's metrics (an object)")
    try:
        timeline = Timeline.read(files["trace.jsonl"])
    except ValueError as exc:
        raise InputError(str(files["trace.jsonl"]), str(exc)) from None
    return LoadedRun(root, record, metrics, timeline)


def run_sweep(spec: str | Path | SweepSpec, db: str | Path, *, workers: int | None = None,
          scheduler_address: str | None = None, task_paths: Sequence[str] = (), retry_errors: bool = False,
          overwrite: bool = False, limit: int | None = None, progress: bool = False) -> SweepSummary:
    """Run every job of a sweep spec that the results database ``db`` does not hold yet
    (:func:`experiments.sweep.driver.run_sweep`: resumable, ``workers`` local processes or the Dask
    scheduler at ``scheduler_address``).  ``task_paths`` add to the spec's own (every folder checked
    before the first job); ``overwrite`` deletes what ``db`` holds first (never while another sweep
    writes it); ``limit`` runs at most that many of the missing jobs."""
    from experiments.sweep import driver
    from experiments.sweep.spec import load_spec

    loaded = load_spec(spec) if isinstance(spec, str | Path) else spec
    paths = [*loaded.task_paths, *(p for p in task_paths if p not in loaded.task_paths)]
    if paths:
        check_task_paths(paths)
        loaded = dataclasses.replace(loaded, task_paths=tuple(paths))
    if overwrite:
        from experiments.metrics.store import remove
        from experiments.sweep.driver import lease

        with lease(db):  # a sweep still writing into it keeps its runs: this one stops instead
            remove(db)
    return driver.run_sweep(loaded, db, workers=workers, scheduler_address=scheduler_address, retry_errors=retry_errors,
                     max_jobs=limit, progress=progress)


def sweep_report(db: str | Path, out: str | Path, *, plots: bool = True) -> ReportFiles:
    """``report.md``, ``summary.csv``, ``paired.csv`` (and ``plots/``, ``report.html``) of a results database."""
    from experiments.sweep.report import build_report

    if not Path(db).is_file():
        raise InputError(str(db), "no such results database (write one with `tasker sweep` or run_sweep())")
    return build_report(db, out, plots=plots)


def compare(db: str | Path) -> Analysis:
    """The strategies of a results database compared: per-metric summaries with 95 % intervals and
    Holm-corrected paired comparisons (:func:`experiments.analysis.compare.analyse`), without files."""
    from experiments.analysis.compare import analyse
    from experiments.metrics.store import ResultStore

    if not Path(db).is_file():
        raise InputError(str(db), "no such results database (write one with `tasker sweep` or run_sweep())")
    with ResultStore(db, readonly=True) as store:
        return analyse(store.rows())


@dataclass(frozen=True)
class DayReport:
    """What :func:`day` produced: one result per (day, scheduler, strategy) and the table of them."""

    results: tuple[dict[str, Any], ...]
    table: str
    """The Markdown table (95 % intervals, paired comparisons), as ``table.md`` holds it."""
    failed: int
    """Days that could not run (listed under the table)."""


def day(protocol: str | Path, days: int, schedulers: Sequence[str], *, out: str | Path, first_seed: int = 1,
        backend: str = "synthetic", strategies: Sequence[Strategy] | None = None, workers: int | None = None,
        keep_runs: bool = False, retry_errors: bool = False, scheduler_address: str | None = None,
        progress: bool = False, command: str | None = None) -> DayReport:
    """Run ``days`` seeded days of a day protocol under each scheduler (and strategy, robot backend)
    into ``out/days.db`` — days already there are not run again — and write ``out/days.jsonl`` and
    ``out/table.md`` (with a "Generated by" line naming ``command`` when given).  ``workers``: local
    processes (default 2 for the synthetic backend, 1 for the robot's)."""
    from experiments.days import pipeline
    from experiments.days.runner import run_days
    from experiments.days.table import report as day_table
    from experiments.inputs.strategy import Strategy

    chosen = list(strategies) if strategies else [Strategy()]
    root = Path(out)
    root.mkdir(parents=True, exist_ok=True)
    proto = pipeline.load(protocol)
    n_workers = workers if workers is not None else (2 if backend == "synthetic" else 1)
    results = run_days(protocol, days, list(schedulers), first_seed=first_seed, workers=n_workers, backend=backend,
                       db=root / "days.db", keep=root / "runs" if keep_runs else None, strategies=chosen,
                       address=scheduler_address, progress=progress, retry_errors=retry_errors)
    (root / "days.jsonl").write_text("".join(json.dumps(r, sort_keys=True) + "\n" for r in results),
                                     encoding="utf-8")
    title = f"{proto.name} ({backend} backend): seeds {first_seed}–{first_seed + days - 1}"
    text = day_table(results, title=title)
    (root / "table.md").write_text(text + (f"\nGenerated by `{command}`.\n" if command else "\n"), encoding="utf-8")
    return DayReport(tuple(results), text, sum(1 for r in results if "error" in r))
