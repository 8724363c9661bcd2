"""The skills the core agent runs: ``navigate``, ``say``, ``manipulate``, ``wait``.

A skill is started by :meth:`Simulation.begin <robot.sim.Simulation.begin>`, gets a
:meth:`Skill.control` call at every control tick of the physics loop (the base
command, for ``navigate``), and reports its :class:`~tasker.protocols.SkillStatus`.
Contract with the task types (``Stage.data``):

* ``navigate``: ``data["to"]`` is a place, a person (the robot stops ``APPROACH``
  metres from them, facing them) or a pose ``[x, y, yaw]``.  Fails when no path
  exists or when people block the way for longer than ``BLOCK_TIMEOUT``.
* ``say``: ``data["text"]``; takes ``stage.duration`` seconds.
* ``manipulate``: takes ``stage.duration`` seconds; fails if ``data["object"]``
  names something the world no longer has.  A manipulation that closes a door (its
  ``delete`` list holds a fact bound to the door) while the robot stands in that doorway
  first drives to the stage's place argument — the side the task says it acts from — so
  the door never closes through the robot.
* ``wait``: takes ``stage.duration`` seconds.

On success the simulation applies ``data["add"]`` and ``data["delete"]``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Protocol

import numpy as np

from robot.control import STOP, Command, PathFollower
from robot.drive import DriveLimits
from robot.estimator import MotionEstimator
from robot.motion import BasePlanner
from robot.people import People
from robot.scene import Scene, point_box_distance
from robot.spec import WorldSpec
from tasker.protocols import RUNNING, SUCCEEDED, SkillStatus, failed
from tasker.stage import Stage
from tasker.world import Pose


class SkillHost(Protocol):
    """What a skill may see of the world it runs in (:class:`robot.sim.Simulation` is one).

    The narrow meeting point of skills and simulation: skills read poses, people, the
    collision scene and the motion planner through it, and never step or change the
    world themselves (the simulation calls :meth:`Skill.control` and applies results).
    """

    spec: WorldSpec
    people: People
    scene: Scene
    planner: BasePlanner
    motion: MotionEstimator
    limits: DriveLimits

    def robot_pose(self) -> Pose: ...

    def objects(self) -> Mapping[str, str]: ...

    def doors_closed_by(self, stage: Stage) -> tuple[str, ...]: ...

# Seconds a blocked path is retried before the skill fails.  People block a way while they
# pass: a person walking through a doorway towards the robot holds it for the length of
# both clearances and the leaf (2 x (0.25 + 0.35) + 0.1 = 1.3 m), 6.5 s at the protocols'
# slowest escort pace (0.2 m/s) and about 12 s at the 0.11 m/s a day's person was seen
# walking to their site.  30 s outlasts that, and fails a way held for good soon enough.
BLOCK_TIMEOUT = 30.0
STALL_TIMEOUT = 2 * BLOCK_TIMEOUT  # seconds without moving STALL_MOVE metres before the skill gives up
STALL_MOVE = 0.1
CHECK_PERIOD = 0.2  # seconds between checks of the path ahead
# metres closer to a person than planned that the check of the path ahead tolerates: the
# follower counts a waypoint reached within POS_TOL and drives on from where it really is,
# and keeps to a leg within about a centimetre
TRACKING_SLACK = PathFollower.POS_TOL + 0.01
DOORWAY_MARGIN = 0.05  # metres beyond the robot's radius at which a door leaf would close on it


class Skill:
    """A running skill: timed by default; subclasses override :meth:`control`/:meth:`status`."""

    def __init__(self, sim: SkillHost, stage: Stage, now: float) -> None:
        self.sim = sim
        self.stage = stage
        self.started = now
        self.result: SkillStatus = RUNNING

    def control(self, now: float, dt: float) -> Command:
        if self.result is RUNNING and now - self.started >= self.stage.duration - 1e-9:
            self.result = SUCCEEDED
        return STOP

    def stop(self, now: float) -> None:
        if self.result is RUNNING:
            self.result = failed("stopped")

    def quiet_until(self) -> float:
        """Until when :meth:`control` certainly returns STOP and changes nothing: a timed
        skill until its end, a finished one forever.  The simulation skips physics and
        control ticks up to then when nothing else moves."""
        return self.started + self.stage.duration - 1e-6 if self.result is RUNNING else math.inf


class Manipulate(Skill):
    """A timed manipulation; fails at once if its object is gone.  One that closes a door
    the robot stands in first clears the doorway (see the module's contract)."""

    def __init__(self, sim: SkillHost, stage: Stage, now: float) -> None:
        super().__init__(sim, stage, now)
        self.clearing: Navigate | None = None
        obj = stage.data.get("object")
        if obj is not None and obj not in sim.objects():
            self.result = failed(f"object {obj!r} is gone")
            return
        place = next((a for a in stage.args if a in sim.spec.places), None)
        if place is not None and self._in_doorway(sim.doors_closed_by(stage)):
            self.clearing = Navigate(sim, Stage(f"clear_{stage.action}", skill="navigate", data={"to": place}), now)
            if self.clearing.result is not RUNNING:
                self.result = failed(f"cannot step out of the doorway to {place!r}: {self.clearing.result.reason}")

    def _in_doorway(self, doors: tuple[str, ...]) -> bool:
        if not doors:
            return False
        x, y, _ = self.sim.robot_pose()
        boxes = np.asarray([self.sim.spec.doors[d].box for d in doors], dtype=float)
        return bool(point_box_distance(np.asarray([x]), np.asarray([y]), boxes).min()
                    < self.sim.scene.radius + DOORWAY_MARGIN)

    def control(self, now: float, dt: float) -> Command:
        c = self.clearing
        if c is None:
            return super().control(now, dt)
        cmd = c.control(now, dt)
        if c.result is SUCCEEDED and not c.braking():
            self.clearing, self.started = None, now  # out of the doorway: the manipulation starts now
        elif c.result is not RUNNING and c.result is not SUCCEEDED and self.result is RUNNING:
            self.result = failed(f"could not step out of the doorway: {c.result.reason}")
        return cmd

    def stop(self, now: float) -> None:
        if self.clearing is not None:
            self.clearing.stop(now)
        super().stop(now)

    def quiet_until(self) -> float:
        return -math.inf if self.clearing is not None else super().quiet_until()

    def braking(self) -> bool:
        return self.clearing is not None and self.clearing.braking()


class Navigate(Skill):
    """Drive the base along a planned path to a place, a person or a pose."""

    def __init__(self, sim: SkillHost, stage: Stage, now: float) -> None:
        super().__init__(sim, stage, now)
        self.target = stage.data.get("to")
        self.follower: PathFollower | None = None
        self.goal: Pose | None = None
        self.person_at: tuple[float, float] | None = None
        self.blocked_since: float | None = None
        self.next_check = now
        self.stopping = False
        self.mark = (now, sim.robot_pose()[:2])  # last time and place the base made progress
        bad = self._bad_target()
        if bad:
            self.result = failed(bad)
        elif self._replan() is not None:
            # unreachable now (people in the way, no free pose next to the person): wait for
            # the way to clear as a navigation blocked en route does, failing after BLOCK_TIMEOUT
            self.blocked_since = now

    def _bad_target(self) -> str | None:
        """Why ``data["to"]`` can never be reached (not a place, person or pose), else None."""
        t = self.target
        if isinstance(t, str):
            return None if t in self.sim.spec.places or t in self.sim.people else f"unknown navigation target {t!r}"
        if isinstance(t, list | tuple) and len(t) in (2, 3) and all(isinstance(v, int | float) for v in t):
            return None
        return f"navigate needs data['to'] = a place, a person or [x, y, yaw]; got {t!r}"

    def _goal(self) -> Pose | str:
        t = self.target
        sim = self.sim
        if isinstance(t, str):
            return sim.spec.places[t] if t in sim.spec.places else self._approach(t)
        assert isinstance(t, list | tuple)  # _bad_target ruled out anything else
        return (float(t[0]), float(t[1]), float(t[2]) if len(t) == 3 else math.nan)

    def _approach(self, name: str) -> Pose | str:
        """The pose next to the person that the estimates use too (``MotionEstimator.approach``)."""
        p = self.sim.people[name]
        self.person_at = (p.x, p.y)
        goal, _ = self.sim.motion.approach(self.sim.robot_pose(), name)
        return goal if goal is not None else f"no reachable pose next to {name}"

    def _replan(self) -> str | None:
        goal = self._goal()
        if isinstance(goal, str):
            return goal
        x, y, yaw = self.sim.robot_pose()
        path = self.sim.planner.plan((x, y), (goal[0], goal[1]))
        if path is None:
            return f"no path to {self.target!r}"
        self.goal = goal
        self.follower = PathFollower(path, None if math.isnan(goal[2]) else goal[2], self.sim.limits)
        return None

    def _path_ahead_blocked(self) -> bool:
        f = self.follower
        assert f is not None
        x, y, _ = self.sim.robot_pose()
        ahead = [(x, y)] + f.path[f.leg + 1 :]
        if len(ahead) < 2:
            return False
        # people by the planner's own rule (Scene.people_clear): what it plans, this accepts.
        # Whoever follows the robot is in neither (Scene.making_way): they walk its trail.
        scene = self.sim.scene
        pts = np.asarray(ahead)
        if len(scene.closed_doors()) and not scene.segments_free(pts[:-1], pts[1:], static=False,
                                                                 ignore=tuple(scene.people)).all():
            return True  # a door closed across the way
        return not scene.path_clear(ahead, slack=TRACKING_SLACK)

    def control(self, now: float, dt: float) -> Command:
        f = self.follower
        if f is None:
            f = self._start_when_clear(now)
            if f is None:
                return STOP
        if self.result is not RUNNING:  # finished, failed or stopped: brake (a no-op once done)
            f.brake()
            x, y, yaw = self.sim.robot_pose()
            return f.command(x, y, yaw, dt)
        if not self.stopping and now >= self.next_check:
            self.next_check = now + CHECK_PERIOD
            moved = (self.person_at is not None and isinstance(self.target, str)
                     and math.dist(self.person_at, self.sim.people[self.target].pose[:2]) > 0.5)
            # a failed re-plan left the base braked: retry at every check until it works or
            # BLOCK_TIMEOUT passes, even if the old path ahead has since cleared
            if moved or self.blocked_since is not None or self._path_ahead_blocked():
                why = self._replan()
                f = self.follower
                assert f is not None  # _replan installs a new follower or keeps the old one, never clears it
                if why is None:
                    self.blocked_since = None
                else:
                    self.blocked_since = self.blocked_since if self.blocked_since is not None else now
                    if now - self.blocked_since > BLOCK_TIMEOUT:
                        self.result = failed(f"path to {self.target!r} blocked: {why}")
                    f.brake()
        x, y, yaw = self.sim.robot_pose()
        cmd = f.command(x, y, yaw, dt)
        if f.done and self.blocked_since is None and not self.stopping and self.result is RUNNING:
            self.result = SUCCEEDED
        elif self.result is RUNNING and not self.stopping:
            self._watch_progress(now, x, y)
        return cmd

    def _start_when_clear(self, now: float) -> PathFollower | None:
        """Blocked from the start: re-plan at every check; fail after ``BLOCK_TIMEOUT``."""
        if self.blocked_since is None or self.result is not RUNNING or self.stopping or now < self.next_check:
            return None
        self.next_check = now + CHECK_PERIOD
        why = self._replan()
        if why is None:
            self.blocked_since = None
            self.mark = (now, self.sim.robot_pose()[:2])  # progress is watched from the start of the drive
            return self.follower
        if now - self.blocked_since > BLOCK_TIMEOUT:
            self.result = failed(f"path to {self.target!r} blocked: {why}")
        return None

    def _watch_progress(self, now: float, x: float, y: float) -> None:
        """A navigation that re-plans paths it cannot drive (a person beside a doorway the
        planner squeezes past, say) would wait forever: fail once the base has not moved
        ``STALL_MOVE`` metres for ``STALL_TIMEOUT`` seconds, so the task ends with its reason."""
        since, (mx, my) = self.mark
        if math.hypot(x - mx, y - my) >= STALL_MOVE:
            self.mark = (now, (x, y))
        elif now - since > STALL_TIMEOUT:
            self.result = failed(f"no progress toward {self.target!r} for {STALL_TIMEOUT:g} s "
                                 f"(stuck at ({x:.2f}, {y:.2f}))")

    def stop(self, now: float) -> None:
        """Brake to a standstill at the acceleration limits (the physics loop keeps braking)."""
        self.stopping = True
        if self.follower is not None:
            self.follower.brake()
        super().stop(now)

    def quiet_until(self) -> float:
        done = self.follower is None or self.follower.done
        return math.inf if done and self.result is not RUNNING else -math.inf

    def braking(self) -> bool:
        return self.stopping and self.follower is not None and not self.follower.done


SKILLS: dict[str, type[Skill]] = {"navigate": Navigate, "say": Skill, "manipulate": Manipulate, "wait": Skill}
