"""The frame of every ``report.html``: one page, plotly figures in ``<div>`` elements, tables.

The page works offline: plotly's JavaScript is inlined once (no CDN) — or, for folders that
hold many pages (a day run's), referenced from one ``plotly.min.js`` written beside them
(:func:`shared_plotly`), so that each page does not carry its 4-5 MB.  Figures get the ids
their callers give them and no wall-clock value is added, so the same inputs give the same bytes.
The run page (:mod:`experiments.report.run_page`, always self-contained), the sweep page
(:mod:`experiments.report.sweep_page`) and the day page (:mod:`experiments.report.day_page`) are
built from these.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import plotly.graph_objects as go
import plotly.io as pio
from plotly.offline import get_plotlyjs

_CONFIG = {"displaylogo": False, "responsive": True}
_CSS = """
body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:1200px;color:#222;padding:0 1em}
h1{font-size:1.5em} h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;font-size:.85em;margin:.5em 0;display:block;overflow-x:auto}
td,th{border:1px solid #ddd;padding:3px 8px;
text-align:left} th{background:#f4f4f4} .num{text-align:right;font-variant-numeric:tabular-nums}
.note{color:#666;font-size:.9em} .host{color:#888;font-style:italic} code{background:#f4f4f4;padding:0 3px}
"""


PLOTLY_JS = "plotly.min.js"
"""The name of the shared copy of plotly's JavaScript (:func:`shared_plotly`)."""


def page(title: str, sections: Iterable[str], *, plotly_src: str | None = None) -> str:
    """A whole HTML document with plotly's JavaScript inlined once, or, with ``plotly_src``, loaded
    from that relative path (see :func:`shared_plotly`)."""
    script = (f'<script type="text/javascript" src="{html.escape(plotly_src)}"></script>' if plotly_src is not None
              else f'<script type="text/javascript">{get_plotlyjs()}</script>')
    return "\n".join([
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">', f"<title>{html.escape(title)}</title>",
        f"<style>{_CSS}</style>", script, "</head><body>",
        f"<h1>{html.escape(title)}</h1>", *sections, "</body></html>", ""])


def shared_plotly(folder: Path) -> str:
    """Write plotly's JavaScript once into ``folder`` (:data:`PLOTLY_JS`; rewritten only when it
    differs) and return the name a page in ``folder`` loads it by (``page(..., plotly_src=...)``)."""
    path = folder / PLOTLY_JS
    text = get_plotlyjs()
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        folder.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return PLOTLY_JS


def figure_div(fig: go.Figure | dict[str, Any], div_id: str) -> str:
    """A figure (or a figure dict, already valid: not validated again) as a ``<div>`` and its script."""
    return str(pio.to_html(fig, full_html=False, include_plotlyjs=False, div_id=div_id, config=_CONFIG,
                           validate=not isinstance(fig, dict)))


def table(header: Sequence[str], rows: Iterable[Sequence[Any]], numeric: Sequence[bool] = ()) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = []
    for row in rows:
        cells = []
        for i, c in enumerate(row):
            cls = ' class="num"' if i < len(numeric) and numeric[i] else ""
            cells.append(f"<td{cls}>{c if isinstance(c, Raw) else html.escape(str(c))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


class Raw(str):
    """Table cell text that is already HTML."""
