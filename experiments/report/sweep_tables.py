"""The tables of a sweep report: ``report.md`` (Markdown) and ``summary.csv`` / ``paired.csv``.

Writes what :func:`experiments.analysis.compare.analyse` computed, in the order the report reads:
the primary outcome, the runs per scenario, the per-scenario tables, the paired verdicts,
the errored runs.  Cells are ``mean ± half-width of the 95 % CI (n)``.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterable, Sequence
from pathlib import Path

from experiments.analysis.compare import INFEASIBLE, Analysis, MetricSummary, Paired, PrimaryOutcome, primary_cells
from experiments.analysis.stats import ALPHA, Estimate
from experiments.analysis.tables import markdown_table
from experiments.inputs.strategy import Strategy
from experiments.metrics.registry import (
    has_verdict,
    headline,
    higher_is_better,
    host_dependent,
    label,
    lookup,
    metric,
    numeric_metrics,
)
from experiments.metrics.store import RunRow, Status


def _fmt(x: float) -> str:
    return "–" if math.isnan(x) else f"{x:.4g}"


def _cell(e: Estimate, nonfinite: int = 0) -> str:
    extra = f", {nonfinite} non-finite" if nonfinite else ""
    if e.n == 0:
        return f"– (0{extra})"
    ci = "" if math.isnan(e.half) else f" ± {_fmt(e.half)}"
    return f"{_fmt(e.mean)}{ci} ({e.n}{extra})"


def _table(header: Sequence[str], body: Iterable[Sequence[str]]) -> list[str]:
    return markdown_table(header, body)


def _strategy_table(summaries: Sequence[MetricSummary], scenario: str) -> list[str]:
    mine = [s for s in summaries if s.scenario == scenario]
    metrics = headline({s.metric for s in mine})
    strategies = sorted({s.strategy for s in mine})
    cells = {(s.strategy, s.metric): s for s in mine}
    body = [[st, *(_cell(c.estimate, c.nonfinite) if (c := cells.get((st, m))) else "–" for m in metrics)]
            for st in strategies]
    return _table(["strategy", *(label(m) for m in metrics)], body)


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
    fallback = [r for r in ok if numeric_metrics(r.metrics).get("totals.static_fallbacks", 0.0) > 0]
    if fallback:
        cells_fb = sorted({(r.scenario, r.strategy) for r in fallback})
        out += [f"**{len(fallback)} runs had a planner fallback to static** (a planned genSusp or upTsk the planner "
                "could not solve in time, or at all, ran the static template instead; counted under the strategy "
                "asked for): " + "; ".join(f"{sc} {st}" for sc, st in cells_fb[:10])
                + (f" and {len(cells_fb) - 10} more cells" if len(cells_fb) > 10 else "") + ".", ""]
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
                              [[label(p.metric), p.better, _cell(p.diff, p.nonfinite), _counts(p), _fmt(p.p),
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
    return f"{p.wins}/{p.ties}/{p.losses}" if has_verdict(p.metric) else "–"


def _verdict(p: Paired, short: bool = False) -> str:
    """Which side is better, as the metric's registration says (``experiments.metrics.registry``)."""
    if not has_verdict(p.metric):
        why = "host-dependent" if host_dependent(p.metric) else (
            "not registered" if metric(p.metric) is None else "neither way better")
        return "" if short else f"{why}: no verdict"
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
