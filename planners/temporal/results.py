"""Typed results of a temporal planner call: timed steps, what each engine did, the outcome.

A temporal plan is a list of :class:`TimedStep` (start, ground action, duration), which is what
PDDL 2.1 plans are (``0.000: (move r a b) [5.000]``).  :class:`TemporalResult` is what
:meth:`planners.temporal.portfolio.TemporalPlanner.solve` returns: the plan of the first engine
whose plan UP's validator accepted, and an :class:`Attempt` for every engine tried, so a failure
says what each engine answered and why its plan was not used.  Times are :class:`fractions.Fraction`
as the engines and UP's validator compute them; :meth:`TemporalResult.to_json` rounds them for print.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum
from fractions import Fraction

from planners.results import Failure, PlanResult, PlanStatus


class Outcome(StrEnum):
    """How one engine's attempt ended (the values are what ``--json`` prints)."""

    VALID = "valid"              # a plan, accepted by UP's validator
    INVALID = "invalid"          # a plan UP's validator refused: not used, the next engine tried
    REFUSED = "refused"          # a valid plan the caller cannot use (the one robot doing two things at once)
    UNSOLVABLE = "unsolvable"    # the engine proved (or believes) no plan exists
    TIMEOUT = "timeout"          # its share of the time budget ran out
    UNSUPPORTED = "unsupported"  # the problem has a feature the engine does not handle
    ERROR = "error"              # the engine failed (a crash, a panic, an exception in its wrapper)
    SKIPPED = "skipped"          # not run: no time left, or an earlier engine's plan was used


@dataclass(frozen=True, slots=True)
class TimedStep:
    """One action of a temporal plan: starts at ``start``, lasts ``duration`` (0 for an instantaneous one)."""

    start: Fraction
    action: str
    args: tuple[str, ...]
    duration: Fraction

    def __post_init__(self) -> None:
        if self.start < 0:
            raise ValueError(f"TimedStep {self.action}: start must be >= 0, got {self.start}")
        if self.duration < 0:
            raise ValueError(f"TimedStep {self.action}: duration must be >= 0, got {self.duration}")

    @property
    def end(self) -> Fraction:
        return self.start + self.duration

    @property
    def step(self) -> tuple[str, ...]:
        """The ground action as the classical path writes it: ``("move", "r", "a", "b")``."""
        return (self.action, *self.args)

    def __str__(self) -> str:
        return f"{float(self.start):.3f}: ({' '.join(self.step)}) [{float(self.duration):.3f}]"


@dataclass(frozen=True, slots=True)
class Attempt:
    """What one engine did: its outcome, what it said (or why its plan was refused), its wall seconds."""

    engine: str
    outcome: Outcome
    message: str = ""
    wall_time_s: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.outcome, Outcome):
            raise TypeError(f"Attempt.outcome must be an Outcome, got {self.outcome!r}")
        if self.wall_time_s < 0:
            raise ValueError(f"Attempt.wall_time_s must be >= 0, got {self.wall_time_s}")

    def __str__(self) -> str:
        return f"{self.engine}: {self.outcome.value}" + (f" ({self.message})" if self.message else "")


@dataclass(frozen=True, slots=True)
class TemporalResult:
    """The outcome of a temporal planner call.

    ``plan`` holds the steps in start-time order when ``status`` is SOLVED (empty if the goal
    held), else ``None``; ``engine`` names the engine whose plan it is (``""`` if none);
    ``attempts`` lists every engine tried, in order.  ``makespan`` is the end of the last step.
    """

    status: PlanStatus
    plan: tuple[TimedStep, ...] | None
    engine: str
    attempts: tuple[Attempt, ...]
    wall_time_s: float

    def __post_init__(self) -> None:
        if not isinstance(self.status, PlanStatus):
            raise TypeError(f"TemporalResult.status must be a PlanStatus, got {self.status!r}")
        if (self.status is PlanStatus.SOLVED) != (self.plan is not None):
            raise ValueError(f"a TemporalResult with status {self.status.value} "
                             + ("needs a plan" if self.status is PlanStatus.SOLVED else "must not carry a plan"))
        if self.plan is not None and list(self.plan) != sorted(self.plan, key=_order):
            raise ValueError("TemporalResult.plan must be in start-time order")
        if self.status is PlanStatus.SOLVED and not self.engine:
            raise ValueError("a solved TemporalResult names the engine whose plan it is")
        if self.wall_time_s < 0 or math.isnan(self.wall_time_s):
            raise ValueError(f"TemporalResult.wall_time_s must be >= 0, got {self.wall_time_s}")

    @property
    def solved(self) -> bool:
        return self.status is PlanStatus.SOLVED

    @property
    def makespan(self) -> Fraction | None:
        if self.plan is None:
            return None
        return max((s.end for s in self.plan), default=Fraction(0))

    @property
    def message(self) -> str:
        """What the engines said, one ``engine: outcome (why)`` each, for a failure's reason."""
        return "; ".join(str(a) for a in self.attempts)

    def to_plan_result(self) -> PlanResult:
        """The classical path's result type: steps in start-time order, cost = the makespan."""
        if self.plan is None:
            status = self.status if self.status is not PlanStatus.SOLVED else PlanStatus.ERROR
            return PlanResult(status, None, None, self.engine or "temporal", self.wall_time_s, message=self.message,
                              failure=Failure.ENGINE if status is PlanStatus.ERROR else None)
        makespan = self.makespan
        assert makespan is not None
        return PlanResult(PlanStatus.SOLVED, tuple(s.step for s in self.plan), float(makespan), self.engine,
                          self.wall_time_s, message=self.message, search=self.engine)

    def to_json(self) -> dict[str, object]:
        """``tasker plan --json`` for a temporal problem: the classical keys (``plan`` as steps in
        start-time order, ``cost`` = makespan), and ``timed_plan``, ``makespan``, ``attempts``."""
        out = self.to_plan_result().to_json()
        out["timed_plan"] = None if self.plan is None else [
            {"start": _num(s.start), "action": s.action, "args": list(s.args), "duration": _num(s.duration)}
            for s in self.plan]
        makespan = self.makespan
        out["makespan"] = None if makespan is None else _num(makespan)
        out["attempts"] = [{"engine": a.engine, "outcome": a.outcome.value, "message": a.message,
                            "time_s": round(a.wall_time_s, 6)} for a in self.attempts]
        return out


def _order(s: TimedStep) -> tuple[Fraction, Fraction]:
    return (s.start, s.end)


def _num(x: Fraction) -> float:
    return round(float(x), 6)
