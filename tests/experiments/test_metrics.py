"""Metrics are computed from the trace alone: hand-built traces with values worked out
by hand, and the synthetic demo scenario end to end."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from experiments import metrics, synthetic
from tasker.trace import Trace

DEMO = Path(__file__).resolve().parents[2] / "experiments" / "scenarios" / "synthetic_demo.toml"


@pytest.fixture(scope="module")
def demo() -> Trace:
    return synthetic.run(synthetic.load(DEMO), seed=1)


class Build:
    """A tiny trace builder: one method per event kind, times given explicitly."""

    def __init__(self) -> None:
        self.events: list[dict[str, Any]] = []

    def add(self, t: float, event: str, **fields: Any) -> Build:
        self.events.append({"t": t, "event": event, **fields})
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


def test_a_susp_followed_by_a_start_of_the_same_agent_is_no_switch() -> None:
    b = Build().request(0, "d1").cmd(0, "d1", "start").cmd(5, "d1", "susp").cmd(6, "d1", "start")
    b.cmd(7, "d1", "susp").cmd(8, "d2", "start")
    m = metrics.compute(b.events)
    assert m["switching"]["switches"] == 1
    assert m["switching"]["commands"] == {"start": 3, "susp": 2}


def test_cooker_left_on_through_a_switch_is_unattended_until_resumed() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.stage(5, "d1", "turn_on", "done", "robot", "stove", "kitchen")
    b.go(8, "d1", "exeTsk", "genSusp", "exeSusp").go(10, "d1", "exeSusp", "wait")
    b.go(25, "d1", "wait", "upTsk", "exeTsk").stage(30, "d1", "turn_off", "done", "robot", "stove", "kitchen")
    m = metrics.compute(b.end(31, "d1").events)["safety"]
    cooker = m["hazards"]["cooker_on"]
    assert cooker["active_s"] == 25.0 and cooker["unattended_s"] == 15.0
    assert cooker["at_switch"] == 1 and cooker["active_at_end"] == 0
    assert m["cooker_unattended_s"] == 15.0
    assert m["violations_at_switch"] == 1
    assert m["switches_into_wait"] == [{"t": 10.0, "agent": "d1", "hazards": ["cooker_on(stove)"]}]


def test_a_cooker_never_turned_off_counts_until_the_end_of_the_trace() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.stage(2, "d1", "turn_on", "done", "robot", "stove", "kitchen")
    b.end(4, "d1", cause="failed", reason="stage cook_food failed").add(10, "run", status="horizon reached", active=[])
    m = metrics.compute(b.events)
    assert m["safety"]["hazards"]["cooker_on"] == {"episodes": 1, "active_s": 8.0, "unattended_s": 6.0,
                                                   "at_switch": 0, "active_at_end": 1}
    assert m["totals"]["failed"] == 1 and m["totals"]["by_cause"] == {"failed": 1}
    assert m["totals"]["failure_reasons"] == ["d1: stage cook_food failed"]
    assert m["run"]["horizon_reached"] is True


def test_held_object_open_door_and_follower_at_a_switch() -> None:
    b = Build().request(0, "d1", "carry_object", item="vase").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.stage(1, "d1", "open_door", "done", "robot", "door1", "hall")
    b.stage(2, "d1", "pick", "done", "robot", "vase", "kitchen")
    b.request(2, "d2", "guide_human", person="john").go(2, "d2", "initComm", "compSP")
    b.go(3, "d1", "exeTsk", "genSusp", "exeSusp").go(4, "d1", "exeSusp", "wait")
    b.go(4, "d2", "compSP", "upTsk", "exeTsk").stage(6, "d2", "greet", "done", "robot", "john", "hall")
    b.stage(7, "d2", "ask_to_follow", "done", "robot", "john", "hall")
    b.go(9, "d2", "exeTsk", "genSusp", "exeSusp").go(9, "d2", "exeSusp", "wait")
    m = metrics.compute(b.events)
    s = m["safety"]
    assert s["objects_held_at_switch"] == 1 and s["doors_open_at_switch"] == 1
    assert s["people_following_at_switch"] == 1
    assert s["violations_at_switch"] == 3  # d1: vase + door; d2: john
    assert s["hazards_active_at_switch"] == 2 + 3  # d2's switch also sees d1's leftovers
    people = m["people"]["people"]["d2"]
    assert people["person"] == "john"
    assert people["waiting_s"] == 4.0  # request at 2 -> greeted at 6
    assert people["following_s"] == 2.0  # asked to follow at 7 -> end of trace at 9


def test_people_wait_again_after_ask_to_wait_until_greeted_again() -> None:
    b = Build().request(0, "d1", "guide_human", person="ann").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.stage(3, "d1", "greet", "done", "r", "ann", "hall").stage(4, "d1", "ask_to_follow", "done", "r", "ann", "hall")
    b.stage(10, "d1", "ask_to_wait", "done", "r", "ann", "hall", fsm="exeSusp")
    b.stage(20, "d1", "greet_and_apologise", "done", "r", "ann", "hall")
    b.stage(21, "d1", "ask_to_follow", "done", "r", "ann", "hall")
    b.stage(30, "d1", "say_goodbye", "done", "r", "ann", "k")
    m = metrics.compute(b.end(30, "d1").events)
    assert m["people"]["people"]["d1"]["waiting_s"] == 3.0 + 10.0
    assert m["people"]["people"]["d1"]["following_s"] == 6.0 + 9.0
    assert m["people"]["people_following_s"] == 15.0
    assert m["safety"]["hazards"]["person_following"]["episodes"] == 2


def test_hazards_of_failed_stages_do_not_change() -> None:
    b = Build().request(0, "d1").stage(1, "d1", "turn_on", "failed", "r", "stove", "k")
    assert metrics.compute(b.events)["safety"]["hazards"]["cooker_on"]["episodes"] == 0


def test_every_hazard_rule_names_a_known_hazard_and_a_stage_status() -> None:
    for rule in metrics.HAZARDS:
        assert rule.hazard in metrics.HAZARD_KINDS
        assert rule.status in ("begin", "done")
    assert len({(r.action, r.status) for r in metrics.HAZARDS}) == len(metrics.HAZARDS)


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
    # the guide's suspension asked the person to wait: nobody follows through the switch
    assert m["safety"]["people_following_at_switch"] == 0
    assert m["people"]["people"]["d1"]["following_s"] > 0


def test_deterministic_and_json_ready(demo: Trace) -> None:
    again = synthetic.run(synthetic.load(DEMO), seed=1)
    a, b = metrics.compute(demo.events), metrics.compute(again.events)
    assert json.dumps(a, sort_keys=True, allow_nan=False) == json.dumps(b, sort_keys=True, allow_nan=False)


def test_compute_file_reads_a_saved_trace(demo: Trace, tmp_path: Path) -> None:
    demo.write(tmp_path / "trace.jsonl")
    assert metrics.compute_file(tmp_path / "trace.jsonl") == metrics.compute(demo.events)


def test_collectors_observe_a_live_trace(demo: Trace) -> None:
    live = metrics.HazardCollector()
    trace = Trace()
    trace.subscribe(live.on_event)
    synthetic.run(synthetic.load(DEMO), seed=1, trace=trace)
    assert metrics._clean(live.result()) == metrics.compute(demo.events)["safety"]


def test_infinities_become_strings() -> None:
    assert metrics._clean({"a": float("inf"), "b": [float("-inf"), 0.1 + 0.2], "c": -0.0}) == \
        {"a": "inf", "b": ["-inf", 0.3], "c": 0.0}
