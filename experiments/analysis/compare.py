"""The analysis of a sweep: its runs → per-strategy summaries and paired, Holm-corrected comparisons.

Reads :class:`~experiments.metrics.store.RunRow` values, never a run and never a file: per scenario
(never pooled for a verdict) and strategy cell, an :class:`~experiments.analysis.stats.Estimate` of every
metric (:func:`summarise`); for every two strategies that differ in one factor, the paired
differences over the seeds where both ran (:func:`paired`); and the declared primary outcome per
cell (:func:`primary_cells`).  :func:`analyse` does all of it and drops the constant metrics.
The design it assumes is the one :mod:`experiments.sweep.report` describes.
"""

from __future__ import annotations

import math
import re
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

from experiments.analysis.stats import Estimate, estimate, holm, paired_p
from experiments.inputs.strategy import FACTORS, SUSPENSION_VALUES, Strategy
from experiments.metrics.registry import direction, has_verdict, host_dependent, lookup, numeric_metrics, outcome
from experiments.metrics.store import RunRow, Status

ALL = "*"
"""The scenario column of rows pooled over every scenario (descriptive summaries only, never a verdict)."""

LEVEL_ORDER = {"update": ("static", "planned"), "suspension": SUSPENSION_VALUES,
               "policy": ("strict", "conditional"), "hazard_waiting": ("off", "on")}
"""Each factor's levels, baseline first: of two levels compared, the later one is the treatment
(``planned`` and ``derived`` against ``static``, ``derived`` against ``planned``)."""
TREATMENT = {k: v[-1] for k, v in LEVEL_ORDER.items()}
"""The last level of each factor (the treatment of every comparison it takes part in)."""
"""For each two-level factor, the level compared against the other (the difference is treatment − baseline)."""

INFEASIBLE = re.compile(r"infeasib|unsolvable|no plan|PlanningFailed", re.IGNORECASE)
"""An errored run whose message matches this is counted as an infeasible variant, not a crash."""


@dataclass(frozen=True)
class PrimaryOutcome:
    """The declared primary outcome: hazard-unattended seconds against time-to-help.

    Each is a list of dotted metric paths into ``metrics.json``; the first one a run has is
    used (the names of :mod:`experiments.metrics.run`)."""

    hazard: tuple[str, ...] = ("safety.unattended_s",)
    help: tuple[str, ...] = ("people.time_to_help_s.mean",)


@dataclass(frozen=True)
class MetricSummary:
    """One metric of one strategy, over one scenario (or all: :data:`ALL`); ``nonfinite`` values
    (inf, nan) were seen and are not in the estimate."""

    scenario: str
    strategy: str
    metric: str
    estimate: Estimate
    nonfinite: int = 0


@dataclass(frozen=True)
class Paired:
    """Two levels of one factor, every other factor fixed, on one metric in one scenario, paired by seed.

    ``diff`` estimates *treatment − baseline*; ``p`` is the paired t-test's two-sided p-value and
    ``p_holm`` the Holm-adjusted one (NaN when no test applies: host-dependent, identical, n < 2)."""

    dimension: str  # the factor: "update", "suspension", "policy", "hazard_waiting" or "scheduler"
    treatment: str
    baseline: str
    scenario: str
    metric: str
    diff: Estimate
    wins: int
    ties: int
    losses: int
    nonfinite: int = 0
    p: float = math.nan
    p_holm: float = math.nan

    @property
    def planned(self) -> str:  # the names of the first (planned vs static) report, kept for its readers
        return self.treatment

    @property
    def static(self) -> str:
        return self.baseline

    @property
    def better(self) -> str:
        """``higher`` or ``lower`` as the metric's registration says; ``–`` when it gives no verdict
        (unregistered, a property of the host, or neither way better)."""
        if not has_verdict(self.metric):
            return "–"
        d = direction(self.metric)
        return d.value if d is not None else "–"


@dataclass(frozen=True)
class Analysis:
    """Everything the report says, computed from the rows."""

    rows: tuple[RunRow, ...]
    summaries: tuple[MetricSummary, ...]
    pairs: tuple[Paired, ...]
    constant: Mapping[str, float] = field(default_factory=dict)
    primary: PrimaryOutcome = PrimaryOutcome()


def _finite(values: Iterable[float]) -> list[float]:
    return [v for v in values if math.isfinite(v)]


def constant_metrics(rows: Iterable[RunRow]) -> dict[str, float]:
    """Metrics whose value is the same finite number in every ``ok`` run that has them (no information)."""
    seen: dict[str, set[float]] = defaultdict(set)
    for row in rows:
        if row.status is Status.OK:
            for m, v in numeric_metrics(row.metrics).items():
                seen[m].add(v if math.isfinite(v) else math.inf)  # a non-finite value is never "constant"
    return {m: next(iter(vs)) for m, vs in sorted(seen.items()) if len(vs) == 1 and math.isfinite(next(iter(vs)))}


def summarise(rows: Iterable[RunRow], *, drop: Iterable[str] = ()) -> list[MetricSummary]:
    """Per (scenario or :data:`ALL`, strategy, metric): the estimate over the ``ok`` runs, with the
    count of non-finite values seen (never in the estimate).  Metrics in ``drop`` are left out."""
    skip = set(drop)
    groups: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for row in rows:
        if row.status is not Status.OK:
            continue
        for metric, value in numeric_metrics(row.metrics).items():
            if metric in skip:
                continue
            groups[(row.scenario, row.strategy, metric)].append(value)
            groups[(ALL, row.strategy, metric)].append(value)
    return [MetricSummary(sc, st, m, estimate(_finite(vs)), sum(1 for v in vs if not math.isfinite(v)))
            for (sc, st, m), vs in sorted(groups.items())]


def comparisons(strategies: Iterable[str]) -> list[tuple[str, str, str]]:
    """``(factor, treatment label, baseline label)`` for each pair of strategies that differ in exactly
    one factor.  For two-level factors the treatment is :data:`TREATMENT` (``planned``, ``conditional``,
    ``on``); schedulers are compared in name order (the later name is the treatment)."""
    labels = set(strategies)
    parsed = {}
    for label in labels:
        try:
            parsed[label] = Strategy.parse(label)
        except ValueError:
            continue
    out = []
    items = sorted(parsed.items())
    for i, (la, a) in enumerate(items):
        for lb, b in items[i + 1:]:
            da, db = dict(a.items()), dict(b.items())
            differ = [k for k in FACTORS if da.get(k) != db.get(k)]
            if len(differ) != 1 or differ[0] not in da or differ[0] not in db:
                continue
            k = differ[0]
            va, vb = Strategy(**{k: da[k]}).label.partition("=")[2], Strategy(**{k: db[k]}).label.partition("=")[2]
            order = LEVEL_ORDER.get(k)
            first_is_treatment = order.index(va) > order.index(vb) if order and va in order and vb in order \
                else va > vb
            out.append((k, la, lb) if first_is_treatment else (k, lb, la))
    return sorted(out)


def paired(rows: Iterable[RunRow], *, drop: Iterable[str] = ()) -> list[Paired]:
    """Treatment − baseline per metric and scenario (never pooled), for every pair of strategies that
    differ in one factor, over the seeds where both ran ``ok``; Holm-adjusted over every test returned.

    A pair where either value is not finite is counted in ``nonfinite`` and left out of the difference."""
    skip = set(drop)
    by_run: dict[tuple[str, str], dict[int, dict[str, float]]] = defaultdict(dict)
    for row in rows:
        if row.status is Status.OK:
            by_run[(row.strategy, row.scenario)][row.seed] = numeric_metrics(row.metrics)
    strategies = {st for st, _ in by_run}
    scenarios = sorted({sc for _, sc in by_run})
    out = []
    for dim, t_label, b_label in comparisons(strategies):
        for sc in scenarios:
            diffs: dict[str, list[float]] = defaultdict(list)
            counts: dict[str, list[int]] = defaultdict(lambda: [0, 0, 0])
            nonfinite: dict[str, int] = defaultdict(int)
            a_runs, b_runs = by_run.get((t_label, sc), {}), by_run.get((b_label, sc), {})
            for seed in sorted(set(a_runs) & set(b_runs)):
                a, b = a_runs[seed], b_runs[seed]
                for metric in sorted((set(a) & set(b)) - skip):
                    if math.isfinite(a[metric]) and math.isfinite(b[metric]):
                        diffs[metric].append(a[metric] - b[metric])
                        verdict = outcome(metric, a[metric], b[metric])
                        if verdict is not None:  # a metric without a verdict has no wins or losses
                            counts[metric][1 - verdict] += 1
                    else:
                        nonfinite[metric] += 1
            for metric in sorted(set(diffs) | set(nonfinite)):
                w, t, lo = counts[metric]
                ds = diffs.get(metric, [])
                p = math.nan if host_dependent(metric) else paired_p(ds)
                out.append(Paired(dim, t_label, b_label, sc, metric, estimate(ds), w, t, lo, nonfinite[metric], p))
    adjusted = holm([q.p for q in out])
    return [Paired(q.dimension, q.treatment, q.baseline, q.scenario, q.metric, q.diff, q.wins, q.ties, q.losses,
                   q.nonfinite, q.p, adj) for q, adj in zip(out, adjusted, strict=True)]


def analyse(rows: Sequence[RunRow], primary: PrimaryOutcome = PrimaryOutcome()) -> Analysis:
    """Summaries and Holm-corrected paired comparisons, constant metrics dropped (and remembered)."""
    constant = constant_metrics(rows)
    return Analysis(tuple(rows), tuple(summarise(rows, drop=constant)), tuple(paired(rows, drop=constant)),
                    constant, primary)


def primary_cells(rows: Sequence[RunRow], primary: PrimaryOutcome) -> dict[tuple[str, str], tuple[Estimate, ...]]:
    """Per (scenario, strategy): estimates of the hazard and time-to-help metrics over the ``ok`` runs,
    then the number of runs where each was non-finite (as estimates' ``n``, for the table)."""
    values: dict[tuple[str, str], tuple[list[float], list[float], list[int]]] = {}
    for row in rows:
        if row.status is not Status.OK:
            continue
        flat = numeric_metrics(row.metrics)
        h, w, bad = values.setdefault((row.scenario, row.strategy), ([], [], [0, 0]))
        for found, into, i in ((lookup(flat, primary.hazard), h, 0), (lookup(flat, primary.help), w, 1)):
            if found is None:
                continue
            if math.isfinite(found[1]):
                into.append(found[1])
            else:
                bad[i] += 1
    return {k: (estimate(h), estimate(w), Estimate(bad[0], 0, 0, 0), Estimate(bad[1], 0, 0, 0))
            for k, (h, w, bad) in sorted(values.items())}
