"""What the agent traces for the goal-based judge (issue 36): stages already done, a suspension's goal
checked as it ends, and the fallback strategy planning around a stage of exeSusp that cannot run."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from tasker.stage import Purpose, Stage, StagePlan
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.task import Strategy, TaskContext
from tasker.trace import INAPPLICABLE
from tasker.world import WorldState
from tests.tasker.helpers import make_loop, st


class FactWorld:
    """A world of symbolic facts only: stages add and delete theirs when they succeed (the core below)."""

    rate_hz = 10.0

    def __init__(self, facts: set[tuple[str, ...]]) -> None:
        self.facts = set(facts)

    def advance(self, now: float) -> None:
        pass

    def snapshot(self) -> WorldState:
        return WorldState(frozenset(self.facts))


class ApplyingCore(TimedExecutor):
    def __init__(self, world: FactWorld) -> None:
        super().__init__()
        self.world = world
        self.begun: list[str] = []

    def begin(self, agent: str, stage: Stage, now: float) -> None:
        self.begun.append(stage.action)
        super().begin(agent, stage, now)

    def poll(self, agent: str, stage: Stage, now: float) -> Any:
        status = super().poll(agent, stage, now)
        if status.state.value == "succeeded":
            self.world.facts -= {tuple(f) for f in stage.data.get("delete", ())}
            self.world.facts |= {tuple(f) for f in stage.data.get("add", ())}
        return status


class Facts(SyntheticTask):
    """A synthetic task whose stages have preconditions (``data["pre"]``) and effects, and whose
    genSusp aims for a goal; ``recover`` is the plan genSusp gives when asked again (fallback)."""

    def __init__(self, *a: Any, goal: tuple[tuple[str, ...], ...] = (), recover: tuple[Stage, ...] | None = None,
                 **kw: Any) -> None:
        super().__init__(*a, **kw)
        self.goal = goal
        self.recover = recover
        self.recovering: list[str | None] = []

    def inapplicable(self, ctx: TaskContext, stage: Stage) -> str | None:
        facts = ctx.world.facts
        unmet = [p for p in stage.data.get("pre", ()) if tuple(p) not in facts]
        return f"{INAPPLICABLE} {stage.action} needs {unmet}" if unmet else None

    def already_done(self, ctx: TaskContext, stage: Stage) -> str | None:
        facts = ctx.world.facts
        add = [tuple(f) for f in stage.data.get("add", ())]
        delete = [tuple(f) for f in stage.data.get("delete", ())]
        if (add or delete) and all(f in facts for f in add) and not any(f in facts for f in delete):
            return "already done: its effects hold"
        return None

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:
        self.recovering.append(ctx.recovering)
        plan = super().generate_suspension(ctx)
        if ctx.recovering is not None and self.recover is not None:
            plan = StagePlan(self.recover, Purpose.GEN_SUSP, strategy="fallback", note="planned around it")
        return replace(plan, goal=self.goal)


def _run(task: Facts, facts: set[tuple[str, ...]], *, interrupt_at: float | None = None,
         strategy: Strategy | None = None) -> tuple[list[dict[str, Any]], ApplyingCore, FactWorld]:
    world = FactWorld(facts)
    core = ApplyingCore(world)
    fall = SyntheticTask("fall", [st("help", 2.0)])
    loop = make_loop([task, fall], core=core, classes=[["fall"], [task.name]])
    loop.world = world
    if strategy is not None:
        loop.strategy = strategy
    loop.request(0.0, task.name)
    if interrupt_at is not None:
        loop.request(interrupt_at, "fall")
    return loop.run().events, core, world


OFF = ("cooker_on", "cooker")


def test_a_stage_whose_effects_hold_already_is_skipped_as_already_done_and_the_task_goes_on() -> None:
    task = Facts("cook", [st("stir", 2.0), st("turn_off", 1.0, pre=[OFF], delete=[OFF]), st("serve", 1.0)])
    events, core, _ = _run(task, set())  # someone else switched the cooker off
    off = [e for e in events if e["event"] == "stage" and e["action"] == "turn_off"]
    assert [e["status"] for e in off] == ["begin", "already_done"] and "already done" in off[1]["reason"]
    assert "turn_off" not in core.begun and "serve" in core.begun
    assert next(e for e in events if e["event"] == "end")["cause"] == "finished"


def test_a_stage_that_cannot_run_and_whose_effects_do_not_hold_still_fails() -> None:
    task = Facts("cook", [st("stir", 2.0), st("put", 1.0, pre=[("holding", "pan")], add=[("on", "pan")])])
    events, core, _ = _run(task, set())
    put = [e for e in events if e["event"] == "stage" and e["action"] == "put"]
    assert [e["status"] for e in put] == ["begin", "failed"] and "put" not in core.begun


def test_the_goal_of_a_suspension_is_checked_as_it_ends_and_its_unmet_literals_named() -> None:
    goal = (("not", *OFF), ("hand_empty", "robot"))
    task = Facts("cook", [st("stir", 20.0)], goal=goal, suspension={"stir": [st("turn_off", 1.0, delete=[OFF])]})
    events, _, _ = _run(task, {OFF}, interrupt_at=3.0)
    checked = [e for e in events if e["event"] == "goal"]
    assert len(checked) == 1 and checked[0]["agent"] == "d1"
    assert checked[0]["goal"] == [["not", *OFF], ["hand_empty", "robot"]]
    assert checked[0]["unmet"] == [["hand_empty", "robot"]]  # the cooker is off; the hand was never emptied
    k = events.index(checked[0])
    assert events[k + 1]["event"] == "transition" and events[k + 1]["from"] == "exeSusp"
    plan = next(e for e in events if e["event"] == "plan" and e["purpose"] == "genSusp")
    assert plan["goal"] == checked[0]["goal"]


def test_fallback_plans_around_a_stage_of_exesusp_that_cannot_run_once_then_waits() -> None:
    close = st("close_door", 1.0, pre=[("door_open", "d")], delete=[("door_open", "d")])
    task = Facts("carry", [st("walk", 20.0)], suspension={"walk": [st("put", 1.0, pre=[("clear", "counter")])]},
                 recover=(close,))
    events, core, _ = _run(task, {("door_open", "d")}, interrupt_at=3.0, strategy=Strategy(suspension="fallback"))
    back = [e for e in events if e["event"] == "transition" and e["agent"] == "d1" and e["from"] == "exeSusp"]
    assert [(e["trigger"], e["to"]) for e in back] == [("stage_failed", "genSusp"), ("finished", "wait")]
    assert task.recovering[-1] is not None and "put" in task.recovering[-1] and INAPPLICABLE in task.recovering[-1]
    assert "close_door" in core.begun
    plans = [e for e in events if e["event"] == "plan" and e["purpose"] == "genSusp"]
    assert [p["strategy"] for p in plans] == ["static", "fallback"]
    assert next(e for e in events if e["event"] == "end" and e["agent"] == "d1")["cause"] == "finished"


def test_fallback_plans_around_only_once_a_suspension_and_other_strategies_never() -> None:
    never = st("put", 1.0, pre=[("clear", "counter")])
    task = Facts("carry", [st("walk", 20.0)], suspension={"walk": [never]}, recover=(never,))
    events, _, _ = _run(task, set(), interrupt_at=3.0, strategy=Strategy(suspension="fallback"))
    back = [(e["trigger"], e["to"]) for e in events if e["event"] == "transition" and e["agent"] == "d1"
            and e["from"] == "exeSusp"]
    assert back == [("stage_failed", "genSusp"), ("stage_failed", "end")]
    task2 = Facts("carry", [st("walk", 20.0)], suspension={"walk": [never]}, recover=(never,))
    events, _, _ = _run(task2, set(), interrupt_at=3.0, strategy=Strategy(suspension="planned"))
    back = [(e["trigger"], e["to"]) for e in events if e["event"] == "transition" and e["agent"] == "d1"
            and e["from"] == "exeSusp"]
    assert back == [("stage_failed", "end")] and task2.recovering == [None]
