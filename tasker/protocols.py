"""The protocols through which the model talks to planners, robots and worlds.

``tasker`` knows nothing of PDDL, OMPL or MuJoCo.  A robot (the paper's core agent,
``ca``) plugs in as a :class:`CoreAgent`; its world as a :class:`World`.  Planning is
done inside a task type's hooks (:mod:`tasker.task`), so a planner needs no protocol
of its own here: a task type calls whatever planner it likes and returns stages.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Any, Protocol, runtime_checkable

from tasker.stage import Stage


class SkillState(StrEnum):
    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"


@dataclass(frozen=True, slots=True)
class SkillStatus:
    """What a core agent says about the stage it runs: still running, done, or failed (with why)."""

    state: SkillState
    reason: str | None = None

    def __post_init__(self) -> None:
        if self.state is SkillState.FAILED and not self.reason:
            raise ValueError("a FAILED SkillStatus needs a reason")


RUNNING = SkillStatus(SkillState.RUNNING)
SUCCEEDED = SkillStatus(SkillState.SUCCEEDED)


def failed(reason: str) -> SkillStatus:
    return SkillStatus(SkillState.FAILED, reason)


@runtime_checkable
class CoreAgent(Protocol):
    """The robot's core agent (``ca``): executes the skills of stages.

    Only the agent in ``cmd`` calls it, so a core agent runs one stage at a time.
    Calls are made on the simulated clock ``now`` (seconds).
    """

    def begin(self, agent: str, stage: Stage, now: float) -> None:
        """Start executing ``stage`` for ``agent``."""

    def poll(self, agent: str, stage: Stage, now: float) -> SkillStatus:
        """Advance (if the core agent is stepped by its caller) and say how the stage goes."""

    def stop(self, agent: str, stage: Stage, now: float) -> None:
        """Stop the running stage safely (a suspendable stage interrupted by ``susp``)."""


@runtime_checkable
class World(Protocol):
    """Something that evolves with simulated time (a physics simulation, scripted people).

    The loop calls :meth:`advance` at the world's own rate, before agents step.
    """

    rate_hz: float

    def advance(self, now: float) -> None:
        """Bring the world to simulated time ``now``."""

    def snapshot(self) -> Any:
        """The state task hooks read (symbolic facts, poses)."""
