"""How long the base takes to drive a path: :class:`DriveLimits` and its stop–turn–drive profile.

The controller (:mod:`robot.control`) executes the same profile, so a path timed here is
what MuJoCo takes: stop, turn toward the next point, drive to it with a trapezoidal speed
profile, and at the end turn to the goal's heading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot.roadmap import heading
from robot.spec import RobotSpec

Point = tuple[float, float]


def wrap(angle: float) -> float:
    """An angle brought into [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def profile_time(distance: float, v_max: float, accel: float) -> float:
    """Time to cover ``distance`` from rest to rest with a trapezoidal speed profile."""
    distance = abs(distance)
    if distance * accel >= v_max * v_max:
        return distance / v_max + v_max / accel
    return 2.0 * math.sqrt(distance / accel)


@dataclass(frozen=True, slots=True)
class DriveLimits:
    """Speed and acceleration limits of the base (m/s, rad/s, m/s², rad/s²)."""

    v_max: float = 0.5
    w_max: float = 1.0
    accel: float = 0.5
    turn_accel: float = 2.0
    turn_tolerance: float = 0.02  # radians: a turn smaller than this is skipped

    def __post_init__(self) -> None:
        for name in ("v_max", "w_max", "accel", "turn_accel"):
            if not getattr(self, name) > 0:
                raise ValueError(f"DriveLimits.{name} must be > 0, got {getattr(self, name)}")

    @classmethod
    def of(cls, robot: RobotSpec) -> DriveLimits:
        return cls(robot.max_speed, robot.max_turn, robot.max_accel, robot.max_turn_accel)

    def turn_time(self, angle: float) -> float:
        angle = abs(wrap(angle))
        return 0.0 if angle < self.turn_tolerance else profile_time(angle, self.w_max, self.turn_accel)

    def drive_time(self, distance: float) -> float:
        return profile_time(distance, self.v_max, self.accel) if distance > 1e-6 else 0.0

    def travel_time(self, path: list[Point], start_yaw: float, goal_yaw: float | None) -> float:
        """Stop, turn toward the next point, drive to it; at the end turn to ``goal_yaw``."""
        t, yaw = 0.0, start_yaw
        for a, b in zip(path, path[1:], strict=False):
            d = math.hypot(b[0] - a[0], b[1] - a[1])
            if d < 1e-6:
                continue
            h = heading(a, b)
            t += self.turn_time(h - yaw) + self.drive_time(d)
            yaw = h
        if goal_yaw is not None:
            t += self.turn_time(goal_yaw - yaw)
        return t
