"""Metrics are computed from the trace alone: hand-built traces with values worked out
by hand, and the synthetic demo scenario end to end."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from experiments.inputs import synthetic
from experiments.metrics import run as metrics
from tasker.trace import Trace
from tests.experiments.events import complete

DEMO = Path(__file__).resolve().parents[2] / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml"


@pytest.fixture(scope="module")
def demo() -> Trace:
    return synthetic.run(synthetic.load(DEMO), seed=1)


class Build:
    """A tiny trace builder: one method per event kind, times given explicitly."""

    def __init__(self) -> None:
        self.events: list[dict[str, Any]] = []

    def add(self, t: float, event: str, **fields: Any) -> Build:
        self.events.append(complete({"t": t, "event": event, **fields}))
        return self

    def request(self, t: float, agent: str, task_type: str = "cook", **args: Any) -> Build:
        return self.add(t, "request", agent=agent, task_type=task_type, args=args, requester="test")

    def go(self, t: float, agent: str, *states: str) -> Build:
        """Transitions through ``states`` at time ``t`` (the first is the current state)."""
        for a, b in zip(states, states[1:], strict=False):
            self.add(t, "transition", agent=agent, **{"from": a, "to": b})
        return self

    def cmd(self, t: float, agent: str, flag: str) -> Build:
        return self.add(t, "command", agent=agent, flag=flag)

    def stage(self, t: float, agent: str, action: str, status: str, *args: str, fsm: str = "exeTsk") -> Build:
        return self.add(t, "stage", agent=agent, fsm=fsm, index=0, action=action, args=list(args),
                        kind="suspendable", status=status)

    def hazard(self, t: float, agent: str | None, hazard: str, status: str, *args: str,
               budget_s: float = 0.0) -> Build:
        return self.add(t, "hazard", agent=agent, hazard=hazard, args=list(args), status=status, budget_s=budget_s)

    def role(self, t: float, agent: str, role: str, status: str, person: str) -> Build:
        return self.add(t, "role", agent=agent, role=role, person=person, status=status)

    def end(self, t: float, agent: str, cause: str = "finished", reason: str = "finished") -> Build:
        self.go(t, agent, "exeTsk", "end")
        return self.add(t, "end", agent=agent, task_type="cook", reason=reason, cause=cause)


def suspended_twice_started() -> Build:
    """d1 runs, is suspended at 10 for d2, resumes at 30 and ends at 40; d2 ends at 28."""
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP").cmd(0, "d1", "start")
    b.go(0, "d1", "compSP", "upTsk", "exeTsk").stage(0, "d1", "navigate", "begin")
    b.request(8, "d2").go(8, "d2", "initComm", "compSP").cmd(10, "d1", "susp")
    b.stage(10.5, "d1", "navigate", "stopped").go(10.5, "d1", "exeTsk", "genSusp", "exeSusp")
    b.go(12.5, "d1", "exeSusp", "wait").cmd(12.5, "d2", "start").go(12.5, "d2", "compSP", "upTsk", "exeTsk")
    b.end(28, "d2").cmd(30, "d1", "start").go(30, "d1", "wait", "upTsk")
    b.add(30, "plan", agent="d1", purpose="upTsk", strategy="static", stages=[], note="planner failed: fallback")
    b.go(30, "d1", "upTsk", "exeTsk").stage(31, "d1", "navigate", "begin").stage(39, "d1", "navigate", "done")
    return b.end(40, "d1")


def test_suspension_suspended_and_resumption_times_by_hand() -> None:
    m = metrics.compute(suspended_twice_started().events)
    d1 = m["tasks"]["d1"]
    assert d1["suspensions"] == 1
    assert d1["suspension_s"] == [2.0]  # genSusp at 10.5 -> wait at 12.5
    assert d1["suspended_s"] == 17.5  # wait at 12.5 -> upTsk at 30
    assert d1["resumption_s"] == [1.0]  # upTsk at 30 -> first stage at 31
    assert d1["duration_s"] == 40.0 and m["tasks"]["d2"]["duration_s"] == 20.0
    assert d1["stages"] == {"done": 1, "stopped": 1, "failed": 0}
    assert d1["plans"] == 1 and d1["plans_by"] == {"upTsk/static": 1} and d1["static_fallbacks"] == 1
    assert m["switching"]["switches"] == 1
    assert m["switching"]["switch_list"][0] == {"t_susp": 10.0, "t_start": 12.5, "from": "d1", "to": "d2",
                                                "latency_s": 2.5}
    assert m["totals"]["makespan_s"] == 40.0
    assert m["totals"]["duration_s"] == {"mean": 30.0, "max": 40.0}
    assert m["totals"]["finished"] == 2 and m["totals"]["failed"] == 0


def test_a_suspension_that_ends_the_task_is_not_a_time_to_wait() -> None:
    """``suspension_s`` is entering genSusp to entering wait (docs/metrics.md): a suspension made for a
    ``term``, which ends the task instead, counts as a suspension but gives no such time.  (A planted
    bug that dropped the ``wait`` filter passed every test before this one.)"""
    b = suspended_twice_started()
    b.events = b.events[:-2]  # d1 does not finish at 40: it is terminated while it runs
    b.cmd(35, "d1", "term").go(35, "d1", "exeTsk", "genSusp", "exeSusp").go(38, "d1", "exeSusp", "end")
    b.add(38, "end", agent="d1", task_type="cook", reason="terminated", cause="term")
    m = metrics.compute(b.events)
    assert m["tasks"]["d1"]["suspensions"] == 2
    assert m["tasks"]["d1"]["suspension_s"] == [2.0]  # 10.5 -> 12.5; not 35 -> 38, which ended the task
    assert m["totals"]["suspension_s"] == {"mean": 2.0, "max": 2.0}


def test_a_susp_followed_by_a_start_of_the_same_agent_is_no_switch() -> None:
    b = Build().request(0, "d1").cmd(0, "d1", "start").cmd(5, "d1", "susp").cmd(6, "d1", "start")
    b.cmd(7, "d1", "susp").cmd(8, "d2", "start")
    m = metrics.compute(b.events)
    assert m["switching"]["switches"] == 1
    assert m["switching"]["commands"] == {"start": 3, "susp": 2}


def test_cooker_left_on_through_a_switch_is_unattended_until_resumed() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.hazard(5, "d1", "cooker_on", "on", "stove", budget_s=10.0)
    b.go(8, "d1", "exeTsk", "genSusp", "exeSusp").go(10, "d1", "exeSusp", "wait")
    b.go(25, "d1", "wait", "upTsk", "exeTsk").hazard(30, "d1", "cooker_on", "off", "stove", budget_s=10.0)
    m = metrics.compute(b.end(31, "d1").events)["safety"]
    cooker = m["hazards"]["cooker_on"]
    assert cooker["active_s"] == 25.0 and cooker["unattended_s"] == 15.0
    assert cooker["longest_unattended_s"] == 15.0 and cooker["budget_s"] == 10.0
    assert cooker["overruns"] == 1 and cooker["overrun_s"] == 5.0  # 15 s unattended against a 10 s budget
    assert cooker["at_switch"] == 1 and cooker["active_at_end"] == 0
    assert m["unattended_s"] == 15.0 and m["budget_overruns"] == 1
    assert m["after_end_s"] == 0.0  # unattended while its task waited, not after it ended
    assert m["violations_at_switch"] == 1
    assert m["switches_into_wait"] == [{"t": 10.0, "agent": "d1", "hazards": ["cooker_on(stove)"]}]


def test_a_hazard_turned_off_in_the_instant_of_the_switch_is_not_left_behind() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.hazard(1, "d1", "held", "on", "robot", "vase")
    b.go(3, "d1", "exeTsk", "genSusp", "exeSusp").go(4, "d1", "exeSusp", "wait")
    b.hazard(4, "d1", "held", "off", "robot", "vase")  # the monitor writes edges after the tick's transitions
    assert metrics.compute(b.events)["safety"]["violations_at_switch"] == 0


def test_a_cooker_never_turned_off_counts_until_the_end_of_the_trace() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.hazard(2, "d1", "cooker_on", "on", "stove", budget_s=60.0)
    b.end(4, "d1", cause="failed", reason="stage cook_food failed").add(10, "run", status="horizon reached", active=[])
    m = metrics.compute(b.events)
    assert m["safety"]["hazards"]["cooker_on"] == {
        "episodes": 1, "budget_s": 60.0, "active_s": 8.0, "unattended_s": 6.0, "longest_unattended_s": 6.0,
        "overruns": 0, "overrun_s": 0.0, "after_end_s": 6.0, "at_switch": 0, "active_at_end": 1, "unowned": 0}
    assert m["safety"]["after_end_s"] == 6.0  # every unattended second came after its task had ended
    assert m["totals"]["failed"] == 1 and m["totals"]["by_cause"] == {"failed": 1}
    assert m["totals"]["failure_reasons"] == ["d1: stage cook_food failed"]
    assert m["run"]["horizon_reached"] is True


def test_a_hazard_nobody_owns_is_counted_apart() -> None:
    b = Build().hazard(0, None, "door_open", "on", "door1").request(1, "d1").end(5, "d1")
    s = metrics.compute(b.events)["safety"]
    assert s["unowned_hazards"] == 1 and s["unattended_s"] == 0.0 and s["hazards"]["door_open"]["unowned"] == 1


def test_held_object_open_door_and_follower_at_a_switch() -> None:
    b = Build().request(0, "d1", "carry_object", item="vase").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.hazard(1, "d1", "door_open", "on", "door1").hazard(2, "d1", "object_held", "on", "robot", "vase")
    b.request(2, "d2", "guide_human", person="john").go(2, "d2", "initComm", "compSP")
    b.role(2, "d2", "waiting", "on", "john")
    b.go(3, "d1", "exeTsk", "genSusp", "exeSusp").go(4, "d1", "exeSusp", "wait")
    b.go(4, "d2", "compSP", "upTsk", "exeTsk").role(6, "d2", "waiting", "off", "john")
    b.hazard(7, "d2", "person_following", "on", "john").role(7, "d2", "following", "on", "john")
    b.go(9, "d2", "exeTsk", "genSusp", "exeSusp").go(9, "d2", "exeSusp", "wait")
    m = metrics.compute(b.events)
    s = m["safety"]
    assert s["hazards"]["object_held"]["at_switch"] == 1 and s["hazards"]["door_open"]["at_switch"] == 1
    assert s["hazards"]["person_following"]["at_switch"] == 1
    assert s["violations_at_switch"] == 3  # d1: vase + door; d2: john
    assert s["hazards_active_at_switch"] == 2 + 3  # d2's switch also sees d1's leftovers
    people = m["people"]["people"]["d2"]
    assert people["person"] == "john"
    assert people["waiting_s"] == 4.0  # request at 2 -> greeted at 6
    assert people["following_s"] == 2.0  # asked to follow at 7 -> end of trace at 9


def test_people_waiting_following_and_time_to_help() -> None:
    b = Build().request(0, "d1", "guide_human", person="ann").role(0, "d1", "waiting", "on", "ann")
    b.role(3, "d1", "waiting", "off", "ann").role(4, "d1", "following", "on", "ann")
    b.role(10, "d1", "following", "off", "ann").role(10, "d1", "waiting", "on", "ann")
    b.role(10, "d1", "told_to_wait", "on", "ann")
    b.role(21, "d1", "waiting", "off", "ann").role(21, "d1", "told_to_wait", "off", "ann")
    b.role(21, "d1", "following", "on", "ann").role(30, "d1", "following", "off", "ann")
    b.request(5, "d2", "human_fell", person="bob").role(5, "d2", "needs_help", "on", "bob")
    b.role(5, "d2", "waiting", "on", "bob").role(12, "d2", "waiting", "off", "bob")
    b.role(17, "d2", "helped", "on", "bob")
    m = metrics.compute(b.events)["people"]
    assert m["people"]["d1"]["waiting_s"] == 3.0 + 11.0 and m["people"]["d1"]["told_to_wait_s"] == 11.0
    assert m["people"]["d1"]["following_s"] == 6.0 + 9.0 and m["people_following_s"] == 15.0
    assert m["people"]["d2"]["time_to_help_s"] == 12.0 and m["needing_help"] == 1 and m["not_helped"] == 0
    assert m["time_to_help_s"] == {"mean": 12.0, "max": 12.0}


def test_metrics_name_no_task_action_or_predicate() -> None:
    """The hazard and people collectors read declared names from the trace: a hazard of a
    made-up task is measured like any other."""
    b = Build().request(0, "d1", "juggle").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.hazard(1, "d1", "balls_in_the_air", "on", "ball3", budget_s=2.0).go(2, "d1", "exeTsk", "genSusp", "exeSusp")
    b.go(2, "d1", "exeSusp", "wait").hazard(7, "d1", "balls_in_the_air", "off", "ball3", budget_s=2.0)
    s = metrics.compute(b.events)["safety"]
    assert s["hazards"]["balls_in_the_air"]["unattended_s"] == 5.0 and s["budget_overruns"] == 1


def test_empty_trace() -> None:
    m = metrics.compute([])
    assert m["totals"]["requested"] == 0 and m["switching"]["switches"] == 0
    assert m["totals"]["duration_s"] == {"mean": None, "max": None}
    json.dumps(m, allow_nan=False)


def test_demo_scenario(demo: Trace) -> None:
    m = metrics.compute(demo.events)
    assert m["totals"]["requested"] == 4 and m["totals"]["finished"] == 4
    assert m["switching"]["switches"] == 1 and m["totals"]["suspensions"] == 1
    assert m["decisions"]["decisions"] == len(demo.of("decision"))
    assert m["tasks"]["d1"]["suspensions"] == 1
    # synthetic runs have no world: no hazard or role edges (docs/metrics.md says so)
    assert m["safety"]["hazards"] == {} and m["people"]["people"] == {}


def test_deterministic_and_json_ready(demo: Trace) -> None:
    again = synthetic.run(synthetic.load(DEMO), seed=1)
    a, b = metrics.compute(demo.events), metrics.compute(again.events)
    assert json.dumps(a, sort_keys=True, allow_nan=False) == json.dumps(b, sort_keys=True, allow_nan=False)


def test_compute_file_reads_a_saved_trace(demo: Trace, tmp_path: Path) -> None:
    demo.write(tmp_path / "trace.jsonl")
    assert metrics.compute_file(tmp_path / "trace.jsonl") == metrics.compute(demo.events)


def test_a_live_trace_and_its_saved_file_give_the_same_metrics(demo: Trace, tmp_path: Path) -> None:
    demo.write(tmp_path / "trace.jsonl")
    assert metrics.compute(demo.typed) == metrics.compute(demo.events) == metrics.compute_file(tmp_path / "trace.jsonl")


def test_infinities_become_strings() -> None:
    assert metrics._clean({"a": float("inf"), "b": [float("-inf"), 0.1 + 0.2], "c": -0.0}) == \
        {"a": "inf", "b": ["-inf", 0.3], "c": 0.0}


def test_a_suspension_is_safe_only_with_its_hazards_off_and_every_stage_applicable() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.hazard(5, "d1", "cooker_on", "on", "stove", budget_s=10.0)
    b.go(8, "d1", "exeTsk", "genSusp", "exeSusp").go(10, "d1", "exeSusp", "wait")  # left the cooker on: unsafe
    b.go(25, "d1", "wait", "upTsk", "exeTsk").hazard(30, "d1", "cooker_on", "off", "stove", budget_s=10.0)
    b.go(32, "d1", "exeTsk", "genSusp", "exeSusp")
    b.stage(32, "d1", "place", "begin", fsm="exeSusp")
    b.add(32, "stage", agent="d1", fsm="exeSusp", index=0, action="place", args=[], kind="blocking",
          status="failed", reason="inapplicable: (surface hall) does not hold")
    b.go(32, "d1", "exeSusp", "end")
    b.add(32, "end", agent="d1", task_type="cook", reason="stage place failed", cause="failed")
    b.request(40, "d2").go(40, "d2", "initComm", "compSP", "upTsk", "exeTsk", "genSusp", "exeSusp")
    b.go(43, "d2", "exeSusp", "wait")  # nothing on: safe, 3 s to get there
    s = metrics.compute(b.events)["suspensions"]
    assert [(e["agent"], e["safe"], e["left_on"], e["inapplicable"]) for e in s["episodes"]] == [
        ("d1", False, ["cooker_on(stove)"], []), ("d1", False, [], ["place"]), ("d2", True, [], [])]
    assert (s["count"], s["safe"], s["unsafe"], s["all_safe"], s["inapplicable_stages"]) == (3, 1, 2, False, 1)
    assert s["time_to_safe_s"] == {"mean": 3.0, "max": 3.0}


def test_time_after_the_owner_ended_is_apart_from_time_it_could_attend() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.hazard(2, "d1", "door_open", "on", "door1", budget_s=60.0)
    b.go(4, "d1", "exeTsk", "genSusp", "exeSusp").go(5, "d1", "exeSusp", "wait")
    b.go(9, "d1", "wait", "upTsk", "exeTsk")
    b.end(12, "d1").hazard(20, None, "door_open", "on", "door2", budget_s=60.0).add(30, "mode", mode="IT")
    m = metrics.compute(b.events)["safety"]
    assert m["unattended_s"] == 4.0 + 18.0 and m["after_end_s"] == 18.0 and m["unattended_alive_s"] == 4.0
    assert m["unowned_s"] == 10.0


@pytest.mark.parametrize(("strategy", "note", "counted"), [
    ("static", "fallback to static: the planner timed out", True),
    ("fallback", "fallback: the tree's branch runs as written (branch 'x')", False),
    ("fallback", "fallback: put_down(robot pan counter) cannot run; planned to the derived goal (goal)", False),
    ("fallback", "fallback: the stove is taken; the planner timed out, so the tree's branch runs", True),
    ("planned", "planned to the branch's goal", False),
    ("static", "the tree's branch 'pan held'", False),
])
def test_a_static_fallback_is_a_planned_call_that_ran_the_template(strategy: str, note: str, counted: bool) -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk")
    b.add(0, "plan", agent="d1", purpose="upTsk", strategy=strategy, stages=[], note=note)
    b.go(0, "d1", "upTsk", "exeTsk")
    assert metrics.compute(b.end(1, "d1").events)["tasks"]["d1"]["static_fallbacks"] == int(counted)
