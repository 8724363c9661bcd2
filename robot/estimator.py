"""Motion-cost estimates for the base: :class:`MotionEstimator`, travel matrices.

:class:`MotionEstimator` implements :class:`tasker.world.MotionModel` over a
:class:`robot.motion.BasePlanner`: paths timed with :class:`robot.drive.DriveLimits`, the
same stop–turn–drive profile the controller executes (:mod:`robot.control`), so estimates
match what MuJoCo takes.  A goal at a person means "next to them"
(:meth:`MotionEstimator.approach`).  :func:`travel_matrix` answers a whole matrix in one
call; :func:`motion_model` builds a ready estimator for a world.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robot.drive import DriveLimits
from robot.motion import BasePlanner, Point, open_planner
from robot.roadmap import path_length
from robot.scene import Scene
from robot.spec import WorldSpec
from tasker.world import UNREACHABLE, MotionEstimate, Pose

APPROACH = 0.9  # metres from a person's centre when the robot goes "to" them
APPROACH_DIRECTIONS = 16
APPROACH_RINGS = (APPROACH, 1.1, 1.3)  # tried in turn: a farther ring only when no pose of the nearer is reachable
_ESTIMATE, _APPROACH, _RING = range(3)  # what a remembered answer answers (MotionEstimator._memo keys)


class MotionEstimator:
    """:class:`tasker.world.MotionModel` for the base: OMPL-roadmap paths, profile-timed.

    An unreachable goal (walled off, behind a closed door, in collision) gives
    :data:`tasker.world.UNREACHABLE`: infinite time, never zero.  A goal at a person's
    position means "go to that person": the estimate is for :meth:`approach`'s pose, the
    very pose the ``navigate`` skill drives to, so estimate and motion agree.
    """

    def __init__(self, planner: BasePlanner, limits: DriveLimits, open_planner: BasePlanner | None = None,
                 memo: bool = True) -> None:
        self.planner = planner
        self.limits = limits
        self.open_planner = open_planner
        self.memo = memo
        # answers for the scene state they were computed in (:meth:`_state`); forgotten
        # all at once when it changes
        self._memo_state: tuple[object, ...] | None = None
        self._memo: dict[tuple[object, ...], object] = {}

    def _state(self) -> tuple[object, ...]:
        """What every answer of this estimator depends on besides its arguments and the person
        it is about: the doors, the people in the robot's way (:meth:`Scene.discs
        <robot.scene.Scene.discs>`: everyone but those making way for it, whose walking
        behind the robot changes no path) and where people step aside to.  The planner
        answers from exactly these (its walls and roadmap never change)."""
        scene = self.planner.scene
        return (tuple(sorted(scene.door_open.items())), tuple(scene.discs()),
                tuple(sorted(scene.stepping_to.items())))

    def _remembered(self, key: tuple[object, ...]) -> tuple[bool, object]:
        if not self.memo:
            return False, None
        state = self._state()
        if state != self._memo_state:
            self._memo_state, self._memo = state, {}
        return (True, self._memo[key]) if key in self._memo else (False, None)

    def _remember(self, key: tuple[object, ...], value: object) -> None:
        if self.memo and self._memo_state == self._state():  # unchanged while computing: still true
            self._memo[key] = value

    def estimate(self, start: Pose, goal: Pose) -> MotionEstimate:
        """Time to drive from ``start`` to ``goal`` (to the person there, if any), with everyone
        who is stepping aside already where they are going (:meth:`Scene.as_expected
        <robot.scene.Scene.as_expected>`): they will be by the time the robot gets there.

        Answers are remembered per scene state (:meth:`_state`): the same question in the
        same scene gets the same answer without planning again."""
        scene = self.planner.scene
        person = scene.person_at(goal[0], goal[1])
        key = (_ESTIMATE, tuple(start), tuple(goal), person and scene.people[person])
        known, value = self._remembered(key)
        if known:
            assert isinstance(value, MotionEstimate)
            return value
        if person is not None:
            est = self.approach(start, person)[1]
        else:
            with self.planner.scene.as_expected():
                est = self._estimate(self.planner, start, goal)
        self._remember(key, est)
        return est

    def estimate_ignoring_doors(self, start: Pose, goal: Pose) -> MotionEstimate:
        """As :meth:`estimate` with every door open and nobody in the way.

        A task domain that models doors (``door_between``, ``open``) needs the geometry
        behind a closed door: whether the door is open is the plan's business.
        """
        return self._estimate(self.open_planner or self.planner, start, goal)

    def estimate_ignoring_people(self, start: Pose, goal: Pose) -> MotionEstimate:
        """As :meth:`estimate` with the doors as they are and nobody in the way: the
        geometry a plan's connectivity may rely on without depending on where people stand."""
        return self._timed(self.planner.plan_ignoring_people((start[0], start[1]), (goal[0], goal[1])),
                           start, goal)

    def closed_doors(self) -> tuple[str, ...]:
        """The doors closed now (a key for what :meth:`estimate_ignoring_people` answers)."""
        return self.planner.closed_doors()

    def approach(self, start: Pose, person: str) -> tuple[Pose | None, MotionEstimate]:
        """The cheapest reachable pose ``APPROACH`` metres from ``person``, facing them, with no
        wall or closed door between them (:meth:`Scene.sees <robot.scene.Scene.sees>`).

        Candidates lie in ``APPROACH_DIRECTIONS`` directions around the person; ties go to
        the first direction (east, then counter-clockwise), so the choice is deterministic.
        When no pose of that ring is reachable (a person lying between furniture and a
        wall, someone else standing beside them), the next ring of ``APPROACH_RINGS`` is
        tried, nearest first.  ``(None, UNREACHABLE)`` when no candidate is reachable.  People
        stepping aside count where they are going, as in :meth:`estimate`; the ``navigate``
        skill drives to this pose once the way there is clear.
        """
        key = (_APPROACH, tuple(start), person, self.planner.scene.people[person])
        known, value = self._remembered(key)
        if known:
            return value  # type: ignore[return-value]
        out: tuple[Pose | None, MotionEstimate] = (None, UNREACHABLE)
        with self.planner.scene.as_expected():  # people stepping aside: where they are going
            for radius in APPROACH_RINGS:
                best = self._approach_ring(start, person, radius)
                if best[0] is not None:
                    out = best
                    break
        self._remember(key, out)
        return out

    def _ring(self, person: str, radius: float) -> list[tuple[int, Pose]]:
        """The poses of ``person``'s ring of ``radius`` the robot may help them from (free,
        no wall between): they depend on the scene, not on where the robot starts, so they
        are computed once per scene state (and in it, per person and ring)."""
        key = (_RING, person, radius, self.planner.scene.people[person])
        known, value = self._remembered(key)
        if known:
            return value  # type: ignore[return-value]
        scene = self.planner.scene
        d = scene.people[person]
        out = []
        for k in range(APPROACH_DIRECTIONS):
            a = 2 * math.pi * k / APPROACH_DIRECTIONS
            gx, gy = d.x + radius * math.cos(a), d.y + radius * math.sin(a)
            # a pose the person can be helped from: free, and with no wall between them (a
            # pose 0.9 m away through a wall is the wrong side of it)
            if scene.free(gx, gy, ignore=(person,)) and scene.sees((gx, gy), (d.x, d.y)):
                out.append((k, (gx, gy, math.atan2(d.y - gy, d.x - gx))))
        self._remember(key, out)
        return out

    def _approach_ring(self, start: Pose, person: str, radius: float) -> tuple[Pose | None, MotionEstimate]:
        cands = []
        for k, goal in self._ring(person, radius):
            # the straight-line drive time bounds the travel time from below (the profile
            # is concave, turns cost >= 0), so candidates are tried nearest first and
            # the search stops once no farther one can beat the best
            bound = self.limits.drive_time(math.hypot(goal[0] - start[0], goal[1] - start[1]))
            cands.append((bound, k, goal))
        best: tuple[float, int, Pose, MotionEstimate] | None = None
        for bound, k, goal in sorted(cands):
            if best is not None and bound > best[0]:
                break
            est = self._estimate(self.planner, start, goal)
            if est.reachable and (best is None or (est.time_s, k) < (best[0], best[1])):
                best = (est.time_s, k, goal, est)
        return (best[2], best[3]) if best is not None else (None, UNREACHABLE)

    def table(self, poses: list[Pose] | tuple[Pose, ...]) -> np.ndarray:
        """Seconds from every pose to every other: an ``(n, n)`` matrix, ``inf`` if unreachable.

        One shortest-path search per source and scene state (the planner caches the
        search tree), so a table costs ``n`` searches plus ``n²`` cheap goal links.
        """
        n = len(poses)
        out = np.zeros((n, n))
        for i, a in enumerate(poses):
            for j, b in enumerate(poses):
                if i != j:
                    out[i, j] = self.estimate(a, b).time_s
        return out

    def _estimate(self, planner: BasePlanner, start: Pose, goal: Pose) -> MotionEstimate:
        return self._timed(planner.plan((start[0], start[1]), (goal[0], goal[1])), start, goal)

    def _timed(self, path: tuple[Point, ...] | None, start: Pose, goal: Pose) -> MotionEstimate:
        if path is None:
            return UNREACHABLE
        pts = list(path)
        time_s = self.limits.travel_time(pts, start[2], goal[2])
        end = (float(goal[0]), float(goal[1]), float(goal[2]))
        return MotionEstimate(True, time_s, path_length(pts), end, tuple(pts))


@dataclass(frozen=True, slots=True)
class TravelMatrix:
    """Travel between given places or points of a world: ``time_s[i, j]`` and
    ``distance_m[i, j]`` from ``labels[i]`` to ``labels[j]`` (``inf`` when unreachable)."""

    world: str
    seed: int
    labels: tuple[str, ...]
    poses: tuple[Pose, ...]
    time_s: np.ndarray
    distance_m: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.labels)
        if len(self.poses) != n or self.time_s.shape != (n, n) or self.distance_m.shape != (n, n):
            raise ValueError(f"TravelMatrix: {n} labels need {n} poses and ({n}, {n}) matrices")

    def to_json(self) -> dict[str, object]:
        """Plain JSON: unreachable entries are ``null``."""
        def rows(m: np.ndarray) -> list[list[float | None]]:
            return [[float(v) if math.isfinite(v) else None for v in row] for row in m]

        return {"world": self.world, "seed": self.seed, "labels": list(self.labels),
                "poses": [list(p) for p in self.poses], "time_s": rows(self.time_s),
                "distance_m": rows(self.distance_m)}


def travel_matrix(world: str | WorldSpec, targets: list[str | tuple[float, ...]] | tuple[str | tuple[float, ...], ...],
                  seed: int = 1, people: bool = True) -> TravelMatrix:
    """Travel times and distances between ``targets`` in ``world``, in one call.

    A target is a place name, a person's name (the robot goes next to them, see
    :meth:`MotionEstimator.approach`) or a point ``(x, y)`` / pose ``(x, y, yaw)``.
    People stand where the world file puts them unless ``people`` is False.  An unknown
    name raises :class:`tasker.errors.UnknownName` listing the known ones.
    """
    from robot.spec import load_world
    from tasker.errors import UnknownName

    spec = world if isinstance(world, WorldSpec) else load_world(world)
    model = motion_model(spec, seed=seed, people=people)
    labels: list[str] = []
    poses: list[Pose] = []
    for t in targets:
        if isinstance(t, str):
            if t in spec.places:
                poses.append(spec.places[t])
            elif t in spec.people:
                poses.append(spec.people[t].pose)
            else:
                raise UnknownName(f"place or person of world {spec.name!r}", t, [*spec.places, *spec.people])
            labels.append(t)
        else:
            v = [float(c) for c in t]
            if len(v) not in (2, 3) or not all(math.isfinite(c) for c in v):
                raise ValueError(f"travel_matrix: a point is (x, y) or (x, y, yaw) of finite numbers, got {t!r}")
            poses.append((v[0], v[1], v[2] if len(v) == 3 else 0.0))
            labels.append(",".join(f"{c:g}" for c in v))
    n = len(poses)
    times, dists = np.zeros((n, n)), np.zeros((n, n))
    for i, a in enumerate(poses):
        for j, b in enumerate(poses):
            if i != j:
                est = model.estimate(a, b)
                times[i, j], dists[i, j] = est.time_s, est.distance_m
    return TravelMatrix(spec.name, seed, tuple(labels), tuple(poses), times, dists)


def motion_model(spec: WorldSpec, seed: int = 1, people: bool = True) -> MotionEstimator:
    """A ready estimator for ``spec`` in its initial state (people where the file puts them)."""
    from robot.tiago import robot_dimensions

    scene = Scene(spec, robot_dimensions()[2])
    if people:
        for p in spec.people.values():
            scene.set_person(p.name, p.pose[0], p.pose[1], p.posture)
    return MotionEstimator(BasePlanner(spec, scene, seed=seed), DriveLimits.of(spec.robot),
                           open_planner(spec, scene.radius, seed))
