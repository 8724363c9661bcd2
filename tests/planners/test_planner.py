"""The ``tasker-fd`` engine and the Planner facade: results, cache, engines by name."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from unified_planning.shortcuts import OneshotPlanner

import planners  # noqa: F401 - registers tasker-fd
from planners.checks import load_problem
from planners.planner import PddlText, Planner, oneshot_planners
from planners.results import PlanResult, PlanStatus
from planners.validate import validate_plan
from tasker.errors import UnknownName
from tests.planners.conftest import DOMAIN, problem_text


def test_engine_is_registered_and_found_by_name(pddl_files: tuple[Path, Path]) -> None:
    assert "tasker-fd" in oneshot_planners()
    _, _, problem = load_problem(*pddl_files)
    with OneshotPlanner(name="tasker-fd") as engine:
        engine.skip_checks = True
        res = engine.solve(problem)
    assert res.status.name == "SOLVED_OPTIMALLY"
    steps = [(a.action.name, *(str(p) for p in a.actual_parameters)) for a in res.plan.actions]
    check = validate_plan(problem, steps)
    assert check.valid and check.cost == 6


@pytest.mark.slow
@pytest.mark.parametrize("name", ["tasker-fd", "fast-downward-opt"])
def test_planner_by_name_same_optimal_cost(name: str, pddl_files: tuple[Path, Path]) -> None:
    _, _, problem = load_problem(*pddl_files)
    result = Planner(name).solve(problem)
    assert result.status is PlanStatus.SOLVED and result.cost == 6 and result.planner == name
    assert validate_plan(problem, result.plan).valid


def test_unknown_planner_lists_known() -> None:
    with pytest.raises(UnknownName, match="tasker-fd"):
        Planner("no-such-planner")


def test_cache_hit_is_marked_and_counted() -> None:
    planner = Planner()
    text = PddlText(DOMAIN, problem_text())
    first = planner.solve(text)
    assert not first.cached
    again = planner.solve(PddlText(DOMAIN, problem_text()))
    assert again.cached and again.plan == first.plan  # how fast a hit is: benchmarks/bench_planner.py
    assert planner.hits == 1 and planner.misses == 1


def test_cache_is_bounded_lru() -> None:
    planner = Planner(cache_size=2)
    texts = [PddlText(DOMAIN, problem_text(extra_init=f"; {k}\n")) for k in range(3)]
    for t in texts:
        planner.solve(t)
    assert len(planner._cache) == 2
    assert not planner.solve(texts[0]).cached  # evicted first
    assert planner.solve(texts[2]).cached


@pytest.mark.slow
def test_up_problem_repeat_is_cached(pddl_files: tuple[Path, Path]) -> None:
    _, _, problem = load_problem(*pddl_files)
    planner = Planner()
    planner.solve(problem)
    assert planner.solve(problem).cached
    assert planner.hits == 1 and planner.misses == 1


def test_timeouts_are_not_cached() -> None:
    planner = Planner()
    text = PddlText(DOMAIN, problem_text())
    assert planner.solve(text, timeout=1e-6).status is PlanStatus.TIMEOUT
    assert planner.solve(text).status is PlanStatus.SOLVED


def test_unsolvable_status() -> None:
    res = Planner().solve(PddlText(DOMAIN, problem_text(goal="(holding cup) (item-at cup c)")))
    assert res.status is PlanStatus.UNSOLVABLE and res.plan is None


def test_plan_result_checks_fire() -> None:
    with pytest.raises(ValueError, match="needs a plan"):
        PlanResult(PlanStatus.SOLVED, None, 1.0, "x", 0.0)
    with pytest.raises(ValueError, match="needs a cost"):
        PlanResult(PlanStatus.SOLVED, (), None, "x", 0.0)
    with pytest.raises(ValueError, match="must not carry a plan"):
        PlanResult(PlanStatus.UNSOLVABLE, (), None, "x", 0.0)
    with pytest.raises(TypeError, match="PlanStatus"):
        PlanResult("solved", (), 0.0, "x", 0.0)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="tuples"):
        PlanResult(PlanStatus.SOLVED, ((),), 0.0, "x", 0.0, search="lama-first")
    with pytest.raises(ValueError, match="wall_time_s"):
        PlanResult(PlanStatus.SOLVED, (), 0.0, "x", -1.0, search="lama-first")


def test_deterministic() -> None:
    a = Planner(cache_size=0).solve(PddlText(DOMAIN, problem_text()))
    b = Planner(cache_size=0).solve(PddlText(DOMAIN, problem_text()))
    assert a.plan == b.plan and a.cost == b.cost


class _Clock:
    """A stand-in for ``time`` in :mod:`planners.planner`: it moves only when a solve runs."""

    def __init__(self) -> None:
        self.now = 100.0

    def perf_counter(self) -> float:
        return self.now


def _slow_solves(monkeypatch: pytest.MonkeyPatch, seconds: float) -> _Clock:
    """Every Fast Downward run of the facade takes ``seconds`` on a fake clock."""
    import planners.planner as facade

    clock, real = _Clock(), facade.solve_text

    def run(*args: Any, **kwargs: Any) -> Any:
        clock.now += seconds
        return real(*args, **kwargs)

    monkeypatch.setattr(facade, "time", clock)
    monkeypatch.setattr(facade, "solve_text", run)
    return clock


def test_a_cache_hit_does_not_report_the_original_solve_time_again(monkeypatch: pytest.MonkeyPatch) -> None:
    _slow_solves(monkeypatch, 5.0)
    planner = Planner()
    first = planner.solve(PddlText(DOMAIN, problem_text()))
    again = planner.solve(PddlText(DOMAIN, problem_text()))
    assert not first.cached and first.wall_time_s == 5.0
    assert again.cached and again.wall_time_s == 0.0  # the look-up's time, on a clock only solves move


def test_planner_wall_time_counts_each_solve_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """What ``planner_wall_time_s`` adds up (``planner_time_s`` of every planned upTsk, the
    runner's metric) holds a solve's time once, however often its answer is reused."""
    from planners.bundled import task_types
    from planners.examples import StraightLineMotion, example_context
    from planners.pddl_task import PddlTaskType

    _slow_solves(monkeypatch, 5.0)
    task = next(t for t in task_types() if t.name == "carry_object")
    assert isinstance(task, PddlTaskType)
    task = PddlTaskType(task.spec, task.domain, task.hooks, planner=Planner())
    ctx = example_context(task, motion=StraightLineMotion())
    assert ctx is not None
    plans = [task.update_task(ctx) for _ in range(3)]
    assert [p.info["cached"] for p in plans] == [False, True, True]
    assert sum(p.info["planner_time_s"] for p in plans) == 5.0


def test_engine_takes_a_schedule_and_claims_optimality_only_when_proven(pddl_files: tuple[Path, Path]) -> None:
    _, _, problem = load_problem(*pddl_files)
    with OneshotPlanner(name="tasker-fd", params={"schedule": "tasker-first"}) as engine:
        engine.skip_checks = True
        res = engine.solve(problem)
    assert res.status.name == "SOLVED_SATISFICING" and len(res.plan.actions) == 3  # pick, move a-c, drop
    with pytest.raises(ValueError, match="schedule must be one of"):
        OneshotPlanner(name="tasker-fd", params={"schedule": "fastest"})


def test_an_engine_that_raises_is_an_engine_error_not_an_exception(pddl_files: tuple[Path, Path]) -> None:
    from unified_planning.environment import get_environment

    factory = get_environment().factory
    if "raising" not in factory.engines:
        factory.add_engine("raising", "tests.planners.test_plan_files", "RaisingEngine")
    _, _, problem = load_problem(*pddl_files)
    res = Planner("raising").solve(problem)
    assert res.status is PlanStatus.ERROR and res.failure.value == "engine"
    assert res.message == "engine raising failed: RuntimeError: index 3 out of range in the engine"
