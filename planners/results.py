"""Typed results of a planner call: a status enum and a frozen :class:`PlanResult`.

:func:`from_fd_outcome` is the one place where a Fast Downward run becomes a result:
the :class:`~planners.planner.Planner` facade returns it as is, and the registered
``tasker-fd`` engine (:mod:`planners.engine`) converts it to UP's result type.  This
module imports nothing of unified-planning at load time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum
from typing import TYPE_CHECKING

from planners.fd import FDExit, FDOutcome

if TYPE_CHECKING:
    from unified_planning.engines import PlanGenerationResultStatus as UPStatus


class PlanStatus(StrEnum):
    """How a planner call ended; the values are what ``tasker plan --json`` prints."""

    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"
    TIMEOUT = "timeout"
    ERROR = "error"

    @classmethod
    def from_up(cls, status: UPStatus) -> PlanStatus:
        """Fold unified-planning's nine statuses into our four."""
        from unified_planning.engines import PlanGenerationResultStatus as UPStatus

        if status in (UPStatus.SOLVED_SATISFICING, UPStatus.SOLVED_OPTIMALLY):
            return cls.SOLVED
        if status in (UPStatus.UNSOLVABLE_PROVEN, UPStatus.UNSOLVABLE_INCOMPLETELY):
            return cls.UNSOLVABLE
        if status is UPStatus.TIMEOUT:
            return cls.TIMEOUT
        return cls.ERROR


PlanStep = tuple[str, ...]
"""One ground action: ``("navigate", "robot", "kitchen", "hall")``."""


@dataclass(frozen=True, slots=True)
class PlanResult:
    """What :meth:`planners.planner.Planner.solve` returns.

    ``plan`` holds the steps (empty for an already-satisfied goal) when ``status`` is
    SOLVED and is ``None`` otherwise; ``cost`` is the plan's metric value (the action
    costs, or the length without a metric); ``wall_time_s`` is the measured time of
    the call that returned it (a cache hit's is the look-up's: the original solve's time
    was counted once, when it ran) and ``cached`` tells whether it came from the cache.  ``message`` explains a failure.
    """

    status: PlanStatus
    plan: tuple[PlanStep, ...] | None
    cost: float | None
    planner: str
    wall_time_s: float
    cached: bool = False
    message: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.status, PlanStatus):
            raise TypeError(f"PlanResult.status must be a PlanStatus, got {self.status!r}")
        if self.status is PlanStatus.SOLVED:
            if self.plan is None:
                raise ValueError("a solved PlanResult needs a plan (use () for an empty one)")
            if self.cost is None or math.isnan(self.cost):
                raise ValueError("a solved PlanResult needs a cost")
        elif self.plan is not None:
            raise ValueError(f"a PlanResult with status {self.status.value} must not carry a plan")
        if self.plan is not None and not all(isinstance(s, tuple) and s for s in self.plan):
            raise TypeError("PlanResult.plan must hold non-empty tuples of strings")
        if self.wall_time_s < 0:
            raise ValueError(f"PlanResult.wall_time_s must be >= 0, got {self.wall_time_s}")

    @property
    def solved(self) -> bool:
        return self.status is PlanStatus.SOLVED

    def to_json(self) -> dict[str, object]:
        """The ``--json`` form of the command line."""
        return {
            "status": self.status.value,
            "plan": [list(s) for s in self.plan] if self.plan is not None else None,
            "cost": self.cost,
            "planner": self.planner,
            "planner_time_s": round(self.wall_time_s, 6),
            "cached": self.cached,
            "message": self.message,
        }


_FD_STATUS = {FDExit.SOLVED: PlanStatus.SOLVED, FDExit.UNSOLVABLE: PlanStatus.UNSOLVABLE,
              FDExit.TIMEOUT: PlanStatus.TIMEOUT, FDExit.MEMOUT: PlanStatus.ERROR, FDExit.ERROR: PlanStatus.ERROR}


def from_fd_outcome(outcome: FDOutcome, planner: str, wall_time_s: float) -> PlanResult:
    """The result of one Fast Downward run (the only map from FD's outcome to a status).

    A solved run without a ``; cost`` line costs its length (FD writes the line for every
    plan; this is the unit-cost meaning should a build omit it).  Running out of memory
    is an ``ERROR`` whose message says so.
    """
    if outcome.exit is FDExit.SOLVED:
        assert outcome.plan is not None
        cost = outcome.cost if outcome.cost is not None else float(len(outcome.plan))
        return PlanResult(PlanStatus.SOLVED, outcome.plan, cost, planner, wall_time_s)
    message = outcome.message or f"Fast Downward ended with {outcome.exit.value} (exit code {outcome.code})"
    if outcome.exit is FDExit.MEMOUT and "memory" not in message:
        message = f"out of memory: {message}"
    return PlanResult(_FD_STATUS[outcome.exit], None, None, planner, wall_time_s, message=message)
