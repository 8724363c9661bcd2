"""The differential-drive path follower that drives TIAGo's base along a planned path.

It executes exactly the motion the estimator times (:meth:`DriveLimits.travel_time`):
for every leg of the polyline, turn in place toward the leg, then drive it; at the
end turn to the goal's yaw.  Each phase follows a time-optimal profile
(``min(limit, sqrt(2·accel·remaining))``, ramped by the acceleration limit), so the
MuJoCo time matches the trapezoidal estimate.  While driving, a small heading
correction toward a look-ahead point on the leg keeps the base on the line.

:meth:`PathFollower.brake` turns any phase into a stop at the acceleration limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

from robot.drive import DriveLimits, wrap

Point = tuple[float, float]


class Phase(StrEnum):
    """What the follower is doing now."""

    TURN = "turn"
    DRIVE = "drive"
    FINAL_TURN = "final_turn"
    BRAKE = "brake"
    DONE = "done"


@dataclass(frozen=True, slots=True)
class Command:
    """A base velocity command: forward speed (m/s) and turn rate (rad/s)."""

    v: float
    w: float


STOP = Command(0.0, 0.0)


class PathFollower:
    """Follows ``path`` (a polyline) and ends at ``goal_yaw`` (None: any heading)."""

    POS_TOL = 0.02  # metres left on a leg when it counts as driven
    ANG_TOL = 0.01  # radians left on a turn when it counts as done
    LOOKAHEAD = 0.3
    HEADING_GAIN = 3.0

    def __init__(self, path: list[Point] | tuple[Point, ...], goal_yaw: float | None, limits: DriveLimits) -> None:
        pts = [path[0]]
        for p in path[1:]:
            if math.hypot(p[0] - pts[-1][0], p[1] - pts[-1][1]) > 1e-6:
                pts.append(p)
        self.path = pts
        self.goal_yaw = goal_yaw
        self.limits = limits
        self.leg = 0
        self.phase = Phase.TURN if len(pts) > 1 else Phase.FINAL_TURN
        self.v = 0.0
        self.w = 0.0

    @property
    def done(self) -> bool:
        return self.phase is Phase.DONE

    def brake(self) -> None:
        """Stop as fast as the limits allow; the follower then reports DONE."""
        if self.phase is not Phase.DONE:
            self.phase = Phase.BRAKE

    def _ramp(self, current: float, target: float, accel: float, dt: float) -> float:
        return max(current - accel * dt, min(current + accel * dt, target))

    def _turn(self, target: float, yaw: float, dt: float) -> bool:
        err = wrap(target - yaw)
        lim = self.limits
        if abs(err) < self.ANG_TOL or (abs(err) < lim.turn_tolerance and abs(self.w) < 1e-3):
            self.w = 0.0
            return True
        # speed profile toward rest at the target, and never faster than the remaining angle allows
        want = math.copysign(min(lim.w_max, math.sqrt(2 * lim.turn_accel * abs(err)), abs(err) / dt), err)
        self.w = self._ramp(self.w, want, lim.turn_accel, dt)
        self.v = 0.0
        return False

    def _drive(self, x: float, y: float, yaw: float, dt: float) -> bool:
        (ax, ay), (bx, by) = self.path[self.leg], self.path[self.leg + 1]
        lx, ly = bx - ax, by - ay
        length = math.hypot(lx, ly)
        ux, uy = lx / length, ly / length
        s = (x - ax) * ux + (y - ay) * uy
        remaining = length - s
        lim = self.limits
        if remaining < self.POS_TOL:
            self.v = self.w = 0.0
            return True
        want = min(lim.v_max, math.sqrt(2 * lim.accel * remaining), remaining / dt)
        self.v = self._ramp(self.v, want, lim.accel, dt)
        look = min(length, s + self.LOOKAHEAD)
        tx, ty = ax + look * ux, ay + look * uy
        if remaining > self.LOOKAHEAD * 0.5:
            err = wrap(math.atan2(ty - y, tx - x) - yaw)
        else:
            err = wrap(math.atan2(ly, lx) - yaw)
        self.w = max(-lim.w_max, min(lim.w_max, self.HEADING_GAIN * err))
        return False

    def command(self, x: float, y: float, yaw: float, dt: float) -> Command:
        """The command for the next ``dt`` seconds, given the base's measured pose."""
        lim = self.limits
        if self.phase is Phase.BRAKE:
            self.v = self._ramp(self.v, 0.0, lim.accel, dt)
            self.w = self._ramp(self.w, 0.0, lim.turn_accel, dt)
            if self.v == 0.0 and self.w == 0.0:
                self.phase = Phase.DONE
            return Command(self.v, self.w)
        if self.phase is Phase.TURN:
            a, b = self.path[self.leg], self.path[self.leg + 1]
            if self._turn(math.atan2(b[1] - a[1], b[0] - a[0]), yaw, dt):
                self.phase = Phase.DRIVE
        if self.phase is Phase.DRIVE and self._drive(x, y, yaw, dt):
            self.leg += 1
            self.phase = Phase.TURN if self.leg + 1 < len(self.path) else Phase.FINAL_TURN
            if self.phase is Phase.TURN:
                return self.command(x, y, yaw, dt)
        if self.phase is Phase.FINAL_TURN:
            if self.goal_yaw is None or self._turn(self.goal_yaw, yaw, dt):
                self.phase = Phase.DONE
                self.v = self.w = 0.0
        if self.phase is Phase.DONE:
            return STOP
        return Command(self.v, self.w)
