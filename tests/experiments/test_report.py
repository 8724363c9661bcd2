"""The sweep report: summaries, paired comparisons per factor, the tables and files it writes."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest

from experiments.analysis.compare import (
    ALL,
    PrimaryOutcome,
    analyse,
    comparisons,
    constant_metrics,
    paired,
    primary_cells,
    summarise,
)
from experiments.analysis.stats import holm
from experiments.metrics.registry import higher_is_better, host_dependent, numeric_metrics
from experiments.metrics.store import ResultStore, RunRow, Status, StoreError
from experiments.report import sweep_tables as report_tables
from experiments.report.sweep_plots import plot_frontier
from experiments.sweep.report import build_report

STATIC = "update=static,suspension=static"
PLANNED = "update=static,suspension=planned"


def _row(scenario: str, seed: int, strategy: str, **metrics: object) -> RunRow:
    record = {"scenario": scenario, "seed": seed, "host": "test", "tasker_version": "0.1.0"}
    return RunRow(scenario, seed, strategy, Status.OK, record, dict(metrics))


@pytest.fixture
def rows() -> list[RunRow]:
    """Planned suspension shortens waiting in scenario ``a``, lengthens it in ``b``; no one fails."""
    out = []
    for seed in range(5):
        out += [
            _row("a", seed, STATIC, totals={"duration_s": {"mean": 10.0 + seed}, "failed": 0},
                 safety={"unattended_s": 10.0 + seed}, people={"people_waiting_s": 20.0 + seed}),
            _row("a", seed, PLANNED, totals={"duration_s": {"mean": 8.0 + seed}, "failed": 0},
                 safety={"unattended_s": 8.0 + seed}, people={"people_waiting_s": 20.0 + seed}),
            _row("b", seed, STATIC, totals={"duration_s": {"mean": 5.0}, "failed": 0}, safety={"unattended_s": 5.0}),
            _row("b", seed, PLANNED, totals={"duration_s": {"mean": 6.0 + 0.1 * seed}, "failed": 0},
                 safety={"unattended_s": 6.0 + 0.1 * seed}),
        ]
    return out


def test_numeric_metrics_flatten_and_skip_what_is_not_a_number() -> None:
    flat = numeric_metrics({"totals": {"failed": 1, "duration_s": {"mean": 2.5}}, "run": {"seed": 3, "ok": True},
                            "note": "hello", "list": [1, 2], "inf_metric": "inf", "tasks": {"d1": {"x": 1}}})
    assert flat == {"totals.failed": 1.0, "run.ok": 1.0, "inf_metric": math.inf, "derived.finished_tasks": 0.0}


def test_summaries_per_strategy_pooled_and_per_scenario(rows: list[RunRow]) -> None:
    by = {(s.scenario, s.strategy, s.metric): s.estimate for s in summarise(rows)}
    assert by[(ALL, STATIC, "safety.unattended_s")].n == 10  # pooled rows are descriptive only, never compared
    assert by[("a", PLANNED, "safety.unattended_s")].mean == pytest.approx(10.0)
    assert by[("b", STATIC, "safety.unattended_s")].half == 0.0
    assert (ALL, STATIC, "people.people_waiting_s") in by and ("b", STATIC, "people.people_waiting_s") not in by
    assert by[(ALL, STATIC, "people.people_waiting_s")].n == 5  # missing in b: left out, not zero


def test_verdicts_come_from_the_registry_never_from_a_name() -> None:
    """Before: a regular expression on names called the longer mean duration of finished tasks better
    ('finished' matched), so a sweep said static was better where planned was 8.1 s shorter."""
    shorter = [_row("a", s, st, tasks={"d1": {"cause": "finished", "duration_s": d + s}})
               for s in range(5) for st, d in ((STATIC, 30.0), (PLANNED, 22.0))]
    p = {q.metric: q for q in paired(shorter)}["derived.finished_duration_s.mean"]
    assert p.diff.mean == pytest.approx(-8.0) and (p.wins, p.losses) == (5, 0)
    assert report_tables._verdict(p) == "suspension=planned better"
    unregistered = [_row("a", s, st, made_up_s=float(s + (st == PLANNED)))
                    for s in range(5) for st in (STATIC, PLANNED)]
    q = {r.metric: r for r in paired(unregistered)}["made_up_s"]
    assert (q.wins, q.ties, q.losses, q.better) == (0, 0, 0, "–")
    assert report_tables._verdict(q) == "not registered: no verdict"


def test_direction_of_better() -> None:
    assert higher_is_better("totals.finished")
    assert not higher_is_better("totals.unfinished")
    assert not higher_is_better("safety.violations_at_switch")


def test_comparisons_pair_strategies_that_differ_in_one_factor() -> None:
    labels = [STATIC, PLANNED, "update=planned,suspension=planned", "update=planned,suspension=static,scheduler=x",
              "update=static,suspension=planned,policy=conditional", "update=static,suspension=planned,policy=strict",
              "update=static,suspension=planned,policy=strict,hazard_waiting=on",
              "update=static,suspension=planned,policy=strict,hazard_waiting=off"]
    assert sorted(comparisons(labels)) == [
        ("hazard_waiting", "update=static,suspension=planned,policy=strict,hazard_waiting=on",
         "update=static,suspension=planned,policy=strict,hazard_waiting=off"),
        ("policy", "update=static,suspension=planned,policy=conditional",
         "update=static,suspension=planned,policy=strict"),
        ("suspension", PLANNED, STATIC),
        ("update", "update=planned,suspension=planned", PLANNED),
    ]


def test_paired_is_per_scenario_never_pooled_and_holm_corrected(rows: list[RunRow]) -> None:
    pairs = {(p.scenario, p.metric): p for p in paired(rows)}
    assert not any(sc == ALL for sc, _ in pairs)  # opposite effects in a and b are never pooled
    assert ("a", "totals.duration_s.mean") not in pairs  # replaced by the finished-only duration
    a = pairs[("a", "safety.unattended_s")]
    assert (a.wins, a.ties, a.losses, a.diff.mean, a.diff.n) == (5, 0, 0, pytest.approx(-2.0), 5)
    assert report_tables._verdict(a) == "suspension=planned better"
    b = pairs[("b", "safety.unattended_s")]
    assert (b.wins, b.ties, b.losses) == (0, 0, 5) and report_tables._verdict(b) == "suspension=static better"
    tests = [p for p in pairs.values() if not math.isnan(p.p)]
    assert [p.p_holm for p in tests] == pytest.approx(holm([p.p for p in tests]))
    assert all(p.p_holm >= p.p for p in tests)
    failed = pairs[("a", "totals.failed")]
    assert (failed.ties, report_tables._verdict(failed)) == (5, "identical")


def test_constant_metrics_are_dropped_with_a_note(tmp_path: Path, rows: list[RunRow]) -> None:
    const = [RunRow(r.scenario, r.seed, r.strategy, r.status, r.record, {**r.metrics, "resumption_s": 2.0})
             for r in rows]
    assert constant_metrics(const)["resumption_s"] == 2.0
    analysis = analyse(const)
    assert "resumption_s" not in {s.metric for s in analysis.summaries}
    assert "resumption_s" not in {p.metric for p in analysis.pairs}
    assert "`resumption_s` = 2" in report_tables.markdown(analysis)


def test_non_finite_values_are_counted_and_shown(rows: list[RunRow]) -> None:
    bad = [RunRow(r.scenario, r.seed, r.strategy, r.status, r.record,
                  {**r.metrics, "wall_time_s": "inf" if (r.seed, r.strategy) == (0, PLANNED) else float(r.seed)})
           for r in rows]
    by = {(s.scenario, s.strategy, s.metric): s for s in summarise(bad)}
    assert (by[("a", PLANNED, "wall_time_s")].nonfinite, by[("a", PLANNED, "wall_time_s")].estimate.n) == (1, 4)
    pairs = {(p.scenario, p.metric): p for p in paired(bad)}
    assert (pairs[("a", "wall_time_s")].nonfinite, pairs[("a", "wall_time_s")].diff.n) == (1, 4)
    assert "1 non-finite" in report_tables.markdown(analyse(bad))


def test_failed_and_unfinished_tasks_are_out_of_the_duration_mean_and_counted() -> None:
    m = {"tasks": {"a": {"cause": "finished", "duration_s": 10.0}, "b": {"cause": "failed", "duration_s": 1.0},
                   "c": {"cause": None, "duration_s": None}},
         "totals": {"failed": 1, "unfinished": 1, "duration_s": {"mean": 5.5}}}
    flat = numeric_metrics(m)
    assert flat["derived.finished_duration_s.mean"] == 10.0 and "totals.duration_s.mean" not in flat
    rows = [RunRow("s", 1, STATIC, Status.OK, {}, m), RunRow("s", 2, STATIC, Status.ERROR, {}, {}, error="x: crash"),
            RunRow("s", 3, STATIC, Status.ERROR, {}, {}, error="PlanningFailed: unsolvable")]
    md = report_tables.markdown(analyse(rows))
    assert "3 runs: 1 ok, 1 infeasible, 1 failed" in md
    assert f"| s | {STATIC} | 1 | 1 | 1 | 1 | 1 |" in md


def test_primary_outcome_reads_configured_paths(tmp_path: Path) -> None:
    rows = [RunRow("s", seed, st, Status.OK, {}, {"safety": {"unattended_s": h}, "people": {"time_to_help_s":
                                                                                              {"mean": w}}})
            for seed in range(4) for st, h, w in ((STATIC, 10.0 + seed, 30.0), (PLANNED, 1.0, 40.0 + seed))]
    cells = primary_cells(rows, PrimaryOutcome())
    assert cells[("s", STATIC)][0].mean == pytest.approx(11.5) and cells[("s", PLANNED)][1].mean == 41.5
    custom = PrimaryOutcome(hazard=("people.time_to_help_s.mean",), help=("safety.unattended_s",))
    assert primary_cells(rows, custom)[("s", STATIC)][0].mean == 30.0
    assert plot_frontier(rows, custom, tmp_path) == tmp_path / "primary_frontier.png"


def test_errors_and_unpaired_runs_are_left_out_of_the_comparison(rows: list[RunRow]) -> None:
    extra = [RunRow("a", 9, PLANNED, Status.ERROR, {}, {}, error="Boom: no plan"), _row("a", 8, STATIC, x=1.0)]
    pairs = {(p.scenario, p.metric): p for p in paired(rows + extra)}
    assert pairs[("a", "safety.unattended_s")].diff.n == 5
    assert ("a", "x") not in pairs


@pytest.mark.slow
def test_report_files(tmp_path: Path, rows: list[RunRow]) -> None:
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        for row in rows:
            store.add(row)
        store.add(RunRow("b", 9, PLANNED, Status.ERROR, {}, {}, error="PlanningFailed: unsolvable\ntraceback"))
    files = build_report(db, tmp_path / "out")
    md = files.markdown.read_text()
    assert "| b | 9 | update=static,suspension=planned | infeasible | PlanningFailed: unsolvable |" in md
    assert "p (Holm)" in md and "## Primary outcome" in md
    with files.summary_csv.open() as f:
        summary = list(csv.DictReader(f))
    assert {r["scenario"] for r in summary} == {ALL, "a", "b"}
    with files.paired_csv.open() as f:
        scopes = {(r["dimension"], r["scenario"]) for r in csv.DictReader(f)}
    assert scopes == {("suspension", "a"), ("suspension", "b")}
    names = {p.name for p in files.plots}
    assert "primary_frontier.png" in names and any(n.startswith("paired_") for n in names)


def test_report_of_a_missing_database_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(StoreError, match="no such results database"):
        build_report(tmp_path / "missing.db", tmp_path / "out")


@pytest.mark.slow
def test_host_dependent_metrics_are_reported_without_a_verdict(tmp_path: Path, rows: list[RunRow]) -> None:
    timed = [RunRow(r.scenario, r.seed, r.strategy, r.status, r.record,
                    {**r.metrics, "wall_time_s": 2.0 + r.seed if r.strategy == PLANNED else 1.0 + r.seed,
                     "real_time_factor": 30.0 + r.seed})
             for r in rows]
    pairs = {(p.scenario, p.metric): p for p in paired(timed)}
    wall = pairs[("a", "wall_time_s")]
    assert wall.diff.mean == pytest.approx(1.0) and host_dependent("wall_time_s") and math.isnan(wall.p)
    assert report_tables._verdict(wall) == "host-dependent: no verdict" and wall.better == "–"
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        for row in timed:
            store.add(row)
    files = build_report(db, tmp_path / "out")
    with files.paired_csv.open() as f:
        flags = {r["metric"]: r["host_dependent"] for r in csv.DictReader(f)}
    assert flags["wall_time_s"] == "1" and flags["real_time_factor"] == "1" and flags["safety.unattended_s"] == "0"
    assert files.html is not None
    page = files.html.read_text()
    assert "<table>" in page and "host-dependent: no verdict" in page and 'id="metric-0"' in page
    assert "<script src" not in page


def test_a_sweep_with_planner_fallbacks_says_so(rows: list[RunRow]) -> None:
    assert "fallback" not in report_tables.markdown(analyse(rows))
    fell = [RunRow(r.scenario, r.seed, r.strategy, r.status, r.record,
                   {**r.metrics, "totals": {**r.metrics["totals"], "static_fallbacks": 1}})
            if (r.scenario, r.seed, r.strategy) == ("a", 2, PLANNED) else r for r in rows]
    md = report_tables.markdown(analyse(fell))
    assert "**1 runs had a planner fallback to static**" in md and f"a {PLANNED}" in md
