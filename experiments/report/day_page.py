"""``report.html`` of a day run (``tasker day``): its table as HTML, then interactive charts.

Written beside ``table.md`` and the PNG pictures (:mod:`experiments.report.day_plots`), as the
sweep's page is beside its report: the same Markdown (:func:`experiments.report.sweep_page.markdown_html`)
and the same numbers as the PNGs (:func:`experiments.report.day_plots.figures`) — tasks completed
per type, how the days ended by each rule, completion − deadline per type.  plotly's
JavaScript is loaded from one ``plotly.min.js`` in the same folder (:func:`experiments.report.page.shared_plotly`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import plotly.graph_objects as go

from experiments.report.day_plots import ENDING_COLOURS, figures
from experiments.report.page import figure_div, page, shared_plotly
from experiments.report.sweep_page import markdown_html

PAGE = "report.html"


def day_page(markdown_text: str, results: Sequence[Mapping[str, Any]], *, plotly_src: str | None = None) -> str:
    """The day run as one page: its table (``table.md``), then its charts."""
    title = markdown_text.splitlines()[0].lstrip("# ").strip() if markdown_text.strip() else "Day run"
    f = figures(results)
    sections = [markdown_html(markdown_text), "<h2>Charts</h2>"]
    if f.schedulers:
        panels = [("over the whole day", f.completed)]
        if f.completed_by_stop:
            panels.append(("by the time TaBSA's day would stop", f.completed_by_stop))
        for k, (what, cells) in enumerate(panels):
            fig = go.Figure()
            for t in f.types:
                est = [cells.get((n, t)) for n in f.schedulers]
                fig.add_trace(go.Bar(
                    name=t, x=list(f.schedulers), y=[e.mean if e else None for e in est],
                    error_y={"type": "data", "array": [0.0 if e is None or math.isnan(e.half) else e.half
                                                       for e in est]},
                    hovertemplate=f"{t}<br>%{{x}}: %{{y:.2f}} ± %{{error_y.array:.2f}}<extra></extra>"))
            fig.update_layout(title=f"Completions per type, {what} (mean a day, 95 % CI)", barmode="group",
                              height=400, template="plotly_white", legend={"orientation": "h", "y": -0.3},
                              margin={"t": 50, "r": 10})
            sections.append(figure_div(fig, f"completions-{k}"))
        for k, (rule, counts) in enumerate(f.endings.items()):
            fig = go.Figure()
            for ending in next(iter(counts.values())):
                fig.add_trace(go.Bar(name=ending, x=list(f.schedulers), y=[counts[n][ending] for n in f.schedulers],
                                     marker_color=ENDING_COLOURS.get(ending)))
            fig.update_layout(title=f"How the days end ({'TaBSA' if rule == 'TaBSA' else 'our'} rule)",
                              barmode="stack", height=380, template="plotly_white", yaxis_title="days",
                              legend={"orientation": "h", "y": -0.3}, margin={"t": 50, "r": 10})
            sections.append(figure_div(fig, f"endings-{k}"))
        for k, t in enumerate(f.types):
            fig = go.Figure()
            for n in f.schedulers:
                fig.add_trace(go.Box(name=n, y=list(f.gaps[n, t]), boxpoints="outliers", marker_size=3))
            fig.add_hline(y=0.0, line_color="#d62728", line_width=1)
            fig.update_layout(title=f"completion − deadline: {t} (s; every finished task; above 0: late)",
                              height=380, template="plotly_white", showlegend=False, margin={"t": 50, "r": 10})
            sections.append(figure_div(fig, f"gaps-{k}"))
    return page(title, sections, plotly_src=plotly_src)


def write_day_page(folder: Path, markdown_text: str, results: Sequence[Mapping[str, Any]]) -> Path:
    """``folder/report.html`` with plotly's JavaScript shared in ``folder``; returns its path."""
    path = folder / PAGE
    path.write_text(day_page(markdown_text, results, plotly_src=shared_plotly(folder)), encoding="utf-8")
    return path
