"""Engines in turn, every plan validated: an invalid plan, a refused one or an engine's crash
is that engine's attempt, and the next engine is asked."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

from planners.results import PlanStatus
from planners.temporal import engines, portfolio
from planners.temporal.portfolio import EngineNotInstalled, TemporalPlanner, attempt_engine, validate
from planners.temporal.reading import parse
from planners.temporal.results import Outcome
from tests.planners.temporal.conftest import pair


def _problem(name: str = "plansys2_simple"):  # type: ignore[no-untyped-def]
    d, p = pair(name)
    return parse(d.read_text(), p.read_text(), d, p)


@pytest.mark.slow
@pytest.mark.parametrize("engine", engines.DEFAULT_ORDER)
def test_each_shipped_engine_plans_plansys2s_simple_example(engine: str) -> None:
    problem = _problem()
    attempt, plan = attempt_engine(engine, problem, 30)
    assert attempt.outcome is Outcome.VALID, attempt
    assert plan is not None and plan[-1].step == ("move", "leia", "bedroom", "bathroom")
    # the plan ends at the goal: 6 actions of 5 s in turn (plus each engine's separation epsilon)
    assert Fraction(30) <= max(s.end for s in plan) < Fraction(31)


@pytest.mark.slow
@pytest.mark.parametrize("engine", engines.DEFAULT_ORDER)
def test_an_engine_gives_the_same_plan_twice(engine: str) -> None:
    problem = _problem("plansys2_talk")
    first, second = attempt_engine(engine, problem, 30), attempt_engine(engine, problem, 30)
    assert first[0].outcome is Outcome.VALID and first[1] == second[1]


@pytest.mark.slow
def test_the_first_valid_plan_is_used_and_the_rest_skipped() -> None:
    result = TemporalPlanner(["lpg", "kairos"]).solve(_problem(), 30)
    assert result.solved and result.engine == "lpg"
    assert [(a.engine, a.outcome) for a in result.attempts] == [("lpg", Outcome.VALID), ("kairos", Outcome.SKIPPED)]


@pytest.mark.slow
def test_an_invalid_plan_is_refused_with_its_engine_and_the_next_is_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    real = portfolio.validate
    calls: list[int] = []

    def first_invalid(problem: object, plan: object) -> str | None:
        calls.append(1)
        return "inapplicable action, at move(leia)" if len(calls) == 1 else real(problem, plan)  # type: ignore[arg-type]

    monkeypatch.setattr(portfolio, "validate", first_invalid)
    result = TemporalPlanner(["lpg", "kairos"]).solve(_problem(), 30)
    assert result.solved and result.engine == "kairos"
    assert result.attempts[0].outcome is Outcome.INVALID and "inapplicable action" in result.attempts[0].message


@pytest.mark.slow
def test_an_engine_that_raises_is_an_error_attempt(monkeypatch: pytest.MonkeyPatch) -> None:
    real = engines.register

    def broken(name: str) -> str:
        if name == "lpg":
            raise RuntimeError("thread 'main' panicked at 'state variable lifting'")
        return real(name)

    monkeypatch.setattr(engines, "register", broken)
    result = TemporalPlanner(["lpg", "kairos"]).solve(_problem(), 30)
    assert result.solved and result.engine == "kairos"
    assert result.attempts[0].outcome is Outcome.ERROR and "RuntimeError: thread 'main' panicked" in \
        result.attempts[0].message
    alone = TemporalPlanner(["lpg"]).solve(_problem(), 30)
    assert alone.status is PlanStatus.ERROR and alone.plan is None and "lpg: error (RuntimeError" in alone.message


@pytest.mark.slow
def test_accept_may_refuse_a_valid_plan() -> None:
    result = TemporalPlanner(["lpg", "kairos"]).solve(_problem(), 30, accept=lambda plan: "not today")
    assert result.status is PlanStatus.ERROR
    assert [a.outcome for a in result.attempts] == [Outcome.REFUSED, Outcome.REFUSED]


def test_the_validator_refuses_a_broken_plan() -> None:
    import unified_planning as up

    problem = _problem()
    move = problem.action("move")
    leia, entrance, dinning = (problem.object(n) for n in ("leia", "entrance", "dinning"))
    plan = up.plans.TimeTriggeredPlan([(Fraction(0), up.plans.ActionInstance(move, (leia, entrance, dinning)),
                                        Fraction(5))])
    assert validate(problem, plan) is not None  # the battery is low: move's over-all condition fails


def test_a_problem_without_a_goal_needs_no_engine() -> None:
    d, _ = pair("plansys2_simple")
    empty = "(define (problem p) (:domain simple) (:objects leia - robot) (:init) (:goal (and)))"
    problem = parse(d.read_text(), empty, d, Path("p.pddl"))
    result = TemporalPlanner(["lpg"]).solve(problem)
    assert result.solved and result.plan == () and result.attempts == ()


def test_unknown_and_missing_engines(monkeypatch: pytest.MonkeyPatch) -> None:
    from tasker.errors import UnknownName

    with pytest.raises(UnknownName, match="lpg"):
        TemporalPlanner(["popf"])
    with pytest.raises(ValueError):
        TemporalPlanner(["lpg"], timeout=0)
    monkeypatch.setattr(engines, "installed", lambda name: name != "tamer")
    with pytest.raises(EngineNotInstalled, match="pip install up-tamer"):
        TemporalPlanner(["tamer"])
    monkeypatch.setattr(engines, "installed", lambda name: False)
    with pytest.raises(EngineNotInstalled, match="no temporal engine"):
        TemporalPlanner()


def test_a_plan_the_engine_got_wrong_is_its_error_not_an_exception(monkeypatch: pytest.MonkeyPatch) -> None:
    def negative(plan: object) -> None:
        raise ValueError("TimedStep move: start must be >= 0, got -1")

    monkeypatch.setattr(portfolio, "timed_steps", negative)
    attempt, plan = attempt_engine("kairos", _problem(), 30)
    assert plan is None and attempt.outcome is Outcome.ERROR and "start must be >= 0" in attempt.message
