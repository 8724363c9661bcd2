"""The growth benchmark's pieces still work, on tiny days (no benchmark is run as a test)."""

from __future__ import annotations

import importlib
import math
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))
bench_growth = importlib.import_module("bench_growth")
daysize = importlib.import_module("daysize")


def test_the_exponent_of_a_power_law_is_its_power() -> None:
    xs = [1.0, 2.0, 4.0, 8.0]
    assert bench_growth.exponent(xs, [3.0 * x for x in xs]) == pytest.approx(1.0)
    assert bench_growth.exponent(xs, [0.5 * x ** 2.5 for x in xs]) == pytest.approx(2.5)
    assert math.isnan(bench_growth.exponent([2.0, 2.0], [1.0, 5.0]))


def test_a_longer_day_keeps_the_request_rate() -> None:
    from experiments.days import pipeline

    proto = pipeline.load("tabsa-original")
    day = daysize.longer(proto, 4 * proto.length_s / 3600.0)
    assert day.length_s == 4 * proto.length_s
    for name, spec in proto.tasks.items():
        assert day.tasks[name].count == max(1, round(spec.count * 4))
    busy = daysize.busier(proto, 40, hours=1.0)
    assert sum(s.count for s in busy.tasks.values()) == pytest.approx(40, abs=len(proto.tasks))


def test_the_queue_study_reads_the_look_aheads_decisions(capsys: pytest.CaptureFixture[str]) -> None:
    bench_growth.print_queues("tabsa-original", hours=(0.5,))
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("the look-ahead's queue at its decisions (tabsa-original, seed 1)")
    assert out[1].startswith("  0.5 h: ") and "decisions, queue" in out[1] and "ended on its own" in out[1]
    assert "priced without a search" in out[1]


def test_a_series_is_reported_against_its_events_and_its_trace(capsys: pytest.CaptureFixture[str]) -> None:
    now = {2.0: (1.0, 100, 10_000), 8.0: (6.0, 400, 80_000)}
    assert not bench_growth.report("x", "hours", now, None, (2.0, 8.0))  # x6 for four times the day
    out = capsys.readouterr().out
    assert "trace (kB)" in out and "cost x6.00, work x4.00, trace x8.00 ABOVE TARGET" in out
    assert bench_growth.report("x", "hours", {2.0: (1.0, 1, 1), 8.0: (5.0, 4, 4)}, None, (2.0, 8.0))


def test_the_budget_curve_decides_a_days_problems_with_each_budget() -> None:
    decisions, sampled, jobs, rows = bench_growth.budget_curve("tabsa-original", 0.5, 1, 1, (5, 50), 500)
    assert decisions >= sampled > 0 and jobs >= 3
    assert [r["budget"] for r in rows] == [5, 50]
    for r in rows:
        assert 0 <= r["first_differs"] <= sampled and r["ratio_worst"] >= r["ratio_mean"] > 0


def test_the_stepping_study_prints_both_days(capsys: pytest.CaptureFixture[str]) -> None:
    bench_growth.print_stepping(("tabsa-short",))
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("the clock's own cost") and len(out) == 3
    assert all("stepping with one request a type" in line for line in out[1:])


def test_two_look_aheads_are_compared_on_whole_days(capsys: pytest.CaptureFixture[str]) -> None:
    bench_growth.compare_days("tabsa-short", 1, "lookahead", "lookahead:incremental=false", "a title")
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("a title (tabsa-short, seeds 1-1, whole days): lookahead against")
    rows = {line.split()[0]: line.split() for line in out[2:-1]}
    assert set(rows) == {*bench_growth.QUALITY_KEYS, "cpu_s"}
    assert rows["completed"][-2] in ("0/1", "1/1") and out[-1].startswith("  decisions that hit the node budget")
    same, (lower, higher) = int(rows["cpu_s"][-2].split("/")[0]), map(int, rows["cpu_s"][-1].split("/"))
    assert same + lower + higher == 1


def test_the_horizon_study_compares_the_protocols_days_and_eight_hour_ones(capsys: pytest.CaptureFixture[str]) -> None:
    bench_growth.print_horizon_days("tabsa-short", 1, horizons=(2,))
    out = capsys.readouterr().out.splitlines()
    titles = [line for line in out if line.startswith("the look-ahead's horizon")]
    assert len(titles) == 2 and all("lookahead:horizon=2 against lookahead" in t for t in titles)
    assert "whole days)" in titles[0] and "whole days, 8 h long)" in titles[1]


@pytest.mark.parametrize("bad", ["0", "-3", "many"])
def test_a_day_comparison_needs_at_least_one_day(bad: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        bench_growth.main(["--incremental-study", bad])
    assert exit_.value.code == 2 and "a number of days (an integer >= 1)" in capsys.readouterr().err


@pytest.mark.slow  # runs days in subprocesses: the full lane
def test_the_protocol_table_gives_each_schedulers_ratios(capsys: pytest.CaptureFixture[str]) -> None:
    ok = bench_growth.print_protocols(("tabsa-short",), ("edf", "alg2"), 1, 1, 60.0)
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("a day four times as long") and len(out) == 4
    for line, name in zip(out[2:], ("edf", "alg2"), strict=True):
        cells = line.split()
        assert cells[:2] == ["tabsa-short", name] and cells[-1] in ("met", "ABOVE")
        cost, events, _, per_event = (float(c.rstrip("x")) for c in cells[2:6])
        assert cost > 1 and events > 1 and per_event == pytest.approx(cost / events, abs=0.01)
    assert ok == all(line.split()[-1] == "met" for line in out[2:])


def test_an_unknown_protocol_is_refused_by_name(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        bench_growth.main(["--protocols", "tabsa", "no-such-protocol"])
    assert exit_.value.code == 2 and "--protocols: no-such-protocol: no protocol" in capsys.readouterr().err


@pytest.mark.slow  # runs days in subprocesses: the full lane
def test_the_stale_measurement_runs_days_without_re_estimates(capsys: pytest.CaptureFixture[str]) -> None:
    bench_growth.print_stale(("tabsa-short",), ("edf",), 1, 1, 60.0)
    out = capsys.readouterr().out.splitlines()
    assert "a measurement, not the model" in out[0] and len(out) == 3
    cells = out[2].split()
    assert cells[:2] == ["tabsa-short", "edf"] and all(c.endswith("x") and float(c[:-1]) > 0 for c in cells[2:])


def test_a_stale_worker_re_estimates_no_parked_agent() -> None:
    """The worker's --stale really turns re-estimation off (else the measurement would measure nothing)."""
    import subprocess
    import sys

    code = ("import sys; sys.argv=['x','--worker','--stale','--protocol','tabsa-short','--schedulers','edf',"
            "'--dimension','hours','--sizes','1','--seeds','1','--repeat','1'];"
            "sys.path.insert(0,'benchmarks'); import bench_growth as b; from tasker import parking;"
            "b.main(sys.argv[1:]); print(parking.Lot.changed(None))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                          cwd=bench_growth.ROOT)
    assert done.stdout.strip().splitlines()[-1] == "[]"


def test_the_baseline_is_labelled_with_the_commit_it_was_measured_on(capsys: pytest.CaptureFixture[str]) -> None:
    series = {2.0: (1.0, 1, 1), 8.0: (4.0, 4, 4)}
    bench_growth.report("x", "hours", series, series, (2.0, 8.0), "abc1234")
    out = capsys.readouterr().out
    assert "abc1234 CPU s" in out and "60ed0ea" not in out
