"""The report of a sweep: results database → per-scenario, paired, Holm-corrected comparisons.

Reads only the saved results (:mod:`experiments.store`), never a run.  The design it
assumes is the sweep's factorial one (``docs/sweeps.md``): every strategy is a cell of
factors (``update``, ``suspension``, ``policy``, ``hazard_waiting``, ``scheduler``), and
every strategy runs the same randomised variant for a given ``(scenario, seed)``.

* **Primary outcome first** (:class:`PrimaryOutcome`, declared in ``docs/results.md``
  before running): per scenario and strategy cell, the mean hazard-unattended seconds
  against the mean time-to-help, with 95 % CIs — a table and a scatter plot (the frontier).
* **Per scenario, never pooled**: opposite effects in two scenarios do not cancel out.
* **Paired**: each factor's levels are compared holding every other factor fixed, over the
  seeds where both cells ran; a paired t-test gives a p-value, and **Holm's** step-down
  correction runs over every verdict of the report (:func:`holm`).
* A metric **constant** over every run is dropped with a note; **non-finite** values are
  counted and shown, never silently dropped; **failed and unfinished tasks** are left out of
  the duration mean (``derived.finished_duration_s.mean``, from the per-task details) and
  counted separately; runs that **errored** are counted apart (infeasible: no plan, or other);
  **host-dependent** metrics (wall time) are shown without a verdict.
"""

from __future__ import annotations

import csv
import math
import re
import warnings
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from experiments.store import ResultStore, RunRow, Status
from experiments.strategy import FACTORS, Strategy

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

ALL = "*"
"""The scenario column of rows pooled over every scenario (descriptive summaries only, never a verdict)."""

ALPHA = 0.05
"""The family-wise error rate Holm's correction controls over one report."""

TREATMENT = {"update": "planned", "suspension": "planned", "policy": "conditional", "hazard_waiting": "on"}
"""For each two-level factor, the level compared against the other (the difference is treatment − baseline)."""

INFEASIBLE = re.compile(r"infeasib|unsolvable|no plan|PlanningFailed", re.IGNORECASE)
"""An errored run whose message matches this is counted as an infeasible variant, not a crash."""


@dataclass(frozen=True)
class PrimaryOutcome:
    """The declared primary outcome: hazard-unattended seconds against time-to-help.

    Each is a list of dotted metric paths into ``metrics.json``; the first one a run has is
    used (the names of :mod:`experiments.metrics`)."""

    hazard: tuple[str, ...] = ("safety.unattended_s",)
    help: tuple[str, ...] = ("people.time_to_help_s.mean",)


@dataclass(frozen=True)
class Estimate:
    """A sample mean with its 95 % Student-t confidence interval (``half`` is NaN when n < 2)."""

    n: int
    mean: float
    std: float
    half: float

    @property
    def low(self) -> float:
        return self.mean - self.half

    @property
    def high(self) -> float:
        return self.mean + self.half


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
        if host_dependent(self.metric):
            return "–"  # a property of the host, not of the strategy
        return "higher" if higher_is_better(self.metric) else "lower"


@dataclass(frozen=True)
class Analysis:
    """Everything the report says, computed from the rows."""

    rows: tuple[RunRow, ...]
    summaries: tuple[MetricSummary, ...]
    pairs: tuple[Paired, ...]
    constant: Mapping[str, float] = field(default_factory=dict)
    primary: PrimaryOutcome = PrimaryOutcome()


@dataclass(frozen=True)
class ReportFiles:
    """What :func:`build_report` wrote."""

    markdown: Path
    summary_csv: Path
    paired_csv: Path
    plots: tuple[Path, ...]
    html: Path | None = None


def estimate(values: Sequence[float], confidence: float = 0.95) -> Estimate:
    """Mean and Student-t confidence interval of ``values`` (finite numbers)."""
    from scipy import stats

    n = len(values)
    if n == 0:
        return Estimate(0, math.nan, math.nan, math.nan)
    mean = math.fsum(values) / n
    if n < 2:
        return Estimate(1, mean, math.nan, math.nan)
    std = math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (n - 1))
    half = float(stats.t.ppf(0.5 + confidence / 2, n - 1)) * std / math.sqrt(n)
    return Estimate(n, mean, std, half)


def paired_p(diffs: Sequence[float]) -> float:
    """Two-sided p-value of the paired t-test (H0: mean difference 0); NaN when it does not apply.

    Differences that are all equal and non-zero give 0 (no variance, a sure effect); all zero, NaN."""
    from scipy import stats

    e = estimate(diffs)
    if e.n < 2:
        return math.nan
    if e.std == 0:
        return math.nan if e.mean == 0 else 0.0
    t = e.mean / (e.std / math.sqrt(e.n))
    return float(2 * stats.t.sf(abs(t), e.n - 1))


def holm(pvalues: Sequence[float]) -> list[float]:
    """Holm's step-down adjusted p-values (NaN stays NaN and is not counted in the family).

    Sorted ascending, ``p_(i)`` becomes ``max_{j<=i} min(1, (m - j + 1) p_(j))`` with ``m`` the
    number of tests; reject where the adjusted value is below :data:`ALPHA`."""
    idx = sorted((i for i, p in enumerate(pvalues) if not math.isnan(p)), key=lambda i: (pvalues[i], i))
    m = len(idx)
    out = [math.nan] * len(pvalues)
    running = 0.0
    for rank, i in enumerate(idx):
        running = max(running, min(1.0, (m - rank) * pvalues[i]))
        out[i] = running
    return out


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
            first_is_treatment = va == TREATMENT[k] if k in TREATMENT else va > vb
            out.append((k, la, lb) if first_is_treatment else (k, lb, la))
    return sorted(out)


def _outcome(metric: str, treatment: float, baseline: float) -> int:
    """+1 if the treatment is better, 0 if equal, -1 if worse."""
    if abs(treatment - baseline) <= 1e-9 * max(1.0, abs(treatment), abs(baseline)):
        return 0
    better = treatment > baseline if higher_is_better(metric) else treatment < baseline
    return 1 if better else -1


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
                        counts[metric][1 - _outcome(metric, a[metric], b[metric])] += 1
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


# ----------------------------------------------------------------------------------------- writing


def _fmt(x: float) -> str:
    return "–" if math.isnan(x) else f"{x:.4g}"


def _cell(e: Estimate, nonfinite: int = 0) -> str:
    extra = f", {nonfinite} non-finite" if nonfinite else ""
    if e.n == 0:
        return f"– (0{extra})"
    ci = "" if math.isnan(e.half) else f" ± {_fmt(e.half)}"
    return f"{_fmt(e.mean)}{ci} ({e.n}{extra})"


def _table(header: Sequence[str], body: Iterable[Sequence[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in body]
    return lines


def _strategy_table(summaries: Sequence[MetricSummary], scenario: str) -> list[str]:
    mine = [s for s in summaries if s.scenario == scenario]
    metrics = headline({s.metric for s in mine})
    strategies = sorted({s.strategy for s in mine})
    cells = {(s.strategy, s.metric): s for s in mine}
    body = [[st, *(_cell(c.estimate, c.nonfinite) if (c := cells.get((st, m))) else "–" for m in metrics)]
            for st in strategies]
    return _table(["strategy", *metrics], body)


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


def _primary_names(rows: Sequence[RunRow], primary: PrimaryOutcome) -> tuple[str, str]:
    names: list[set[str]] = [set(), set()]
    for row in rows:
        if row.status is Status.OK:
            flat = numeric_metrics(row.metrics)
            for i, paths in enumerate((primary.hazard, primary.help)):
                if (found := lookup(flat, paths)) is not None:
                    names[i].add(found[0])
    return (", ".join(sorted(names[0])) or "none of " + ", ".join(primary.hazard),
            ", ".join(sorted(names[1])) or "none of " + ", ".join(primary.help))


def markdown(analysis: Analysis, title: str = "Sweep report") -> str:
    """The report as Markdown: the primary outcome, counts, tables, paired verdicts, errors."""
    rows, summaries, pairs = analysis.rows, analysis.summaries, analysis.pairs
    ok = [r for r in rows if r.status is Status.OK]
    errors = [r for r in rows if r.status is Status.ERROR]
    scenarios = sorted({r.scenario for r in rows})
    versions = sorted({str(r.record.get("tasker_version", r.record.get("version"))) for r in ok
                       if "tasker_version" in r.record or "version" in r.record})
    hosts = sorted({str(r.record.get("host")) for r in ok if "host" in r.record})
    infeasible = [r for r in errors if INFEASIBLE.search(r.error or "")]
    out = [f"# {title}", "",
           f"{len(rows)} runs: {len(ok)} ok, {len(infeasible)} infeasible, {len(errors) - len(infeasible)} "
           f"failed; {len(scenarios)} scenarios × {len({r.seed for r in rows})} seeds × "
           f"{len({r.strategy for r in rows})} strategies."
           + (f" tasker {', '.join(versions)}." if versions else "")
           + (f" Hosts: {', '.join(hosts)}." if hosts else ""), ""]
    hazard, helped = _primary_names(rows, analysis.primary)
    cells = primary_cells(rows, analysis.primary)
    out += ["## Primary outcome: hazard-unattended time vs time-to-help", "",
            f"Declared before running (`docs/results.md`). Hazard: `{hazard}`; time-to-help: `{helped}` "
            "(the first of the configured paths each run has). Per scenario and strategy cell: mean ± half-width "
            "of the 95 % Student-t CI (runs, non-finite values). The frontier is `plots/primary_frontier.png`.", ""]
    for sc in scenarios:
        here = [(st, c) for (s2, st), c in cells.items() if s2 == sc]
        if not here:
            continue
        out += [f"### {sc}", ""]
        out += _table(["strategy", "hazard unattended (s)", "time to help (s)"],
                      [[st, _cell(h, hb.n), _cell(w, wb.n)] for st, (h, w, hb, wb) in here])
        out.append("")
    out += ["## Runs per scenario", ""]
    body = []
    for sc in scenarios:
        for st in sorted({r.strategy for r in rows if r.scenario == sc}):
            mine_rows = [r for r in rows if (r.scenario, r.strategy) == (sc, st)]
            flat = [numeric_metrics(r.metrics) for r in mine_rows if r.status is Status.OK]
            inf = sum(1 for r in mine_rows if r.status is Status.ERROR and INFEASIBLE.search(r.error or ""))
            body.append([sc, st, str(len(flat)), str(inf),
                         str(sum(1 for r in mine_rows if r.status is Status.ERROR) - inf),
                         _fmt(sum(f.get("totals.failed", 0.0) for f in flat)),
                         _fmt(sum(f.get("totals.unfinished", 0.0) for f in flat))])
    out += _table(["scenario", "strategy", "ok runs", "infeasible runs", "failed runs", "failed tasks",
                   "unfinished tasks"], body)
    out += ["", "Durations are over finished tasks only (`derived.finished_duration_s.mean`); failed and "
                "unfinished tasks are the counts above.", ""]
    if analysis.constant:
        out += ["Dropped, constant over every run (no information): "
                + ", ".join(f"`{m}` = {_fmt(v)}" for m, v in analysis.constant.items()) + ".", ""]
    out += ["## Per scenario", "", "Cells: mean ± half-width of the 95 % Student-t CI (runs; non-finite values "
            "are counted, never averaged). Every metric is in `summary.csv` and `paired.csv`.", ""]
    for sc in scenarios:
        out += [f"### {sc}", "", *_strategy_table(summaries, sc), ""]
    tests = [p for p in pairs if not math.isnan(p.p)]
    if pairs:
        out += ["## Paired comparisons, per scenario, Holm-corrected", "",
                "Each factor's two levels, every other factor fixed, paired by seed (the same randomised "
                "variant): difference treatment − baseline with its 95 % CI, wins/ties/losses of the "
                "treatment, the paired t-test's p-value and its Holm adjustment over all "
                f"{len(tests)} tests of this report (family-wise α = {ALPHA}). Host-dependent metrics "
                "(wall time, real-time factor, planner time, cache hits) get no verdict.", ""]
        shown = set(headline({p.metric for p in pairs}))
        order = {m: i for i, m in enumerate(headline(shown))}
        for dim, t_label, b_label in sorted({(p.dimension, p.treatment, p.baseline) for p in pairs}):
            out += [f"### {dim}: `{t_label}` vs `{b_label}`", ""]
            for sc in scenarios:
                mine = sorted((p for p in pairs if (p.dimension, p.treatment, p.baseline, p.scenario)
                               == (dim, t_label, b_label, sc) and p.metric in shown), key=lambda p: order[p.metric])
                if not mine:
                    continue
                out += [f"{sc}:", ""]
                out += _table(["metric", "better", "treatment − baseline", "wins/ties/losses", "p", "p (Holm)",
                               "verdict"],
                              [[p.metric, p.better, _cell(p.diff, p.nonfinite), _counts(p), _fmt(p.p),
                                _fmt(p.p_holm), _verdict(p)] for p in mine])
                out.append("")
    elif len({r.strategy for r in ok}) > 1:
        out += ["No two strategies differ in exactly one factor: no paired comparison.", ""]
    if errors:
        out += ["## Errored runs", ""]
        out += _table(["scenario", "seed", "strategy", "kind", "error"],
                      [[r.scenario, str(r.seed), r.strategy,
                        "infeasible" if INFEASIBLE.search(r.error or "") else "failed",
                        (r.error or "").splitlines()[0][:200] if r.error else ""] for r in errors])
        out.append("")
    return "\n".join(out)


def _counts(p: Paired) -> str:
    return "–" if host_dependent(p.metric) else f"{p.wins}/{p.ties}/{p.losses}"


def _verdict(p: Paired, short: bool = False) -> str:
    if host_dependent(p.metric):
        return "" if short else "host-dependent: no verdict"
    if p.wins == p.losses == 0:
        return "=" if short else "identical"
    if math.isnan(p.p_holm):
        return "?" if short else "too few pairs"
    if p.p_holm >= ALPHA:
        return "~" if short else "no significant difference"
    treatment_lower = p.diff.mean < 0
    winner = "treatment" if treatment_lower != higher_is_better(p.metric) else "baseline"
    label = p.treatment if winner == "treatment" else p.baseline
    value = dict(Strategy.parse(label).items()).get(p.dimension, label) if label != "default" else label
    shown = ("on" if value else "off") if isinstance(value, bool) else str(value)
    return shown if short else f"{p.dimension}={shown} better"


def write_csv(summaries: Sequence[MetricSummary], pairs: Sequence[Paired], out: Path) -> tuple[Path, Path]:
    """``summary.csv`` (scenario, strategy, metric, n, mean, std, ci_low, ci_high) and ``paired.csv``."""
    summary_path, paired_path = out / "summary.csv", out / "paired.csv"
    with summary_path.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["scenario", "strategy", "metric", "n", "mean", "std", "ci_low", "ci_high", "nonfinite"])
        for s in summaries:
            e = s.estimate
            w.writerow([s.scenario, s.strategy, s.metric, e.n, e.mean, e.std, e.low, e.high, s.nonfinite])
    with paired_path.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["dimension", "treatment", "baseline", "scenario", "metric", "better", "n", "mean_diff",
                    "ci_low", "ci_high", "wins", "ties", "losses", "nonfinite", "p", "p_holm", "verdict",
                    "host_dependent"])
        for p in pairs:
            w.writerow([p.dimension, p.treatment, p.baseline, p.scenario, p.metric, p.better, p.diff.n, p.diff.mean,
                        p.diff.low, p.diff.high, p.wins, p.ties, p.losses, p.nonfinite, p.p, p.p_holm, _verdict(p),
                        int(host_dependent(p.metric))])
    return summary_path, paired_path


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
        ax.set_title(metric + (" (host-dependent: no verdict)" if host_dependent(metric) else ""), fontsize="medium")
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
        path = out / f"paired_{_slug(dim)}_{_slug(p_label)}.png"
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
        from experiments.report_html import sweep_page

        page = out_dir / "report.html"
        page.write_text(sweep_page(text, summaries, pairs), encoding="utf-8")
    return ReportFiles(md, summary_csv, paired_csv, tuple(files), page)
