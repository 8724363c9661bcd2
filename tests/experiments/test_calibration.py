"""Calibration metrics (experiments.metrics.calibration) on hand-made traces, values worked out by hand."""

from __future__ import annotations

from typing import Any

import pytest

from experiments.metrics import run as metrics
from tests.experiments.events import complete


def ev(t: float, event: str, **fields: Any) -> dict[str, Any]:
    return complete({"t": t, "event": event, **fields})


def go(t: float, agent: str, *states: str) -> list[dict[str, Any]]:
    return [ev(t, "transition", agent=agent, **{"from": a, "to": b}) for a, b in zip(states, states[1:], strict=False)]


def trace() -> list[dict[str, Any]]:
    """d1 starts (predicted 100 s), is suspended at 30 for d2 (expected 40 s), waits from 32 to 82,
    runs again and finishes at 150; d2 (predicted 45 s) runs 32-82 and finishes; d3 is requested,
    started with an infinite cTime and terminated; d4 never starts."""
    return [
        ev(0.0, "request", agent="d1", task_type="cook", args={}, requester="t"),
        *go(0.0, "d1", "initComm", "compSP"),
        ev(0.0, "command", agent="d1", flag="start", predicted_s=100.0),
        *go(0.0, "d1", "compSP", "upTsk", "exeTsk"),
        ev(20.0, "request", agent="d2", task_type="human_fell", args={}, requester="t"),
        *go(20.0, "d2", "initComm", "compSP"),
        ev(30.0, "command", agent="d1", flag="susp", by="d2", expected_s=40.0),
        *go(30.0, "d1", "exeTsk", "genSusp", "exeSusp"),
        *go(32.0, "d1", "exeSusp", "wait"),
        ev(32.0, "command", agent="d2", flag="start", predicted_s=45.0),
        *go(32.0, "d2", "compSP", "upTsk", "exeTsk"),
        *go(82.0, "d2", "exeTsk", "end"),
        ev(82.0, "end", agent="d2", task_type="human_fell", reason="finished", cause="finished"),
        ev(82.0, "command", agent="d1", flag="start", predicted_s=70.0),
        *go(82.0, "d1", "wait", "upTsk", "exeTsk"),
        *go(150.0, "d1", "exeTsk", "end"),
        ev(150.0, "end", agent="d1", task_type="cook", reason="finished", cause="finished"),
        ev(150.0, "request", agent="d3", task_type="cook", args={}, requester="t"),
        *go(150.0, "d3", "initComm", "compSP"),
        ev(150.0, "command", agent="d3", flag="start", predicted_s="inf"),
        *go(150.0, "d3", "compSP", "upTsk", "exeTsk"),
        ev(160.0, "command", agent="d3", flag="term"),
        *go(161.0, "d3", "exeTsk", "end"),
        ev(161.0, "end", agent="d3", task_type="cook", reason="bye", cause="term"),
        ev(161.0, "request", agent="d4", task_type="cook", args={}, requester="t"),
    ]


def test_estimates_compare_the_first_predicted_ctime_with_the_time_owning_the_robot() -> None:
    est = metrics.compute(trace())["calibration"]["estimates"]
    rows = {r["agent"]: r for r in est["tasks"]}
    # d1: owned the robot 0-32 and 82-150 = 100 s, predicted 100 s; 150 s elapsed
    assert rows["d1"]["executing_s"] == pytest.approx(100.0)
    assert rows["d1"]["error_s"] == pytest.approx(0.0)
    assert rows["d1"]["elapsed_error_s"] == pytest.approx(50.0)
    # d2: ran 32-82 = 50 s against 45 s predicted: underestimated by 5 s
    assert rows["d2"]["error_s"] == pytest.approx(5.0)
    assert rows["d3"]["compared"] == "non-finite prediction"
    assert rows["d4"]["compared"] == "never started"
    assert est["compared"] == 2 and est["not_compared"] == 2 and est["nonfinite"] == 1
    assert est["underestimated"] == 1
    assert est["error_s"]["mean"] == pytest.approx(2.5)
    assert est["abs_error_s"]["mean"] == pytest.approx(2.5)
    assert est["ratio"]["mean"] == pytest.approx((1.0 + 50 / 45) / 2, abs=1e-6)


def test_a_task_that_did_not_finish_is_counted_not_compared() -> None:
    events = [e for e in trace() if e.get("agent") != "d3" or e["event"] != "command" or e["flag"] != "start"]
    events.insert(len(events) - 5, ev(150.0, "command", agent="d3", flag="start", predicted_s=12.0))
    rows = {r["agent"]: r for r in metrics.compute(events)["calibration"]["estimates"]["tasks"]}
    assert rows["d3"]["compared"] == "did not finish" and "error_s" not in rows["d3"]
    assert rows["d3"]["executing_s"] == pytest.approx(11.0)


def test_interruptions_compare_expected_with_wait_to_next_start() -> None:
    sus = metrics.compute(trace())["calibration"]["interruptions"]
    (row,) = sus["list"]
    assert (row["agent"], row["by"], row["outcome"]) == ("d1", "d2", "resumed")
    assert row["realised_s"] == pytest.approx(50.0)  # wait at 32, start at 82
    assert row["error_s"] == pytest.approx(10.0)
    assert sus["compared"] == 1 and sus["underestimated"] == 1 and sus["censored"] == 0
    assert sus["ratio"]["mean"] == pytest.approx(1.25)


def test_an_interruption_that_never_resumes_is_censored() -> None:
    events = [e for e in trace() if e["t"] < 82.0]
    sus = metrics.compute(events)["calibration"]["interruptions"]
    (row,) = sus["list"]
    assert row["outcome"] == "open at the end of the run" and row["realised_s"] is None
    assert row["waited_at_least_s"] == pytest.approx(0.0)  # the run's last event is at 32
    assert sus["compared"] == 0 and sus["censored"] == 1 and sus["error_s"]["mean"] is None


def test_infinite_expected_interruption_is_counted_apart() -> None:
    events = [dict(e, expected_s="inf") if e.get("flag") == "susp" else e for e in trace()]
    sus = metrics.compute(events)["calibration"]["interruptions"]
    assert sus["nonfinite"] == 1 and sus["compared"] == 0
    assert sus["list"][0]["expected_s"] == "inf"  # JSON-ready, as in the trace


def test_securing_while_waiting_does_not_end_the_interruption() -> None:
    """Hazard-aware waiting: d1 secures its hazard from wait (48-52) and waits again; its interruption
    still runs from 32 to its real resumption at 82, and the securing counts as time owning the robot."""
    events = trace()
    at = next(i for i, e in enumerate(events) if e["t"] >= 48.0)
    events[at:at] = [ev(48.0, "command", agent="d1", flag="start", secure=True),
                     *go(48.0, "d1", "wait", "genSusp", "exeSusp"), *go(52.0, "d1", "exeSusp", "wait")]
    cal = metrics.compute(events)["calibration"]
    (row,) = cal["interruptions"]["list"]
    assert row["outcome"] == "resumed" and row["realised_s"] == pytest.approx(50.0)
    d1 = next(r for r in cal["estimates"]["tasks"] if r["agent"] == "d1")
    assert d1["executing_s"] == pytest.approx(104.0) and d1["predicted_s"] == 100.0
