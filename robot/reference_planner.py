"""The slow reference for the base planner's speed-ups: the plain layered search.

:class:`PlainPlanner` is :class:`robot.motion.BasePlanner` as it was before its queries
were made fast (issue 11, item 6), kept verbatim apart from its name: every segment tested
each time it is needed, by its exact distance (``pair_distance``; no visibility memo), a
scipy Dijkstra for every start, the shortcut's dynamic programme in numpy.

Nothing in a run uses it.  It is kept, slow on purpose, for two readers that must agree on
what "before" means: ``tests/robot/test_fast_queries.py`` holds the fast planner to its
answers, and ``benchmarks/bench_robot.py`` measures it as the "before" of the same run.  It
lives in the package, not under ``tests/``, so that the benchmarks import nothing from the
tests.
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from robot.motion import RING, RING_SLACK, SNAP_REACH, SNAP_STEP, Layer, Point
from robot.roadmap import Roadmap
from robot.scene import Disc, Scene, pair_distance, point_box_distance
from robot.spec import WorldSpec


def segments_clear(a: np.ndarray, b: np.ndarray, boxes: np.ndarray, r: float) -> np.ndarray:
    """The segment test as it was: a bounding-box filter, then the exact distance of each
    remaining (segment, box) pair (:func:`robot.scene.pair_distance`) compared with ``r``."""
    ok = np.ones(len(a), dtype=bool)
    if not len(a) or not len(boxes):
        return ok
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    near = ((lo[:, None, 0] < boxes[None, :, 2] + r) & (hi[:, None, 0] > boxes[None, :, 0] - r)
            & (lo[:, None, 1] < boxes[None, :, 3] + r) & (hi[:, None, 1] > boxes[None, :, 1] - r))
    si, mi = np.nonzero(near)
    if len(si):
        ok[si[pair_distance(a[si], b[si], boxes[mi]) < r]] = False
    return ok


class PlainPlanner:
    """Collision-free paths for the disc robot in ``scene``, from the world's roadmap.

    A query ``plan(start, goal)`` is answered in layers, each cached by exactly what it
    depends on, so a change in the scene invalidates only what it can affect:

    1. the **door layer** (walls, furniture, closed doors): a Dijkstra tree from the
       start over the roadmap less the edges closed doors block, cached by
       (start, closed doors); the goal is linked to it, the route shortened.  After
       ``table_after`` such searches under one set of closed doors, the roadmap's
       all-pairs table for them is built once and new starts read their route off it
       (:meth:`_table_route`, same lengths); ``table_after=None`` always searches;
    2. if that path is clear of people, it is the answer (people only add constraints,
       so it is still the shortest);
    3. otherwise the **people layer**: the roadmap less the edges people block, plus a
       ring of milestones around each person in the way (so the path hugs them), searched
       from the start and cached by (start, closed doors, people).

    People are judged by :meth:`Scene.people_clear <robot.scene.Scene.people_clear>`,
    the rule the ``navigate`` skill checks the path ahead with, so every path returned
    is one the skill drives.  A start in collision (braked next to a door jamb, pushed
    against a wall) is snapped to the nearest free point first (:meth:`snap`); the
    path then starts with that short move.
    """

    def __init__(self, spec: WorldSpec, scene: Scene, seed: int = 1, milestones: int | None = None,
                 cache_size: int = 4096, table_after: int | None = None) -> None:
        self.scene = scene
        self.roadmap = Roadmap.for_world(spec, scene, seed, milestones)
        self._cache: OrderedDict[tuple[object, ...], tuple[Point, ...] | None] = OrderedDict()
        self._cache_size = cache_size
        self._door_masks: dict[tuple[str, ...], np.ndarray] = {}
        self._disc_masks: OrderedDict[Disc, np.ndarray] = OrderedDict()
        self._rings: OrderedDict[tuple[Disc, tuple[str, ...]], tuple[np.ndarray, np.ndarray]] = OrderedDict()
        self._trees: OrderedDict[tuple[object, ...], tuple[np.ndarray, np.ndarray, np.ndarray]] = OrderedDict()
        self._graphs: OrderedDict[Layer, tuple[np.ndarray, np.ndarray, np.ndarray, csr_matrix]] = OrderedDict()
        self._starts: OrderedDict[tuple[Point, tuple[str, ...]], tuple[np.ndarray, np.ndarray]] = OrderedDict()
        self._door_searches: dict[tuple[str, ...], int] = {}  # door-layer searches per set of closed doors
        self.table_after = table_after
        self.searches = 0  # Dijkstra runs so far (benchmarks and tests read it)
        self._boxes_key: tuple[str, ...] | None = None
        self._all_boxes = np.zeros((0, 4))

    def forget_starts(self) -> None:
        """Drop every per-start result (search trees, start links, answers), keeping what
        depends on the scene alone (layer graphs, door tables): the next query from any start
        is planned as from a new one (benchmarks measure new-source queries this way)."""
        self._trees.clear()
        self._starts.clear()
        self._cache.clear()

    # ---- the scene, by layer -----------------------------------------------------------
    def _doors(self) -> tuple[str, ...]:
        return tuple(n for n, o in sorted(self.scene.door_open.items()) if not o)

    def _boxes(self) -> np.ndarray:
        """Walls, furniture and closed doors as one array (cached per set of closed doors)."""
        doors = self._doors()
        if self._boxes_key != doors:
            self._boxes_key = doors
            self._all_boxes = np.vstack([self.scene.static, self.scene.closed_doors()])
        return self._all_boxes

    def _free_segments(self, a: np.ndarray, b: np.ndarray, discs: tuple[Disc, ...], leaving: bool = True,
                       goal: Point | None = None) -> np.ndarray:
        """Which segments are clear of the bounds, walls, furniture, closed doors and ``discs``.

        People by :meth:`Scene.people_clear <robot.scene.Scene.people_clear>` — the very
        rule the ``navigate`` skill checks the path ahead with: segments of a path, driven
        from ``a`` to ``b`` (``leaving``), stopping at ``goal``; roadmap edges, which are
        searched both ways, with ``leaving=False``.
        """
        scene, r = self.scene, self.scene.radius
        a, b = np.asarray(a, float).reshape(-1, 2), np.asarray(b, float).reshape(-1, 2)
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        ok = (lo[:, 0] >= scene.xmin + r) & (hi[:, 0] <= scene.xmax - r) & (lo[:, 1] >= scene.ymin + r)
        ok &= hi[:, 1] <= scene.ymax - r
        ok &= segments_clear(a, b, self._boxes(), r)
        if discs and ok.any():
            idx = np.flatnonzero(ok)
            ok[idx] = scene.people_clear(a[idx], b[idx], discs, leaving=leaving, goal=goal)
        return ok

    def _free_points(self, pts: np.ndarray) -> np.ndarray:
        """Which points the robot may stand on: clear of bounds, walls, furniture, closed doors.

        People never make a point invalid: the robot may be beside them already, or stop
        next to them; :meth:`_free_segments` keeps it from driving deeper.
        """
        scene, r = self.scene, self.scene.radius
        x, y = pts[:, 0], pts[:, 1]
        ok = (x >= scene.xmin + r) & (x <= scene.xmax - r) & (y >= scene.ymin + r) & (y <= scene.ymax - r)
        if len(scene.static):
            ok &= point_box_distance(x, y, scene.static).min(axis=1) >= r
        if len(scene.closed_doors()):
            ok &= point_box_distance(x, y, scene.closed_doors()).min(axis=1) >= r
        return ok

    def _door_mask(self, doors: tuple[str, ...]) -> np.ndarray:
        if doors not in self._door_masks:
            boxes = np.array([self.scene.door_boxes[n] for n in doors], dtype=float).reshape(-1, 4)
            self._door_masks[doors] = self.roadmap.box_blocked(boxes, self.scene.radius)
        return self._door_masks[doors]

    def _disc_mask(self, d: Disc) -> np.ndarray:
        if d not in self._disc_masks:
            self._disc_masks[d] = self.roadmap.disc_blocked(d.x, d.y, self.scene.clearance(d))
            if len(self._disc_masks) > 256:
                self._disc_masks.popitem(last=False)
        return self._disc_masks[d]

    def _ring(self, d: Disc, doors: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
        """Milestones around person ``d`` and their edges (ring-local index, roadmap node or
        ``-1 - ring index``), clear of walls, furniture and closed doors."""
        key = (d, doors)
        if key not in self._rings:
            radius = self.scene.clearance(d) / math.cos(math.pi / RING) + RING_SLACK
            ang = 2 * math.pi * np.arange(RING) / RING
            pts = np.stack([d.x + radius * np.cos(ang), d.y + radius * np.sin(ang)], axis=1)
            keep = self._free_points(pts)
            pts = pts[keep]
            local = np.flatnonzero(keep)
            rm = self.roadmap
            a_idx, b_idx = [], []
            for k in range(len(pts)):  # neighbours on the ring, then nearby roadmap nodes
                nxt = np.flatnonzero(local == (local[k] + 1) % RING)
                if len(nxt):
                    a_idx.append(k)
                    b_idx.append(-1 - int(nxt[0]))
                near, _ = rm.nearest(pts[k, 0], pts[k, 1], 24)
                a_idx += [k] * len(near)
                b_idx += [int(n) for n in near]
            a_arr, b_arr = np.array(a_idx, dtype=int), np.array(b_idx, dtype=int)
            ends = np.where(b_arr[:, None] >= 0, rm.nodes[np.maximum(b_arr, 0)], pts[-1 - np.minimum(b_arr, -1)])
            ok = self._free_segments(pts[a_arr], ends, (), leaving=False) if len(a_arr) else np.zeros(0, dtype=bool)
            self._rings[key] = (pts, np.stack([a_arr[ok], b_arr[ok]], axis=1).reshape(-1, 2))
            if len(self._rings) > 256:
                self._rings.popitem(last=False)
        return self._rings[key]

    # ---- search ------------------------------------------------------------------------
    def _graph(self, layer: Layer) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Nodes, undirected edges and lengths of the roadmap as ``layer`` leaves it."""
        return self._layer_graph(layer)[:3]

    def _layer_graph(self, layer: Layer) -> tuple[np.ndarray, np.ndarray, np.ndarray, csr_matrix]:
        """:meth:`_graph`'s nodes, edges and lengths, and the layer's sparse matrix with one
        extra, empty row for a start (cached per layer: it depends on nothing else)."""
        if layer in self._graphs:
            self._graphs.move_to_end(layer)
            return self._graphs[layer]
        nodes, edges, lengths = self._build_graph(layer)
        n = len(nodes)
        matrix = csr_matrix((np.concatenate([lengths, lengths]),
                             (np.concatenate([edges[:, 0], edges[:, 1]]), np.concatenate([edges[:, 1], edges[:, 0]]))),
                            shape=(n + 1, n + 1))
        self._graphs[layer] = (nodes, edges, lengths, matrix)
        if len(self._graphs) > 32:
            self._graphs.popitem(last=False)
        return self._graphs[layer]

    def _build_graph(self, layer: Layer) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        doors, discs = layer
        rm = self.roadmap
        blocked = self._door_mask(doors).copy()
        for d in discs:
            blocked |= self._disc_mask(d)
        nodes, edges = [rm.nodes], [rm.edges[~blocked]]
        n = len(rm.nodes)
        for d in discs:
            pts, ring_edges = self._ring(d, doors)
            if not len(pts):
                continue
            a = ring_edges[:, 0] + n
            b = np.where(ring_edges[:, 1] >= 0, ring_edges[:, 1], n - 1 - ring_edges[:, 1])
            nodes.append(pts)
            edges.append(np.stack([a, b], axis=1))
            n += len(pts)
        all_nodes = np.vstack(nodes)
        all_edges = np.vstack(edges)
        if len(discs) and len(all_edges) > len(edges[0]):
            ring_part = all_edges[len(edges[0]):]
            ok = self._free_segments(all_nodes[ring_part[:, 0]], all_nodes[ring_part[:, 1]], discs, leaving=False)
            all_edges = np.vstack([edges[0], ring_part[ok]])
        lengths = np.hypot(*(all_nodes[all_edges[:, 0]] - all_nodes[all_edges[:, 1]]).T)
        return all_nodes, all_edges, lengths

    def _links(self, p: Point, nodes: np.ndarray, discs: tuple[Disc, ...], k: int = 16,
               also: Point | None = None, goal: bool = False) -> tuple[np.ndarray, np.ndarray, bool]:
        """Nodes visible from ``p`` among its ``k`` nearest and the nearest 24 milestones within
        3 m that are not OMPL samples (corners, doors, places, rings), with distances; and
        whether ``p`` sees ``also`` directly (one vectorised test for all).

        ``p`` is the path's start (segments ``p → node``), or with ``goal`` its goal
        (segments ``node → p`` and ``also → p``): people are judged in driving order."""
        d = np.hypot(nodes[:, 0] - p[0], nodes[:, 1] - p[1])
        first = int(self.roadmap.corner_nodes[0]) if len(self.roadmap.corner_nodes) else len(self.roadmap.nodes)
        near = np.argpartition(d, min(k, len(d) - 1))[:k]
        special = first + np.flatnonzero(d[first:] <= 3.0)
        if len(special) > 24:
            special = special[np.argsort(d[special], kind="stable")[:24]]
        cand = np.unique(np.concatenate([near, special]))
        ends = nodes[cand] if also is None else np.vstack([nodes[cand], [also]])
        here = np.repeat([p], len(ends), axis=0)
        ok = self._free_segments(ends, here, discs, goal=p) if goal else self._free_segments(here, ends, discs)
        direct = bool(ok[-1]) if also is not None else False
        ok = ok[: len(cand)]
        return cand[ok], d[cand[ok]], direct

    def _tree(self, s: Point, layer: Layer) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distances and predecessors from ``s`` over ``layer``'s graph (cached), and its nodes:
        a scipy Dijkstra over the layer's cached graph plus the start's links."""
        key = (s, layer)
        if key in self._trees:
            self._trees.move_to_end(key)
            return self._trees[key]
        doors, discs = layer
        nodes, _, _, base = self._layer_graph(layer)
        n = len(nodes)
        si, sd, _ = self._links(s, nodes, discs)
        # the layer's matrix with its empty last row (the start's) filled in with the links
        indptr = base.indptr.copy()
        indptr[-1] += len(si)
        graph = csr_matrix((np.concatenate([base.data, sd + 1e-9]), np.concatenate([base.indices, si]), indptr),
                           shape=(n + 1, n + 1))
        dist, pred = dijkstra(graph, directed=True, indices=n, return_predecessors=True)
        self.searches += 1
        if not discs:
            self._door_searches[doors] = self._door_searches.get(doors, 0) + 1
        self._trees[key] = (dist, pred, nodes)
        if len(self._trees) > 512:
            self._trees.popitem(last=False)
        return self._trees[key]

    def _use_table(self, layer: Layer) -> bool:
        """Is ``layer`` the door layer, searched often enough under its closed doors that
        their all-pairs table (built once, shared by every planner of the roadmap) pays?"""
        return (not layer[1] and self.table_after is not None
                and self._door_searches.get(layer[0], 0) >= self.table_after)

    def _start_links(self, s: Point, doors: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
        """The roadmap nodes start ``s`` links to on the door layer, and their distances (cached)."""
        key = (s, doors)
        if key not in self._starts:
            si, sd, _ = self._links(s, self.roadmap.nodes, ())
            self._starts[key] = (si, sd)
            if len(self._starts) > 512:
                self._starts.popitem(last=False)
        self._starts.move_to_end(key)
        return self._starts[key]

    def _table_route(self, s: Point, doors: tuple[str, ...], gi: np.ndarray, gd: np.ndarray) -> list[int] | None:
        """The door layer's shortest route of roadmap nodes from start ``s`` to one of the goal's
        links ``gi`` (at ``gd``), read off the all-pairs table of ``doors`` instead of searched:
        the least ``link(s, a) + table[a, b] + link(b, goal)`` over the start's links ``a`` and
        the goal's ``b``, then ``table``'s predecessors from ``b`` back to ``a``.  The same
        length as :meth:`_tree`'s search (which adds the same 1e-9 to each start link)."""
        si, sd = self._start_links(s, doors)
        if not len(si):
            return None
        table, pred = self.roadmap.all_pairs(self._door_mask(doors))
        total = (sd + 1e-9)[:, None] + table[np.ix_(si, gi)] + gd[None, :]
        i, j = np.unravel_index(int(np.argmin(total)), total.shape)
        if not math.isfinite(total[i, j]):
            return None
        a, row = int(si[i]), pred[si[i]]
        route = [int(gi[j])]
        while route[-1] != a:
            route.append(int(row[route[-1]]))
        return route[::-1]

    def _shortcut(self, pts: list[Point], discs: tuple[Disc, ...]) -> list[Point]:
        """The shortest chain through ``pts`` whose links are all collision-free."""
        n = len(pts)
        if n <= 2:
            return pts
        P = np.asarray(pts)
        ii, jj = np.triu_indices(n, 1)
        free = np.zeros((n, n), dtype=bool)
        free[ii, jj] = self._free_segments(P[ii], P[jj], discs, goal=pts[-1])
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

    def snap(self, p: Point, discs: tuple[Disc, ...] = ()) -> Point | None:
        """The nearest point to ``p`` the robot may stand on (``p`` itself when it may), within
        ``SNAP_REACH``, reached from ``p`` without coming closer to any of ``discs`` than it is
        (:meth:`Scene.people_clear <robot.scene.Scene.people_clear>`): a start braked against a
        door jamb is moved off it, a start beside a person stays where it is."""
        if self._free_points(np.array([p]))[0]:
            return p
        radii = np.arange(1, int(SNAP_REACH / SNAP_STEP) + 1) * SNAP_STEP
        ang = 2 * math.pi * np.arange(32) / 32
        # rounded first, then tested: a snapped start must be free as it is returned
        pts = np.round(np.stack([p[0] + np.outer(radii, np.cos(ang)).ravel(),
                                 p[1] + np.outer(radii, np.sin(ang)).ravel()], 1), 4)
        ok = np.flatnonzero(self._free_points(pts))
        if len(ok) and discs:
            ok = ok[self.scene.people_clear(np.repeat([p], len(ok), axis=0), pts[ok], discs)]
        if not len(ok):
            return None
        return (float(pts[ok[0], 0]), float(pts[ok[0], 1]))

    def _query(self, s: Point, g: Point, layer: Layer) -> tuple[Point, ...] | None:
        discs = layer[1]
        if not self._free_points(np.array([g]))[0]:
            return None
        s0 = s
        snapped = self.snap(s, discs)
        if snapped is None:
            return None
        s = snapped
        head = (s0,) if s != s0 else ()
        if math.hypot(g[0] - s[0], g[1] - s[1]) < 1e-6:
            return (*head, s, g)
        if self._use_table(layer):
            nodes = self.roadmap.nodes
            gi, gd, direct = self._links(g, nodes, discs, also=s, goal=True)
            if direct:
                return (*head, s, g)
            route = self._table_route(s, layer[0], gi, gd) if len(gi) else None
            if route is None:
                return None
        else:
            dist, pred, nodes = self._tree(s, layer)
            gi, gd, direct = self._links(g, nodes, discs, also=s, goal=True)
            if direct:
                return (*head, s, g)
            if not len(gi):
                return None
            total = dist[gi] + gd
            b = int(np.argmin(total))
            if not math.isfinite(total[b]):
                return None
            route = [int(gi[b])]
            n = len(nodes)
            while route[-1] != n:
                route.append(int(pred[route[-1]]))
            route = route[-2::-1]
        pts = [s] + [(float(x), float(y)) for x, y in nodes[route]] + [g]
        return (*head, *self._shortcut(pts, discs))

    def plan(self, start: Point, goal: Point) -> tuple[Point, ...] | None:
        """A collision-free polyline from ``start`` to ``goal``, or None when there is none."""
        s = (round(float(start[0]), 4), round(float(start[1]), 4))
        g = (round(float(goal[0]), 4), round(float(goal[1]), 4))
        doors = self._doors()
        # people the goal is beside do not block the way to it (Scene.people_clear)
        discs = tuple(d for d in self.scene.discs() if not self.scene.holds(d, g))
        path = self._cached((s, g, doors, ()))
        if path is None or not discs:
            return path
        pts = np.asarray(path)
        # the door-layer path may start with a snap off a jamb; people judge it as driven
        if self.scene.people_clear(pts[:-1], pts[1:], discs, goal=g).all():
            return path
        path = self._cached((s, g, doors, discs))
        if path is None:
            # no way that leaves the people the robot is beside without coming closer (a
            # place between two people): pass them, as Scene.path_clear allows
            away = tuple(d for d in discs if not self.scene.holds(d, s))
            if len(away) < len(discs):
                path = self._cached((s, g, doors, away))
        return path

    def plan_ignoring_people(self, start: Point, goal: Point) -> tuple[Point, ...] | None:
        """As :meth:`plan` with the doors as they are and nobody in the way."""
        s = (round(float(start[0]), 4), round(float(start[1]), 4))
        g = (round(float(goal[0]), 4), round(float(goal[1]), 4))
        return self._cached((s, g, self._doors(), ()))

    def closed_doors(self) -> tuple[str, ...]:
        """The names of the doors closed now, sorted."""
        return self._doors()

    def _cached(self, key: tuple[Point, Point, tuple[str, ...], tuple[Disc, ...]]) -> tuple[Point, ...] | None:
        if key in self._cache:
            self._cache.move_to_end(key)
            return self._cache[key]
        s, g, doors, discs = key
        result = self._query(s, g, (doors, discs))
        self._cache[key] = result
        if len(self._cache) > self._cache_size:
            self._cache.popitem(last=False)
        return result
