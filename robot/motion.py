"""Base path planning and motion-cost estimates over the roadmap.

:class:`BasePlanner` answers "how does the base get from here to there" on the
:class:`~robot.roadmap.Roadmap` grown once by OMPL:

1. a start in collision is snapped off it; start and goal are linked to their nearest
   visible roadmap nodes (exact tests; people judged by
   :meth:`Scene.people_clear <robot.scene.Scene.people_clear>`, the rule the
   ``navigate`` skill checks paths with: a path may leave a person's clearance or
   stop inside it, never enter it);
2. a Dijkstra search (scipy) from the start over the roadmap less the edges closed
   doors block — or, once a set of closed doors has been searched from ``TABLE_AFTER``
   starts, a look-up in the all-pairs table of those doors; if its path is clear of
   people it is the answer, otherwise a search over the roadmap less the edges people
   block, plus rings of milestones around them;
3. the route is shortened: the shortest chain of mutually visible route points.

Time comes from :class:`~robot.drive.DriveLimits` with the same stop–turn–drive profile the controller
executes (:mod:`robot.control`); :mod:`robot.estimator` turns paths into
:class:`tasker.world.MotionModel` estimates with it.

**Caching.**  Results and search trees are cached by exactly what they depend on
(start, goal, closed doors, people), so a cached answer can never describe a scene
that no longer exists; the roadmap itself covers only walls and furniture and never
needs rebuilding.  Straight-line tests against walls, furniture and closed doors — what
a query spends its time on — are made once and remembered (:mod:`robot.visibility`).
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from robot.roadmap import Roadmap
from robot.scene import Disc, Scene, point_box_distance
from robot.spec import WorldSpec
from robot.visibility import Visibility

Point = tuple[float, float]


Layer = tuple[tuple[str, ...], tuple[Disc, ...]]  # closed doors, people in the way
RING = 16  # milestones around a person in the way
SNAP_STEP = 0.01  # metres between the rings searched for a free start
SNAP_REACH = 0.6  # metres: a start deeper in collision than this is not snapped
RING_SLACK = 0.005  # metres a ring's chords keep outside the person's clearance
# Door-layer searches under one set of closed doors before their all-pairs table is built:
# the table (paper apartment: ~0.5 s) costs a few hundred searches (~1-2 ms each), so it is
# built only once that many were run (ski rental: never more than twice the better choice).
# A scenario run searches few starts (places repeat, answers are cached; the paper scenario
# and the bench's 1-hour day each stay well under 256) and does not pay for it.
TABLE_AFTER = 256


class BasePlanner:
    """Collision-free paths for the disc robot in ``scene``, from the world's roadmap.

    A query ``plan(start, goal)`` is answered in layers, each cached by exactly what it
    depends on, so a change in the scene invalidates only what it can affect:

    1. the **door layer** (walls, furniture, closed doors): a Dijkstra tree from the
       start over the roadmap less the edges closed doors block, cached by
       (start, closed doors); the goal is linked to it, the route shortened.  After
       ``table_after`` such searches under one set of closed doors, the roadmap's
       all-pairs table for them is built once and new starts read their route off it
       (:meth:`_table_query`, same lengths); ``table_after=None`` always searches;
    2. if that path is clear of people, it is the answer (people only add constraints,
       so it is still the shortest);
    3. otherwise the **people layer**: the roadmap less the edges people block, plus a
       ring of milestones around each person in the way (so the path hugs them), searched
       from the start and cached by (start, closed doors, people).

    People are judged by :meth:`Scene.people_clear <robot.scene.Scene.people_clear>`,
    the rule the ``navigate`` skill checks the path ahead with, so every path returned
    is one the skill drives.  A start in collision (braked next to a door jamb, pushed
    against a wall) is snapped to the nearest free point first (:meth:`snap`); the
    path then starts with that short move.  Straight-line tests against walls, furniture
    and closed doors are made once and remembered in :attr:`vis`
    (:class:`robot.visibility.Visibility`).
    """

    def __init__(self, spec: WorldSpec, scene: Scene, seed: int = 1, milestones: int | None = None,
                 cache_size: int = 4096, table_after: int | None = TABLE_AFTER) -> None:
        self.scene = scene
        self.roadmap = Roadmap.for_world(spec, scene, seed, milestones)
        self._cache: OrderedDict[tuple[object, ...], tuple[Point, ...] | None] = OrderedDict()
        self._cache_size = cache_size
        self._door_masks: dict[tuple[str, ...], np.ndarray] = {}
        self._disc_masks: OrderedDict[Disc, np.ndarray] = OrderedDict()
        self._rings: OrderedDict[tuple[Disc, tuple[str, ...]], tuple[np.ndarray, np.ndarray]] = OrderedDict()
        self._trees: OrderedDict[tuple[object, ...], tuple[np.ndarray, np.ndarray, np.ndarray]] = OrderedDict()
        self._graphs: OrderedDict[Layer, tuple[np.ndarray, np.ndarray, np.ndarray, csr_matrix]] = OrderedDict()
        self._door_searches: dict[tuple[str, ...], int] = {}  # door-layer searches per set of closed doors
        self.table_after = table_after
        self.searches = 0  # Dijkstra runs so far (benchmarks and tests read it)
        self._doors_at = -1  # the scene version _closed was read at
        self._closed: tuple[str, ...] = ()
        self.vis = Visibility(self.roadmap, scene)  # straight-line tests, memoised (never people)
        self._tables: dict[tuple[str, ...], tuple[np.ndarray, np.ndarray]] = {}

    def forget_starts(self) -> None:
        """Drop every per-start result (search trees, start and goal links, answers), keeping
        what depends on the scene alone (layer graphs, door tables, visibility between roadmap
        nodes): the next query from any start is planned as from a new one (benchmarks measure
        new-source queries this way)."""
        self._trees.clear()
        self._cache.clear()
        self.vis.forget_points()

    # ---- the scene, by layer -----------------------------------------------------------
    def _doors(self) -> tuple[str, ...]:
        """The closed doors, sorted (looked up again only when the scene's version moves)."""
        if self._doors_at != self.scene.version:
            self._closed = tuple(n for n, o in sorted(self.scene.door_open.items()) if not o)
            self._doors_at = self.scene.version
        return self._closed

    def _static_free(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Which segments ``a[i]→b[i]`` are clear of the bounds, walls, furniture and closed
        doors (exact; people are not looked at)."""
        return self.vis.free(a, b, self._doors())

    def _free_segments(self, a: np.ndarray, b: np.ndarray, discs: tuple[Disc, ...], leaving: bool = True,
                       goal: Point | None = None) -> np.ndarray:
        """Which segments are clear of the bounds, walls, furniture, closed doors and ``discs``.

        People by :meth:`Scene.people_clear <robot.scene.Scene.people_clear>` — the very
        rule the ``navigate`` skill checks the path ahead with: segments of a path, driven
        from ``a`` to ``b`` (``leaving``), stopping at ``goal``; roadmap edges, which are
        searched both ways, with ``leaving=False``.
        """
        a, b = np.asarray(a, float).reshape(-1, 2), np.asarray(b, float).reshape(-1, 2)
        ok = self._static_free(a, b)
        return self._people_free(a, b, ok, discs, leaving, goal)

    def _people_free(self, a: np.ndarray, b: np.ndarray, ok: np.ndarray, discs: tuple[Disc, ...],
                     leaving: bool = True, goal: Point | None = None) -> np.ndarray:
        """``ok`` (segments clear of everything else) less those ``discs`` block."""
        if discs and ok.any():
            idx = np.flatnonzero(ok)
            ok[idx] = self.scene.people_clear(a[idx], b[idx], discs, leaving=leaving, goal=goal)
        return ok

    def _node_memo(self, doors: tuple[str, ...]) -> np.ndarray:
        """Visibility between roadmap nodes under ``doors`` (:meth:`Visibility.between_nodes`)."""
        return self.vis.between_nodes(doors, self._door_mask(doors))

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

    def _candidates(self, p: Point, nodes: np.ndarray, k: int = 16) -> tuple[np.ndarray, np.ndarray]:
        """``p``'s link candidates among ``nodes`` (:meth:`Visibility.select`), with their
        distances; memoised for the roadmap's own nodes."""
        if nodes is self.roadmap.nodes and k == 16:
            return self.vis.candidates((p,), self._doors())[0]
        return self.vis.select(np.array([p], dtype=float), nodes[:, 0], nodes[:, 1], k)[0]

    def _links(self, p: Point, nodes: np.ndarray, discs: tuple[Disc, ...], k: int = 16,
               also: Point | None = None, goal: bool = False) -> tuple[np.ndarray, np.ndarray, bool]:
        """Nodes visible from ``p`` among its link candidates (:meth:`_candidates`), with
        distances; and whether ``p`` sees ``also`` directly.

        ``p`` is the path's start (segments ``p → node``), or with ``goal`` its goal
        (segments ``node → p`` and ``also → p``): people are judged in driving order.  Walls,
        furniture and closed doors come from the visibility memo, tested (all at once) only
        where it does not know yet; people are judged afresh.
        """
        cand, d = self._candidates(p, nodes, k)
        doors = self._doors()
        n_rm = len(self.roadmap.nodes)
        split = int(np.searchsorted(cand, n_rm))
        ends = nodes[cand] if also is None else np.vstack([nodes[cand], [also]])
        here = np.broadcast_to(np.asarray(p, float), (len(ends), 2))
        off = ends[split:]  # ring milestones, and ``also``: not in the memo
        fresh = self.vis.settle(doors, p, cand[:split], off if len(off) else None)
        ok = np.concatenate([self.vis.point(p, doors).vis[cand[:split]] == 1, fresh])
        if goal:
            ok = self._people_free(ends, here, ok, discs, goal=p)
        else:
            ok = self._people_free(here, ends, ok, discs)
        direct = bool(ok[-1]) if also is not None else False
        ok = ok[: len(cand)]
        return cand[ok], d[ok], direct

    def _point_free(self, p: Point) -> bool:
        """May the robot stand on ``p`` (:meth:`_free_points`' rule; memoised)?"""
        return self.vis.point_free(p, self._doors())

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

    def _door_table(self, doors: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
        """The roadmap's all-pairs distances and predecessors under ``doors`` (looked up once)."""
        if doors not in self._tables:
            self._tables[doors] = self.roadmap.all_pairs(self._door_mask(doors))
            if len(self._tables) > 4:
                self._tables.pop(next(iter(self._tables)))
        return self._tables[doors]

    def _table_query(self, s: Point, g: Point, doors: tuple[str, ...]) -> list[Point] | None:
        """The door layer's shortest path, its route read off the all-pairs table of ``doors``.

        The route is the least ``link(s, a) + table[a, b] + link(b, goal)`` over the start's
        visible links ``a`` and the goal's ``b`` (the length :meth:`_tree`'s search gives, which
        adds the same 1e-9 to each start link), then ``table``'s predecessors from ``b`` back to
        ``a``.  One exact test covers the straight way and the links the memos do not know
        yet, a second the shortcut's pairs they do not know.
        """
        nodes = self.roadmap.nodes
        (cs, ds), (cg, dg) = self.vis.candidates((s, g), doors)
        vs, vg = self.vis.point(s, doors).vis, self.vis.point(g, doors).vis
        # one exact test: the straight way and every link not in the memos yet
        us, ug = cs[vs[cs] < 0], cg[vg[cg] < 0]
        here = np.array([s, g], dtype=float)
        k = 1 + len(us)  # the straight way first, then the start's links, then the goal's
        ok = self._static_free(np.repeat(here, [k, len(ug)], axis=0),
                               np.concatenate([here[1:], nodes[us], nodes[ug]]))
        vs[us] = ok[1:k]
        vg[ug] = ok[k:]
        if ok[0]:
            return [s, g]
        ks, kg = vs[cs] == 1, vg[cg] == 1
        si, gi = cs[ks], cg[kg]
        if not (len(si) and len(gi)):
            return None
        table, pred = self._door_table(doors)
        total = (ds[ks] + 1e-9)[:, None] + table[si[:, None], gi] + dg[kg][None, :]
        flat = int(np.argmin(total))
        i, j = divmod(flat, len(gi))
        if not math.isfinite(total[i, j]):
            return None
        pts, ids = self._route_points(s, g, nodes, self._walk(pred, int(si[i]), int(gi[j])))
        return self._shortcut(pts, (), ids, direct=False)

    @staticmethod
    def _walk(pred: np.ndarray, a: int, b: int) -> list[int]:
        """Roadmap nodes from ``a`` to ``b`` along the all-pairs predecessors."""
        row = pred[a]
        route = [b]
        while route[-1] != a:
            route.append(int(row[route[-1]]))
        return route[::-1]

    def _route_points(self, s: Point, g: Point, nodes: np.ndarray, route: list[int]) -> tuple[list[Point], list[int]]:
        """The points of ``s``, the ``route`` nodes and ``g``, and which roadmap node each is
        (``-1`` for the ends and for ring milestones)."""
        n_rm = len(self.roadmap.nodes)
        pts = [s] + [(float(x), float(y)) for x, y in nodes[route].tolist()] + [g]
        return pts, [-1] + [k if k < n_rm else -1 for k in route] + [-1]

    def _shortcut(self, pts: list[Point], discs: tuple[Disc, ...], ids: list[int],
                  direct: bool | None = None) -> list[Point]:
        """The shortest chain through ``pts`` whose links are all collision-free.

        ``ids`` names the roadmap node each point is (``-1``: the start, the goal, a ring
        milestone).  Walls, furniture and closed doors between two nodes, or between the
        start or the goal and a node, come from the visibility memos; what they do not know
        is tested in one call (and remembered); ``direct`` is the start–goal pair's answer if
        known.  People are judged afresh.
        """
        n = len(pts)
        if n <= 2:
            return pts
        doors = self._doors()
        P = np.asarray(pts, dtype=float)
        node_vis = self._node_memo(doors)
        vs, vg = self.vis.point(pts[0], doors).vis, self.vis.point(pts[-1], doors).vis
        inner = np.maximum(np.asarray(ids[1:-1]), 0)
        s_row, g_col = vs[inner].tolist(), vg[inner].tolist()
        sub = node_vis[np.ix_(inner, inner)].tolist()
        # what the memos know of every pair that is not a route link (those are valid by
        # construction); plain Python: a route has a few dozen points at most
        on = [k >= 0 for k in ids]
        fr = [[j == i + 1 for j in range(n)] for i in range(n)]
        clear: list[tuple[int, int]] = []
        unknown: list[tuple[int, int]] = []
        for i in range(n - 2):
            for j in range(i + 2, n):
                if i == 0:
                    v = (-1 if direct is None else int(direct)) if j == n - 1 else (s_row[j - 1] if on[j] else -1)
                elif j == n - 1:
                    v = g_col[i - 1] if on[i] else -1
                else:
                    v = sub[i - 1][j - 1] if on[i] and on[j] else -1
                if v < 0:
                    unknown.append((i, j))
                elif v:
                    clear.append((i, j))
        if unknown:
            u = np.array(unknown)
            got = self._static_free(P[u[:, 0]], P[u[:, 1]]).tolist()
            for (i, j), v in zip(unknown, got, strict=True):
                if v:
                    clear.append((i, j))
                if i == 0 and j == n - 1:
                    continue  # the start–goal pair: not memoised
                if i == 0:
                    if on[j]:
                        vs[ids[j]] = v
                elif j == n - 1:
                    if on[i]:
                        vg[ids[i]] = v
                elif on[i] and on[j]:
                    node_vis[ids[i], ids[j]] = node_vis[ids[j], ids[i]] = v
        if discs and clear:
            c = np.array(clear)
            fine = self.scene.people_clear(P[c[:, 0]], P[c[:, 1]], discs, goal=pts[-1]).tolist()
            clear = [pair for pair, v in zip(clear, fine, strict=True) if v]
        for i, j in clear:
            fr[i][j] = True
        seg = np.hypot(*(P[None, :, :] - P[:, None, :]).transpose(2, 0, 1)).tolist()
        # the least-cost chain, first predecessor on ties; plain floats: n is small
        best = [math.inf] * n
        back = [0] * n
        best[0] = 0.0
        for j in range(1, n):
            bj, bi = math.inf, 0
            for i in range(j):
                if fr[i][j]:
                    c = best[i] + seg[i][j]
                    if c < bj:
                        bj, bi = c, i
            best[j], back[j] = bj, bi
        out = [n - 1]
        while out[-1] != 0:
            out.append(back[out[-1]])
        return [pts[k] for k in reversed(out)]

    def snap(self, p: Point, discs: tuple[Disc, ...] = ()) -> Point | None:
        """The nearest point to ``p`` the robot may stand on (``p`` itself when it may), within
        ``SNAP_REACH``, reached from ``p`` without coming closer to any of ``discs`` than it is
        (:meth:`Scene.people_clear <robot.scene.Scene.people_clear>`): a start braked against a
        door jamb is moved off it, a start beside a person stays where it is."""
        if self._point_free(p):
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
        doors, discs = layer
        if not self._point_free(g):
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
            path = self._table_query(s, g, doors)
            return None if path is None else (*head, *path)
        nodes = self._layer_graph(layer)[0]
        gi, gd, direct = self._links(g, nodes, discs, also=s, goal=True)
        if direct:
            return (*head, s, g)
        if not len(gi):
            return None
        dist, pred, nodes = self._tree(s, layer)
        total = dist[gi] + gd
        b = int(np.argmin(total))
        if not math.isfinite(total[b]):
            return None
        route = [int(gi[b])]
        n = len(nodes)
        while route[-1] != n:
            route.append(int(pred[route[-1]]))
        pts, ids = self._route_points(s, g, nodes, route[-2::-1])
        return (*head, *self._shortcut(pts, discs, ids))

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


def open_planner(spec: WorldSpec, radius: float, seed: int = 1, milestones: int | None = None) -> BasePlanner:
    """A planner over the same roadmap with every door open and no people (see
    :meth:`robot.estimator.MotionEstimator.estimate_ignoring_doors`)."""
    scene = Scene(spec, radius)
    for name in spec.doors:
        scene.set_door(name, True)
    return BasePlanner(spec, scene, seed=seed, milestones=milestones)
