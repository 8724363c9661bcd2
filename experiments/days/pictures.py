"""The pictures of a day run beside its ``table.md``: the PNGs and the HTML page.

One call for ``tasker day`` (:func:`write`): :func:`experiments.report.day_plots.plot` (completions
per type, how the days ended by each rule, completion − deadline per type, per scheduler) and
:func:`experiments.report.day_page.write_day_page` (the table and the same charts, interactive,
with one shared ``plotly.min.js``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from experiments.report.day_page import write_day_page
from experiments.report.day_plots import plot


def write(out: Path, table_text: str, results: Sequence[Mapping[str, Any]]) -> list[Path]:
    """Write the day run's pictures and ``report.html`` into ``out``; returns the files written."""
    files = plot(results, out)
    files.append(write_day_page(out, table_text, results))
    return files
