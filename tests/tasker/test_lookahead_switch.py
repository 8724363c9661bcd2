"""The look-ahead's switch penalty from the executing task's own suspension, and hazards left on.

Views are made by hand: ``ScheduleView.suspension`` and ``ScheduleView.hazards`` are what the
harmoniser is to pass (``tasker.schedulers.base``).
"""

from __future__ import annotations

import itertools
import math
import random

import pytest

from tasker import schedulers
from tasker.errors import ConfigError
from tasker.messages import CompletionCost, CostParams, SPRequest
from tasker.schedulers.base import Candidate, ScheduleView, UnattendedHazard
from tasker.schedulers.lookahead import Problem, solve


def cand(agent: str, order: int, c_time: float, *, x: float = 0.0, deadline: float | None = None,
         cps: float = 1.0) -> Candidate:
    params = CostParams("t", cost=cps * c_time, cps=cps, c_time=c_time, end_pose=(x, 0.0), deadline=deadline)
    return Candidate(agent, "t", params, float(order), order)


def view(exe: Candidate | None, cands: list[Candidate], *, suspension: dict[str, float] | None = None,
         hazards: tuple[UnattendedHazard, ...] = ()) -> ScheduleView:
    every = {c.id: c for c in [*cands, *([exe] if exe else [])]}

    def req_sp(agent: str, req: SPRequest) -> CompletionCost:  # 1 m/s travel from the pose to the task's x
        p = every[agent].params
        assert isinstance(p, CostParams) and p.end_pose is not None
        return CompletionCost(p.cps * (p.c_time + abs(req.args["pose"][0] - p.end_pose[0])), p.cps)

    ask = None if suspension is None else suspension.__getitem__
    return ScheduleView(0.0, exe, cands, req_sp, suspension=ask, hazards=hazards)


def test_the_executing_tasks_own_suspension_decides_the_switch() -> None:
    exe, urgent = cand("d1", 0, 30), cand("d2", 1, 10, deadline=15.0)
    s = schedulers.create("lookahead", lateness_weight=10.0, switch_penalty_s=100.0)
    assert s.schedule(view(exe, [urgent])).irr_da is None  # the constant: too dear to switch
    quick = s.schedule(view(exe, [urgent], suspension={"d2": 2.0}))  # the plan: 2 s to suspend
    assert quick.irr_da == "d2" and quick.record is not None and quick.record["suspend_s"] == {"d2": 2.0}
    slow = s.schedule(view(exe, [urgent], suspension={"d2": 60.0}))
    assert slow.irr_da is None and slow.record is not None and slow.record["suspend_s"] == {"d2": 60.0}
    stuck = s.schedule(view(exe, [urgent], suspension={"d2": math.inf}))  # cannot be planned: never first
    assert stuck.irr_da is None
    assert "suspend_s" not in (s.schedule(view(exe, [urgent])).record or {})  # a record without the plan says so


def test_the_penalty_is_per_replacement() -> None:
    """The suspension may depend on the interruption announced (a cooker left on for a short one)."""
    exe, a, b = cand("d1", 0, 100), cand("d2", 1, 10, deadline=20.0), cand("d3", 2, 10, deadline=20.0)
    s = schedulers.create("lookahead", lateness_weight=10.0)
    assert s.schedule(view(exe, [a, b], suspension={"d2": 9.0, "d3": 1.0})).irr_da == "d3"
    assert s.schedule(view(exe, [a, b], suspension={"d2": 1.0, "d3": 9.0})).irr_da == "d2"


def test_a_suspension_estimate_that_is_not_seconds_is_an_error() -> None:
    s = schedulers.create("lookahead")
    with pytest.raises(ConfigError, match="suspension estimate of d1 for d2 is nan"):
        s.schedule(view(cand("d1", 0, 30), [cand("d2", 1, 10)], suspension={"d2": math.nan}))


def test_a_hazard_left_on_brings_its_task_back_before_its_budget_runs_out() -> None:
    chore, cooking = cand("d1", 1, 10), cand("d2", 2, 10)  # equal: the earlier request goes first
    s = schedulers.create("lookahead")
    assert s.schedule(view(None, [chore, cooking])).irr_da == "d1"
    left_on = (UnattendedHazard("d2", "cooker-on", budget_s=105.0, since=-100.0),)  # back in cmd by t = 5
    d = s.schedule(view(None, [chore, cooking], hazards=left_on))
    assert d.irr_da == "d2" and d.record is not None
    assert d.record["left_on"] == [{"agent": "d2", "hazard": "cooker-on", "due": 5.0}]
    lax = (UnattendedHazard("d2", "cooker-on", budget_s=200.0, since=-100.0),)  # back by t = 100: after d1 is fine
    assert s.schedule(view(None, [chore, cooking], hazards=lax)).irr_da == "d1"
    other = (UnattendedHazard("d9", "cooker-on", budget_s=0.0, since=-100.0),)  # not in the queue: ignored
    assert s.schedule(view(None, [chore, cooking], hazards=other)).irr_da == "d1"


@pytest.mark.parametrize("seed", range(20))
def test_the_exact_search_with_hazards_matches_brute_force(seed: int) -> None:
    rng = random.Random(seed)
    n = rng.randint(1, 6)
    first = [rng.uniform(5, 60) for _ in range(n)]
    after = [[0.0 if i == j else rng.uniform(5, 60) for j in range(n)] for i in range(n)]
    left_on = [[rng.uniform(0, 150)] if rng.random() < 0.5 else [] for _ in range(n)]
    p = Problem(0.0, first, after, [rng.choice([0.0, 1.0, 5.0]) for _ in range(n)], [math.inf] * n,
                [math.inf] * n, hazard_weight=100.0, left_on=left_on)
    order, obj, _, exact = solve(p, node_budget=10**6)
    assert exact and obj == pytest.approx(p.evaluate(order))
    assert obj == pytest.approx(min(p.evaluate(o) for o in itertools.permutations(range(n))))
