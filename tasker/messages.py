"""Messages exchanged by the harmoniser (tha) and the dynamic agents (da).

The names follow the paper: the command buffer ``[triggerFlag, data]`` (eqs. 13-17),
the report ``{fsmState, scheduleParams}`` (eqs. 18-19), and argument-dependent
schedule-parameter requests ``[spID, args] -> [scheduleParam]`` (eqs. 20-21).

Commands carry a sequence number and reports acknowledge the last command the agent
has handled (``ack``).  The paper's Alg. 1 reads "the executing agent reports
``wait``" as "it has suspended"; without the acknowledgement a report written just
before a ``start`` arrived would look like a finished suspension and let a second
agent into ``cmd``.  The sequence number closes that race.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

from tasker.fsm import FsmState

__all__ = [
    "SP_COMPLETION", "Command", "CompletionCost", "CostParams", "Flag", "FsmState", "Report", "SPRequest",
    "ScheduleParams",
]


class Flag(StrEnum):
    """``triggerFlag`` of the command buffer (eq. 14)."""

    START = "start"
    SUSP = "susp"
    TERM = "term"


@dataclass(frozen=True, slots=True)
class Command:
    """The command buffer ``[triggerFlag, data]`` (eq. 13), with a sequence number."""

    flag: Flag
    seq: int
    data: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.flag, Flag):
            raise TypeError(f"Command.flag must be a Flag, got {self.flag!r}")
        if self.seq < 1:
            raise ValueError(f"Command.seq must be >= 1, got {self.seq}")


@dataclass(frozen=True, slots=True)
class ScheduleParams:
    """Task-dependent schedule parameters (the ``scheduleParams`` of eq. 19).

    The structure depends on the scheduling algorithm, so this base carries only the
    task type; a scheduler states which subclass it needs.
    """

    task_type: str


@dataclass(frozen=True, slots=True)
class CostParams(ScheduleParams):
    """The paper's ``[taskType, cost, cps, cTime, endPose]`` (eq. 39), in one meaning of cost.

    ``cost``
        the harm or discomfort the task will have accumulated by the time it
        completes if it is started now (cost units; lower is better, costs add);
    ``cps``
        how fast that cost grows per second the task is delayed (cost units / s);
    ``cTime``
        seconds to complete the task if it is started now;
    ``endPose``
        the robot's pose when the task is complete (``(x, y, yaw)``), or ``None``;
    ``deadline``
        optional absolute simulated time by which the task should be complete
        (used by the EDF baseline);
    ``priority``
        optional static priority, higher is more urgent (fixed-priority baseline).

    An infeasible task reports ``cost = inf``: never zero.
    """

    cost: float = 0.0
    cps: float = 0.0
    c_time: float = 0.0
    end_pose: tuple[float, ...] | None = None
    deadline: float | None = None
    priority: int | None = None

    def __post_init__(self) -> None:
        cost, cps, c_time = self.cost, self.cps, self.c_time
        if type(cost) is float and type(cps) is float and type(c_time) is float and cost == cost and cps == cps \
                and c_time >= 0.0:  # the common case, checked without the loop (every report builds one)
            return
        for name, value in (("cost", cost), ("cps", cps), ("c_time", c_time)):
            if not isinstance(value, _NUMBERS) or value != value:  # value != value: NaN
                raise ValueError(f"CostParams.{name} must be a number, got {value!r}")
        if self.c_time < 0:
            raise ValueError(f"CostParams.c_time must be >= 0, got {self.c_time}")


@dataclass(frozen=True, slots=True)
class Report:
    """The report buffer ``{fsmState, scheduleParams}`` (eqs. 18-19).

    ``ack`` is the sequence number of the last command the agent has handled;
    ``reason`` is set with ``fsm_state == END``.
    """

    fsm_state: FsmState
    params: ScheduleParams | None = None
    ack: int = 0
    reason: str | None = None


@dataclass(frozen=True, slots=True)
class SPRequest:
    """``[spID, args]`` (eq. 20): ask an agent for an argument-dependent parameter."""

    sp_id: str
    args: Mapping[str, Any] = field(default_factory=dict)


_NUMBERS = (int, float)

SP_COMPLETION = "cc"
"""``spID`` of Alg. 2's request: cost of completing the task from a given start pose.

Arguments: ``pose``, the start pose; ``after`` (optional), the id of the agent whose
completion the start follows, so that the estimate assumes what that task leaves changed
(:meth:`tasker.task.TaskType.leaves`)."""


@dataclass(frozen=True, slots=True)
class CompletionCost:
    """Answer to :data:`SP_COMPLETION` (eq. 21): ``{cc, ccps}`` of Alg. 2.

    ``cc`` is the cost of completing the task if it were started from the pose given
    in the request; ``ccps`` the cost per second while it waits to begin.  ``c_time``
    (optional) is the seconds that completion takes: a task that knows it says it, and
    a whole-queue scheduler then reads the duration as the task computed it rather than
    recovering it from two costs computed at different moments (and may keep it while the
    task's estimate inputs hold, :attr:`tasker.schedulers.base.ScheduleView.generation`).
    """

    cc: float
    ccps: float
    c_time: float | None = None
