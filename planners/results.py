"""Typed results of a planner call: a status enum and a frozen :class:`PlanResult`.

:func:`from_fd_outcome` is where a single Fast Downward run becomes a result, and the
search schedules (:mod:`planners.schedules`) build theirs from the :class:`Attempt` s they
ran; the :class:`~planners.planner.Planner` facade returns them as they are, and the
registered ``tasker-fd`` engine (:mod:`planners.engine`) converts them to UP's result
type.  This module imports nothing of unified-planning at load time.
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


class Failure(StrEnum):
    """Why a call ended in ``ERROR``: what the command line's exit status follows.

    ``INPUT``: the planner refuses the task as written (Fast Downward's translator, a feature
    its search lacks) — bad input, exit 2.  ``ENGINE``: the engine itself failed (raised,
    crashed, or answered something unusable) — exit 1, the engine named.  ``MEMORY``: it
    ran out of memory — exit 1.
    """

    INPUT = "input"
    ENGINE = "engine"
    MEMORY = "memory"


PlanStep = tuple[str, ...]
"""One ground action: ``("navigate", "robot", "kitchen", "hall")``."""


@dataclass(frozen=True, slots=True)
class Attempt:
    """One search a call ran: its label (``lama-first``, ``astar(lmcut())``, ...), how it ended,
    the cost of the best plan it found (``None``: none), and when it began and how long it ran
    (wall seconds from the start of the call: measured, so never written to a trace)."""

    search: str
    exit: FDExit
    cost: float | None
    started_s: float
    seconds: float
    note: str = ""

    def __post_init__(self) -> None:
        if not self.search:
            raise ValueError("an Attempt needs the label of its search")
        if self.started_s < 0 or self.seconds < 0:
            raise ValueError(f"an Attempt's times must be >= 0, got {self.started_s}, {self.seconds}")

    def describe(self, timed: bool = False) -> str:
        """``lama-first: solved, cost 102`` (``timed``: ``lama-first 0.31 s: ...``).  Untimed in a result's
        message, which a run writes to its ``problems/`` index and a task's end reason: no wall clock there."""
        found = f", cost {self.cost:g}" if self.cost is not None else ""
        note = f" ({self.note})" if self.note else ""
        return f"{self.search}{f' {self.seconds:.2f} s' if timed else ''}: {self.exit.value}{found}{note}"

    def to_json(self) -> dict[str, object]:
        return {"search": self.search, "exit": self.exit.value, "cost": self.cost,
                "started_s": round(self.started_s, 6), "seconds": round(self.seconds, 6), "note": self.note}


@dataclass(frozen=True, slots=True)
class PlanResult:
    """What :meth:`planners.planner.Planner.solve` returns.

    ``plan`` holds the steps (empty for an already-satisfied goal) when ``status`` is
    SOLVED and is ``None`` otherwise; ``cost`` is the plan's metric value (the action
    costs, or the length without a metric); ``wall_time_s`` is the measured time of
    the call that returned it (a cache hit's is the look-up's: the original solve's time
    was counted once, when it ran) and ``cached`` tells whether it came from the cache.
    ``message`` explains a failure, or what a plan is not (proven optimal).

    ``optimal`` says the plan is *proven* optimal (an optimal search found it, or exhausted
    every cheaper one); ``search`` names the search that produced it (``lama-first``,
    ``astar(lmcut())``, or the engine's name for another UP engine).  Both are deterministic
    for a deterministic planner and go into the trace; ``attempts`` (every search run, with
    wall times), ``first_plan_s`` and ``best_plan_s`` (when the first and the returned plan
    were found) are measurements and do not.  ``failure`` says why an ``ERROR`` happened.
    """

    status: PlanStatus
    plan: tuple[PlanStep, ...] | None
    cost: float | None
    planner: str
    wall_time_s: float
    cached: bool = False
    message: str = ""
    optimal: bool = False
    search: str = ""
    failure: Failure | None = None
    attempts: tuple[Attempt, ...] = ()
    first_plan_s: float | None = None
    best_plan_s: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.status, PlanStatus):
            raise TypeError(f"PlanResult.status must be a PlanStatus, got {self.status!r}")
        if self.status is PlanStatus.SOLVED:
            if self.plan is None:
                raise ValueError("a solved PlanResult needs a plan (use () for an empty one)")
            if self.cost is None or math.isnan(self.cost):
                raise ValueError("a solved PlanResult needs a cost")
            if not self.search:
                raise ValueError("a solved PlanResult needs the search that produced it")
        elif self.plan is not None:
            raise ValueError(f"a PlanResult with status {self.status.value} must not carry a plan")
        if self.optimal and self.status is not PlanStatus.SOLVED:
            raise ValueError(f"a PlanResult with status {self.status.value} cannot be optimal")
        if (self.status is PlanStatus.ERROR) != (self.failure is not None):
            raise ValueError("a PlanResult carries a failure exactly when its status is error")
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
            "optimal": self.optimal,
            "search": self.search or None,
            "planner": self.planner,
            "planner_time_s": round(self.wall_time_s, 6),
            "first_plan_s": None if self.first_plan_s is None else round(self.first_plan_s, 6),
            "best_plan_s": None if self.best_plan_s is None else round(self.best_plan_s, 6),
            "tried": [a.to_json() for a in self.attempts],
            "cached": self.cached,
            "failure": self.failure.value if self.failure is not None else None,
            "message": self.message,
        }

    def trace_info(self) -> dict[str, object]:
        """What the trace records of the call: no wall-clock value (traces are reproducible)."""
        return {"planner": self.planner, "cost": self.cost, "optimal": self.optimal, "search": self.search}


_FD_STATUS = {FDExit.SOLVED: PlanStatus.SOLVED, FDExit.UNSOLVABLE: PlanStatus.UNSOLVABLE,
              FDExit.TIMEOUT: PlanStatus.TIMEOUT, FDExit.MEMOUT: PlanStatus.ERROR, FDExit.ERROR: PlanStatus.ERROR,
              FDExit.OVER_BUDGET: PlanStatus.TIMEOUT}


def failure_of(exit: FDExit, message: str) -> Failure | None:
    """The failure an FD outcome is (``None`` unless it is an error): running out of memory is
    ``MEMORY``; the translator's refusals and unsupported features are ``INPUT``; the rest ``ENGINE``."""
    if _FD_STATUS[exit] is not PlanStatus.ERROR:
        return None
    if exit is FDExit.MEMOUT:
        return Failure.MEMORY
    return Failure.INPUT if message.startswith("translator") or "code 34" in message else Failure.ENGINE


def from_fd_outcome(outcome: FDOutcome, planner: str, wall_time_s: float, search: str = "",
                    optimal: bool = False) -> PlanResult:
    """The result of one Fast Downward run with one ``search`` (the only map from FD's outcome to a status).

    A solved run without a ``; cost`` line costs its length (FD writes the line for every
    plan; this is the unit-cost meaning should a build omit it).  Running out of memory
    is an ``ERROR`` whose message says so.  ``optimal``: whether that search proves the plan optimal.
    """
    if outcome.exit is FDExit.SOLVED:
        assert outcome.plan is not None
        cost = outcome.cost if outcome.cost is not None else float(len(outcome.plan))
        return PlanResult(PlanStatus.SOLVED, outcome.plan, cost, planner, wall_time_s, optimal=optimal,
                          search=search or "custom")
    message = outcome.message or f"Fast Downward ended with {outcome.exit.value} (exit code {outcome.code})"
    if outcome.exit is FDExit.MEMOUT and "memory" not in message:
        message = f"out of memory: {message}"
    return PlanResult(_FD_STATUS[outcome.exit], None, None, planner, wall_time_s, message=message,
                      failure=failure_of(outcome.exit, message))
