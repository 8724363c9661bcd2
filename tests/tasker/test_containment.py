"""A run never dies of one task: exceptions in hooks, skills, planners and schedulers are contained.

Acceptance test of the core brief: a skill, a task hook and the planning hook raise
mid-run; only those tasks end (cause ``error``, the exception in the reason), the
others finish, and the trace is complete (every begun stage closed, every agent
ended, one ``end`` each).
"""

from __future__ import annotations

from collections import Counter
from typing import Any

import pytest

from tasker import schedulers
from tasker.errors import RunAborted
from tasker.messages import SPRequest
from tasker.protocols import SkillStatus, failed
from tasker.schedulers.base import Decision, Scheduler, ScheduleView
from tasker.stage import Stage, StagePlan
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.task import TaskContext

from .helpers import BLOCK, make_loop, st


class FaultyCore(TimedExecutor):
    """A core agent whose skills raise when a stage's data says so; counts ``stop`` calls per stage."""

    def __init__(self) -> None:
        super().__init__()
        self.stops: Counter[tuple[str, str]] = Counter()

    def begin(self, agent: str, stage: Stage, now: float) -> None:
        super().begin(agent, stage, now)
        if stage.data.get("raise_in") == "begin":
            raise RuntimeError("gripper driver not responding")

    def poll(self, agent: str, stage: Stage, now: float) -> SkillStatus:
        if stage.data.get("raise_in") == "poll" and now >= 1.0 + self._running[agent][1] - stage.duration:
            raise RuntimeError("motor controller fault")
        return super().poll(agent, stage, now)

    def stop(self, agent: str, stage: Stage, now: float) -> None:
        self.stops[(agent, stage.action)] += 1
        super().stop(agent, stage, now)
        if stage.data.get("raise_in_stop"):
            raise OSError("stop service unavailable")


class HookRaises(SyntheticTask):
    def on_stage_done(self, ctx: TaskContext, stage: Stage) -> None:
        if stage.action == "second":
            raise KeyError("memory['person'] was never set")


class PlannerRaises(SyntheticTask):
    def update_task(self, ctx: TaskContext) -> StagePlan:
        raise ValueError("PDDL problem: unknown object 'kitchen2'")


class ReqSPRaises(SyntheticTask):
    def request_sp(self, ctx: TaskContext, request: SPRequest) -> Any:
        raise ZeroDivisionError("division by zero in the cost model")


def closed_stages(events: list[dict[str, Any]]) -> None:
    """Every ``begin`` of a stage is followed by exactly one closing event of that stage."""
    open_: dict[str, dict[str, Any]] = {}
    for e in events:
        if e["event"] != "stage":
            continue
        if e["status"] == "begin":
            assert e["agent"] not in open_, f"{e['agent']} began a stage while one was open"
            open_[e["agent"]] = e
        else:
            assert e["status"] in ("done", "stopped", "failed")
            began = open_.pop(e["agent"])
            assert (began["action"], began["index"], began["fsm"]) == (e["action"], e["index"], e["fsm"])
    assert not open_, f"stages never closed: {open_}"


def test_a_skill_a_hook_and_the_planner_raise_and_only_their_tasks_end() -> None:
    tasks = [
        SyntheticTask("skill", [st("first", 2), st("drive", 3, raise_in="poll"), st("third", 2)]),
        HookRaises("hook", [st("first", 1), st("second", 1, BLOCK), st("third", 1)]),
        PlannerRaises("plan", [st("x", 1)]),
        SyntheticTask("grip", [st("grasp", 2, BLOCK, raise_in="begin")]),
        SyntheticTask("fine", [st("a", 2), st("b", 2, BLOCK)]),
    ]
    core = FaultyCore()
    loop = make_loop(tasks, scheduler="fifo", core=core)
    for i, name in enumerate(["skill", "fine", "hook", "plan", "grip", "fine"]):
        loop.request(0.1 * i, name)
    tr = loop.run()  # returns: nothing escaped

    ends = {e["agent"]: e for e in tr.of("end")}
    assert sorted(ends) == ["d1", "d2", "d3", "d4", "d5", "d6"]
    assert Counter(e["agent"] for e in tr.of("end")) == Counter({f"d{i}": 1 for i in range(1, 7)})
    assert {a: e["cause"] for a, e in ends.items()} == {
        "d1": "error", "d2": "finished", "d3": "error", "d4": "error", "d5": "error", "d6": "finished"}
    assert ends["d1"]["reason"] == "poll() raised RuntimeError: motor controller fault (in exeTsk)"
    assert ends["d3"]["reason"] == "on_stage_done() raised KeyError: \"memory['person'] was never set\" (in exeTsk)"
    assert ends["d4"]["reason"] == "update_task() raised ValueError: PDDL problem: unknown object 'kitchen2' (in upTsk)"
    assert "begin() raised RuntimeError: gripper driver not responding" in ends["d5"]["reason"]
    # the skill that raised was stopped (once) and its stage closed as failed
    assert core.stops[("d1", "drive")] == 1
    failed = tr.of("stage", agent="d1", status="failed")
    assert [e["action"] for e in failed] == ["drive"] and "motor controller fault" in failed[0]["reason"]
    closed_stages(tr.events)
    # the transitions the agents made are all in the one FSM table, with their trigger
    from tasker import fsm

    table = {(t.source.value, t.event, t.target.value) for t in fsm.TRANSITIONS}
    assert all((e["from"], e["trigger"], e["to"]) in table for e in tr.of("transition"))
    assert ("exeTsk", "error", "end") in {(e["from"], e["trigger"], e["to"]) for e in tr.of("transition", agent="d1")}


def test_a_core_stop_that_raises_during_cleanup_is_contained() -> None:
    tasks = [SyntheticTask("bad", [st("drive", 3, raise_in="poll", raise_in_stop=True)]),
             SyntheticTask("ok", [st("a", 1)])]
    core = FaultyCore()
    loop = make_loop(tasks, scheduler="fifo", core=core)
    loop.request(0.0, "bad")
    loop.request(0.0, "ok")
    tr = loop.run()
    bad = tr.of("end", agent="d1")[0]
    assert bad["cause"] == "error" and "motor controller fault" in bad["reason"]
    assert core.stops[("d1", "drive")] == 1
    closing = tr.of("stage", agent="d1", status="failed")[0]
    assert "stop() raised OSError: stop service unavailable" in closing["reason"]
    assert tr.of("end", agent="d2")[0]["cause"] == "finished"


def test_a_request_sp_that_raises_ends_that_agent_and_the_schedule_goes_on() -> None:
    tasks = [SyntheticTask("t", [st("a", 5)]), ReqSPRaises("t_bad", [st("a", 1)], weight=50.0)]
    loop = make_loop(tasks, classes=[["t", "t_bad"]])
    loop.request(0.0, "t")
    loop.request(1.0, "t_bad")  # alg2 compares it with d1 through reqSP: it raises
    tr = loop.run()
    bad = tr.of("end", agent="d2")[0]
    assert bad["cause"] == "error" and "request_sp() raised ZeroDivisionError" in bad["reason"]
    assert tr.of("end", agent="d1")[0]["cause"] == "finished"
    assert not tr.of("command", agent="d2")  # never a candidate again


class Exploding(Scheduler):
    name = "exploding"

    def __init__(self) -> None:
        self.calls = 0

    def schedule(self, view: ScheduleView) -> Decision:
        self.calls += 1
        if self.calls == 1:
            raise RuntimeError("bug in the scheduler")
        return Decision(min(view.candidates, key=lambda c: c.order).id) if view.exe is None else Decision()


def test_a_scheduler_that_raises_is_recorded_and_changes_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(schedulers._registry, "exploding", Exploding)  # gone after the test: others read names()
    loop = make_loop([SyntheticTask("t", [st("a", 1)])], scheduler="exploding")
    loop.request(0.0, "t")
    tr = loop.run()
    err = tr.of("decision", rule="error")
    assert len(err) == 1 and err[0]["error"] == "RuntimeError: bug in the scheduler" and err[0]["switch"] is False
    assert tr.of("end", agent="d1")[0]["cause"] == "finished"  # scheduled at the next step


class BrokenWorld:
    rate_hz = 10.0

    def __init__(self, fail_at: float) -> None:
        self.fail_at = fail_at

    def advance(self, now: float) -> None:
        if now >= self.fail_at:
            raise RuntimeError("physics diverged")

    def snapshot(self) -> Any:
        return None


def test_a_world_that_raises_aborts_the_run_and_keeps_the_trace() -> None:
    from tasker.loop import SimulationLoop
    from tasker.store import TaskStore

    core = FaultyCore()
    loop = SimulationLoop(TaskStore([SyntheticTask("t", [st("a", 5), st("b", 5)])]), schedulers.create("fifo"),
                          core=core, world=BrokenWorld(fail_at=3.0))
    loop.request(0.0, "t")
    loop.request(0.0, "t")
    with pytest.raises(RunAborted, match="World.advance raised RuntimeError: physics diverged") as info:
        loop.run()
    assert isinstance(info.value.__cause__, Exception)
    tr = loop.trace
    last = tr.events[-1]
    assert last["event"] == "run" and last["status"] == "aborted" and last["active"] == ["d1", "d2"]
    assert last["t"] == pytest.approx(3.0, abs=0.11)
    assert {e["agent"]: e["cause"] for e in tr.of("end")} == {"d1": "error", "d2": "error"}
    closed_stages(tr.events)
    assert core.stops[("d1", "a")] == 1  # the running skill was stopped
    with pytest.raises(RunAborted):
        loop.run()  # an aborted run stays aborted


def test_ic_term_during_a_blocking_stage_finishes_it_then_suspends_safely() -> None:
    """Eqs. 25-26 for the task's own ic_term: the blocking stage completes, genSusp runs, then end (self)."""
    t = SyntheticTask("carry", [st("walk", 2), st("pick", 4, BLOCK), st("walk_on", 10)],
                      suspension={"walk_on": [st("put_down", 2, BLOCK)]})
    core = FaultyCore()
    loop = make_loop([t], core=core)
    loop.request(0.0, "carry", {"cancel_at": 3.0})  # during the blocking "pick" (2..6)
    tr = loop.run()
    steps = [(e["from"], e["to"]) for e in tr.of("transition", agent="d1")]
    assert steps[-3:] == [("exeTsk", "genSusp"), ("genSusp", "exeSusp"), ("exeSusp", "end")]
    assert [(e["action"], e["status"]) for e in tr.of("stage", agent="d1")] == [
        ("walk", "begin"), ("walk", "done"), ("pick", "begin"), ("pick", "done"),
        ("put_down", "begin"), ("put_down", "done")]
    gen = tr.of("transition", agent="d1", to="genSusp")[0]
    assert gen["t"] == pytest.approx(6.0, abs=0.11)  # after "pick", not at 3.0
    end = tr.of("end", agent="d1")[0]
    assert end["cause"] == "self" and end["reason"] == "no longer needed"
    assert sum(core.stops.values()) == 0  # nothing was stopped: the stages completed


def test_ic_term_during_a_suspendable_stage_stops_it_once_then_suspends() -> None:
    t = SyntheticTask("carry", [st("walk", 10)], suspension={"walk": [st("park", 1)]})
    core = FaultyCore()
    loop = make_loop([t], core=core)
    loop.request(0.0, "carry", {"cancel_at": 3.0})
    tr = loop.run()
    assert [(e["action"], e["status"]) for e in tr.of("stage", agent="d1")] == [
        ("walk", "begin"), ("walk", "stopped"), ("park", "begin"), ("park", "done")]
    assert core.stops == Counter({("d1", "walk"): 1})
    assert tr.of("end", agent="d1")[0]["cause"] == "self"


def test_a_run_with_contained_errors_is_reproducible() -> None:
    def run() -> str:
        tasks = [SyntheticTask("skill", [st("drive", 3, raise_in="poll")]), HookRaises("hook", [st("second", 1)]),
                 SyntheticTask("fine", [st("a", 2)])]
        loop = make_loop(tasks, scheduler="alg2", core=FaultyCore())
        for i, name in enumerate(["skill", "hook", "fine"]):
            loop.request(0.5 * i, name)
        return loop.run().dumps()

    assert run() == run()


class FailingCore(TimedExecutor):
    """A core agent whose skill reports failure (no exception) a second into a stage marked ``fail``."""

    def poll(self, agent: str, stage: Stage, now: float) -> SkillStatus:
        if stage.data.get("fail") and now >= 1.0 + self._running[agent][1] - stage.duration:
            del self._running[agent]  # a skill that reports failure has ended
            return failed("path to 'office' blocked")
        return super().poll(agent, stage, now)


@pytest.mark.parametrize("safe_stage_fails", [False, True])
def test_a_failed_stage_ends_its_task_after_a_safe_suspension(safe_stage_fails: bool) -> None:
    """A skill failure in exeTsk does not leave the task's state as it stands (an object held):
    the task suspends safely (genSusp, exeSusp) and then ends, cause ``failed``, with the
    stage's reason first; the other task goes on."""
    put_down = st("put_down", 2, BLOCK, fail=safe_stage_fails)
    tasks = [SyntheticTask("carry", [st("pick", 1, BLOCK), st("drive", 4, fail=True), st("place", 1, BLOCK)],
                           suspension={"drive": [put_down]}),
             SyntheticTask("other", [st("a", 1)])]
    loop = make_loop(tasks, scheduler="fifo", core=FailingCore())
    loop.request(0.0, "carry")
    loop.request(0.0, "other")
    tr = loop.run()
    path = [(e["from"], e["trigger"], e["to"]) for e in tr.of("transition", agent="d1")]
    assert ("exeTsk", "stage_failed", "genSusp") in path and ("genSusp", "planned", "exeSusp") in path
    end = tr.of("end", agent="d1")[0]
    assert end["cause"] == "failed" and end["reason"].startswith("stage drive failed: path to 'office' blocked")
    ran = [(e["fsm"], e["action"], e["status"]) for e in tr.of("stage", agent="d1") if e["status"] != "begin"]
    if safe_stage_fails:  # nothing safer to fall back on: the task ends, both failures in its reason
        assert ran[-1] == ("exeSusp", "put_down", "failed") and path[-1] == ("exeSusp", "stage_failed", "end")
        assert end["reason"].count("path to 'office' blocked") == 2 and "; then stage put_down" in end["reason"]
    else:
        assert ran[-1] == ("exeSusp", "put_down", "done") and path[-1] == ("exeSusp", "finished", "end")
    assert tr.of("end", agent="d2")[0]["cause"] == "finished"
    closed_stages(tr.events)
    from tasker import fsm

    table = {(t.source.value, t.event, t.target.value) for t in fsm.TRANSITIONS}
    assert all((e["from"], e["trigger"], e["to"]) in table for e in tr.of("transition"))


def test_a_term_during_a_failed_tasks_safe_suspension_keeps_the_failure() -> None:
    """A requester's term that arrives while a failed task is being made safe does not turn the
    failure into a cancellation: the task still ends ``failed``, with its stage's reason."""
    tasks = [SyntheticTask("carry", [st("drive", 4, fail=True)], suspension={"drive": [st("put_down", 5, BLOCK)]})]
    loop = make_loop(tasks, scheduler="fifo", core=FailingCore())
    loop.request(0.0, "carry")
    loop.terminate(3.0, "d1", "cancelled")  # drive fails at about 1 s; put_down runs until about 6 s
    end = loop.run().of("end", agent="d1")[0]
    assert end["cause"] == "failed" and end["reason"].startswith("stage drive failed")


def test_a_failed_task_whose_safe_suspension_cannot_be_planned_ends_with_both_reasons() -> None:
    from tasker.errors import PlanningFailed

    def no_way(ctx: TaskContext) -> list[Stage]:
        raise PlanningFailed("unsolvable", "no place to put it down")

    tasks = [SyntheticTask("carry", [st("drive", 4, fail=True)], suspension=no_way)]
    loop = make_loop(tasks, scheduler="fifo", core=FailingCore())
    loop.request(0.0, "carry")
    end = loop.run().of("end", agent="d1")[0]
    assert end["cause"] == "failed"
    assert end["reason"] == ("stage drive failed: path to 'office' blocked; "
                             "then genSusp unsolvable: no place to put it down")
