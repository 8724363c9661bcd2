"""A stage that cannot run in the world as it is fails without running, as on a robot (issue 26)."""

from __future__ import annotations

from typing import Any

from tasker.stage import Stage
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.task import TaskContext
from tasker.trace import INAPPLICABLE
from tests.tasker.helpers import make_loop, st


class Refusing(SyntheticTask):
    """A synthetic task whose stages named in ``refuse`` can never run."""

    def __init__(self, *args: Any, refuse: frozenset[str], **kw: Any) -> None:
        super().__init__(*args, **kw)
        self.refuse = refuse

    def inapplicable(self, ctx: TaskContext, stage: Stage) -> str | None:
        return f"{INAPPLICABLE} {stage.action} needs (ready)" if stage.action in self.refuse else None


class CountingCore(TimedExecutor):
    def __init__(self) -> None:
        super().__init__()
        self.begun: list[str] = []

    def begin(self, agent: str, stage: Stage, now: float) -> None:
        self.begun.append(stage.action)
        super().begin(agent, stage, now)


def _run(task: SyntheticTask, *also: SyntheticTask, interrupt_at: float | None = None) -> tuple[list[dict[str, Any]],
                                                                                               CountingCore]:
    core = CountingCore()
    loop = make_loop([task, *also], core=core, classes=[[t.name for t in also], [task.name]])
    loop.request(0.0, task.name)
    if interrupt_at is not None:
        loop.request(interrupt_at, also[0].name)
    return loop.run().events, core


def test_an_inapplicable_stage_of_exetsk_fails_unrun_and_the_task_is_made_safe_then_ends() -> None:
    task = Refusing("carry", [st("pick", 2.0), st("place", 2.0)], refuse=frozenset({"place"}),
                    suspension={"place": [st("close", 1.0)]})
    events, core = _run(task)
    place = [e for e in events if e["event"] == "stage" and e["action"] == "place"]
    assert [e["status"] for e in place] == ["begin", "failed"] and place[1]["reason"].startswith(INAPPLICABLE)
    assert place[0]["t"] == place[1]["t"] and "place" not in core.begun  # never given to the robot
    assert any(e["event"] == "transition" and e["trigger"] == "stage_failed" and e["to"] == "genSusp" for e in events)
    assert "close" in core.begun  # made safe first
    end = next(e for e in events if e["event"] == "end")
    assert end["cause"] == "failed" and "place" in end["reason"]


def test_an_inapplicable_stage_of_exesusp_ends_the_task_with_its_reason() -> None:
    task = Refusing("cook", [st("stir", 20.0)], refuse=frozenset({"turn_off"}),
                    suspension={"stir": [st("turn_off", 1.0)]})
    fall = SyntheticTask("fall", [st("help", 2.0)])
    events, core = _run(task, fall, interrupt_at=3.0)
    off = [e for e in events if e["event"] == "stage" and e["action"] == "turn_off"]
    assert [e["status"] for e in off] == ["begin", "failed"] and "turn_off" not in core.begun
    end = next(e for e in events if e["event"] == "end" and e["agent"] == "d1")
    assert end["cause"] == "failed" and INAPPLICABLE in end["reason"]
    assert next(e for e in events if e["event"] == "end" and e["agent"] == "d2")["cause"] == "finished"
