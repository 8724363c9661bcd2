"""A probabilistic roadmap of the apartment's free space, grown once with OMPL.

OMPL's PRM grows the roadmap over the **static** layer of the :class:`~robot.scene.Scene`
(walls and furniture) in R², with the robot as a disc.  Growth stops at a fixed number
of milestones and OMPL's random generator is seeded first
(:func:`ompl.util.RNG.setSeed`), so the same world and seed give the same roadmap.

The roadmap is then exported out of OMPL into numpy arrays, so no OMPL object outlives
the build (no nanobind leaks at exit), and completed:

* every edge is re-checked with the scene's exact segment test (OMPL checks motions
  by sampling at a resolution) and dropped if it grazes an obstacle;
* **corner milestones** are added around every convex corner of the walls and furniture,
  on an arc just outside the robot's clearance, and joined to every corner milestone
  they see: the visibility graph of the inflated obstacles, on which the shortest path
  around any set of boxes lies (within the arc's chord error, < 2 %).  Every passage the
  robot fits through — doorways included — is thereby in the roadmap, whatever the
  random samples did;
* nodes are added at the named places and through every door (centre and both sides);
* OMPL's seed: OMPL ignores ``RNG.setSeed(0)``, so the seed given to OMPL is
  ``seed + 1`` (:func:`ompl_seed`): seed 0 is a seed like any other, and the roadmap
  never depends on what the process ran before.

Shortest paths are searched per source and scene state by :mod:`robot.motion`
(Dijkstra, scipy).  Roadmaps are cached in-process by (world, radius, seed, size), and
on disk (:mod:`tasker.support.diskcache`, kind ``roadmap``, an ``.npz`` of the nodes, edges,
lengths, corner nodes and stats) under the SHA-256 of the world's ``repr``, the robot's
radius, the seed, the size, the OMPL and numpy versions and the source of this module, of
:mod:`robot.scene` and of :mod:`robot.spec` (whose exact tests complete the roadmap): a process
that finds it there grows nothing and loads the same arrays, bit for bit.  An entry that cannot be read
(truncated, corrupt, inconsistent) is grown again and rewritten.
"""

from __future__ import annotations

import io
import logging
import math
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.sparse import csr_matrix

from robot.scene import Scene
from robot.spec import DEFAULT_DENSITY, WorldSpec
from tasker.support.diskcache import content_key, installed_version, remembered

DISK_KIND = "roadmap"  # the on-disk cache's kind (tasker.support.diskcache)
_GEOMETRY = ("scene.py", "spec.py")  # the exact tests that complete the roadmap (disc_clear is spec's)
_CACHE: dict[tuple[object, ...], Roadmap] = {}
log = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class RoadmapStats:
    """How a roadmap was made: sizes, seed, and the OMPL planner that grew it."""

    nodes: int
    edges: int
    seed: int
    planner: str
    ompl_milestones: int
    dropped_edges: int


def ompl_setup(scene: Scene, resolution: float, dynamic: bool = False) -> Any:
    """An OMPL ``SimpleSetup`` for the base in R² over ``scene``'s static layer (walls, furniture),
    or, with ``dynamic``, over the whole scene (closed doors and people too).

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
    if dynamic:
        setup.setStateValidityChecker(lambda s: scene.free(s[0], s[1]))
    else:
        setup.setStateValidityChecker(lambda s: scene.static_free(s[0], s[1]))
    setup.getSpaceInformation().setStateValidityCheckingResolution(resolution)
    return setup


def ompl_seed(seed: int) -> int:
    """The seed handed to OMPL for our ``seed``: OMPL ignores 0, so every seed is shifted by one."""
    if seed < 0:
        raise ValueError(f"roadmap seed must be >= 0, got {seed}")
    return seed % (2**32 - 1) + 1


def _grow_with_ompl(scene: Scene, seed: int, milestones: int) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """Grow a PRM with OMPL and return its vertices ``(N, 2)`` and undirected edges."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)  # setSeed complains if RNGs already exist; the reseed still works
    ou.RNG.setSeed(ompl_seed(seed))
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


CORNER_ARC = 5  # milestones on the quarter arc around each convex corner


def corner_points(scene: Scene, boxes: np.ndarray) -> np.ndarray:
    """Milestones on a quarter arc outside each corner of ``boxes``, free of the static layer.

    The arc's radius is the robot's radius divided by ``cos(half the arc step)``, so the
    chord between two neighbouring milestones stays clear of the corner; the path along
    the chords is at most ``1/cos(11.25°) - 1`` ≈ 2 % longer than along the arc.
    """
    step = (math.pi / 2) / (CORNER_ARC - 1)
    radius = scene.radius / math.cos(step / 2) + 0.005
    out = []
    for x0, y0, x1, y1 in boxes:
        for cx, cy, a0 in ((x1, y1, 0.0), (x0, y1, math.pi / 2), (x0, y0, math.pi), (x1, y0, 1.5 * math.pi)):
            for k in range(CORNER_ARC):
                a = a0 + k * step
                out.append((cx + radius * math.cos(a), cy + radius * math.sin(a)))
    pts = [p for p in out if scene.static_free(*p)]
    return np.array(sorted(set((round(x, 6), round(y, 6)) for x, y in pts)), dtype=float).reshape(-1, 2)


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


def disk_key(spec: WorldSpec, scene: Scene, seed: int, milestones: int | None) -> str:
    """The on-disk cache key of the roadmap :meth:`Roadmap.for_world` returns: everything it is grown from."""
    return content_key(DISK_KIND, [repr(spec), repr(float(scene.radius)), str(seed), repr(milestones),
                                   installed_version("ompl"), f"numpy {np.__version__}", Path(__file__).read_bytes(),
                                   *(Path(__file__).with_name(m).read_bytes() for m in _GEOMETRY)])


class Roadmap:
    """The roadmap graph over the static layer: nodes ``(N, 2)``, undirected edges, lengths.

    Build with :meth:`for_world`, which caches.  Node order: OMPL's milestones, the
    corner milestones (:attr:`corner_nodes`), then door and place nodes.
    """

    def __init__(self, spec: WorldSpec, scene: Scene, seed: int = 1, milestones: int | None = None) -> None:
        (x0, y0), (x1, y1) = spec.bounds
        milestones = milestones or int(DEFAULT_DENSITY * (x1 - x0) * (y1 - y0))
        verts, edges = _grow_with_ompl(scene, seed, milestones)
        corners = corner_points(scene, scene.static)
        extra = [p for p in _door_points(spec) + [(x, y) for x, y, _ in spec.places.values()]
                 if scene.static_free(*p)]
        ompl_n = len(verts)
        self.corner_nodes = np.arange(ompl_n, ompl_n + len(corners))
        self.nodes = np.vstack([verts, corners, np.array(extra, dtype=float).reshape(-1, 2)])
        edge_arr = np.array(edges, dtype=int).reshape(-1, 2)
        new = [self._connect_extra(scene, ompl_n), self._visibility(scene)]
        edge_arr = np.vstack([edge_arr, *new])
        ok = scene.segments_free(self.nodes[edge_arr[:, 0]], self.nodes[edge_arr[:, 1]], dynamic=False)
        self.edges = np.unique(np.sort(edge_arr[ok], axis=1), axis=0)
        self.lengths = np.hypot(*(self.nodes[self.edges[:, 0]] - self.nodes[self.edges[:, 1]]).T)
        self.stats = RoadmapStats(len(self.nodes), len(self.edges), seed, "ompl.geometric.PRM", ompl_n,
                                  int((~ok).sum()))
        self._finish()

    def _finish(self) -> None:
        """The search graph (both directions of every edge) and the empty table cache."""
        n = len(self.nodes)
        self.graph = csr_matrix((np.concatenate([self.lengths, self.lengths]),
                                 (np.concatenate([self.edges[:, 0], self.edges[:, 1]]),
                                  np.concatenate([self.edges[:, 1], self.edges[:, 0]]))), shape=(n, n))
        self._tables: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def _visibility(self, scene: Scene) -> np.ndarray:
        """Edges between every pair of corner and added nodes that see each other (static layer)."""
        idx = np.arange(int(self.corner_nodes[0]) if len(self.corner_nodes) else len(self.nodes), len(self.nodes))
        ii, jj = np.triu_indices(len(idx), 1)
        a, b = idx[ii], idx[jj]
        ok = scene.segments_free(self.nodes[a], self.nodes[b], dynamic=False)
        return np.stack([a[ok], b[ok]], axis=1).reshape(-1, 2)

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
        """The roadmap of ``spec`` for a robot of ``scene.radius``: grown once per process, or
        loaded from the on-disk cache (see the module docstring) when a process grew it before."""
        key = (repr(spec), round(scene.radius, 4), seed, milestones)
        if key not in _CACHE:
            _CACHE[key] = remembered(DISK_KIND, disk_key(spec, scene, seed, milestones), ".npz",
                                     lambda: cls(spec, scene, seed, milestones), Roadmap.to_npz, cls.from_npz)
        return _CACHE[key]

    def to_npz(self) -> bytes:
        """The roadmap as ``.npz`` bytes (uncompressed, no pickles): what :meth:`from_npz` reads."""
        buf = io.BytesIO()
        s = self.stats
        np.savez(buf, nodes=self.nodes, edges=self.edges, lengths=self.lengths, corner_nodes=self.corner_nodes,
                 stats=np.array([s.nodes, s.edges, s.seed, s.ompl_milestones, s.dropped_edges], dtype=np.int64),
                 planner=np.array(s.planner))
        return buf.getvalue()

    @classmethod
    def from_npz(cls, data: bytes) -> Roadmap | None:
        """The roadmap saved by :meth:`to_npz`; ``None`` (and a debug log) when ``data`` is not a
        whole, consistent one."""
        try:
            with np.load(io.BytesIO(data), allow_pickle=False) as z:
                nodes, edges, lengths, corners = z["nodes"], z["edges"], z["lengths"], z["corner_nodes"]
                n_nodes, n_edges, seed, ompl_n, dropped = (int(v) for v in z["stats"])
                planner = str(z["planner"])
            n = len(nodes)
            if not (nodes.shape == (n, 2) and edges.shape == (n_edges, 2) and lengths.shape == (n_edges,)
                    and corners.ndim == 1 and n == n_nodes and nodes.dtype.kind == lengths.dtype.kind == "f"
                    and edges.dtype.kind == corners.dtype.kind == "i"
                    and (not edges.size or (edges.min() >= 0 and edges.max() < n))):
                raise ValueError("arrays of inconsistent shapes, types or indices")
        except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile) as exc:
            log.debug("roadmap cache entry unusable, grown again: %s", exc)
            return None
        roadmap = cls.__new__(cls)
        roadmap.nodes, roadmap.edges, roadmap.lengths, roadmap.corner_nodes = nodes, edges, lengths, corners
        roadmap.stats = RoadmapStats(n_nodes, n_edges, seed, planner, ompl_n, dropped)
        roadmap._finish()
        return roadmap

    def nearest(self, x: float, y: float, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The ``k`` nodes closest to ``(x, y)`` and their distances, nearest first."""
        d = np.hypot(self.nodes[:, 0] - x, self.nodes[:, 1] - y)
        idx = np.argpartition(d, min(k, len(d) - 1))[:k]
        idx = idx[np.argsort(d[idx])]
        return idx, d[idx]

    def all_pairs(self, blocked: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Shortest distances and predecessors between all nodes over the roadmap less the
        ``blocked`` edges (scipy Dijkstra from every node), cached per mask: one table per set
        of closed doors, shared by every planner over this roadmap.  ``pred[i, j]`` is ``j``'s
        predecessor on a shortest path from ``i`` (negative for ``i`` itself and unreachable)."""
        key = np.packbits(blocked).tobytes()
        if key not in self._tables:
            from scipy.sparse.csgraph import dijkstra

            e, w = self.edges[~blocked], self.lengths[~blocked]
            n = len(self.nodes)
            g = csr_matrix((np.concatenate([w, w]), (np.concatenate([e[:, 0], e[:, 1]]),
                                                     np.concatenate([e[:, 1], e[:, 0]]))), shape=(n, n))
            dist, pred = dijkstra(g, directed=True, return_predecessors=True)
            if len(self._tables) >= 4:
                self._tables.pop(next(iter(self._tables)))
            self._tables[key] = (dist, pred)
        return self._tables[key]

    def box_blocked(self, boxes: np.ndarray, radius: float) -> np.ndarray:
        """Mask of edges that pass closer than ``radius`` to any of ``boxes`` (closed doors)."""
        from robot.scene import segments_clear

        a, b = self.nodes[self.edges[:, 0]], self.nodes[self.edges[:, 1]]
        return ~segments_clear(a, b, np.asarray(boxes, dtype=float).reshape(-1, 4), radius)

    def disc_blocked(self, x: float, y: float, clearance: float) -> np.ndarray:
        """Mask of edges that pass closer than ``clearance`` to ``(x, y)`` (a person)."""
        from robot.scene import point_segment_distance

        a, b = self.nodes[self.edges[:, 0]], self.nodes[self.edges[:, 1]]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        near = ((hi[:, 0] > x - clearance) & (lo[:, 0] < x + clearance)
                & (hi[:, 1] > y - clearance) & (lo[:, 1] < y + clearance))
        out = np.zeros(len(a), dtype=bool)
        idx = np.flatnonzero(near)
        if len(idx):
            d = point_segment_distance(np.array([x]), np.array([y]), a[idx], b[idx])[:, 0]
            out[idx] = d < clearance
        return out


def path_length(points: list[tuple[float, float]] | np.ndarray) -> float:
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0


def heading(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])
