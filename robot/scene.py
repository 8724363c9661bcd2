"""The 2-D collision scene the base planner works in: boxes, doors and people as discs.

TIAGo's base is round, so base planning happens in R² with the robot as a disc of
radius ``radius`` (the footprint of the whole robot with its arm tucked, taken from the
Pinocchio model, plus a margin).  The scene has two layers:

* **static**: walls and furniture, which never move.  The roadmap is grown over this
  layer only, so it never has to be rebuilt.
* **dynamic**: closed doors and people.  Every change to this layer bumps
  :attr:`Scene.version`; anything cached from it (blocked roadmap edges, cost
  estimates) is keyed on that version and so is never stale.

Distances are exact (point/segment against axis-aligned box or disc), not sampled,
and vectorised over obstacles and segments with numpy.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from robot.spec import Box, WorldSpec, disc_clear, in_bounds

PERSON_RADIUS = {"standing": 0.25, "sitting": 0.35, "fallen": 0.6}
PEOPLE_TOLERANCE = 1e-3  # metres of slack: planned paths are rounded to 0.1 mm, the skill checks from the true pose


@dataclass(frozen=True, slots=True)
class Disc:
    """A round obstacle in the plane: a person, with the radius of their posture."""

    name: str
    x: float
    y: float
    r: float


def point_box_distance(px: np.ndarray, py: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Distance from points ``(P,)`` to boxes ``(M, 4)``: an array ``(P, M)``, 0 inside."""
    x0, y0, x1, y1 = (boxes[:, k][None, :] for k in range(4))
    dx = np.maximum(np.maximum(x0 - px[:, None], px[:, None] - x1), 0.0)
    dy = np.maximum(np.maximum(y0 - py[:, None], py[:, None] - y1), 0.0)
    return np.hypot(dx, dy)


def point_segment_distance(px: np.ndarray, py: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points ``(P,)`` to segments ``a→b`` ``(S, 2)``: an array ``(S, P)``."""
    d = b - a
    L2 = np.maximum((d * d).sum(axis=1), 1e-18)[:, None]
    t = np.clip(((px[None, :] - a[:, :1]) * d[:, :1] + (py[None, :] - a[:, 1:]) * d[:, 1:]) / L2, 0.0, 1.0)
    return np.hypot(a[:, :1] + t * d[:, :1] - px[None, :], a[:, 1:] + t * d[:, 1:] - py[None, :])


def pair_distance(a: np.ndarray, b: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Exact distance from segment ``a[i]→b[i]`` to box ``boxes[i]``, element-wise: ``(P,)``.

    Two disjoint convex polygons are closest at a vertex of one of them, so the
    distance is the least of the endpoints-to-box and corners-to-segment distances,
    or 0 when the segment crosses the box (slab test).
    """
    x0, y0, x1, y1 = boxes[:, 0], boxes[:, 1], boxes[:, 2], boxes[:, 3]
    d = b - a
    dist = np.minimum(_point_box(a, boxes), _point_box(b, boxes))
    corners = np.stack([np.stack([x0, y0], 1), np.stack([x1, y0], 1), np.stack([x0, y1], 1),
                        np.stack([x1, y1], 1)], 1)  # (P, 4, 2)
    L2 = np.maximum((d * d).sum(axis=1), 1e-18)[:, None]
    rel = corners - a[:, None, :]
    t = np.clip((rel * d[:, None, :]).sum(axis=2) / L2, 0.0, 1.0)
    gap = rel - t[:, :, None] * d[:, None, :]
    dist = np.minimum(dist, np.sqrt((gap * gap).sum(axis=2).min(axis=1)))
    # slab test: does the segment cross the box?
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        tx0, tx1 = (x0 - a[:, 0]) * inv[:, 0], (x1 - a[:, 0]) * inv[:, 0]
        ty0, ty1 = (y0 - a[:, 1]) * inv[:, 1], (y1 - a[:, 1]) * inv[:, 1]
    par_x, par_y = d[:, 0] == 0, d[:, 1] == 0
    in_x = (a[:, 0] >= x0) & (a[:, 0] <= x1)
    in_y = (a[:, 1] >= y0) & (a[:, 1] <= y1)
    lo_x = np.where(par_x, np.where(in_x, -np.inf, np.inf), np.minimum(tx0, tx1))
    hi_x = np.where(par_x, np.where(in_x, np.inf, -np.inf), np.maximum(tx0, tx1))
    lo_y = np.where(par_y, np.where(in_y, -np.inf, np.inf), np.minimum(ty0, ty1))
    hi_y = np.where(par_y, np.where(in_y, np.inf, -np.inf), np.maximum(ty0, ty1))
    cross = np.maximum(np.maximum(lo_x, lo_y), 0.0) <= np.minimum(np.minimum(hi_x, hi_y), 1.0)
    return np.where(cross, 0.0, dist)


def _point_box(p: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    dx = np.maximum(np.maximum(boxes[:, 0] - p[:, 0], p[:, 0] - boxes[:, 2]), 0.0)
    dy = np.maximum(np.maximum(boxes[:, 1] - p[:, 1], p[:, 1] - boxes[:, 3]), 0.0)
    return np.sqrt(dx * dx + dy * dy)


def segment_box_distance(a: np.ndarray, b: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Exact distance from segments ``a→b`` ``(S, 2)`` to boxes ``(M, 4)``: ``(S, M)``."""
    S, M = len(a), len(boxes)
    si, mi = np.repeat(np.arange(S), M), np.tile(np.arange(M), S)
    return pair_distance(a[si], b[si], boxes[mi]).reshape(S, M)


def segments_clear(a: np.ndarray, b: np.ndarray, boxes: np.ndarray, r: float) -> np.ndarray:
    """Which segments stay at least ``r`` from every box: a cheap bounding-box filter,
    then the exact test (:func:`pairs_near`) for the few (segment, box) pairs that pass it."""
    return BoxSet(boxes, r).clear(np.asarray(a, dtype=float), np.asarray(b, dtype=float))


class BoxSet:
    """Boxes ``(M, 4)`` and a clearance ``r``, ready for many segment tests (:meth:`clear`):
    the boxes grown by ``r`` (the bounding-box filter), their centres and half sizes."""

    __slots__ = ("boxes", "r", "r2", "grown", "centre", "half")

    def __init__(self, boxes: np.ndarray, r: float) -> None:
        self.boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
        self.r, self.r2 = float(r), float(r) * float(r)
        self.grown = (self.boxes + np.array([-r, -r, r, r])).T.copy()  # (4, M): x0, y0, x1, y1
        self.centre = (self.boxes[:, :2] + self.boxes[:, 2:]) * 0.5
        self.half = (self.boxes[:, 2:] - self.boxes[:, :2]) * 0.5

    def clear(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Which segments ``a[i]→b[i]`` stay at least ``r`` from every box (exact)."""
        ok = np.ones(len(a), dtype=bool)
        if not len(a) or not len(self.boxes):
            return ok
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        gx0, gy0, gx1, gy1 = self.grown
        near = ((lo[:, 0, None] < gx1) & (hi[:, 0, None] > gx0) & (lo[:, 1, None] < gy1) & (hi[:, 1, None] > gy0))
        si, mi = np.nonzero(near)
        if len(si):
            ok[si[_near(a[si], b[si], self.centre[mi], self.half[mi], self.r2)]] = False
        return ok


def pairs_near(a: np.ndarray, b: np.ndarray, boxes: np.ndarray, r: float) -> np.ndarray:
    """Does segment ``a[i]→b[i]`` come closer than ``r`` to box ``boxes[i]``?  Element-wise,
    exact: the answer of ``pair_distance(a, b, boxes) < r``, in far fewer numpy calls.

    The distance from the point at ``t`` on the segment to the box is convex in ``t``, linear
    where the point faces a side, the distance to a corner where it faces a corner, and 0
    inside.  So its least value over ``t ∈ [0, 1]`` is taken at an end, at the projection of a
    corner, or — if the segment crosses the box — where it crosses a diagonal (a chord of a
    rectangle crosses one of its diagonals).  Those eight parameters are evaluated at once.
    """
    boxes = np.asarray(boxes, dtype=float)
    return _near(a, b, (boxes[:, :2] + boxes[:, 2:]) * 0.5, (boxes[:, 2:] - boxes[:, :2]) * 0.5, r * r)


def _near(a: np.ndarray, b: np.ndarray, c: np.ndarray, h: np.ndarray, r2: float) -> np.ndarray:
    """:func:`pairs_near` for boxes given by centres ``c`` and half sizes ``h`` (column by
    column: for the few dozen pairs of a query, fewer and cheaper numpy calls than matrices)."""
    ax, ay = a[:, 0], a[:, 1]
    px, py = ax - c[:, 0], ay - c[:, 1]  # the start, box-centred
    dx, dy = b[:, 0] - ax, b[:, 1] - ay
    hx, hy = h[:, 0], h[:, 1]
    T = np.empty((8, len(a)))
    T[0] = 0.0
    T[1] = 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / (dx * dx + dy * dy)
        # corners (±hx, ±hy): t = ((corner - p)·d) / |d|²
        tc = -(px * dx + py * dy) * inv
        u, v = hx * dx * inv, hy * dy * inv
        T[2] = tc + u + v
        T[3] = tc + u - v
        T[4] = tc - u + v
        T[5] = tc - u - v
        # diagonals through the centre along (hx, hy) and (hx, -hy): cross(p + t d, e) = 0
        xh, yh, dxh, dyh = px * hy, py * hx, dx * hy, dy * hx
        T[6] = (yh - xh) / (dxh - dyh)
        T[7] = (xh + yh) / -(dxh + dyh)
    T = np.fmin(np.fmax(T, 0.0), 1.0)  # into [0, 1]; NaN (a zero-length or parallel case) to 0
    ex = np.maximum(np.abs(px + T * dx) - hx, 0.0)
    ey = np.maximum(np.abs(py + T * dy) - hy, 0.0)
    return np.asarray((ex * ex + ey * ey).min(axis=0) < r2)


SMALL = 64  # (segment, person) pairs up to which people_clear works in plain floats


def _people_clear_array(a: np.ndarray, b: np.ndarray, discs: list[Disc], radius: float, leaving: bool,
                        tol: float) -> np.ndarray:
    """:meth:`Scene.people_clear`'s arithmetic, vectorised over segments and people."""
    px, py = np.array([d.x for d in discs]), np.array([d.y for d in discs])
    limit = np.broadcast_to(np.array([d.r + radius for d in discs])[None, :], (len(a), len(discs)))
    if leaving:
        limit = np.minimum(limit, np.hypot(a[:, :1] - px[None, :], a[:, 1:] - py[None, :]))
    near = point_segment_distance(px, py, a, b) < limit - tol
    return np.asarray(~near.any(axis=1), dtype=bool)


def _people_clear_small(a: list[list[float]], b: list[list[float]], discs: list[Disc], radius: float,
                        leaving: bool, tol: float) -> np.ndarray:
    """:func:`_people_clear_array`'s arithmetic, operation for operation, in plain floats: for
    the few segments and people of a path check, cheaper than numpy's calls.  (A square root
    may round differently in its last bit, far inside the millimetre of tolerance.)"""
    out = []
    for (ax, ay), (bx, by) in zip(a, b, strict=True):
        dx, dy = bx - ax, by - ay
        l2 = max(dx * dx + dy * dy, 1e-18)
        clear = True
        for d in discs:
            limit = d.r + radius
            if leaving:
                limit = min(limit, math.hypot(ax - d.x, ay - d.y))
            t = min(max(((d.x - ax) * dx + (d.y - ay) * dy) / l2, 0.0), 1.0)
            if math.hypot(ax + t * dx - d.x, ay + t * dy - d.y) < limit - tol:
                clear = False
                break
        out.append(clear)
    return np.array(out, dtype=bool)


class Scene:
    """The plane as the base planner sees it; a disc robot of ``radius`` metres.

    Mutators (:meth:`set_door`, :meth:`set_person`) bump :attr:`version` whenever
    the dynamic layer really changes.
    """

    def __init__(self, spec: WorldSpec, radius: float) -> None:
        self.radius = float(radius)
        (self.xmin, self.ymin), (self.xmax, self.ymax) = spec.bounds
        self._bounds = spec.bounds
        self.static = np.array([o.box for o in spec.obstacles], dtype=float).reshape(-1, 4)
        self.walls = np.array([o.box for o in spec.obstacles if o.kind == "wall"], dtype=float).reshape(-1, 4)
        self._static_list: list[Box] = [o.box for o in spec.obstacles]
        self.door_boxes: dict[str, Box] = {n: d.box for n, d in spec.doors.items()}
        self.door_open: dict[str, bool] = {n: d.open for n, d in spec.doors.items()}
        self.people: dict[str, Disc] = {}
        self.making_way: set[str] = set()  # people who follow the robot: never in its way
        self.stepping_to: dict[str, tuple[float, float]] = {}  # people stepping aside: where to
        self.version = 0
        self._closed = np.zeros((0, 4))
        self._refresh_doors()

    # ---- dynamic layer -------------------------------------------------------------
    def _refresh_doors(self) -> None:
        self._closed = np.array([self.door_boxes[n] for n, o in sorted(self.door_open.items()) if not o],
                                dtype=float).reshape(-1, 4)

    def set_door(self, name: str, is_open: bool) -> None:
        if self.door_open[name] != is_open:
            self.door_open[name] = is_open
            self._refresh_doors()
            self.version += 1

    def set_person(self, name: str, x: float, y: float, posture: str) -> None:
        disc = Disc(name, round(x, 3), round(y, 3), PERSON_RADIUS[posture])
        if self.people.get(name) != disc:
            self.people[name] = disc
            self.version += 1

    def remove_person(self, name: str) -> None:
        if self.people.pop(name, None) is not None:
            self.version += 1

    def set_making_way(self, name: str, yes: bool) -> None:
        """Person ``name`` follows the robot (``yes``) or no longer does.  Someone who follows
        walks the robot's trail and steps aside for it, as a guided person does, so they are
        no obstacle to anything the robot plans or drives: :meth:`discs` leaves them out."""
        if (name in self.making_way) != yes:
            (self.making_way.add if yes else self.making_way.discard)(name)
            self.version += 1

    def set_stepping_to(self, name: str, spot: tuple[float, float] | None) -> None:
        """Person ``name`` is stepping aside to ``spot`` (None: not, or arrived)."""
        if spot is None:
            self.stepping_to.pop(name, None)
        else:
            self.stepping_to[name] = (float(spot[0]), float(spot[1]))

    @contextlib.contextmanager
    def as_expected(self) -> Iterator[None]:
        """The scene with everyone who is stepping aside already where they are going
        (:meth:`set_stepping_to`): what an estimate of the robot's motion should see, since by
        the time the robot gets there they stand at their spot.  Restored on exit."""
        moved = {n: self.people[n] for n in sorted(self.stepping_to) if n in self.people}
        if not moved:
            yield
            return
        for n, d in moved.items():
            x, y = self.stepping_to[n]
            self.people[n] = Disc(n, round(x, 3), round(y, 3), d.r)
        self.version += 1
        try:
            yield
        finally:
            self.people.update(moved)
            self.version += 1

    def closed_doors(self) -> np.ndarray:
        return self._closed

    def person_at(self, x: float, y: float, tolerance: float = 0.002) -> str | None:
        """The person whose centre is at ``(x, y)`` (first by name), if any."""
        for n, d in sorted(self.people.items()):
            if abs(d.x - x) <= tolerance and abs(d.y - y) <= tolerance:
                return n
        return None

    def discs(self, ignore: tuple[str, ...] = ()) -> list[Disc]:
        """The people in the robot's way (less ``ignore``): all but those making way for it."""
        return [d for n, d in sorted(self.people.items()) if n not in ignore and n not in self.making_way]

    # ---- queries ---------------------------------------------------------------------
    def in_bounds(self, x: float, y: float) -> bool:
        return in_bounds(self._bounds, x, y, self.radius)

    def static_free(self, x: float, y: float) -> bool:
        """Is the disc at ``(x, y)`` clear of walls and furniture (:func:`robot.spec.disc_clear`)?
        OMPL's validity checker calls it."""
        return disc_clear(self._static_list, self._bounds, self.radius, x, y)

    def sees(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        """Is there a line from ``a`` to ``b`` that crosses no wall and no closed door?  (Furniture
        is low: the robot beside a sofa still sees, and helps, the person lying behind it.)"""
        boxes = np.vstack([self.walls, self._closed])
        if not len(boxes):
            return True
        return bool(segments_clear(np.array([a], dtype=float), np.array([b], dtype=float), boxes, 1e-9)[0])

    def clearance(self, d: Disc) -> float:
        """How close the robot's centre may come to person ``d``'s centre: their radius plus its."""
        return d.r + self.radius

    def holds(self, d: Disc, point: tuple[float, float]) -> bool:
        """Is ``point`` inside person ``d``'s clearance (the robot there would touch them)?"""
        return math.hypot(point[0] - d.x, point[1] - d.y) < self.clearance(d)

    def beside(self, point: tuple[float, float]) -> tuple[str, ...]:
        """People whose clearance holds ``point`` (by name)."""
        return tuple(d.name for d in self.discs() if self.holds(d, point))

    def path_clear(self, points: list[tuple[float, float]] | np.ndarray, slack: float = 0.0,
                   ignore: tuple[str, ...] = ()) -> bool:
        """Is the polyline ``points`` clear of people (less ``ignore``), driven from its first
        point to its last?  What the ``navigate`` skill asks of the path ahead, from the
        base's true pose.  People the robot is beside at either end do not block it (it is
        leaving them, or stopping beside them); the planner prefers a path that leaves
        them without coming closer (:meth:`people_clear`), and every path it returns
        passes this test.
        """
        pts = np.asarray(points, float).reshape(-1, 2)
        if len(pts) < 2:
            return True
        start, goal = (float(pts[0, 0]), float(pts[0, 1])), (float(pts[-1, 0]), float(pts[-1, 1]))
        skip = set(ignore) | set(self.beside(start))
        discs = [d for d in self.discs() if d.name not in skip]
        return bool(self.people_clear(pts[:-1], pts[1:], discs, goal=goal, slack=slack).all())

    def people_clear(self, a: np.ndarray, b: np.ndarray, discs: tuple[Disc, ...] | list[Disc] | None = None,
                     leaving: bool = True, goal: tuple[float, float] | None = None,
                     slack: float = 0.0) -> np.ndarray:
        """**The** definition of "a person blocks this segment", used by the base planner,
        the ``navigate`` skill's check of the path ahead and the snapping of a start alike,
        so that a path the planner returns is one the skill drives.

        Segment ``a[i]→b[i]`` is blocked by a person when it comes closer to their centre
        than :meth:`clearance` — except that

        * the robot may already be closer (a person walked up to it, it braked beside
          them): with ``leaving``, a segment that starts inside a clearance is clear as
          long as it never comes closer than its start, so the robot can always back
          away, and a path never *enters* a clearance on its way;
        * the robot may be sent next to someone (0.9 m from a fallen person, to a place
          a person stands on): people whose clearance holds ``goal`` do not block the
          path to it — they are who the robot is going to stop beside.

        Without ``leaving`` (the undirected roadmap edges) a segment is blocked whenever
        it comes closer than the clearance.  ``discs`` defaults to everyone in the scene.
        ``slack`` metres closer are tolerated: the planner plans with none; the skill,
        which checks from the base's true pose (a waypoint counts as reached within a
        couple of centimetres), with a little, so that it accepts every path the planner
        returns as the base really drives it.
        """
        a, b = np.asarray(a, float).reshape(-1, 2), np.asarray(b, float).reshape(-1, 2)
        ok = np.ones(len(a), dtype=bool)
        discs = self.discs() if discs is None else list(discs)
        if goal is not None:
            discs = [d for d in discs if not self.holds(d, goal)]
        if not discs or not len(a):
            return ok
        tol = PEOPLE_TOLERANCE + slack
        if len(a) * len(discs) <= SMALL:
            return _people_clear_small(a.tolist(), b.tolist(), discs, self.radius, leaving, tol)
        # people farther from the segments' bounding box than their clearance block none of
        # them (the limit below never exceeds the clearance): dropped before any distance
        x0, y0 = np.minimum(a, b).min(axis=0).tolist()
        x1, y1 = np.maximum(a, b).max(axis=0).tolist()
        discs = [d for d in discs if math.hypot(max(x0 - d.x, 0.0, d.x - x1), max(y0 - d.y, 0.0, d.y - y1))
                 < self.clearance(d)]
        if not discs:
            return ok
        return _people_clear_array(a, b, discs, self.radius, leaving, tol)

    def free(self, x: float, y: float, ignore: tuple[str, ...] = ()) -> bool:
        """Static and dynamic layers: walls, furniture, closed doors, people (less ``ignore``)."""
        if not self.static_free(x, y):
            return False
        p = np.array([x]), np.array([y])
        if len(self._closed) and point_box_distance(*p, self._closed).min() < self.radius:
            return False
        return all(math.hypot(x - d.x, y - d.y) >= d.r + self.radius for d in self.discs(ignore))

    def segments_free(self, a: np.ndarray, b: np.ndarray, dynamic: bool = True, static: bool = True,
                      goal: tuple[float, float] | None = None, slack: float = 0.0,
                      ignore: tuple[str, ...] = ()) -> np.ndarray:
        """Which segments ``a[i]→b[i]`` the disc robot can sweep along (exact, vectorised).

        The dynamic layer is closed doors and people; people by :meth:`people_clear`
        (driven from ``a`` to ``b``, stopping at ``goal``, ``slack`` metres tolerated),
        less the people named in ``ignore``.
        """
        a, b = np.asarray(a, float).reshape(-1, 2), np.asarray(b, float).reshape(-1, 2)
        ok = np.ones(len(a), dtype=bool)
        r = self.radius
        if static:
            ok &= (a[:, 0] >= self.xmin + r) & (a[:, 0] <= self.xmax - r) & (b[:, 0] >= self.xmin + r)
            ok &= (b[:, 0] <= self.xmax - r) & (a[:, 1] >= self.ymin + r) & (a[:, 1] <= self.ymax - r)
            ok &= (b[:, 1] >= self.ymin + r) & (b[:, 1] <= self.ymax - r)
            ok &= segments_clear(a, b, self.static, r)
        if dynamic:
            ok &= segments_clear(a, b, self._closed, r)
            ok &= self.people_clear(a, b, self.discs(ignore), goal=goal, slack=slack)
        return ok
