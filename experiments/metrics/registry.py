"""How a sweep report reads a run's metrics: flattened to dotted names, which are shown, which way is better.

``metrics.json`` (:mod:`experiments.metrics.run`) is nested; the report compares numbers, so
:func:`numeric_metrics` flattens it (``totals.duration_s.mean``) and adds the metrics derived from
the per-task details.  The names decide the rest: the headline metrics of the tables and plots
(:data:`HEADLINE`), the direction of *better* (:data:`HIGHER_IS_BETTER`) and the metrics that
measure the host rather than the strategy (:data:`HOST_DEPENDENT`, never given a verdict).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

HIGHER_IS_BETTER = re.compile(r"(?<!un)finished|completed|success|throughput|reward|real_time_factor")
"""Metric names for which a larger value is better (otherwise smaller is)."""

HOST_DEPENDENT = re.compile(r"wall_time|real_time_factor|cache_hits|planner_time")
"""Metric names that measure the machine a run ran on, not the strategy: reported, never given a verdict."""

HEADLINE = (
    "derived.finished_duration_s.mean", "totals.makespan_s", "people.people_waiting_s", "people.people_following_s",
    "safety.unattended_s", "safety.budget_overruns", "safety.violations_at_switch", "safety.hazards_active_at_switch",
    "totals.suspension_s.mean", "totals.resumption_s.mean", "switching.switches", "totals.failed",
    "totals.unfinished", "totals.plans", "totals.static_fallbacks", "planner_wall_time_s", "wall_time_s",
)
"""The metrics shown in the report's tables and plots, in this order, when the runs have them (and they
are not constant); every metric is in the CSV files.  If the runs have none of them, every metric is shown."""

EXCLUDED = ("tasks.", "people.people.", "run.seed", "totals.duration_s.")
"""Prefixes of metrics left out of the report: per-agent details, the seed itself, and the duration over
every ended task (failed ones included) — replaced by ``derived.finished_duration_s``."""


def higher_is_better(metric: str) -> bool:
    return HIGHER_IS_BETTER.search(metric.lower()) is not None


def host_dependent(metric: str) -> bool:
    """True for metrics of the host (wall time, real-time factor, …): no verdict, no wins or losses."""
    return HOST_DEPENDENT.search(metric.lower()) is not None


def headline(metrics: Iterable[str]) -> list[str]:
    """The metrics the tables and plots show: those of :data:`HEADLINE` present, else all."""
    present = set(metrics)
    chosen = [m for m in HEADLINE if m in present]
    return chosen or sorted(present)


def numeric_metrics(metrics: Mapping[str, Any], prefix: str = "") -> dict[str, float]:
    """The numeric values of a metrics dict, nested tables flattened to ``a.b``; others dropped.

    At the top level, ``derived.finished_duration_s.mean`` is added from the per-task details
    (``tasks.*`` with ``cause == "finished"``): the mean duration of the tasks that finished."""
    out: dict[str, float] = {}
    for key, value in metrics.items():
        name = f"{prefix}{key}"
        if name.startswith(EXCLUDED):
            continue
        if isinstance(value, Mapping):
            out.update(numeric_metrics(value, prefix=f"{name}."))
        elif isinstance(value, bool | int | float):
            out[name] = float(value)
        elif isinstance(value, str) and value in ("inf", "-inf", "nan"):
            out[name] = float(value)
    if not prefix:
        out.update(derived(metrics))
    return out


def derived(metrics: Mapping[str, Any]) -> dict[str, float]:
    """Metrics the report derives from a run's per-task details: duration over finished tasks only."""
    tasks = metrics.get("tasks")
    if not isinstance(tasks, Mapping):
        return {}
    finished = [float(t["duration_s"]) for t in tasks.values()
                if isinstance(t, Mapping) and t.get("cause") == "finished"
                and isinstance(t.get("duration_s"), int | float) and not isinstance(t.get("duration_s"), bool)]
    if not finished:
        return {"derived.finished_tasks": 0.0}
    return {"derived.finished_duration_s.mean": math.fsum(finished) / len(finished),
            "derived.finished_tasks": float(len(finished))}


def lookup(metrics: Mapping[str, float], paths: Sequence[str]) -> tuple[str, float] | None:
    """The first of ``paths`` a flattened metrics dict has, with its value."""
    for p in paths:
        if p in metrics:
            return p, metrics[p]
    return None
