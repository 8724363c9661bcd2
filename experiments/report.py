"""The report of a sweep: results database → comparison tables, CSV and plots.

Reads only the saved results (:mod:`experiments.store`), never a run.  For every
numeric metric the runs returned it gives, per strategy (over all scenarios and per
scenario), the mean with a 95 % Student-t confidence interval; and, for every pair of
strategies that differ only in ``update`` or only in ``suspension``, the paired
difference *planned − static* over the ``(scenario, seed)`` pairs where both ran,
with its confidence interval and a count of wins, ties and losses of *planned*, so a
reader sees where planned suspension beats static and where it does not.

Metrics are whatever the runs stored: nested tables are flattened to dotted names,
booleans count as 0/1, ``"inf"``/``"nan"`` strings are read as numbers, and values
that are not finite are left out (the ``n`` column says how many were used).  A
metric is taken as "lower is better" unless its name says otherwise (see
:func:`higher_is_better`).
"""

from __future__ import annotations

import csv
import math
import re
import warnings
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from experiments.store import ResultStore, RunRow, Status
from experiments.sweep import Strategy

HIGHER_IS_BETTER = re.compile(r"(?<!un)finished|completed|success|throughput|reward|real_time_factor")
"""Metric names for which a larger value is better (otherwise smaller is)."""

HOST_DEPENDENT = re.compile(r"wall_time|real_time_factor|cache_hits|planner_time")
"""Metric names that measure the machine a run ran on, not the strategy: reported, never given a verdict."""

HEADLINE = (
    "totals.duration_s.mean", "totals.makespan_s", "people.people_waiting_s", "people.people_following_s",
    "safety.cooker_unattended_s", "safety.violations_at_switch", "safety.hazards_active_at_switch",
    "totals.suspension_s.mean", "totals.resumption_s.mean", "switching.switches", "totals.failed",
    "totals.unfinished", "totals.plans", "totals.static_fallbacks", "planner_wall_time_s", "wall_time_s",
)
"""The metrics (of :func:`experiments.metrics.compute` and the runner) shown in the report's tables
and plots, in this order, when the runs have them; every metric is in the CSV files.  If the
runs have none of them, every metric is shown."""

EXCLUDED = ("tasks.", "people.people.", "run.seed")
"""Prefixes of metrics left out of the report: per-agent details and the seed itself."""

ALL = "*"
"""The scenario column of rows pooled over every scenario."""


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
    """One metric of one strategy, over one scenario (or all: :data:`ALL`)."""

    scenario: str
    strategy: str
    metric: str
    estimate: Estimate


@dataclass(frozen=True)
class Paired:
    """Planned vs static on one metric, paired by ``(scenario, seed)``: the difference planned − static."""

    dimension: str  # "update", "suspension" or "update+suspension"
    planned: str
    static: str
    scenario: str
    metric: str
    diff: Estimate
    wins: int
    ties: int
    losses: int

    @property
    def better(self) -> str:
        if host_dependent(self.metric):
            return "–"  # a property of the host, not of the strategy
        return "higher" if higher_is_better(self.metric) else "lower"


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
    """The numeric values of a metrics dict, nested tables flattened to ``a.b``; others dropped."""
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
    return out


def _finite(values: Iterable[float]) -> list[float]:
    return [v for v in values if math.isfinite(v)]


def summarise(rows: Iterable[RunRow]) -> list[MetricSummary]:
    """Per (scenario or :data:`ALL`, strategy, metric): the estimate over the ``ok`` runs."""
    groups: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for row in rows:
        if row.status is not Status.OK:
            continue
        for metric, value in numeric_metrics(row.metrics).items():
            groups[(row.scenario, row.strategy, metric)].append(value)
            groups[(ALL, row.strategy, metric)].append(value)
    return [MetricSummary(sc, st, m, estimate(_finite(vs))) for (sc, st, m), vs in sorted(groups.items())]


def comparisons(strategies: Iterable[str]) -> list[tuple[str, str, str]]:
    """``(dimension, planned label, static label)`` for each pair of strategies that differ only in
    planned → static in ``update``, in ``suspension``, or in both (dimension ``update+suspension``)."""
    labels = set(strategies)
    out = []
    for label in sorted(labels):
        try:
            s = Strategy.parse(label)
        except ValueError:
            continue
        planned = [d for d in ("update", "suspension") if getattr(s, d) == "planned"]
        subsets = [[d] for d in planned] + ([planned] if len(planned) == 2 else [])
        for dims in subsets:
            other = Strategy(**(dict(s.items()) | {d: "static" for d in dims})).label
            if other in labels:
                out.append(("+".join(dims), label, other))
    return out


def _outcome(metric: str, planned: float, static: float) -> int:
    """+1 if planned is better, 0 if equal, -1 if worse."""
    if abs(planned - static) <= 1e-9 * max(1.0, abs(planned), abs(static)):
        return 0
    better = planned > static if higher_is_better(metric) else planned < static
    return 1 if better else -1


def paired(rows: Iterable[RunRow]) -> list[Paired]:
    """Planned − static per metric, over all scenarios and per scenario, for every comparable pair."""
    by_run: dict[tuple[str, str], dict[tuple[str, int], dict[str, float]]] = defaultdict(dict)
    for row in rows:
        if row.status is Status.OK:
            by_run[(row.strategy, row.scenario)][(row.scenario, row.seed)] = numeric_metrics(row.metrics)
    strategies = {st for st, _ in by_run}
    scenarios = sorted({sc for _, sc in by_run})
    out = []
    for dim, planned_label, static_label in comparisons(strategies):
        for scope in [ALL, *scenarios]:
            diffs: dict[str, list[float]] = defaultdict(list)
            counts: dict[str, list[int]] = defaultdict(lambda: [0, 0, 0])
            for sc in scenarios if scope == ALL else [scope]:
                a_runs, b_runs = by_run.get((planned_label, sc), {}), by_run.get((static_label, sc), {})
                for pair in sorted(set(a_runs) & set(b_runs)):
                    a, b = a_runs[pair], b_runs[pair]
                    for metric in sorted(set(a) & set(b)):
                        if math.isfinite(a[metric]) and math.isfinite(b[metric]):
                            diffs[metric].append(a[metric] - b[metric])
                            counts[metric][1 - _outcome(metric, a[metric], b[metric])] += 1
            for metric in sorted(diffs):
                w, t, lo = counts[metric]
                out.append(Paired(dim, planned_label, static_label, scope, metric, estimate(diffs[metric]), w, t, lo))
            if len(scenarios) == 1:
                break  # per-scenario rows would repeat the pooled ones
    return out


# ----------------------------------------------------------------------------------------- writing


def _fmt(x: float) -> str:
    return "–" if math.isnan(x) else f"{x:.4g}"


def _cell(e: Estimate) -> str:
    if e.n == 0:
        return "–"
    ci = "" if math.isnan(e.half) else f" ± {_fmt(e.half)}"
    return f"{_fmt(e.mean)}{ci} ({e.n})"


def _table(header: Sequence[str], body: Iterable[Sequence[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in body]
    return lines


def _strategy_table(summaries: Sequence[MetricSummary], scenario: str) -> list[str]:
    mine = [s for s in summaries if s.scenario == scenario]
    metrics = headline({s.metric for s in mine})
    strategies = sorted({s.strategy for s in mine})
    cells = {(s.strategy, s.metric): s.estimate for s in mine}
    body = [[st, *(_cell(cells[(st, m)]) if (st, m) in cells else "–" for m in metrics)] for st in strategies]
    return _table(["strategy", *metrics], body)


def markdown(rows: Sequence[RunRow], summaries: Sequence[MetricSummary], pairs: Sequence[Paired],
             title: str = "Sweep report") -> str:
    """The report as Markdown: a row per strategy, then the paired comparisons and the errors."""
    ok = [r for r in rows if r.status is Status.OK]
    errors = [r for r in rows if r.status is Status.ERROR]
    scenarios = sorted({r.scenario for r in rows})
    versions = sorted({str(r.record.get("tasker_version", r.record.get("version"))) for r in ok
                       if "tasker_version" in r.record or "version" in r.record})
    hosts = sorted({str(r.record.get("host")) for r in ok if "host" in r.record})
    out = [f"# {title}", "",
           f"{len(rows)} runs ({len(ok)} ok, {len(errors)} errors): {len(scenarios)} scenarios × "
           f"{len({r.seed for r in rows})} seeds × {len({r.strategy for r in rows})} strategies."
           + (f" tasker {', '.join(versions)}." if versions else "")
           + (f" Hosts: {', '.join(hosts)}." if hosts else ""),
           "", "Cells: mean ± half-width of the 95 % Student-t confidence interval (number of runs). "
           "Every metric is in `summary.csv` and `paired.csv`.", ""]
    out += ["## All scenarios", "", *_strategy_table(summaries, ALL), ""]
    if len(scenarios) > 1:
        for sc in scenarios:
            out += [f"### {sc}", "", *_strategy_table(summaries, sc), ""]
    if pairs:
        out += ["## Planned vs static, paired by (scenario, seed)", "",
                "Difference planned − static over the pairs where both ran; *wins/ties/losses* count the "
                "pairs where planned is better / equal / worse (*better* says which direction is better); "
                "the verdict reads the 95 % confidence interval of the difference. Host-dependent metrics "
                "(wall time, real-time factor, planner time, cache hits) measure the machine, not the strategy: "
                "their difference is reported without a verdict.", ""]
        shown = set(headline({p.metric for p in pairs}))
        for dim, p_label, s_label in sorted({(p.dimension, p.planned, p.static) for p in pairs}):
            mine = [p for p in pairs if (p.dimension, p.planned, p.static) == (dim, p_label, s_label)
                    and p.metric in shown]
            order = {m: i for i, m in enumerate(headline(shown))}
            out += [f"### {dim}: `{p_label}` vs `{s_label}`", ""]
            pooled = sorted((p for p in mine if p.scenario == ALL), key=lambda p: order[p.metric])
            out += _table(["metric", "better", "planned − static", "wins/ties/losses", "verdict"],
                          [[p.metric, p.better, _cell(p.diff), _counts(p), _verdict(p)] for p in pooled])
            out.append("")
            per = {(p.scenario, p.metric): p for p in mine if p.scenario != ALL}
            if per:
                metrics = [p.metric for p in pooled]
                out += ["Per scenario (wins/ties/losses, verdict):", ""]
                out += _table(["scenario", *metrics],
                              [[sc, *(f"{_counts(q)} {_verdict(q, short=True)}".strip()
                                      if (q := per.get((sc, m))) else "–" for m in metrics)]
                               for sc in sorted({sc for sc, _ in per})])
                out.append("")
    elif len({r.strategy for r in ok}) > 1:
        out += ["No two strategies differ only in planned → static: no paired comparison.", ""]
    if errors:
        out += ["## Errors", ""]
        out += _table(["scenario", "seed", "strategy", "error"],
                      [[r.scenario, str(r.seed), r.strategy, (r.error or "").splitlines()[0][:200]] for r in errors])
        out.append("")
    return "\n".join(out)


def _counts(p: Paired) -> str:
    return "–" if host_dependent(p.metric) else f"{p.wins}/{p.ties}/{p.losses}"


def _verdict(p: Paired, short: bool = False) -> str:
    if host_dependent(p.metric):
        return "" if short else "host-dependent: no verdict"
    if p.wins == p.losses == 0:
        return "=" if short else "identical"
    if p.diff.n < 2 or math.isnan(p.diff.half):
        return "?" if short else "too few pairs"
    if p.diff.low <= 0 <= p.diff.high:
        return "~" if short else "no significant difference"
    planned_lower = p.diff.high < 0
    winner = "planned" if planned_lower != higher_is_better(p.metric) else "static"
    return winner if short else f"{winner} better"


def write_csv(summaries: Sequence[MetricSummary], pairs: Sequence[Paired], out: Path) -> tuple[Path, Path]:
    """``summary.csv`` (scenario, strategy, metric, n, mean, std, ci_low, ci_high) and ``paired.csv``."""
    summary_path, paired_path = out / "summary.csv", out / "paired.csv"
    with summary_path.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["scenario", "strategy", "metric", "n", "mean", "std", "ci_low", "ci_high"])
        for s in summaries:
            e = s.estimate
            w.writerow([s.scenario, s.strategy, s.metric, e.n, e.mean, e.std, e.low, e.high])
    with paired_path.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["dimension", "planned", "static", "scenario", "metric", "better", "n", "mean_diff",
                    "ci_low", "ci_high", "wins", "ties", "losses", "host_dependent"])
        for p in pairs:
            w.writerow([p.dimension, p.planned, p.static, p.scenario, p.metric, p.better, p.diff.n, p.diff.mean,
                        p.diff.low, p.diff.high, p.wins, p.ties, p.losses, int(host_dependent(p.metric))])
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
    groups = scenarios if len(scenarios) > 1 else [ALL]
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
                       and p.scenario == ALL and p.metric in shown and not host_dependent(p.metric)),
                      key=lambda p: shown.index(p.metric))
        if not mine:
            continue
        fig, ax = plt.subplots(figsize=(6.4, 1.4 + 0.35 * len(mine)), layout="constrained")
        ys = range(len(mine))
        ax.barh(ys, [p.wins for p in mine], color="tab:green", label="planned better")
        ax.barh(ys, [p.ties for p in mine], left=[p.wins for p in mine], color="tab:gray", label="tie")
        ax.barh(ys, [p.losses for p in mine], left=[p.wins + p.ties for p in mine], color="tab:red",
                label="static better")
        ax.set_yticks(list(ys), [p.metric for p in mine])
        ax.set_xlabel("(scenario, seed) pairs")
        ax.set_title(f"{dim}: planned vs static", fontsize="medium")
        fig.legend(fontsize="x-small", loc="outside lower center", ncol=3)  # never over a bar
        path = out / f"paired_{_slug(dim)}_{_slug(p_label)}.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        files.append(path)
    return files


class EmptyDatabase(UserWarning):
    """The results database holds no runs (the sweep has not run, or ran nothing)."""


def build_report(db_path: str | Path, out: str | Path, *, plots: bool = True) -> ReportFiles:
    """Read the results database and write ``report.md``, ``summary.csv``, ``paired.csv`` and ``plots/``."""
    with ResultStore(db_path, readonly=True) as store:  # a report never writes to the database
        rows = store.rows()
    if not rows:
        warnings.warn(EmptyDatabase(f"{db_path}: the results database holds no runs yet; the report is empty"),
                      stacklevel=2)
    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    summaries = summarise(rows)
    pairs = paired(rows)
    md = out_dir / "report.md"
    text = markdown(rows, summaries, pairs, title=f"Sweep report: {Path(db_path).name}")
    md.write_text(text + "\n", encoding="utf-8")
    summary_csv, paired_csv = write_csv(summaries, pairs, out_dir)
    files = plot(summaries, pairs, out_dir / "plots") if plots and summaries else []
    page = None
    if plots:
        from experiments.report_html import sweep_page

        page = out_dir / "report.html"
        page.write_text(sweep_page(text, summaries, pairs), encoding="utf-8")
    return ReportFiles(md, summary_csv, paired_csv, tuple(files), page)
