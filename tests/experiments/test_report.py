"""The sweep report: confidence intervals, paired planned-vs-static comparison, files written."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest
from scipy import stats

from experiments import report
from experiments.report import ALL, build_report, comparisons, estimate, numeric_metrics, paired, summarise
from experiments.store import ResultStore, RunRow, Status, StoreError

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
                 people={"people_waiting_s": 20.0 + seed}),
            _row("a", seed, PLANNED, totals={"duration_s": {"mean": 8.0 + seed}, "failed": 0},
                 people={"people_waiting_s": 20.0 + seed}),
            _row("b", seed, STATIC, totals={"duration_s": {"mean": 5.0}, "failed": 0}),
            _row("b", seed, PLANNED, totals={"duration_s": {"mean": 6.0 + 0.1 * seed}, "failed": 0}),
        ]
    return out


def test_estimate_is_the_student_t_interval() -> None:
    values = [1.0, 2.0, 4.0, 7.0]
    e = estimate(values)
    low, high = stats.t.interval(0.95, len(values) - 1, loc=sum(values) / 4, scale=stats.sem(values))
    assert (e.n, e.low, e.high) == (4, pytest.approx(low), pytest.approx(high))
    one = estimate([3.0])
    assert one.mean == 3.0 and math.isnan(one.half)
    assert estimate([]).n == 0


def test_numeric_metrics_flatten_and_skip_what_is_not_a_number() -> None:
    flat = numeric_metrics({"totals": {"failed": 1, "duration_s": {"mean": 2.5}}, "run": {"seed": 3, "ok": True},
                            "note": "hello", "list": [1, 2], "inf_metric": "inf", "tasks": {"d1": {"x": 1}}})
    assert flat == {"totals.failed": 1.0, "totals.duration_s.mean": 2.5, "run.ok": 1.0, "inf_metric": math.inf}


def test_summaries_per_strategy_pooled_and_per_scenario(rows: list[RunRow]) -> None:
    by = {(s.scenario, s.strategy, s.metric): s.estimate for s in summarise(rows)}
    assert by[(ALL, STATIC, "totals.duration_s.mean")].n == 10
    assert by[("a", PLANNED, "totals.duration_s.mean")].mean == pytest.approx(10.0)
    assert by[("b", STATIC, "totals.duration_s.mean")].half == 0.0
    assert (ALL, STATIC, "people.people_waiting_s") in by and ("b", STATIC, "people.people_waiting_s") not in by
    assert by[(ALL, STATIC, "people.people_waiting_s")].n == 5  # missing in b: left out, not zero


def test_direction_of_better() -> None:
    assert report.higher_is_better("totals.finished")
    assert not report.higher_is_better("totals.unfinished")
    assert not report.higher_is_better("safety.violations_at_switch")


def test_comparisons_pair_strategies_that_differ_only_in_planned_vs_static() -> None:
    labels = [STATIC, PLANNED, "update=planned,suspension=planned", "update=planned,suspension=static,scheduler=x"]
    assert sorted(comparisons(labels)) == [
        ("suspension", PLANNED, STATIC),
        ("update", "update=planned,suspension=planned", PLANNED),
        ("update+suspension", "update=planned,suspension=planned", STATIC),
    ]


def test_paired_counts_wins_ties_losses_per_scenario(rows: list[RunRow]) -> None:
    pairs = {(p.scenario, p.metric): p for p in paired(rows)}
    a = pairs[("a", "totals.duration_s.mean")]
    assert (a.wins, a.ties, a.losses, a.diff.mean, a.diff.n) == (5, 0, 0, pytest.approx(-2.0), 5)
    assert report._verdict(a) == "planned better"
    b = pairs[("b", "totals.duration_s.mean")]
    assert (b.wins, b.ties, b.losses) == (0, 0, 5)
    assert report._verdict(b) == "static better"
    pooled = pairs[(ALL, "totals.duration_s.mean")]
    assert (pooled.wins, pooled.losses, pooled.diff.n) == (5, 5, 10)
    failed = pairs[(ALL, "totals.failed")]
    assert (failed.ties, report._verdict(failed)) == (10, "identical")
    assert pairs[(ALL, "people.people_waiting_s")].diff.n == 5  # only where both runs have it


def test_errors_and_unpaired_runs_are_left_out_of_the_comparison(rows: list[RunRow]) -> None:
    extra = [RunRow("a", 9, PLANNED, Status.ERROR, {}, {}, error="Boom: no plan"), _row("a", 8, STATIC, x=1.0)]
    pairs = {(p.scenario, p.metric): p for p in paired(rows + extra)}
    assert pairs[("a", "totals.duration_s.mean")].diff.n == 5
    assert ("a", "x") not in pairs


def test_report_files(tmp_path: Path, rows: list[RunRow]) -> None:
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        for row in rows:
            store.add(row)
        store.add(RunRow("b", 9, PLANNED, Status.ERROR, {}, {}, error="PlanningFailed: unsolvable\ntraceback"))
    files = build_report(db, tmp_path / "out")
    md = files.markdown.read_text()
    lines = md.splitlines()
    assert sum(line.startswith(f"| {STATIC} |") for line in lines) == 3  # all, a, b
    assert sum(line.startswith(f"| {PLANNED} |") for line in lines) == 3
    assert "totals.duration_s.mean" in md and "± " in md
    assert "| b | 9 | update=static,suspension=planned | PlanningFailed: unsolvable |" in md
    assert "| a | 5/0/0 planned |" in md and "| b | 0/0/5 static |" in md  # where planned wins, where not
    assert "| totals.duration_s.mean | lower | -0.4 ± 1.209 (10) | 5/0/5 | no significant difference |" in md
    with files.summary_csv.open() as f:
        summary = list(csv.DictReader(f))
    assert {r["scenario"] for r in summary} == {ALL, "a", "b"}
    assert all(float(r["ci_low"]) <= float(r["mean"]) <= float(r["ci_high"]) for r in summary)
    with files.paired_csv.open() as f:
        assert {r["dimension"] for r in csv.DictReader(f)} == {"suspension"}
    names = {p.name for p in files.plots}
    assert "totals.duration_s.mean.png" in names and any(n.startswith("paired_") for n in names)


def test_report_of_a_missing_database_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(StoreError, match="no such results database"):
        build_report(tmp_path / "missing.db", tmp_path / "out")


def test_host_dependent_metrics_are_reported_without_a_verdict(tmp_path: Path, rows: list[RunRow]) -> None:
    timed = [RunRow(r.scenario, r.seed, r.strategy, r.status, r.record,
                    {**r.metrics, "wall_time_s": 2.0 + r.seed if r.strategy == PLANNED else 1.0 + r.seed,
                     "real_time_factor": 30.0})
             for r in rows]
    pairs = {(p.scenario, p.metric): p for p in paired(timed)}
    wall = pairs[(ALL, "wall_time_s")]
    assert wall.diff.mean == pytest.approx(1.0) and report.host_dependent("wall_time_s")
    assert report._verdict(wall) == "host-dependent: no verdict" and wall.better == "–"
    md = report.markdown(timed, summarise(timed), list(pairs.values()))
    assert "| wall_time_s | – | 1 ± 0 (10) | – | host-dependent: no verdict |" in md
    assert "static better" not in [line for line in md.splitlines() if "wall_time_s" in line][-1]
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        for row in timed:
            store.add(row)
    files = build_report(db, tmp_path / "out")
    with files.paired_csv.open() as f:
        flags = {r["metric"]: r["host_dependent"] for r in csv.DictReader(f)}
    assert flags["wall_time_s"] == "1" and flags["real_time_factor"] == "1" and flags["totals.failed"] == "0"
    assert files.html is not None
    page = files.html.read_text()
    assert "<table>" in page and "host-dependent: no verdict" in page and 'id="metric-0"' in page
    assert "<script src" not in page
