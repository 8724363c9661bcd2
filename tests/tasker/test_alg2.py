"""Alg. 2 against decisions computed by hand."""

from __future__ import annotations

from typing import Any

import pytest

from tasker import schedulers
from tasker.errors import ConfigError
from tasker.messages import SP_COMPLETION, CompletionCost, CostParams, SPRequest
from tasker.schedulers.base import Candidate, ScheduleView


def cand(agent: str, task_type: str, cost: float, cps: float, c_time: float, pose: tuple[float, ...],
         order: int = 0) -> Candidate:
    return Candidate(agent, task_type, CostParams(task_type, cost=cost, cps=cps, c_time=c_time, end_pose=pose),
                     0.0, order)


class Answers:
    """reqSP buffers: fixed ``{cc, ccps}`` per agent; records what was asked."""

    def __init__(self, answers: dict[str, tuple[float, float]]) -> None:
        self.answers = answers
        self.asked: list[tuple[str, Any]] = []

    def __call__(self, agent: str, req: SPRequest) -> CompletionCost:
        assert req.sp_id == SP_COMPLETION
        self.asked.append((agent, req.args["pose"]))
        cc, ccps = self.answers[agent]
        return CompletionCost(cc, ccps)


PAPER = [["human_fell"], ["guide_human"]]
"""The paper's classes, as a scenario gives them (the model names no task type)."""


def alg2(**options: Any) -> Any:
    return schedulers.create("alg2", classes=PAPER, **options)


def view(exe: Candidate | None, cands: list[Candidate], answers: Answers) -> ScheduleView:
    return ScheduleView(now=10.0, exe=exe, candidates=cands, req_sp=answers)


def test_same_class_switches_when_c_switch_below_c_wait() -> None:
    # exe: guide John; dac: guide Alice (paper, t = 2509)
    exe = cand("d1", "guide_human", cost=50, cps=2, c_time=30, pose=(1.0, 1.0, 0.0))
    dac = cand("d2", "guide_human", cost=20, cps=1, c_time=10, pose=(5.0, 5.0, 0.0), order=1)
    ans = Answers({"d2": (25.0, 1.0), "d1": (55.0, 2.0)})
    d = alg2().schedule(view(exe, [dac], ans))
    # c_switch = cost_dac + cc_exe + cps_exe * cTime_dac = 20 + 55 + 2*10 = 95
    # c_wait   = cost_exe + cc_dac + cps_dac * cTime_exe = 50 + 25 + 1*30 = 105
    assert d.record is not None
    assert d.record["c_switch"] == pytest.approx(95.0)
    assert d.record["c_wait"] == pytest.approx(105.0)
    assert d.record["switch"] is True and d.irr_da == "d2"
    # reqSP asks each for its cost from the other's endPose (lines 22 and 25)
    assert ans.asked == [("d2", (1.0, 1.0, 0.0)), ("d1", (5.0, 5.0, 0.0))]


def test_same_class_stays_when_c_switch_not_below_c_wait() -> None:
    exe = cand("d1", "guide_human", cost=50, cps=2, c_time=30, pose=(1.0, 1.0, 0.0))
    dac = cand("d2", "guide_human", cost=20, cps=1, c_time=10, pose=(5.0, 5.0, 0.0), order=1)
    ans = Answers({"d2": (15.0, 1.0), "d1": (55.0, 2.0)})  # c_switch 95, c_wait 95: not strictly less
    d = alg2().schedule(view(exe, [dac], ans))
    assert d.record is not None and d.record["c_switch"] == d.record["c_wait"] == pytest.approx(95.0)
    assert d.irr_da is None and d.record["switch"] is False


def test_hysteresis_of_the_ros_code() -> None:
    exe = cand("d1", "guide_human", cost=50, cps=2, c_time=30, pose=(1.0, 1.0, 0.0))
    dac = cand("d2", "guide_human", cost=20, cps=1, c_time=10, pose=(5.0, 5.0, 0.0), order=1)
    ans = Answers({"d2": (25.0, 1.0), "d1": (55.0, 2.0)})  # 95 < 105 but not < 0.9 * 105 = 94.5
    assert alg2().schedule(view(exe, [dac], ans)).irr_da == "d2"
    assert alg2(hysteresis=0.9).schedule(view(exe, [dac], ans)).irr_da is None


def test_human_fell_preempts_guide_human_at_once() -> None:
    exe = cand("d1", "guide_human", cost=1, cps=0, c_time=1, pose=(0.0, 0.0, 0.0))
    fell = cand("d3", "human_fell", cost=1e6, cps=1, c_time=100, pose=(9.0, 9.0, 0.0), order=2)
    ans = Answers({})
    d = alg2().schedule(view(exe, [fell], ans))
    assert d.irr_da == "d3"
    assert ans.asked == []  # lines 10-12: no comparison, no reqSP
    assert d.record is not None and d.record["rule"] == "priority class"


def test_guide_human_never_preempts_human_fell() -> None:
    exe = cand("d3", "human_fell", cost=1e6, cps=10, c_time=100, pose=(0.0, 0.0, 0.0))
    g = cand("d1", "guide_human", cost=0, cps=0, c_time=1, pose=(1.0, 0.0, 0.0))
    d = alg2().schedule(view(exe, [g], Answers({})))
    assert d.irr_da is None and d.record is None


def test_lowest_cost_of_the_highest_class_is_the_candidate() -> None:
    exe = cand("d1", "human_fell", cost=100, cps=1, c_time=20, pose=(0.0, 0.0, 0.0))
    cheap_guide = cand("d2", "guide_human", cost=1, cps=1, c_time=1, pose=(0.0, 0.0, 0.0), order=1)
    f1 = cand("d3", "human_fell", cost=40, cps=1, c_time=5, pose=(1.0, 0.0, 0.0), order=2)
    f2 = cand("d4", "human_fell", cost=30, cps=1, c_time=5, pose=(2.0, 0.0, 0.0), order=3)
    ans = Answers({"d4": (30.0, 1.0), "d1": (100.0, 1.0)})
    d = alg2().schedule(view(exe, [cheap_guide, f1, f2], ans))
    assert d.record is not None and d.record["dac"] == "d4"
    # c_switch = 30 + 100 + 1*5 = 135 ; c_wait = 100 + 30 + 1*20 = 150
    assert d.record["c_switch"] == pytest.approx(135.0) and d.record["c_wait"] == pytest.approx(150.0)
    assert d.irr_da == "d4"


def test_no_executing_agent_starts_best_candidate_without_comparing() -> None:
    g1 = cand("d1", "guide_human", cost=10, cps=1, c_time=1, pose=(0.0, 0.0, 0.0))
    g2 = cand("d2", "guide_human", cost=5, cps=1, c_time=1, pose=(0.0, 0.0, 0.0), order=1)
    ans = Answers({})
    d = alg2().schedule(view(None, [g1, g2], ans))
    assert d.irr_da == "d2" and ans.asked == []  # no reqSP: nothing to compare with
    assert d.record is not None and d.record["rule"] == "no exeDA" and d.record["switch"] is True


def test_a_non_finite_estimate_never_forces_a_switch() -> None:
    inf = float("inf")
    # the executing task became infeasible (cost inf): c_wait = inf, c_switch finite -- still no switch
    exe = cand("d1", "t", cost=inf, cps=1, c_time=5, pose=(0.0, 0.0, 0.0))
    dac = cand("d2", "t", cost=1, cps=1, c_time=1, pose=(0.0, 0.0, 0.0), order=1)
    d = alg2().schedule(view(exe, [dac], Answers({"d2": (1.0, 1.0), "d1": (2.0, 1.0)})))
    assert d.record is not None and d.record["c_wait"] == inf and d.record["c_switch"] < inf
    assert d.irr_da is None and d.record["switch"] is False and d.record["undecided"] == "non-finite"
    # a higher-class candidate with an infinite cost does not preempt either
    low = cand("d1", "guide", cost=5, cps=1, c_time=5, pose=(0.0, 0.0, 0.0))
    fell = cand("d2", "fell", cost=inf, cps=1, c_time=1, pose=(0.0, 0.0, 0.0), order=1)
    s = schedulers.create("alg2", classes=[["fell"], ["guide"]])
    d = s.schedule(view(low, [fell], Answers({})))
    assert d.irr_da is None and d.record is not None and d.record["rule"] == "priority class"
    assert d.record["switch"] is False


def test_the_comparison_uses_parameters_of_one_moment() -> None:
    """Reports of different ticks are not mixed: both agents compute their parameters at the view's now."""
    exe = cand("d1", "t", cost=50, cps=2, c_time=30, pose=(1.0, 1.0, 0.0))
    dac = cand("d2", "t", cost=20, cps=1, c_time=10, pose=(5.0, 5.0, 0.0), order=1)
    now = {"d1": CostParams("t", cost=80, cps=2, c_time=30, end_pose=(1.0, 1.0, 0.0)),
           "d2": CostParams("t", cost=20, cps=1, c_time=10, end_pose=(5.0, 5.0, 0.0))}
    asked: list[str] = []

    def fresh(agent: str) -> CostParams:
        asked.append(agent)
        return now[agent]

    v = ScheduleView(10.0, exe, [dac], Answers({"d2": (25.0, 1.0), "d1": (55.0, 2.0)}), fresh=fresh)
    d = alg2().schedule(v)
    assert sorted(asked) == ["d1", "d2"]
    assert d.record is not None and d.record["cost_exeDA"] == 80  # the fresh value, not the report's 50
    assert d.record["c_wait"] == pytest.approx(80 + 25 + 1 * 30)


def test_infinite_cost_never_wins_and_zero_times_inf_is_zero() -> None:
    inf = float("inf")
    exe = cand("d1", "t", cost=10, cps=0, c_time=5, pose=(0.0, 0.0, 0.0))
    dac = cand("d2", "t", cost=inf, cps=1, c_time=inf, pose=(0.0, 0.0, 0.0), order=1)
    d = alg2().schedule(view(exe, [dac], Answers({"d2": (inf, 1.0), "d1": (10.0, 0.0)})))
    assert d.irr_da is None and d.record is not None and d.record["c_switch"] == inf


def test_configured_classes_and_errors() -> None:
    s = schedulers.create("alg2", classes=[["fire"], ["fell"], ["guide"]])
    assert [s.rank(t) for t in ("fire", "fell", "guide", "other")] == [0, 1, 2, 3]
    with pytest.raises(ConfigError, match="two priority classes"):
        schedulers.create("alg2", classes=[["a"], ["a"]])
    with pytest.raises(ConfigError, match="hysteresis"):
        schedulers.create("alg2", hysteresis=0)
    with pytest.raises(ConfigError, match="list of task types"):
        schedulers.create("alg2", classes=["fell"])


def test_alg2_needs_cost_params() -> None:
    from tasker.messages import ScheduleParams

    bare = Candidate("d1", "x", ScheduleParams("x"), 0.0, 0)
    with pytest.raises(ConfigError, match="needs CostParams"):
        alg2().schedule(view(None, [bare], Answers({})))


def test_without_classes_every_type_is_one_class_and_costs_decide() -> None:
    # the model names no task type: a human_fell candidate is compared on cost like any other
    exe = cand("d1", "guide_human", cost=1, cps=1, c_time=1, pose=(0.0, 0.0, 0.0))
    fell = cand("d3", "human_fell", cost=1e6, cps=1, c_time=100, pose=(9.0, 9.0, 0.0), order=2)
    s = schedulers.create("alg2")
    assert s.classes == () and s.rank("human_fell") == s.rank("guide_human") == 0
    d = s.schedule(view(exe, [fell], Answers({"d3": (1e6, 1.0), "d1": (1.0, 1.0)})))
    # c_switch = 1e6 + 1 + 1*100 > c_wait = 1 + 1e6 + 1*1: the executing guide stays
    assert d.record is not None and d.record["rule"] == "cost" and d.irr_da is None
    import tasker.schedulers.alg2 as module

    assert not hasattr(module, "DEFAULT_CLASSES")
