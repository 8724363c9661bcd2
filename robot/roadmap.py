"""A probabilistic roadmap of the apartment's free space, grown once with OMPL.

OMPL's PRM grows the roadmap over the **static** layer of the :class:`~robot.scene.Scene`
(walls and furniture) in R², with the robot as a disc.  Growth stops at a fixed number
of milestones and OMPL's random generator is seeded first
(:func:`ompl.util.RNG.setSeed`), so the same world and seed give the same roadmap.

The roadmap is then exported out of OMPL into numpy arrays, so no OMPL object outlives
the build (no nanobind leaks at exit), and completed:

* every edge is re-checked with the scene's exact segment test (OMPL checks motions
  by sampling at a resolution) and dropped if it grazes an obstacle;
* nodes are added at the named places and through every door (centre and both sides),
  the narrow passages uniform sampling finds last;
* all-pairs shortest paths are computed once (scipy), so a query on an unobstructed
  roadmap is a table look-up.

Roadmaps are cached in-process by (world, radius, seed, size).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import shortest_path

from robot.scene import Scene
from robot.spec import WorldSpec

DEFAULT_DENSITY = 13.0  # milestones per square metre of the bounding box
_CACHE: dict[tuple[object, ...], Roadmap] = {}


@dataclass(frozen=True, slots=True)
class RoadmapStats:
    """How a roadmap was made: sizes, seed, and the OMPL planner that grew it."""

    nodes: int
    edges: int
    seed: int
    planner: str
    ompl_milestones: int
    dropped_edges: int


def ompl_setup(scene: Scene, resolution: float) -> Any:
    """An OMPL ``SimpleSetup`` for the base in R² over ``scene``'s static layer (walls, furniture).

    ``resolution`` is OMPL's validity-checking resolution, a fraction of the space's extent.
    """
    from ompl import base as ob
    from ompl import geometric as og

    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, scene.xmin)
    bounds.setHigh(0, scene.xmax)
    bounds.setLow(1, scene.ymin)
    bounds.setHigh(1, scene.ymax)
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(lambda s: scene.static_free(s[0], s[1]))
    setup.getSpaceInformation().setStateValidityCheckingResolution(resolution)
    return setup


def _grow_with_ompl(scene: Scene, seed: int, milestones: int) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """Grow a PRM with OMPL and return its vertices ``(N, 2)`` and undirected edges."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)  # setSeed complains if RNGs already exist; the reseed still works
    ou.RNG.setSeed(seed)
    setup = ompl_setup(scene, 0.01)  # coarse: every edge is re-checked exactly afterwards
    si = setup.getSpaceInformation()
    prm = og.PRM(si)
    setup.setPlanner(prm)
    setup.setup()
    prm.growRoadmapPtc(ob.PlannerTerminationCondition(lambda p=prm: p.milestoneCount() >= milestones))
    data = ob.PlannerData(si)
    prm.getPlannerData(data)
    n = data.numVertices()
    verts = np.array([[data.getVertex(i).getState()[0], data.getVertex(i).getState()[1]] for i in range(n)])
    edges = [(i, int(j)) for i in range(n) for j in data.getEdges(i) if i < j]
    ou.setLogLevel(ou.LOG_WARN)
    del prm, setup, si, data
    return verts.reshape(-1, 2), edges


def _door_points(spec: WorldSpec) -> list[tuple[float, float]]:
    pts = []
    for d in spec.doors.values():
        x0, y0, x1, y1 = d.box
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        if x1 - x0 < y1 - y0:  # a door in a vertical wall: pass along x
            pts += [(cx, cy), (cx - 0.45, cy), (cx + 0.45, cy)]
        else:
            pts += [(cx, cy), (cx, cy - 0.45), (cx, cy + 0.45)]
    return pts


class Roadmap:
    """The roadmap graph: nodes, edge lengths, and all-pairs distances and predecessors.

    Build with :meth:`for_world`, which caches.  ``dist[i, j]`` is the roadmap
    distance between nodes ``i`` and ``j`` (``inf`` if disconnected) and
    :meth:`route` walks the predecessor table.
    """

    def __init__(self, spec: WorldSpec, scene: Scene, seed: int = 1, milestones: int | None = None) -> None:
        (x0, y0), (x1, y1) = spec.bounds
        milestones = milestones or int(DEFAULT_DENSITY * (x1 - x0) * (y1 - y0))
        verts, edges = _grow_with_ompl(scene, seed, milestones)
        extra = [p for p in _door_points(spec) + [(x, y) for x, y, _ in spec.places.values()]
                 if scene.static_free(*p)]
        ompl_n = len(verts)
        self.nodes = np.vstack([verts, np.array(extra, dtype=float).reshape(-1, 2)])
        edge_arr = np.array(edges, dtype=int).reshape(-1, 2)
        new = self._connect_extra(scene, ompl_n)
        edge_arr = np.vstack([edge_arr, new]) if len(new) else edge_arr
        ok = scene.segments_free(self.nodes[edge_arr[:, 0]], self.nodes[edge_arr[:, 1]], dynamic=False)
        self.edges = edge_arr[ok]
        self.lengths = np.hypot(*(self.nodes[self.edges[:, 0]] - self.nodes[self.edges[:, 1]]).T)
        n = len(self.nodes)
        self.graph = csr_matrix((np.concatenate([self.lengths, self.lengths]),
                                 (np.concatenate([self.edges[:, 0], self.edges[:, 1]]),
                                  np.concatenate([self.edges[:, 1], self.edges[:, 0]]))), shape=(n, n))
        self.dist, self.pred = shortest_path(self.graph, method="D", directed=False, return_predecessors=True)
        self.stats = RoadmapStats(n, len(self.edges), seed, "ompl.geometric.PRM", ompl_n,
                                  int((~ok).sum()))

    def _connect_extra(self, scene: Scene, first: int, k: int = 14, reach: float = 2.0) -> np.ndarray:
        """Edges from each added node (door, place) to its nearest visible nodes."""
        out: list[tuple[int, int]] = []
        for i in range(first, len(self.nodes)):
            d = np.hypot(*(self.nodes[:i] - self.nodes[i]).T)
            near = np.argsort(d)[: k * 2]
            near = near[d[near] <= reach][: k * 2]
            if not len(near):
                continue
            ok = scene.segments_free(np.repeat(self.nodes[i : i + 1], len(near), axis=0), self.nodes[near],
                                     dynamic=False)
            out += [(int(j), i) for j in near[ok][:k]]
        return np.array(out, dtype=int).reshape(-1, 2)

    @classmethod
    def for_world(cls, spec: WorldSpec, scene: Scene, seed: int = 1, milestones: int | None = None) -> Roadmap:
        """The roadmap of ``spec`` for a robot of ``scene.radius``; grown once per process."""
        key = (repr(spec), round(scene.radius, 4), seed, milestones)
        if key not in _CACHE:
            _CACHE[key] = cls(spec, scene, seed, milestones)
        return _CACHE[key]

    def nearest(self, x: float, y: float, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The ``k`` nodes closest to ``(x, y)`` and their distances, nearest first."""
        d = np.hypot(self.nodes[:, 0] - x, self.nodes[:, 1] - y)
        idx = np.argpartition(d, min(k, len(d) - 1))[:k]
        idx = idx[np.argsort(d[idx])]
        return idx, d[idx]

    def route(self, i: int, j: int, pred: np.ndarray | None = None) -> list[int]:
        """Node indices from ``i`` to ``j`` along shortest paths (``pred`` rows are sources)."""
        table = self.pred if pred is None else pred
        out = [j]
        while out[-1] != i:
            p = int(table[i, out[-1]]) if table.ndim == 2 else int(table[out[-1]])
            if p < 0:
                return []
            out.append(p)
        return out[::-1]

    def blocked_edges(self, scene: Scene, ignore: tuple[str, ...]) -> np.ndarray:
        """Mask of edges that the dynamic layer (closed doors, people not ignored) blocks."""
        a, b = self.nodes[self.edges[:, 0]], self.nodes[self.edges[:, 1]]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        r = scene.radius
        boxes = [tuple(bx) for bx in scene.closed_doors()] + [
            (d.x - d.r, d.y - d.r, d.x + d.r, d.y + d.r) for d in scene.discs(ignore)]
        near = np.zeros(len(a), dtype=bool)
        for x0, y0, x1, y1 in boxes:  # cheap bounding-box filter before the exact test
            near |= (hi[:, 0] > x0 - r) & (lo[:, 0] < x1 + r) & (hi[:, 1] > y0 - r) & (lo[:, 1] < y1 + r)
        blocked = np.zeros(len(a), dtype=bool)
        if near.any():
            idx = np.flatnonzero(near)
            blocked[idx] = ~scene.segments_free(a[idx], b[idx], static=False, ignore=ignore)
        return blocked


def path_length(points: list[tuple[float, float]] | np.ndarray) -> float:
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0


def heading(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])
