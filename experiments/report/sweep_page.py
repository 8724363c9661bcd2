"""``report.html`` of a sweep: the report's Markdown as HTML, then interactive charts.

Written by :func:`experiments.sweep.report.build_report` beside ``report.md``: the same tables
(:func:`markdown_html` reads the Markdown :mod:`experiments.report.sweep_tables` wrote), a chart per
headline metric and the wins/ties/losses of each paired comparison.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import plotly.graph_objects as go

from experiments.analysis.compare import ALL
from experiments.metrics.registry import headline, host_dependent
from experiments.metrics.registry import label as metric_label
from experiments.report.page import Raw, figure_div, page, table


def markdown_html(text: str) -> str:
    """The sweep report's Markdown (headings, paragraphs, pipe tables, `code`) as HTML."""
    out: list[str] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("|"):
            block = []
            while i < len(lines) and lines[i].startswith("|"):
                block.append([c.strip().replace("\\|", "|") for c in _split_row(lines[i])])
                i += 1
            header, body = block[0], [r for r in block[2:]]
            numeric = [False] + [True] * (len(header) - 1)
            out.append(table(header, ([Raw(_inline(c)) for c in r] for r in body), numeric))
            continue
        if line.startswith("#"):
            level = min(len(line) - len(line.lstrip("#")) + 1, 4)  # the page's <h1> is the title
            if level > 2 or out:
                out.append(f"<h{level}>{_inline(line.lstrip('#').strip())}</h{level}>")
        elif line.strip():
            out.append(f"<p>{_inline(line)}</p>")
        i += 1
    return "\n".join(out)


def _split_row(line: str) -> list[str]:
    cells, cur, esc = [], "", False
    for ch in line.strip()[1:-1]:
        if ch == "|" and not esc:
            cells.append(cur)
            cur = ""
        else:
            cur += ch
        esc = ch == "\\"
    return [*cells, cur]


def _inline(text: str) -> str:
    parts = html.escape(text).split("`")
    return "".join(f"<code>{p}</code>" if i % 2 else p for i, p in enumerate(parts)).replace("*", "")


def sweep_page(markdown_text: str, summaries: Sequence[Any], pairs: Sequence[Any]) -> str:
    """The sweep report as one page: its tables, then a chart per headline metric (mean and 95 %
    CI per strategy and scenario) and the wins/ties/losses of each paired comparison (host-dependent
    metrics are shown, never counted as wins or losses)."""
    title = markdown_text.splitlines()[0].lstrip("# ").strip() if markdown_text else "Sweep report"
    sections = [markdown_html(markdown_text), "<h2>Charts</h2>"]
    scenarios = sorted({s.scenario for s in summaries if s.scenario != ALL})
    groups = scenarios if len(scenarios) > 1 else [ALL]
    strategies = sorted({s.strategy for s in summaries})
    cells = {(s.scenario, s.strategy, s.metric): s.estimate for s in summaries}
    for n, metric in enumerate(headline({s.metric for s in summaries})):
        fig = go.Figure()
        for st in strategies:
            est = [cells.get((g, st, metric)) for g in groups]
            fig.add_trace(go.Bar(
                name=st, x=["all scenarios" if g == ALL else Path(g).stem for g in groups],
                y=[e.mean if e and math.isfinite(e.mean) else None for e in est],
                error_y={"type": "data", "array": [e.half if e and math.isfinite(e.half) else 0 for e in est]},
                customdata=[e.n if e else 0 for e in est],
                hovertemplate=f"{st}<br>%{{x}}: %{{y:.4g}} ± %{{error_y.array:.3g}} (n=%{{customdata}})"
                              "<extra></extra>"))
        note = " (host-dependent: reported, no verdict)" if host_dependent(metric) else ""
        fig.update_layout(title=metric_label(metric) + note, barmode="group", template="plotly_white", height=380,
                          yaxis_title="mean, 95 % CI", legend={"orientation": "h", "y": -0.2},
                          margin={"t": 50, "r": 10})
        sections.append(figure_div(fig, f"metric-{n}"))
    shown = headline({p.metric for p in pairs})
    for n, key in enumerate(sorted({(p.dimension, p.treatment, p.baseline) for p in pairs})):
        # pairs are per scenario, never pooled: one bar per (scenario, metric), as in the PNG charts
        mine = sorted((p for p in pairs if (p.dimension, p.treatment, p.baseline) == key
                       and p.metric in shown and not host_dependent(p.metric)),
                      key=lambda p: (p.scenario, shown.index(p.metric)))
        if not mine:
            continue
        labels = [f"{Path(p.scenario).stem}: {metric_label(p.metric)}" for p in mine]
        fig = go.Figure()
        for label, attr, colour in (("treatment better", "wins", "#2ca02c"), ("tie", "ties", "#999"),
                                    ("baseline better", "losses", "#d62728")):
            fig.add_trace(go.Bar(name=label, orientation="h", y=labels,
                                 x=[getattr(p, attr) for p in mine], marker_color=colour))
        fig.update_layout(title=f"{key[0]}: {key[1]} (treatment) vs {key[2]}, seed pairs",
                          barmode="stack", template="plotly_white", height=160 + 26 * len(mine),
                          yaxis={"autorange": "reversed"}, legend={"orientation": "h", "y": -0.25},
                          margin={"t": 50, "r": 10})
        sections.append(figure_div(fig, f"paired-{n}"))
    return page(title, sections)
