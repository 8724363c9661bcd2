"""A neutral picture of the world that task hooks read.

Robots and simulators produce a :class:`WorldState` (ground facts, named poses);
task types turn it into whatever their planner needs (a PDDL problem, say).  Nothing
here knows PDDL or physics: facts are tuples of strings such as
``("at", "robot", "kitchen")``, poses are ``(x, y, yaw)`` in metres and radians.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

Pose = tuple[float, float, float]
Fact = tuple[str, ...]


@dataclass(frozen=True, slots=True)
class WorldState:
    """Ground facts that hold now, the poses of named things, and object types."""

    facts: frozenset[Fact] = frozenset()
    poses: Mapping[str, Pose] = field(default_factory=dict)
    objects: Mapping[str, str] = field(default_factory=dict)
    time: float = 0.0

    def holds(self, *atom: str) -> bool:
        return tuple(atom) in self.facts

    def matching(self, predicate: str) -> list[Fact]:
        """Facts of one predicate, sorted (so callers iterate deterministically)."""
        return sorted(f for f in self.facts if f and f[0] == predicate)

    def updated(self, add: Iterable[Fact] = (), delete: Iterable[Fact] = ()) -> WorldState:
        facts = (set(self.facts) - {tuple(f) for f in delete}) | {tuple(f) for f in add}
        return WorldState(frozenset(facts), self.poses, self.objects, self.time)


@dataclass(frozen=True, slots=True)
class MotionEstimate:
    """Result of a motion-cost query: an unreachable goal has infinite time, never zero."""

    reachable: bool
    time_s: float
    distance_m: float
    end_pose: Pose | None
    path: tuple[tuple[float, float], ...] = ()

    def __post_init__(self) -> None:
        if not self.reachable and math.isfinite(self.time_s):
            raise ValueError("an unreachable MotionEstimate must have time_s = inf")
        if self.reachable and (math.isnan(self.time_s) or self.time_s < 0):
            raise ValueError(f"MotionEstimate.time_s must be >= 0, got {self.time_s}")


UNREACHABLE = MotionEstimate(False, math.inf, math.inf, None)


@runtime_checkable
class MotionModel(Protocol):
    """Estimates what moving the robot's base costs (OMPL over the robot model, in ``robot/``)."""

    def estimate(self, start: Pose, goal: Pose) -> MotionEstimate:
        """Travel from ``start`` to ``goal``: time (rotation included), distance, reachability."""
