"""The pictures of a day run (``tasker day``), written beside ``table.md``: PNG files (matplotlib).

Each reads the days' stored metrics (the rows of ``days.jsonl``), never a run, one series per
scheduler: tasks completed per type (mean and 95 % CI over days), how the days ended (stacked
counts, by TaBSA's stopping rule and by ours), and the distribution of completion − deadline
over every finished task of every day, per type.  :func:`figures` gives the numbers both the
PNGs and the HTML page (:mod:`experiments.report.day_page`) draw, so the two never disagree.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from experiments.analysis.stats import Estimate, estimate
from experiments.metrics.day import ENDINGS, TABSA_ENDINGS


@dataclass(frozen=True)
class DayFigures:
    """What the day's pictures show, per scheduler (in the run's order) and task type."""

    schedulers: tuple[str, ...]
    types: tuple[str, ...]
    completed: Mapping[tuple[str, str], Estimate]
    """(scheduler, type) -> tasks of that type completed a day."""
    completed_by_stop: Mapping[tuple[str, str], Estimate]
    """(scheduler, type) -> those completed by the time TaBSA's day would stop (empty for days stored
    before TaBSA's rule was read)."""
    endings: Mapping[str, Mapping[str, Mapping[str, int]]]
    """rule ("TaBSA", "ours") -> scheduler -> ending -> days."""
    gaps: Mapping[tuple[str, str], tuple[float, ...]]
    """(scheduler, type) -> completion − deadline of every finished task of every day (s)."""


def figures(results: Sequence[Mapping[str, Any]]) -> DayFigures:
    """The numbers of the pictures, from the days that ran (those with an ``error`` are left out)."""
    ok = [r for r in results if "error" not in r]
    names = tuple(dict.fromkeys(str(r["scheduler"]) for r in ok))
    types = tuple(sorted({t for r in ok for t in r["per_type"]}))
    by = {n: [r for r in ok if r["scheduler"] == n] for n in names}
    completed = {(n, t): estimate([float(r["per_type"].get(t, {}).get("completed", 0)) for r in by[n]])
                 for n in names for t in types}
    by_stop = {(n, t): estimate([float(r["per_type"][t]["tabsa_completed"]) for r in by[n]
                                 if "tabsa_completed" in r["per_type"].get(t, {})]) for n in names for t in types}
    by_stop = {k: e for k, e in by_stop.items() if e.n}
    endings = {"TaBSA": {n: {e: sum(1 for r in by[n] if r.get("tabsa_ending") == e) for e in TABSA_ENDINGS}
                         for n in names},
               "ours": {n: {e: sum(1 for r in by[n] if r.get("ending") == e) for e in ENDINGS} for n in names}}
    if not any(sum(v.values()) for v in endings["TaBSA"].values()):  # days stored before TaBSA's rule was read
        del endings["TaBSA"]
    gaps = {(n, t): tuple(float(g) for r in by[n] for g in r["per_type"].get(t, {}).get("gaps_s", []) or [])
            for n in names for t in types}
    return DayFigures(names, types, completed, by_stop, endings, gaps)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")


ENDING_COLOURS = {"all done": "#2ca02c", "a fall died": "#d62728", "oscillation": "#ff7f0e",
                  "time ran out": "#7f7f7f"}


def plot(results: Sequence[Mapping[str, Any]], out: Path) -> list[Path]:
    """Write the day's PNG pictures to ``out`` (created); returns their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f = figures(results)
    out.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    if not f.schedulers:
        return files
    width = 0.8 / max(1, len(f.types))
    wide = max(6.0, 1.0 + 0.9 * len(f.schedulers))
    panels = [("over the whole day", f.completed)]
    if f.completed_by_stop:
        panels.append(("by the time TaBSA's day would stop", f.completed_by_stop))
    fig, axes = plt.subplots(len(panels), 1, figsize=(wide, 0.6 + 3.4 * len(panels)), layout="constrained",
                             squeeze=False, sharey=True)
    for ax, (title, cells) in zip(axes[:, 0], panels, strict=True):
        for i, t in enumerate(f.types):
            est = [cells.get((n, t)) for n in f.schedulers]
            xs = [k + (i - (len(f.types) - 1) / 2) * width for k in range(len(f.schedulers))]
            ax.bar(xs, [e.mean if e else math.nan for e in est], width,
                   yerr=[0.0 if e is None or math.isnan(e.half) else e.half for e in est], capsize=3,
                   label=t if ax is axes[0, 0] else None)
        ax.set_xticks(range(len(f.schedulers)), f.schedulers, rotation=30, ha="right", fontsize="small")
        ax.set_ylabel("tasks a day (mean, 95 % CI)")
        ax.set_title(f"Completions per type, {title}", fontsize="medium")
    fig.legend(fontsize="small", loc="outside lower center", ncol=len(f.types))
    files.append(_save(fig, out / "completions_per_type.png"))
    plt.close(fig)
    for rule, counts in f.endings.items():
        fig, ax = plt.subplots(figsize=(wide, 4.2), layout="constrained")
        bottom = [0] * len(f.schedulers)
        for ending in next(iter(counts.values())):
            values = [counts[n][ending] for n in f.schedulers]
            ax.bar(range(len(f.schedulers)), values, 0.6, bottom=bottom, label=ending,
                   color=ENDING_COLOURS.get(ending))
            bottom = [b + v for b, v in zip(bottom, values, strict=True)]
        ax.set_xticks(range(len(f.schedulers)), f.schedulers, rotation=30, ha="right", fontsize="small")
        ax.set_ylabel("days")
        ax.set_title(f"How the days end ({rule}'s rule)" if rule == "TaBSA" else "How the days end (our rule)",
                     fontsize="medium")
        fig.legend(fontsize="small", loc="outside lower center", ncol=len(ENDING_COLOURS))
        files.append(_save(fig, out / f"endings_{_slug(rule.lower())}.png"))
        plt.close(fig)
    fig, axes = plt.subplots(len(f.types), 1, figsize=(wide, 2.6 * len(f.types) + 0.6), layout="constrained",
                             squeeze=False)
    for ax, t in zip(axes[:, 0], f.types, strict=True):
        data = [list(f.gaps[n, t]) or [math.nan] for n in f.schedulers]
        ax.boxplot(data, showfliers=True, flierprops={"markersize": 2})
        ax.axhline(0.0, color="#d62728", linewidth=0.8)
        ax.set_xticks(range(1, len(f.schedulers) + 1), f.schedulers, rotation=30, ha="right", fontsize="small")
        ax.set_ylabel("s")
        ax.set_title(f"completion − deadline: {t} (every finished task; above 0: late)", fontsize="medium")
    files.append(_save(fig, out / "completion_minus_deadline.png"))
    plt.close(fig)
    return files


def _save(fig: Any, path: Path) -> Path:
    fig.savefig(path, dpi=100, metadata={"Software": None})  # no version stamp: the same days, the same bytes
    return path
