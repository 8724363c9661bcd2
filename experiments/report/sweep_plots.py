"""The PNG charts of a sweep report (matplotlib): a bar chart per headline metric, wins/ties/losses
per paired comparison, and the frontier of the primary outcome.

Plots read what :mod:`experiments.analysis.compare` computed from the saved results, never a run.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path

from experiments.analysis.compare import ALL, MetricSummary, Paired, PrimaryOutcome, primary_cells
from experiments.metrics.registry import headline, host_dependent, label
from experiments.metrics.store import RunRow


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "metric"


def plot(summaries: Sequence[MetricSummary], pairs: Sequence[Paired], out: Path) -> list[Path]:
    """A bar chart with 95 % CI error bars per headline metric (bars: strategies, groups: scenarios),
    and a wins/ties/losses chart per paired comparison.  Files go to ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    files = []
    scenarios = sorted({s.scenario for s in summaries if s.scenario != ALL})
    groups = scenarios or [ALL]
    strategies = sorted({s.strategy for s in summaries})
    cells = {(s.scenario, s.strategy, s.metric): s.estimate for s in summaries}
    width = 0.8 / max(1, len(strategies))
    for metric in headline({s.metric for s in summaries}):
        fig, ax = plt.subplots(figsize=(max(5.5, 1.5 + 0.7 * len(groups) * len(strategies)),
                                        4.0 + 0.2 * math.ceil(len(strategies) / 2)), layout="constrained")
        for i, st in enumerate(strategies):
            est = [cells.get((g, st, metric)) for g in groups]
            means = [e.mean if e else math.nan for e in est]
            errs = [0.0 if e is None or math.isnan(e.half) else e.half for e in est]
            xs = [g + (i - (len(strategies) - 1) / 2) * width for g in range(len(groups))]
            ax.bar(xs, means, width, yerr=errs, capsize=3, label=st)
        ax.set_xticks(range(len(groups)), ["all scenarios" if g == ALL else Path(g).stem for g in groups])
        ax.set_ylabel("mean, 95 % CI")
        ax.set_title(label(metric) + (" (host-dependent: no verdict)" if host_dependent(metric) else ""),
                     fontsize="medium")
        # below the axes, never over a bar
        fig.legend(fontsize="x-small", loc="outside lower center", ncol=min(2, len(strategies)))
        path = out / f"{_slug(metric)}.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        files.append(path)
    for dim, p_label, s_label in sorted({(p.dimension, p.planned, p.static) for p in pairs}):
        shown = headline({p.metric for p in pairs})
        mine = sorted((p for p in pairs if (p.dimension, p.planned, p.static) == (dim, p_label, s_label)
                       and p.metric in shown and not host_dependent(p.metric)),
                      key=lambda p: (p.scenario, shown.index(p.metric)))
        if not mine:
            continue
        fig, ax = plt.subplots(figsize=(6.4, 1.4 + 0.35 * len(mine)), layout="constrained")
        ys = range(len(mine))
        ax.barh(ys, [p.wins for p in mine], color="tab:green", label="treatment better")
        ax.barh(ys, [p.ties for p in mine], left=[p.wins for p in mine], color="tab:gray", label="tie")
        ax.barh(ys, [p.losses for p in mine], left=[p.wins + p.ties for p in mine], color="tab:red",
                label="baseline better")
        ax.set_yticks(list(ys), [f"{Path(p.scenario).stem}: {p.metric}" for p in mine])
        ax.set_xlabel("seed pairs")
        ax.set_title(f"{dim}: {p_label} vs {s_label}", fontsize="small")
        fig.legend(fontsize="x-small", loc="outside lower center", ncol=3)  # never over a bar
        path = out / f"paired_{_slug(dim)}_{_slug(p_label)}_vs_{_slug(s_label)}.png"  # one file per comparison
        fig.savefig(path, dpi=100)
        plt.close(fig)
        files.append(path)
    return files


def plot_frontier(rows: Sequence[RunRow], primary: PrimaryOutcome, out: Path) -> Path | None:
    """``primary_frontier.png``: per scenario, each strategy cell at (mean time-to-help, mean hazard
    unattended) with 95 % CI bars both ways — the frontier of the primary outcome."""
    cells = primary_cells(rows, primary)
    if not cells:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenarios = sorted({sc for sc, _ in cells})
    fig, axes = plt.subplots(1, len(scenarios), figsize=(5.0 * len(scenarios), 4.6), layout="constrained",
                             squeeze=False)
    strategies = sorted({st for _, st in cells})
    for ax, sc in zip(axes[0], scenarios, strict=True):
        for i, st in enumerate(strategies):
            if (sc, st) not in cells:
                continue
            h, w, _, _ = cells[(sc, st)]
            ax.errorbar([w.mean], [h.mean], xerr=[0 if math.isnan(w.half) else w.half],
                        yerr=[0 if math.isnan(h.half) else h.half], fmt="o", capsize=3, color=f"C{i % 10}",
                        label=st)
        ax.set_title(Path(sc).stem, fontsize="medium")
        ax.set_xlabel("time to help (s), mean, 95 % CI")
        ax.set_ylabel("hazard unattended (s), mean, 95 % CI")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize="x-small", loc="outside lower center", ncol=min(2, len(strategies)))
    out.mkdir(parents=True, exist_ok=True)
    path = out / "primary_frontier.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
