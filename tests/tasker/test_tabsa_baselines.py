"""TaBSA's agents as its code defines them, and the WSPT and ATC rules, on hand-made queues.

Each test states what the definition picks (Smit-Sim ``my_agents.py``; the original request
table ``RequestTable.py`` / ``PriorityShdl.py``; Smith's rule; Vepsalainen and Morton's ATC)
and checks the scheduler picks it.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

from tasker import schedulers
from tasker.messages import CompletionCost, CostParams, SPRequest
from tasker.schedulers.base import Candidate, Decision, ScheduleView
from tasker.schedulers.tabsa import draw
from tasker.schedulers.tabsa_slots import Request, Slot, book

from .helpers import make_loop, st
from .test_oscillation import ThrashTask, oscillations


def cand(agent: str, order: int, c_time: float, *, x: float | None = None, task_type: str = "t",
         deadline: float | None = None, priority: int | None = None, cps: float = 1.0,
         requested: float | None = None) -> Candidate:
    pose = None if x is None else (x, 0.0)
    params = CostParams(task_type, cost=cps * c_time, cps=cps, c_time=c_time, end_pose=pose, deadline=deadline,
                        priority=priority)
    return Candidate(agent, task_type, params, float(order) if requested is None else requested, order)


def answer(agent: str, req: SPRequest) -> CompletionCost:
    return CompletionCost(1.0, 1.0)


def view(exe: Candidate | None, cands: list[Candidate], now: float = 0.0) -> ScheduleView:
    return ScheduleView(now, exe, cands, answer)


def decide(name: str, exe: Candidate | None, cands: list[Candidate], now: float = 0.0, **options: Any) -> Decision:
    return schedulers.create(name, **options).schedule(view(exe, cands, now))


# -- tabsa-simple / tabsa-simple2 (SimpleAgent, SimpleAgent2) --------------------------------------------

def test_simple_runs_the_longest_and_ignores_priority_and_deadlines() -> None:
    short_urgent = cand("d2", 1, 10, priority=9, deadline=1.0)
    long_lax = cand("d3", 2, 60, priority=0)
    assert decide("tabsa-simple", None, [short_urgent, long_lax]).irr_da == "d3"
    assert decide("tabsa-simple2", None, [short_urgent, long_lax]).irr_da == "d2"


def test_simple_ties_go_to_the_executing_task_then_the_earliest_request() -> None:
    assert decide("tabsa-simple", None, [cand("d3", 3, 20), cand("d2", 2, 20)]).irr_da == "d2"
    d = decide("tabsa-simple", cand("d1", 5, 20), [cand("d2", 2, 20)])
    assert d.irr_da is None and d.record is not None and d.record["dac"] == "d1"


@pytest.mark.parametrize(("name", "rival"), [("tabsa-simple", 50.0), ("tabsa-simple2", 2.0)])
def test_hesitance_zero_always_switches_and_one_never_does(name: str, rival: float) -> None:
    exe, better = cand("d1", 0, 10), cand("d2", 1, rival)
    for now in range(50):
        assert decide(name, exe, [better], float(now), hesitance=0.0).irr_da == "d2"
        kept = decide(name, exe, [better], float(now), hesitance=1.0)
        assert kept.irr_da is None and kept.record is not None and kept.record["rule"] == "hesitance"


def test_hesitance_is_a_probability_drawn_from_the_seed_never_from_global_state() -> None:
    exe, better = cand("d1", 0, 10), cand("d2", 1, 50)

    def run(seed: int) -> list[bool]:
        s = schedulers.create("tabsa-simple", hesitance=0.5, seed=seed)
        return [s.schedule(view(exe, [better], now)).irr_da is None for now in (k * 5.0 for k in range(400))]

    kept = run(7)
    assert 0.4 < sum(kept) / len(kept) < 0.6  # keeps the executing task with probability 0.5
    assert run(7) == kept and run(8) != kept  # the seed decides, nothing else
    s = schedulers.create("tabsa-simple", hesitance=0.5, seed=7)
    first, again = s.schedule(view(exe, [better], 35.0)), s.schedule(view(exe, [better], 35.0))
    assert first.irr_da == again.irr_da  # one draw a moment, however often the moment is asked
    assert first.record is not None and again.record is not None and first.record["draw"] == again.record["draw"]
    assert first.record is not None and first.record["draw"] == draw(7, 35.0, "d1")
    assert (first.irr_da is None) == (draw(7, 35.0, "d1") <= 0.5)


def test_a_non_preemptive_executing_task_is_kept() -> None:
    exe, longer = cand("d1", 0, 5, task_type="fall"), cand("d2", 1, 90)
    for name in ("tabsa-simple", "tabsa-distance", "tabsa-scheduler"):
        d = decide(name, exe, [longer], non_preemptive=["fall"])
        assert d.irr_da is None and d.record is not None and d.record["rule"] == "non-preemptive"
    assert decide("tabsa-simple", exe, [longer]).irr_da == "d2"  # by default every task is preemptive


def test_estimates_are_re_read_when_a_request_arrives_or_the_executing_task_changes() -> None:
    for estimates, switched in (("events", False), ("reports", True)):
        s = schedulers.create("tabsa-simple", estimates=estimates)
        assert s.schedule(view(cand("d1", 0, 50), [cand("d2", 1, 40)])).irr_da is None
        d = s.schedule(view(cand("d1", 0, 30), [cand("d2", 1, 40)], 20.0))  # d1 progressed, nothing arrived
        assert (d.irr_da == "d2") is switched
    s = schedulers.create("tabsa-simple")
    s.schedule(view(cand("d1", 0, 50), [cand("d2", 1, 40)]))
    s.schedule(view(cand("d1", 0, 30), [cand("d2", 1, 40)], 20.0))
    d = s.schedule(view(cand("d1", 0, 30), [cand("d2", 1, 40), cand("d3", 2, 1)], 21.0))  # d3 arrives
    assert d.irr_da == "d2" and d.record is not None and d.record["refreshed"] is True


def test_refreshing_at_events_is_what_keeps_tabsa_simple2_from_thrashing() -> None:
    """ThrashTask's executing task reports itself long, its waiting one short: read at every
    report, shortest-first switches back and forth; read at events, as in TaBSA, it does not."""
    for estimates, thrashes in (("reports", True), ("events", False)):
        loop = make_loop([ThrashTask("thrash", [st("work", 60.0)])], scheduler="tabsa-simple2", estimates=estimates)
        loop.harmoniser.guard = None
        loop.request(0.0, "thrash")
        loop.request(0.0, "thrash")
        assert (oscillations(loop.run(until=30.0).events) != []) is thrashes


# -- tabsa-distance (DistanceAgent) --------------------------------------------------------------------

def test_distance_maximises_distance_minus_ratio_times_duration() -> None:
    exe = cand("d1", 0, 10, x=0.0)  # the robot will be at x = 0
    near_short, far_long = cand("d2", 1, 1, x=2.0), cand("d3", 2, 20, x=8.0)
    d0 = decide("tabsa-distance", exe, [near_short, far_long], ratio=0.0)
    assert d0.irr_da == "d3"  # ratio 0: the farthest task, preempting the one at hand
    assert d0.record is not None and d0.record["distance_dac"] == 8.0 and d0.record["score_exeDA"] == 0.0
    d1 = decide("tabsa-distance", exe, [near_short, far_long], ratio=1.0)
    assert d1.irr_da == "d2"  # ratio 1: 2 - 1 beats 8 - 20 and the executing 0 - 10
    assert d1.record is not None and d1.record["score_dac"] == 1.0


def test_distance_ignores_priority_and_measures_from_the_last_task_when_idle() -> None:
    s = schedulers.create("tabsa-distance")
    s.schedule(view(cand("d1", 0, 10, x=10.0), [cand("d2", 1, 5, x=9.0)]))  # the robot heads for x = 10
    d = s.schedule(view(None, [cand("d2", 1, 5, x=9.0), cand("d4", 4, 5, x=0.0, priority=0),
                               cand("d3", 3, 5, x=9.5, priority=9)], 50.0))
    assert d.irr_da == "d4"  # 10 m away from x = 10: the farthest, whatever the priorities


# -- tabsa-scheduler (RequestTable + PriorityShdl + SchedulerAgent) ----------------------------------------

def test_the_table_books_by_priority_at_the_deadline_and_never_earlier() -> None:
    slots, rejected = book([Request("lo", 100.0, 10.0, 1), Request("hi", 100.0, 20.0, 3)])
    assert slots == [Slot(80.0, 100.0, "hi")]
    assert rejected == ["lo"]  # [90, 100] is taken; the free [70, 80] is not considered


def test_the_table_gives_a_whole_slot_and_drops_gaps_of_five_seconds_or_less() -> None:
    slots, _ = book([Request("h1", 50.0, 10.0, 5), Request("h2", 73.0, 10.0, 5), Request("lo", 62.0, 10.0, 1)])
    assert Slot(50.0, 63.0, "lo") in slots  # [52, 62] in the free [50, 63]: 3 s over, the whole slot
    slots, rejected = book([Request("h", 50.0, 10.0, 5), Request("m", 58.0, 5.0, 4), Request("lo", 52.0, 2.0, 1)])
    assert slots == [Slot(40.0, 50.0, "h"), Slot(53.0, 58.0, "m")] and rejected == ["lo"]  # [50, 53] was dropped


def test_the_table_keeps_the_order_of_requests_at_equal_priority_and_sorts_slots_by_start() -> None:
    slots, rejected = book([Request("a", 200.0, 10.0, 2), Request("b", 100.0, 10.0, 2), Request("c", 200.0, 5.0, 2),
                            Request("x", 300.0, math.inf, 9)])
    assert [s.job for s in slots] == ["b", "a"] and rejected == ["x", "c"]


def test_a_slot_is_due_from_one_slot_length_before_its_start_until_its_stop() -> None:
    slot = Slot(40.0, 50.0, "d1")
    assert [slot.due(t) for t in (29.9, 30.0, 45.0, 49.9, 50.0)] == [False, True, True, True, False]


def test_the_scheduler_runs_the_first_due_slot_or_leaves_the_robot_idle() -> None:
    early, late = cand("d2", 1, 10, deadline=100.0, priority=1), cand("d3", 2, 10, deadline=300.0, priority=5)
    idle = decide("tabsa-scheduler", None, [early, late], now=10.0)
    assert idle.irr_da is None and idle.record is not None and idle.record["rule"] == "no slot due"
    assert idle.record["slots"] == [["d2", 90.0, 100.0], ["d3", 290.0, 300.0]]
    d = decide("tabsa-scheduler", None, [early, late], now=80.0)
    assert d.irr_da == "d2" and d.record is not None and d.record["slot_dac"] == [90.0, 100.0]
    exe = cand("d1", 0, 500, deadline=5000.0, priority=9)  # a higher priority does not protect it
    assert decide("tabsa-scheduler", exe, [early, late], now=285.0).irr_da == "d3"
    kept = decide("tabsa-scheduler", exe, [early, late], now=150.0)
    assert kept.irr_da is None and kept.record is not None and kept.record["rule"] == "no slot due"


def test_bursts_are_kept_until_the_requests_change() -> None:
    s = schedulers.create("tabsa-scheduler")
    assert s.schedule(view(None, [cand("d1", 1, 10, deadline=100.0)], 0.0)).record == {
        "algorithm": "tabsa-scheduler", "exeDA": None, "rebuilt": True, "slots": [["d1", 90.0, 100.0]],
        "rejected": [], "rule": "no slot due", "dac": None, "switch": False}
    d = s.schedule(view(None, [cand("d1", 1, 40, deadline=100.0)], 1.0))  # a new estimate, same requests
    assert d.record is not None and d.record["rebuilt"] is False
    d = s.schedule(view(None, [cand("d1", 1, 40, deadline=100.0), cand("d2", 2, 5, deadline=200.0)], 2.0))
    assert d.record is not None and d.record["slots"] == [["d1", 90.0, 100.0], ["d2", 195.0, 200.0]]
    # one request left and another came at once: same count, a new last request: bursts re-read
    d = s.schedule(view(None, [cand("d1", 1, 40, deadline=100.0), cand("d3", 3, 5, deadline=300.0)], 25.0))
    assert d.record is not None and d.record["slots"] == [["d1", 60.0, 100.0], ["d3", 295.0, 300.0]]
    assert d.irr_da == "d1"  # now due: [60 - 40, 100)


def test_a_request_without_deadline_asks_for_the_time_from_each_rebuild_on() -> None:
    s = schedulers.create("tabsa-scheduler")
    d = s.schedule(view(None, [cand("d1", 1, 30), cand("d2", 2, 20, priority=1)], now=12.0))
    assert d.irr_da == "d2" and d.record is not None and d.record["slot_dac"] == [12.0, 32.0]
    assert d.record["rejected"] == ["d1"]  # [12, 42] overlaps d2's slot
    d = s.schedule(view(None, [cand("d1", 1, 25)], now=40.0))  # d2 done: the table is rebuilt at 40
    assert d.irr_da == "d1" and d.record is not None and d.record["slot_dac"] == [40.0, 70.0]  # burst kept: 30


# -- wspt and atc -------------------------------------------------------------------------------------

def test_wspt_runs_the_highest_weight_per_second_and_preempts_only_for_a_higher_one() -> None:
    a, b, c = cand("d2", 2, 10, priority=1), cand("d3", 3, 60, priority=3), cand("d4", 4, 10, priority=2)
    assert decide("wspt", None, [a, b, c]).irr_da == "d4"  # 0.2 beats 0.1 and 0.05
    assert decide("wspt", None, [a, b, c], weight="cps").irr_da == "d2"  # equal cps: the shortest, first
    assert decide("wspt", cand("d1", 1, 5, priority=1), [c]).irr_da is None  # 0.2 = 0.2: no switch
    d = decide("wspt", cand("d1", 1, 20, priority=1), [c])
    assert d.irr_da == "d4" and d.record is not None and (d.record["wspt_dac"], d.record["wspt_exeDA"]) == (0.2, 0.05)
    assert decide("wspt", None, [cand("d2", 2, 10, priority=1, deadline=11.0), c]).irr_da == "d4"  # no deadlines


def test_atc_is_wspt_discounted_by_slack() -> None:
    urgent = cand("d2", 2, 20, priority=1, deadline=25.0)  # WSPT 0.05, slack 5 s
    lax = cand("d3", 3, 10, priority=1, deadline=500.0)  # WSPT 0.1, slack 490 s
    d = decide("atc", None, [urgent, lax], k=2.0)
    assert d.irr_da == "d2" and d.record is not None
    p_mean = 15.0
    assert d.record["p_mean"] == p_mean
    assert d.record["log_atc_dac"] == pytest.approx(math.log(1 / 20) - 5 / (2.0 * p_mean))
    assert decide("atc", None, [urgent, lax], k=1e6).irr_da == "d3"  # a long look-ahead: WSPT
    no_deadline = cand("d4", 4, 1, priority=9)
    assert decide("atc", None, [no_deadline, lax]).irr_da == "d3"  # infinite slack: index 0
    assert decide("atc", None, [no_deadline, cand("d5", 5, 1, priority=18)]).irr_da == "d5"  # then WSPT


def test_atc_preempts_for_a_strictly_higher_index() -> None:
    exe = cand("d1", 1, 10, priority=1, deadline=1000.0)
    d = decide("atc", exe, [cand("d2", 2, 10, priority=1, deadline=15.0)])
    assert d.irr_da == "d2" and d.record is not None and d.record["log_atc_dac"] > d.record["log_atc_exeDA"]
    assert decide("atc", exe, [cand("d2", 2, 10, priority=1, deadline=1000.0)]).irr_da is None
