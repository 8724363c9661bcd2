"""The look-ahead between decisions: the last orders reused, durations kept while estimates hold.

Views are made by hand, as the harmoniser passes them (``tasker.schedulers.base.ScheduleView``).
"""

from __future__ import annotations

import math
import random
from dataclasses import replace

import pytest

from tasker import schedulers
from tasker.errors import ConfigError
from tasker.messages import CompletionCost, CostParams, SPRequest
from tasker.schedulers.base import Candidate, ScheduleView
from tasker.schedulers.lookahead import LookAhead, Problem, adapt


def cand(agent: str, order: int, c_time: float, *, x: float = 0.0, deadline: float | None = None,
         cps: float = 1.0) -> Candidate:
    params = CostParams("t", cost=cps * c_time, cps=cps, c_time=c_time, end_pose=(x, 0.0), deadline=deadline)
    return Candidate(agent, "t", params, float(order), order)


class Answers:
    """reqSP answers: 1 m/s travel from the pose to the task's x; counts what it was asked."""

    def __init__(self, every: dict[str, Candidate], seconds: bool = True) -> None:
        self.every, self.seconds, self.asked = every, seconds, 0

    def __call__(self, agent: str, req: SPRequest) -> CompletionCost:
        self.asked += 1
        p = self.every[agent].params
        assert isinstance(p, CostParams) and p.end_pose is not None
        c_time = p.c_time + abs(req.args["pose"][0] - p.end_pose[0])
        return CompletionCost(p.cps * c_time, p.cps, c_time if self.seconds else None)


def view(now: float, exe: Candidate | None, cands: list[Candidate], answers: Answers | None = None, *,
         generation: int | None = None, suspension: float | None = None) -> ScheduleView:
    every = {c.id: c for c in [*cands, *([exe] if exe else [])]}
    ask = answers if answers is not None else Answers(every)
    ask.every = every
    return ScheduleView(now, exe, cands, ask, generation=generation,
                        suspension=None if suspension is None else (lambda by: suspension))


def queue(rng: random.Random, n: int) -> list[Candidate]:
    return [cand(f"d{k + 2}", k + 1, rng.uniform(5, 60), x=rng.uniform(0, 20), cps=rng.choice([1.0, 2.0, 10.0]),
                 deadline=rng.choice([None, rng.uniform(50, 400)])) for k in range(n)]


def test_when_only_the_clock_moved_the_last_orders_are_priced_again_not_searched() -> None:
    rng = random.Random(3)
    waiting = queue(rng, 6)
    s = LookAhead()
    first = s.schedule(view(0.0, cand("d1", 0, 100.0), waiting))
    assert first.record is not None and first.record["rule"] in ("exact", "anytime")
    # 5 s later: exeDA has 5 s less to do, nobody else changed
    later = s.schedule(view(5.0, cand("d1", 0, 95.0), waiting))
    assert later.record is not None and later.record["rule"] == "incremental"
    if not first.record["switch"]:  # continuing exeDA: the same order, every completion where it was
        assert later.record["order"] == first.record["order"]
        full = LookAhead().schedule(view(5.0, cand("d1", 0, 95.0), waiting))
        assert full.record is not None
        assert later.record["objective_continue"] == pytest.approx(full.record["objective_continue"], rel=1e-9)


def test_a_new_request_or_a_new_estimate_is_searched_again() -> None:
    rng = random.Random(4)
    waiting = queue(rng, 4)
    s = LookAhead()
    s.schedule(view(0.0, cand("d1", 0, 100.0), waiting))
    grown = s.schedule(view(5.0, cand("d1", 0, 95.0), [*waiting, cand("d9", 9, 20.0, x=3.0)]))
    assert grown.record is not None and grown.record["rule"] != "incremental"
    s.schedule(view(10.0, cand("d1", 0, 90.0), waiting))
    moved = [replace(waiting[0], params=replace(waiting[0].params, c_time=waiting[0].params.c_time + 1.0)),
             *waiting[1:]]
    again = s.schedule(view(15.0, cand("d1", 0, 85.0), moved))
    assert again.record is not None and again.record["rule"] != "incremental"


def test_a_dearer_suspension_is_priced_at_once_without_a_new_search() -> None:
    exe, urgent = cand("d1", 0, 30), cand("d2", 1, 10, deadline=15.0)
    s = schedulers.create("lookahead", lateness_weight=10.0)
    quick = s.schedule(view(0.0, exe, [urgent], suspension=2.0))
    assert quick.irr_da == "d2"
    slow = s.schedule(view(0.0, exe, [urgent], suspension=60.0))
    assert slow.record is not None and slow.record["rule"] == "incremental" and slow.irr_da is None


def test_incremental_false_searches_at_every_decision() -> None:
    rng = random.Random(5)
    waiting = queue(rng, 5)
    s = schedulers.create("lookahead", incremental=False)
    for t in range(4):
        d = s.schedule(view(5.0 * t, cand("d1", 0, 100.0 - 5 * t), waiting))
        assert d.record is not None and d.record["rule"] in ("exact", "anytime")


@pytest.mark.parametrize("bad", ["yes", 1, None])
def test_incremental_must_be_a_bool(bad: object) -> None:
    with pytest.raises(ConfigError, match="incremental"):
        schedulers.create("lookahead", incremental=bad)


def test_durations_are_kept_while_the_generation_holds_and_asked_again_after() -> None:
    rng = random.Random(6)
    waiting = queue(rng, 5)
    answers = Answers({})
    s = LookAhead()
    s.schedule(view(0.0, cand("d1", 0, 100.0), waiting, answers, generation=7))
    n = len(waiting)
    assert answers.asked == (n + 1) * n  # every ordered pair once (exeDA resumed after each, each after each)
    answers.asked = 0
    s.schedule(view(5.0, cand("d1", 0, 95.0), waiting, answers, generation=7))
    assert answers.asked == 2 * n  # only the pairs with exeDA in them: its progress is not in the generation
    answers.asked = 0
    s.schedule(view(10.0, cand("d1", 0, 90.0), waiting, answers, generation=8))
    assert answers.asked == (n + 1) * n
    answers.asked = 0
    s.schedule(view(15.0, cand("d1", 0, 85.0), waiting, answers, generation=None))
    assert answers.asked == (n + 1) * n  # no generation: nothing is kept


def test_an_answer_in_seconds_is_the_duration_and_one_without_is_recovered_from_the_costs() -> None:
    exe, other = cand("d1", 0, 10.0, x=0.0), cand("d2", 1, 5.0, x=4.0)
    for seconds in (True, False):
        s = LookAhead()
        prob, _ = s.problem(view(0.0, exe, [other], Answers({}, seconds=seconds)))
        assert prob.after[0][1] == pytest.approx(9.0)  # d2 from d1's end pose: 5 s + 4 m at 1 m/s
        assert prob.after[1][0] == pytest.approx(14.0)  # d1 resumed from d2's: 10 s + 4 m


def test_adapt_keeps_the_last_order_appends_the_new_jobs_and_honours_the_first() -> None:
    prob = Problem(0.0, [5.0, 1.0, 2.0, 3.0], [[0.0, 1.0, 2.0, 3.0]] * 4, [1.0, 1.0, 1.0, 10.0],
                   [math.inf] * 4, [math.inf] * 4, has_exe=True)
    ids = ["d1", "d2", "d3", "d4"]
    assert adapt(prob, ids, ["d3", "gone", "d1"]) == [2, 0, 3, 1]  # new ones by Smith's key: d4 (3/10), d2 (1/1)
    assert adapt(prob, ids, ["d3", "d1"], fixed_first=0) == [0, 2, 3, 1]
    assert adapt(prob, ids, ["d1", "d3"], exclude_first=0) == [2, 0, 3, 1]
    single = Problem(0.0, [5.0], [[0.0]], [1.0], [math.inf], [math.inf], has_exe=True)
    assert adapt(single, ["d1"], ["d1"], exclude_first=0) == []


def test_a_warm_start_never_makes_the_search_worse() -> None:
    rng = random.Random(7)
    for _ in range(20):
        waiting = queue(rng, rng.randint(2, 9))
        exe = cand("d1", 0, rng.uniform(10, 100))
        warm, cold = LookAhead(node_budget=60), LookAhead(node_budget=60, incremental=False)
        for t in range(3):  # the queue changes each time (one more second of work): always a search
            waiting = [replace(c, params=replace(c.params, c_time=c.params.c_time + 1.0)) for c in waiting]
            v = view(5.0 * t, replace(exe, params=replace(exe.params, c_time=exe.params.c_time - 5 * t)), waiting)
            a, b = warm.schedule(v), cold.schedule(v)
            assert a.record is not None and b.record is not None and a.record["rule"] != "incremental"
            assert min(a.record["objective"], a.record["objective_continue"]) <= \
                min(b.record["objective"], b.record["objective_continue"]) * (1 + 1e-9) or t == 0


def test_a_pose_that_is_not_a_value_is_asked_again_not_kept() -> None:
    waiting = [replace(c, params=replace(c.params, end_pose=[c.params.end_pose[0], 0.0]))  # type: ignore[index]
               for c in queue(random.Random(8), 3)]
    answers = Answers({})
    s = LookAhead()
    for t in range(2):
        s.schedule(view(5.0 * t, cand("d1", 0, 100.0 - 5 * t), waiting, answers, generation=3))
    assert answers.asked == 2 * 4 * 3  # nothing kept: every pair asked at both decisions


@pytest.mark.parametrize("bad", ["12", True, [3.0]])
def test_an_answer_whose_seconds_are_not_a_number_is_refused_naming_the_task_type(bad: object) -> None:
    exe, other = cand("d1", 0, 10.0), cand("d2", 1, 5.0, x=4.0)

    def req_sp(agent: str, req: SPRequest) -> CompletionCost:
        return CompletionCost(1.0, 1.0, bad)  # type: ignore[arg-type]

    with pytest.raises(ConfigError, match=r"task type 't'.*c_time"):
        LookAhead().problem(ScheduleView(0.0, exe, [other], req_sp))


def test_a_non_finite_answer_in_seconds_is_a_job_that_cannot_follow() -> None:
    exe, other = cand("d1", 0, 10.0), cand("d2", 1, 5.0, x=4.0)

    def req_sp(agent: str, req: SPRequest) -> CompletionCost:
        return CompletionCost(math.inf, 1.0, math.nan)

    prob, _ = LookAhead().problem(ScheduleView(0.0, exe, [other], req_sp))
    assert prob.after[0][1] == math.inf and prob.after[1][0] == math.inf
