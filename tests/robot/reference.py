"""An independent reference for shortest paths: Dijkstra on a fine grid (16-connected).

The free cells are those whose centre is at least the robot's radius from every wall,
piece of furniture, closed door and person (exact point distances, no roadmap, no OMPL).
A 16-connected grid path is at most ~2.7 % longer than the true Euclidean shortest path
(it moves in 16 directions), and it may cut a corner by at most half a cell.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from robot.scene import point_box_distance

MOVES = [(1, 0), (0, 1), (1, 1), (1, -1), (2, 1), (1, 2), (2, -1), (1, -2)]


class GridReference:
    """Shortest collision-free path lengths for a disc robot, on a ``cell``-metre grid."""

    def __init__(self, scene, cell: float = 0.025, discs=()) -> None:
        r = scene.radius
        self.cell = cell
        self.x0, self.y0 = scene.xmin, scene.ymin
        xs = np.arange(scene.xmin, scene.xmax + 1e-9, cell)
        ys = np.arange(scene.ymin, scene.ymax + 1e-9, cell)
        self.nx, self.ny = len(xs), len(ys)
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        px, py = X.ravel(), Y.ravel()
        free = (px >= scene.xmin + r) & (px <= scene.xmax - r) & (py >= scene.ymin + r) & (py <= scene.ymax - r)
        boxes = np.vstack([scene.static, scene.closed_doors()])
        free &= point_box_distance(px, py, boxes).min(axis=1) >= r
        for d in discs:
            free &= np.hypot(px - d.x, py - d.y) >= d.r + r
        self.free = free.reshape(self.nx, self.ny)
        idx = np.arange(self.nx * self.ny).reshape(self.nx, self.ny)

        def cells(ox: int, oy: int, dx: int, dy: int) -> np.ndarray:
            """Cells at offset ``(ox, oy)`` from every cell that has a neighbour at ``(dx, dy)``."""
            i0, j0 = max(0, -dx) + ox, max(0, -dy) + oy
            return idx[i0 : self.nx - max(0, dx) + ox, j0 : self.ny - max(0, dy) + oy].ravel()

        rows, cols, w = [], [], []
        for dx, dy in MOVES:
            a, b = cells(0, 0, dx, dy), cells(dx, dy, dx, dy)
            ok = free[a] & free[b]
            if abs(dx) + abs(dy) == 3:  # a knight's move: the cell it passes over must be free too
                ok &= free[cells(int(dx / 2) if abs(dx) == 2 else 0, int(dy / 2) if abs(dy) == 2 else 0, dx, dy)]
            rows.append(a[ok])
            cols.append(b[ok])
            w.append(np.full(int(ok.sum()), cell * float(np.hypot(dx, dy))))
        n = self.nx * self.ny
        self.graph = coo_matrix((np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))),
                                shape=(n, n)).tocsr()

    def cell_of(self, x: float, y: float) -> int:
        i, j = round((x - self.x0) / self.cell), round((y - self.y0) / self.cell)
        return i * self.ny + j

    def lengths(self, start: tuple[float, float], goals: list[tuple[float, float]]) -> np.ndarray:
        """Grid path lengths from ``start`` to each goal (``inf``: no path on the grid)."""
        dist = dijkstra(self.graph, directed=False, indices=self.cell_of(*start))
        return np.array([dist[self.cell_of(*g)] for g in goals])
