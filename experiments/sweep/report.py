"""The report of a sweep: results database → per-scenario, paired, Holm-corrected comparisons.

Reads only the saved results (:mod:`experiments.metrics.store`), never a run.  The design it
assumes is the sweep's factorial one (``docs/sweeps.md``): every strategy is a cell of
factors (``update``, ``suspension``, ``policy``, ``hazard_waiting``, ``scheduler``), and
every strategy runs the same randomised variant for a given ``(scenario, seed)``.

* **Primary outcome first** (:class:`~experiments.analysis.compare.PrimaryOutcome`, declared in ``docs/results.md``
  before running): per scenario and strategy cell, the mean hazard-unattended seconds
  against the mean time-to-help, with 95 % CIs — a table and a scatter plot (the frontier).
* **Per scenario, never pooled**: opposite effects in two scenarios do not cancel out.
* **Paired**: each factor's levels are compared holding every other factor fixed, over the
  seeds where both cells ran; a paired t-test gives a p-value, and **Holm's** step-down
  correction runs over every verdict of the report (:func:`experiments.analysis.stats.holm`).
* A metric **constant** over every run is dropped with a note; **non-finite** values are
  counted and shown, never silently dropped; **failed and unfinished tasks** are left out of
  the duration mean (``derived.finished_duration_s.mean``, from the per-task details) and
  counted separately; runs that **errored** are counted apart (infeasible: no plan, or other);
  **host-dependent** metrics (wall time) are shown without a verdict.

The builder is this module; each step is its own: :mod:`experiments.analysis.compare` (summaries and
paired comparisons, over :mod:`experiments.analysis.stats` and :mod:`experiments.metrics.registry`),
:mod:`experiments.report.sweep_tables` (``report.md``, the CSV files), :mod:`experiments.report.sweep_plots`
(the PNGs) and :mod:`experiments.report.sweep_page` (``report.html``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

from experiments.analysis.compare import PrimaryOutcome, analyse
from experiments.metrics.store import ResultStore
from experiments.report.sweep_plots import plot, plot_frontier
from experiments.report.sweep_tables import markdown, write_csv


@dataclass(frozen=True)
class ReportFiles:
    """What :func:`build_report` wrote."""

    markdown: Path
    summary_csv: Path
    paired_csv: Path
    plots: tuple[Path, ...]
    html: Path | None = None


class EmptyDatabase(UserWarning):
    """The results database holds no runs (the sweep has not run, or ran nothing)."""


def build_report(db_path: str | Path, out: str | Path, *, plots: bool = True,
                 primary: PrimaryOutcome = PrimaryOutcome()) -> ReportFiles:
    """Read the results database and write ``report.md``, ``summary.csv``, ``paired.csv`` and ``plots/``.

    ``primary`` says which metrics are the declared primary outcome (first present path wins)."""
    with ResultStore(db_path, readonly=True) as store:  # a report never writes to the database
        rows = store.rows()
    if not rows:
        warnings.warn(EmptyDatabase(f"{db_path}: the results database holds no runs yet; the report is empty"),
                      stacklevel=2)
    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    analysis = analyse(rows, primary)
    summaries, pairs = list(analysis.summaries), list(analysis.pairs)
    md = out_dir / "report.md"
    text = markdown(analysis, title=f"Sweep report: {Path(db_path).name}")
    md.write_text(text + "\n", encoding="utf-8")
    summary_csv, paired_csv = write_csv(summaries, pairs, out_dir)
    files = plot(summaries, pairs, out_dir / "plots") if plots and summaries else []
    if plots and (frontier := plot_frontier(rows, primary, out_dir / "plots")) is not None:
        files.insert(0, frontier)
    page = None
    if plots:
        from experiments.report.sweep_page import sweep_page

        page = out_dir / "report.html"
        page.write_text(sweep_page(text, summaries, pairs), encoding="utf-8")
    return ReportFiles(md, summary_csv, paired_csv, tuple(files), page)
