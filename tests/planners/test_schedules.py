"""Search schedules: what each runs, what it claims of its plan, and that tasker-fd's answer does not
depend on the clock.  Expected plans and costs are worked out by hand (``pddl_cases``)."""

from __future__ import annotations

import pytest

import planners.schedules as schedules
from planners.fd import LAMA_FIRST, OPTIMAL_SEARCH, FDExit, FoundPlan, SearchRun, search
from planners.planner import PddlText, Planner
from planners.results import Attempt, Failure, PlanResult, PlanStatus
from planners.translate import translate
from tests.planners.conftest import DOMAIN, problem_text
from tests.planners.pddl_cases import DERIVED, GRIPPER, gripper_problem

OPTIMAL_DELIVERY = (("pick", "cup", "a"), ("move", "a", "b"), ("move", "b", "c"), ("drop", "cup", "c"))
"""Cost 1 + 2 + 2 + 1 = 6: the route through b beats the direct move a-c (10), which a search
that ignores action costs takes (1 + 10 + 1 = 12)."""


def _solve(name: str, domain: str = DOMAIN, problem: str | None = None, timeout: float = 30.0) -> PlanResult:
    return Planner(name, cache_size=0).solve(PddlText(domain, problem or problem_text()), timeout=timeout)


def test_tasker_fd_is_optimal_and_says_so() -> None:
    res = _solve("tasker-fd")
    assert res.plan == OPTIMAL_DELIVERY and res.cost == 6
    assert res.optimal and res.search == OPTIMAL_SEARCH
    assert [a.search for a in res.attempts] == [OPTIMAL_SEARCH]


def test_lama_first_ignores_costs_and_anytime_improves_and_proves() -> None:
    first = _solve("tasker-first")
    assert first.cost == 12 and not first.optimal and first.search == "lama-first"
    best = _solve("tasker-anytime")
    assert best.plan == OPTIMAL_DELIVERY and best.cost == 6 and best.optimal
    assert [a.search for a in best.attempts] == ["lama-first", "lama", OPTIMAL_SEARCH]
    assert best.attempts[0].cost == 12  # the first plan, at once
    assert best.first_plan_s is not None and best.best_plan_s is not None
    assert best.first_plan_s <= best.best_plan_s <= best.wall_time_s


def test_tasker_opt_alone() -> None:
    res = _solve("tasker-opt")
    assert res.plan == OPTIMAL_DELIVERY and res.optimal and len(res.attempts) == 1


def test_axioms_are_searched_blind_and_still_optimal() -> None:
    res = _solve("tasker-fd", DERIVED.domain, DERIVED.problem)
    assert res.plan == DERIVED.plan and res.optimal and res.search == "astar(blind())"
    assert [(a.search, a.exit) for a in res.attempts] == [(OPTIMAL_SEARCH, FDExit.ERROR),
                                                          ("astar(blind())", FDExit.SOLVED)]


def test_search_stops_past_its_expansion_budget() -> None:
    sas = translate(GRIPPER, gripper_problem(8)).sas  # A* + LM-cut needs about 10,500 expansions
    over = search(sas, OPTIMAL_SEARCH, expansions=1000)
    assert over.exit is FDExit.OVER_BUDGET and over.plans == () and over.expanded is not None
    assert over.expanded > 1000
    done = search(sas, OPTIMAL_SEARCH, expansions=100_000)
    assert done.exit is FDExit.SOLVED and done.best is not None and done.best.cost == 23  # 3·8 - 1
    assert done.expanded is not None and 1000 < done.expanded <= 100_000


def test_tasker_fd_past_its_budget_answers_lama_first_reproducibly(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(schedules, "EXPANSION_BUDGET", 1000)
    text = gripper_problem(8)
    runs = [_solve("tasker-fd", GRIPPER, text) for _ in range(2)]
    for res in runs:
        assert res.solved and res.search == "lama-first" and not res.optimal
        assert "expanded more than 1000 states" in res.message
        assert [a.exit for a in res.attempts] == [FDExit.OVER_BUDGET, FDExit.SOLVED]
    assert runs[0].plan == runs[1].plan and runs[0].trace_info() == runs[1].trace_info()


def test_the_budget_does_not_touch_what_fits_in_it() -> None:
    res = _solve("tasker-fd", GRIPPER, gripper_problem(4))
    assert res.optimal and res.cost == 11 and res.search == OPTIMAL_SEARCH  # 3·4 - 1


@pytest.mark.slow
def test_anytime_keeps_its_plan_when_the_proof_runs_out_of_time() -> None:
    res = _solve("tasker-anytime", GRIPPER, gripper_problem(14), timeout=3.0)
    assert res.solved and res.cost == 41 and not res.optimal  # 3·14 - 1: LAMA finds the optimum, A* cannot prove it
    assert "did not finish within the time limit" in res.message and "tried: lama-first" in res.message
    assert res.attempts[-1].search == OPTIMAL_SEARCH and res.attempts[-1].exit is FDExit.TIMEOUT
    assert res.wall_time_s < 6.0


def test_a_timeout_says_what_was_tried_and_what_to_try() -> None:
    call = schedules._Call(translate(GRIPPER, gripper_problem(14)).sas, 0.5)  # the search's time, not translation
    res = schedules.optimal_only(call, "tasker-opt")
    assert res.status is PlanStatus.TIMEOUT and res.failure is None
    assert res.message == ("time limit reached; tried: astar(lmcut()): timeout; an optimal search may need far "
                           "longer: the default planner, tasker-anytime, finds a plan at once and improves it")


def test_unsolvable_is_proven_by_every_schedule() -> None:
    for name in schedules.SCHEDULES:
        res = _solve(name, problem=problem_text(goal="(holding cup) (item-at cup c)"))
        assert res.status is PlanStatus.UNSOLVABLE and not res.optimal, name
        assert res.message.startswith("no plan exists ("), res.message
    # a message reaches a run's problems/ index and a task's end reason: no wall-clock value in it
    res = _solve("tasker-fd", problem=problem_text(goal="(holding cup) (item-at cup c)"))
    assert res.message == "no plan exists (astar(lmcut()): unsolvable)"


def test_translator_refusal_is_an_input_failure() -> None:
    res = _solve("tasker-anytime", problem=problem_text(goal="(nonsense cup)"))
    assert res.status is PlanStatus.ERROR and res.failure is Failure.INPUT and "translator" in res.message


def test_lama_first_string_is_fast_downwards_alias() -> None:
    """The LAMA-first configuration is the one FD's own driver runs for ``--alias lama-first``."""
    from up_fast_downward.downward.driver import aliases

    theirs = [x.replace(" ", "").replace("\n", "") for x in aliases.ALIASES["lama-first"]]  # as the driver does
    assert theirs == ["--search", LAMA_FIRST]


def test_result_checks_fire() -> None:
    with pytest.raises(ValueError, match="needs the search"):
        PlanResult(PlanStatus.SOLVED, (), 0.0, "x", 0.0)
    with pytest.raises(ValueError, match="cannot be optimal"):
        PlanResult(PlanStatus.TIMEOUT, None, None, "x", 0.0, optimal=True)
    with pytest.raises(ValueError, match="failure exactly when"):
        PlanResult(PlanStatus.ERROR, None, None, "x", 0.0)
    with pytest.raises(ValueError, match="failure exactly when"):
        PlanResult(PlanStatus.TIMEOUT, None, None, "x", 0.0, failure=Failure.ENGINE)
    with pytest.raises(ValueError, match="label"):
        Attempt("", FDExit.SOLVED, 1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match=">= 0"):
        Attempt("lama", FDExit.SOLVED, 1.0, -1.0, 0.0)
    with pytest.raises(ValueError, match="needs a plan"):
        SearchRun(FDExit.SOLVED, 0, (), None, 0.0)
    with pytest.raises(ValueError, match="expansion budget"):
        SearchRun(FDExit.OVER_BUDGET, -9, (FoundPlan((), 0.0, 0.0),), 5, 0.0)


def test_the_trace_records_whether_the_plan_is_optimal_and_which_search_made_it() -> None:
    """A task's planned upTsk carries ``optimal`` and ``search`` into the trace (PlanMade's info),
    and nothing measured: the agent keeps only the keys that are not volatile."""
    from planners.bundled import task_types
    from planners.examples import StraightLineMotion, example_context
    from planners.pddl_task import PddlTaskType
    from tasker.stagerun import VOLATILE_INFO

    task = next(t for t in task_types() if t.name == "carry_object")
    assert isinstance(task, PddlTaskType)
    task = PddlTaskType(task.spec, task.domain, task.hooks, planner=Planner(cache_size=0))
    ctx = example_context(task, motion=StraightLineMotion())
    assert ctx is not None
    plan = task.update_task(ctx)
    traced = {k: v for k, v in plan.info.items() if k not in VOLATILE_INFO}
    assert traced == {"planner": "tasker-fd", "cost": traced["cost"], "optimal": True, "search": OPTIMAL_SEARCH}
