"""The result types refuse what they cannot mean (every ``__post_init__`` check fires)."""

from __future__ import annotations

from fractions import Fraction as F

import pytest

from planners.results import PlanStatus
from planners.temporal.results import Attempt, Outcome, TemporalResult, TimedStep


def step(start: int, duration: int, name: str = "a") -> TimedStep:
    return TimedStep(F(start), name, ("x",), F(duration))


def test_timed_step_checks() -> None:
    with pytest.raises(ValueError, match="start"):
        TimedStep(F(-1), "a", (), F(1))
    with pytest.raises(ValueError, match="duration"):
        TimedStep(F(0), "a", (), F(-1))
    assert step(2, 3).end == 5 and step(2, 3).step == ("a", "x") and str(step(2, 3)) == "2.000: (a x) [3.000]"


def test_attempt_checks() -> None:
    with pytest.raises(TypeError):
        Attempt("lpg", "valid")  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        Attempt("lpg", Outcome.VALID, wall_time_s=-1)


def test_result_checks() -> None:
    with pytest.raises(TypeError):
        TemporalResult("solved", (), "lpg", (), 0.0)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="needs a plan"):
        TemporalResult(PlanStatus.SOLVED, None, "lpg", (), 0.0)
    with pytest.raises(ValueError, match="must not carry"):
        TemporalResult(PlanStatus.TIMEOUT, (), "", (), 0.0)
    with pytest.raises(ValueError, match="start-time order"):
        TemporalResult(PlanStatus.SOLVED, (step(5, 1), step(0, 1)), "lpg", (), 0.0)
    with pytest.raises(ValueError, match="names the engine"):
        TemporalResult(PlanStatus.SOLVED, (), "", (), 0.0)
    with pytest.raises(ValueError, match="wall_time_s"):
        TemporalResult(PlanStatus.ERROR, None, "", (), -1.0)


def test_json_and_classical_view() -> None:
    r = TemporalResult(PlanStatus.SOLVED, (step(0, 5, "move"), step(5, 2, "charge")), "aries",
                       (Attempt("lpg", Outcome.INVALID, "why"), Attempt("aries", Outcome.VALID)), 0.5)
    assert r.makespan == 7
    out = r.to_json()
    assert out["status"] == "solved" and out["planner"] == "aries" and out["cost"] == 7.0
    assert out["plan"] == [["move", "x"], ["charge", "x"]] and out["makespan"] == 7.0
    assert out["timed_plan"] == [{"start": 0.0, "action": "move", "args": ["x"], "duration": 5.0},
                                 {"start": 5.0, "action": "charge", "args": ["x"], "duration": 2.0}]
    assert [a["outcome"] for a in out["attempts"]] == ["invalid", "valid"]
    failed = TemporalResult(PlanStatus.ERROR, None, "", (Attempt("lpg", Outcome.ERROR, "boom"),), 0.1)
    assert failed.to_plan_result().message == "lpg: error (boom)" and failed.to_json()["timed_plan"] is None
