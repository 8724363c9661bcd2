"""Base path planning and motion-cost estimates over the roadmap.

:class:`BasePlanner` answers "how does the base get from here to there" on the
:class:`~robot.roadmap.Roadmap` grown once by OMPL:

1. start and goal are linked to their nearest visible roadmap nodes (exact tests,
   people standing at the start or goal are ignored: the robot is beside them);
2. if nothing dynamic (closed door, person) blocks a roadmap edge, the best route is
   a look-up in the all-pairs table; otherwise a Dijkstra search (scipy) runs on the
   roadmap less its blocked edges;
3. the route is shortened: the shortest chain of mutually visible route points.

:class:`MotionEstimator` implements :class:`tasker.world.MotionModel`: time comes from
:class:`DriveLimits` with the same stop–turn–drive profile the controller executes
(:mod:`robot.control`), so estimates match what MuJoCo takes.

**Caching.**  Results are cached by (start, goal, ``Scene.version``).  The version
changes whenever a door opens or closes or a person moves or changes posture, so a
cached answer can never describe a scene that no longer exists; the roadmap itself
covers only walls and furniture and never needs rebuilding.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from robot.roadmap import Roadmap, heading, path_length
from robot.scene import Scene
from robot.spec import RobotSpec, WorldSpec
from tasker.world import UNREACHABLE, MotionEstimate, Pose

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


class BasePlanner:
    """Collision-free paths for the disc robot in ``scene``, from the world's roadmap."""

    def __init__(self, spec: WorldSpec, scene: Scene, seed: int = 1, milestones: int | None = None,
                 cache_size: int = 4096) -> None:
        self.scene = scene
        self.roadmap = Roadmap.for_world(spec, scene, seed, milestones)
        self._cache: OrderedDict[tuple[object, ...], tuple[Point, ...] | None] = OrderedDict()
        self._cache_size = cache_size
        self._blocked: dict[tuple[int, tuple[str, ...]], tuple[bool, np.ndarray]] = {}

    def _links(self, s: Point, g: Point, ignore: tuple[str, ...], k: int = 12) -> tuple[
            bool, tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
        """Is ``s→g`` free, and which nearest nodes each end sees: one vectorised test."""
        si, sd = self.roadmap.nearest(s[0], s[1], k)
        gi, gd = self.roadmap.nearest(g[0], g[1], k)
        nodes = self.roadmap.nodes
        a = np.vstack([[s], np.repeat([s], len(si), axis=0), np.repeat([g], len(gi), axis=0)])
        b = np.vstack([[g], nodes[si], nodes[gi]])
        ok = self.scene.segments_free(a, b, ignore=ignore)
        ok_s, ok_g = ok[1 : 1 + len(si)], ok[1 + len(si) :]
        return bool(ok[0]), (si[ok_s], sd[ok_s]), (gi[ok_g], gd[ok_g])

    def _blocked_graph(self, ignore: tuple[str, ...]) -> tuple[bool, np.ndarray]:
        key = (self.scene.version, ignore)
        if key not in self._blocked:
            if len(self._blocked) > 64:
                self._blocked.clear()
            mask = self.roadmap.blocked_edges(self.scene, ignore)
            self._blocked[key] = (bool(mask.any()), mask)
        return self._blocked[key]

    def _search(self, src: tuple[np.ndarray, np.ndarray], dst: tuple[np.ndarray, np.ndarray],
                ignore: tuple[str, ...]) -> list[int] | None:
        rm = self.roadmap
        any_blocked, mask = self._blocked_graph(ignore)
        (si, sd), (gi, gd) = src, dst
        if not any_blocked:
            total = sd[:, None] + rm.dist[np.ix_(si, gi)] + gd[None, :]
            a, b = np.unravel_index(int(np.argmin(total)), total.shape)
            if not math.isfinite(total[a, b]):
                return None
            return rm.route(int(si[a]), int(gi[b]))
        keep = ~mask
        n = len(rm.nodes)
        e, w = rm.edges[keep], rm.lengths[keep]
        rows = np.concatenate([e[:, 0], e[:, 1], np.full(len(si), n), gi])
        cols = np.concatenate([e[:, 1], e[:, 0], si, np.full(len(gi), n + 1)])
        graph = csr_matrix((np.concatenate([w, w, sd + 1e-9, gd + 1e-9]), (rows, cols)), shape=(n + 2, n + 2))
        dist, pred = dijkstra(graph, directed=True, indices=n, return_predecessors=True)
        if not math.isfinite(dist[n + 1]):
            return None
        route = [n + 1]
        while route[-1] != n:
            route.append(int(pred[route[-1]]))
        return route[-2:0:-1]

    def _shortcut(self, pts: list[Point], ignore: tuple[str, ...]) -> list[Point]:
        """The shortest chain through ``pts`` whose links are all collision-free."""
        n = len(pts)
        if n <= 2:
            return pts
        P = np.asarray(pts)
        ii, jj = np.triu_indices(n, 1)
        free = np.zeros((n, n), dtype=bool)
        free[ii, jj] = self.scene.segments_free(P[ii], P[jj], ignore=ignore)
        free[np.arange(n - 1), np.arange(1, n)] = True  # route links are valid by construction
        seg = np.hypot(*(P[None, :, :] - P[:, None, :]).transpose(2, 0, 1))
        best = np.full(n, math.inf)
        back = np.zeros(n, dtype=int)
        best[0] = 0.0
        for j in range(1, n):
            cand = np.where(free[:j, j], best[:j] + seg[:j, j], math.inf)
            back[j] = int(np.argmin(cand))
            best[j] = cand[back[j]]
        out = [n - 1]
        while out[-1] != 0:
            out.append(int(back[out[-1]]))
        return [pts[k] for k in reversed(out)]

    def plan(self, start: Point, goal: Point) -> tuple[Point, ...] | None:
        """A collision-free polyline from ``start`` to ``goal``, or None when there is none."""
        s = (round(float(start[0]), 4), round(float(start[1]), 4))
        g = (round(float(goal[0]), 4), round(float(goal[1]), 4))
        key = (s, g, self.scene.version)
        if key in self._cache:
            self._cache.move_to_end(key)
            return self._cache[key]
        result = self._plan(s, g)
        self._cache[key] = result
        if len(self._cache) > self._cache_size:
            self._cache.popitem(last=False)
        return result

    def _plan(self, s: Point, g: Point) -> tuple[Point, ...] | None:
        ignore = self.scene.blocking_discs([s, g])
        if not (self.scene.free(*s, ignore=ignore) and self.scene.free(*g, ignore=ignore)):
            return None
        if math.hypot(g[0] - s[0], g[1] - s[1]) < 1e-6:
            return (s, g)
        direct, src, dst = self._links(s, g, ignore)
        if direct:
            return (s, g)
        if not len(src[0]) or not len(dst[0]):
            return None
        route = self._search(src, dst, ignore)
        if route is None:
            return None
        pts = [s] + [(float(x), float(y)) for x, y in self.roadmap.nodes[route]] + [g]
        return tuple(self._shortcut(pts, ignore))


class MotionEstimator:
    """:class:`tasker.world.MotionModel` for the base: OMPL-roadmap paths, profile-timed.

    An unreachable goal (walled off, behind a closed door, in collision) gives
    :data:`tasker.world.UNREACHABLE`: infinite time, never zero.
    """

    def __init__(self, planner: BasePlanner, limits: DriveLimits, open_planner: BasePlanner | None = None) -> None:
        self.planner = planner
        self.limits = limits
        self.open_planner = open_planner

    def estimate(self, start: Pose, goal: Pose) -> MotionEstimate:
        return self._estimate(self.planner, start, goal)

    def estimate_ignoring_doors(self, start: Pose, goal: Pose) -> MotionEstimate:
        """As :meth:`estimate` with every door open and nobody in the way.

        A task domain that models doors (``door_between``, ``open``) needs the geometry
        behind a closed door: whether the door is open is the plan's business.
        """
        return self._estimate(self.open_planner or self.planner, start, goal)

    def _estimate(self, planner: BasePlanner, start: Pose, goal: Pose) -> MotionEstimate:
        path = planner.plan((start[0], start[1]), (goal[0], goal[1]))
        if path is None:
            return UNREACHABLE
        pts = list(path)
        time_s = self.limits.travel_time(pts, start[2], goal[2])
        end = (float(goal[0]), float(goal[1]), float(goal[2]))
        return MotionEstimate(True, time_s, path_length(pts), end, tuple(pts))


def motion_model(spec: WorldSpec, seed: int = 1, people: bool = True) -> MotionEstimator:
    """A ready estimator for ``spec`` in its initial state (people where the file puts them)."""
    from robot.tiago import robot_dimensions

    scene = Scene(spec, robot_dimensions()[2])
    if people:
        for p in spec.people.values():
            scene.set_person(p.name, p.pose[0], p.pose[1], p.posture)
    return MotionEstimator(BasePlanner(spec, scene, seed=seed), DriveLimits.of(spec.robot),
                           open_planner(spec, scene.radius, seed))


def open_planner(spec: WorldSpec, radius: float, seed: int = 1, milestones: int | None = None) -> BasePlanner:
    """A planner over the same roadmap with every door open and no people (see
    :meth:`MotionEstimator.estimate_ignoring_doors`)."""
    scene = Scene(spec, radius)
    for name in spec.doors:
        scene.set_door(name, True)
    return BasePlanner(spec, scene, seed=seed, milestones=milestones)
