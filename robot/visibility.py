"""What the disc robot can sweep in a straight line, tested once: the base planner's memos.

Testing segments against walls, furniture, the bounds and closed doors is what a motion
query spends its time on (:mod:`robot.motion`).  :class:`Visibility` answers those tests
exactly (:class:`robot.scene.BoxSet`, the bounds as four boxes outside them) and remembers
them, keyed by exactly what they depend on — the set of closed doors; people never enter
(they are judged afresh by :meth:`Scene.people_clear <robot.scene.Scene.people_clear>`):

* between roadmap nodes (``int8 (N, N)``, per set of closed doors), seeded from the roadmap
  itself: its edges are clear of walls and furniture (closed doors block those in the door
  mask), and every pair of corner, door and place nodes that is not an edge is blocked (the
  roadmap's visibility graph tested them all);
* from a point — a start, a goal — to every roadmap node, with whether the robot may stand
  there and its link candidates (:class:`PointMemo`, per point and set of closed doors).

A start asked again, a goal asked from elsewhere, a route through known nodes test nothing
new; what is not known is tested in one vectorised call (:meth:`Visibility.settle`).
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from robot.roadmap import Roadmap
from robot.scene import BoxSet, Scene

Point = tuple[float, float]
Doors = tuple[str, ...]
POINTS = 1024  # point memos kept (least recently used dropped)
DOOR_SETS = 4  # node-to-node memos kept, one per set of closed doors


@dataclass(slots=True)
class PointMemo:
    """What is known of one point under one set of closed doors."""

    point: Point
    vis: np.ndarray  # int8 per roadmap node: 1 visible, 0 not, -1 not tested yet
    free: bool | None = None  # may the robot stand there
    cand: tuple[np.ndarray, np.ndarray] | None = None  # link candidates and their distances


class Visibility:
    """Exact straight-line tests for a disc robot over ``roadmap`` in ``scene``, memoised."""

    def __init__(self, roadmap: Roadmap, scene: Scene) -> None:
        self.roadmap, self.scene = roadmap, scene
        n = len(roadmap.nodes)
        self.first = int(roadmap.corner_nodes[0]) if len(roadmap.corner_nodes) else n  # not OMPL samples
        self.x, self.y = roadmap.nodes[:, 0].copy(), roadmap.nodes[:, 1].copy()
        self._boxes: dict[Doors, BoxSet] = {}
        self._nodes: OrderedDict[Doors, np.ndarray] = OrderedDict()
        self._points: OrderedDict[tuple[Point, Doors], PointMemo] = OrderedDict()

    def forget_points(self) -> None:
        """Drop every point memo (what depends on the scene alone stays)."""
        self._points.clear()

    def boxes(self, doors: Doors) -> BoxSet:
        """What the robot's centre keeps ``radius`` from: walls, furniture, the closed ``doors``
        and four boxes outside the bounds (so the bounds are tested alike)."""
        if doors not in self._boxes:
            sc, big = self.scene, 10.0
            outside = np.array([[sc.xmin - big, sc.ymin - big, sc.xmin, sc.ymax + big],
                                [sc.xmax, sc.ymin - big, sc.xmax + big, sc.ymax + big],
                                [sc.xmin - big, sc.ymin - big, sc.xmax + big, sc.ymin],
                                [sc.xmin - big, sc.ymax, sc.xmax + big, sc.ymax + big]])
            closed = np.array([sc.door_boxes[name] for name in doors], dtype=float).reshape(-1, 4)
            self._boxes[doors] = BoxSet(np.vstack([sc.static, closed, outside]), sc.radius)
        return self._boxes[doors]

    def free(self, a: np.ndarray, b: np.ndarray, doors: Doors) -> np.ndarray:
        """Which segments ``a[i]→b[i]`` are clear of the bounds, walls, furniture and ``doors``."""
        return self.boxes(doors).clear(a, b)

    def between_nodes(self, doors: Doors, door_mask: np.ndarray) -> np.ndarray:
        """The node-to-node memo under ``doors`` (``door_mask``: the roadmap edges they block);
        a node "sees" itself unless it stands in a closed door."""
        if doors in self._nodes:
            self._nodes.move_to_end(doors)
            return self._nodes[doors]
        rm = self.roadmap
        n = len(rm.nodes)
        memo = np.full((n, n), -1, dtype=np.int8)
        memo[self.first:, self.first:] = 0
        ok = (~door_mask).astype(np.int8)
        memo[rm.edges[:, 0], rm.edges[:, 1]] = ok
        memo[rm.edges[:, 1], rm.edges[:, 0]] = ok
        memo[np.arange(n), np.arange(n)] = self.free(rm.nodes, rm.nodes, doors)
        self._nodes[doors] = memo
        if len(self._nodes) > DOOR_SETS:
            self._nodes.popitem(last=False)
        return memo

    def point(self, p: Point, doors: Doors) -> PointMemo:
        """The memo of point ``p`` under ``doors``."""
        key = (p, doors)
        memo = self._points.get(key)
        if memo is None:
            memo = PointMemo(p, np.full(len(self.roadmap.nodes), -1, dtype=np.int8))
            self._points[key] = memo
            if len(self._points) > POINTS:
                self._points.popitem(last=False)
        else:
            self._points.move_to_end(key)
        return memo

    def settle(self, doors: Doors, p: Point, idx: np.ndarray, extra: np.ndarray | None = None) -> np.ndarray:
        """Test, in one exact call, the segments from ``p`` to the roadmap nodes ``idx`` the memo
        does not know yet (and store the answers), and those from ``p`` to the ``extra`` points
        (ring milestones, a start seen from its goal), whose answers are returned."""
        vis = self.point(p, doors).vis
        todo = idx[vis[idx] < 0]
        ends = self.roadmap.nodes[todo] if extra is None else np.vstack([self.roadmap.nodes[todo], extra])
        if not len(ends):
            return np.zeros(0, dtype=bool)
        ok = self.free(np.broadcast_to(np.asarray(p, dtype=float), ends.shape), ends, doors)
        vis[todo] = ok[: len(todo)]
        return ok[len(todo):]

    def point_free(self, p: Point, doors: Doors) -> bool:
        """May the robot stand on ``p``: clear of the bounds, walls, furniture and ``doors``?
        (Plain floats: for one point they beat numpy's call overhead.)"""
        memo = self.point(p, doors)
        if memo.free is None:
            x, y = p
            free = self.scene.static_free(x, y)
            r2 = self.scene.radius * self.scene.radius
            for name in doors if free else ():
                x0, y0, x1, y1 = self.scene.door_boxes[name]
                dx = x0 - x if x < x0 else (x - x1 if x > x1 else 0.0)
                dy = y0 - y if y < y0 else (y - y1 if y > y1 else 0.0)
                if dx * dx + dy * dy < r2:
                    free = False
            memo.free = free
        return memo.free

    # ---- link candidates -------------------------------------------------------------
    def candidates(self, points: tuple[Point, ...], doors: Doors) -> list[tuple[np.ndarray, np.ndarray]]:
        """The link candidates among the roadmap's nodes of each point (:meth:`select`),
        memoised; those not known yet selected together."""
        memos = [self.point(p, doors) for p in points]
        todo = [m for m in memos if m.cand is None]
        if todo:
            for m, got in zip(todo, self.select(np.array([m.point for m in todo]), self.x, self.y), strict=True):
                m.cand = got
        return [m.cand for m in memos if m.cand is not None]

    def select(self, here: np.ndarray, x: np.ndarray, y: np.ndarray,
               k: int = 16) -> list[tuple[np.ndarray, np.ndarray]]:
        """The link candidates of each point of ``here`` among the nodes at ``x``, ``y``: its ``k``
        nearest and the nearest 24 within 3 m from index ``first`` on (corners, doors, places,
        rings), sorted, with their distances.  Chosen by squared distance (square roots only
        for the chosen; the same order)."""
        dx, dy = x[None, :] - here[:, :1], y[None, :] - here[:, 1:]
        d2 = dx * dx + dy * dy
        rows = np.arange(len(here))[:, None]
        pick = np.zeros(d2.shape, dtype=bool)
        pick[rows, np.argpartition(d2, min(k, d2.shape[1] - 1), axis=1)[:, :k]] = True
        # the nearest 24 within 3 m (9 m²) of the others, ties to the lower index, every row at once
        far = d2[:, self.first:]
        order = np.argsort(np.where(far <= 9.0, far, np.inf), axis=1, kind="stable")[:, :24]
        pick[:, self.first:][rows, order] |= far[rows, order] <= 9.0
        r, cand = np.nonzero(pick)
        dist = np.hypot(x[cand] - here[r, 0], y[cand] - here[r, 1])
        cut = np.cumsum(pick.sum(axis=1))[:-1]
        return list(zip(np.split(cand, cut), np.split(dist, cut), strict=True))
