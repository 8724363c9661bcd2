"""The goal-based judge of suspensions (issue 36): safe means the goal held and nothing the agent owns or
the robot carries was on as the suspension ended; a stage already done is no failure; hazard time runs
until the hazard is off or the run ends, whoever ended; hazards carried into another task are named.

Hand-made traces, expected values worked out here."""

from __future__ import annotations

from experiments.metrics import run as metrics
from tests.experiments.test_metrics import Build

GOAL = [["hand_empty", "robot"], ["not", "cooker_on", "cooker"]]


def _suspend(b: Build, t: float, agent: str, *, goal: list[list[str]] | None = GOAL,
             unmet: list[list[str]] | None = None, end: float | None = None, to: str = "wait",
             strategy: str = "static") -> Build:
    """``agent`` in exeTsk at ``t``: genSusp (a plan aiming at ``goal``), exeSusp, then ``to`` at ``end``."""
    b.go(t, agent, "exeTsk", "genSusp")
    b.add(t, "plan", agent=agent, purpose="genSusp", strategy=strategy, stages=[], goal=goal)
    b.go(t, agent, "genSusp", "exeSusp")
    when = t + 2 if end is None else end
    if goal is not None:
        b.add(when, "goal", agent=agent, goal=goal, unmet=unmet or [])
    return b.go(when, agent, "exeSusp", to)


def _started(agent: str = "d1", t: float = 0.0) -> Build:
    return Build().request(t, agent).go(t, agent, "initComm", "compSP", "upTsk", "exeTsk")


def test_a_suspension_is_safe_when_its_goal_held_and_nothing_its_agent_owns_was_on() -> None:
    s = metrics.compute(_suspend(_started(), 5, "d1").events)["suspensions"]
    assert (s["count"], s["safe"], s["all_safe"], s["goal_unmet"]) == (1, 1, True, 0)


def test_a_goal_literal_that_does_not_hold_makes_it_unsafe_even_with_no_hazard_on() -> None:
    b = _suspend(_started(), 5, "d1", unmet=[["hand_empty", "robot"]])
    s = metrics.compute(b.events)["suspensions"]
    (row,) = s["episodes"]
    assert row["safe"] is False and row["goal_unmet"] == ["hand_empty robot"] and s["goal_unmet"] == 1


def test_an_already_done_stage_is_no_failure_and_counted_apart() -> None:
    b = _started()
    b.go(5, "d1", "exeTsk", "genSusp")
    b.add(5, "plan", agent="d1", purpose="genSusp", strategy="static", stages=[], goal=GOAL)
    b.go(5, "d1", "genSusp", "exeSusp")
    b.stage(5, "d1", "turn_off", "begin", fsm="exeSusp")
    b.add(5, "stage", agent="d1", fsm="exeSusp", index=0, action="turn_off", args=[], kind="suspendable",
          status="already_done", reason="already done: (not (cooker_on cooker)) holds in the world now")
    b.add(6, "goal", agent="d1", goal=GOAL, unmet=[]).go(6, "d1", "exeSusp", "wait")
    s = metrics.compute(b.events)["suspensions"]
    assert (s["safe"], s["inapplicable_stages"], s["already_done_stages"]) == (1, 0, 1)


def test_a_genSusp_that_made_no_plan_is_unsafe() -> None:
    b = _started().go(5, "d1", "exeTsk", "genSusp", "end")
    b.add(5, "end", agent="d1", task_type="cook", reason="genSusp unsolvable: no plan", cause="failed")
    s = metrics.compute(b.events)["suspensions"]
    assert (s["count"], s["safe"], s["no_plan"]) == (1, 0, 1)


def test_a_hazard_the_robot_carries_is_unsafe_whoever_owns_it_and_is_measured_in_the_task_it_goes_into() -> None:
    b = _started()
    b.add(3, "hazard", agent="d1", hazard="hot_pan_held", args=["robot", "pan"], fact=["holding", "robot", "pan"],
          status="on", carried=True)
    # d1's tree cannot put the pan down: its stage fails, the task ends, the goal unmet
    _suspend(b, 5, "d1", unmet=[["hand_empty", "robot"]], end=5, to="end")
    b.add(5, "end", agent="d1", task_type="cook", reason="stage put_down failed", cause="failed")
    b.request(5, "d2", "human_fell").go(5, "d2", "initComm", "compSP", "upTsk", "exeTsk")
    b.end(35, "d2")  # 30 s helping with the hot pan in hand
    b.add(40, "mode", mode="IT")  # the run goes on 5 s more: the pan is still held
    m = metrics.compute(b.events)
    (row,) = m["suspensions"]["episodes"]
    assert row["safe"] is False and row["left_on"] == ["hot_pan_held(robot, pan)"]
    (c,) = m["carried"]["episodes"]
    assert (c["agent"], c["owner"], c["task_type"], c["seconds"]) == ("d2", "d1", "human_fell", 30.0)
    assert c["name"] == "human_fell (d2) with hot_pan_held(robot, pan)"
    assert m["carried"]["seconds"] == 30.0 and m["carried"]["count"] == 1
    # hazard time runs until the run ends, although its owner ended at 5: 2 s before the suspension
    # began (d1 in cmd: attended) do not count, 5 -> 40 does
    assert m["safety"]["unattended_s"] == 35.0 and m["safety"]["after_end_s"] == 35.0
    assert m["safety"]["unattended_alive_s"] == 0.0  # 0.3's primary outcome saw none of it


def test_a_hazard_of_another_agent_left_on_does_not_make_this_suspension_unsafe_unless_carried() -> None:
    b = _started().request(0, "d2")
    b.add(1, "hazard", agent="d2", hazard="cooker_on", args=["cooker"], fact=["cooker_on", "cooker"], status="on")
    s = metrics.compute(_suspend(b, 5, "d1").events)["suspensions"]
    assert s["safe"] == 1
    carried = _started().request(0, "d2")  # the same, but the robot holds d2's hot thing as d1 suspends
    carried.add(1, "hazard", agent="d2", hazard="hot_pan_held", args=["robot", "pan"], fact=["holding", "robot", "pan"],
                status="on", carried=True)
    s = metrics.compute(_suspend(carried, 5, "d1").events)["suspensions"]
    assert s["safe"] == 0 and s["episodes"][0]["left_on"] == ["hot_pan_held(robot, pan)"]


def test_fallback_replanning_keeps_one_episode_with_both_plans() -> None:
    b = _started()
    b.go(5, "d1", "exeTsk", "genSusp")
    b.add(5, "plan", agent="d1", purpose="genSusp", strategy="fallback", stages=[], goal=GOAL,
          info={"fallback": "tree"})
    b.go(5, "d1", "genSusp", "exeSusp")
    b.add(6, "transition", agent="d1", trigger="stage_failed", **{"from": "exeSusp", "to": "genSusp"})
    b.add(6, "plan", agent="d1", purpose="genSusp", strategy="fallback", stages=[], goal=GOAL,
          info={"fallback": "planned"})
    b.go(6, "d1", "genSusp", "exeSusp")
    b.add(9, "goal", agent="d1", goal=GOAL, unmet=[]).go(9, "d1", "exeSusp", "wait")
    s = metrics.compute(b.events)["suspensions"]
    (row,) = s["episodes"]
    assert (row["start"], row["end"], row["replanned"], row["fallback"], row["safe"]) == (5, 9, 1, "planned", True)
    assert s["fallback_planned"] == 1
