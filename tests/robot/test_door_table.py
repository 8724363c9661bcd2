"""The door layer's all-pairs table gives exactly the paths a search per start gives.

A planner reads a new start's door-layer route off the roadmap's all-pairs table for the
closed doors (``table_after=0``: from the first query); the reference is the same planner
searching every start with scipy's Dijkstra (``table_after=None``).  Over random start and
goal pairs in every shipped world, with and without people, with the shipped doors and with
one door toggled, both answer the same: reachable alike, path lengths equal to 1e-6.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse.csgraph import dijkstra

from robot.motion import BasePlanner
from robot.roadmap import path_length
from robot.scene import Scene
from robot.spec import load_world, shipped_worlds
from robot.tiago import robot_dimensions

PAIRS = 40


def _scene(world: str, people: bool, toggle_one: bool) -> Scene:
    spec = load_world(world)
    scene = Scene(spec, robot_dimensions()[2])
    if people:
        for p in spec.people.values():
            scene.set_person(p.name, p.pose[0], p.pose[1], p.posture)
    if toggle_one:  # another set of closed doors: the first door opened or closed
        first = sorted(scene.door_open)[0]
        scene.set_door(first, not scene.door_open[first])
    return scene


@pytest.mark.slow
@pytest.mark.parametrize("toggle_one", [False, True], ids=["doors-as-shipped", "one-door-toggled"])
@pytest.mark.parametrize("people", [False, True], ids=["empty", "with-people"])
@pytest.mark.parametrize("world", shipped_worlds())
def test_table_routes_equal_a_search_per_start(world: str, people: bool, toggle_one: bool) -> None:
    spec = load_world(world)
    scene = _scene(world, people, toggle_one)
    table = BasePlanner(spec, scene, table_after=0)
    search = BasePlanner(spec, scene, table_after=None)
    rng = np.random.default_rng(11)
    reached = compared = 0
    while compared < PAIRS:
        s = (float(rng.uniform(scene.xmin, scene.xmax)), float(rng.uniform(scene.ymin, scene.ymax)))
        g = (float(rng.uniform(scene.xmin, scene.xmax)), float(rng.uniform(scene.ymin, scene.ymax)))
        if not (scene.free(*s) and scene.free(*g)):
            continue
        compared += 1
        a, b = table.plan(s, g), search.plan(s, g)
        assert (a is None) == (b is None), (world, s, g, a, b)
        if a is not None and b is not None:
            reached += 1
            assert path_length(list(a)) == pytest.approx(path_length(list(b)), abs=1e-6), (world, s, g, a, b)
    assert reached >= PAIRS // 2  # the comparison is about real routes, most of them reachable
    # the table really answered the door layer: searches only where people were in the way
    assert table.searches < search.searches
    if not people:
        assert table.searches == 0


@pytest.mark.slow
def test_all_pairs_table_is_scipy_dijkstra_from_each_node(paper) -> None:  # type: ignore[no-untyped-def]
    scene = _scene("paper", people=False, toggle_one=True)
    planner = BasePlanner(paper, scene, table_after=0)
    rm = planner.roadmap
    mask = planner._door_mask(planner._doors())
    assert mask.any()  # the closed door cuts some edges
    dist, pred = rm.all_pairs(mask)
    graph = rm.graph.tolil()
    for i, j in rm.edges[mask]:
        graph[i, j] = graph[j, i] = 0  # scipy reads an explicit zero as no edge
    graph = graph.tocsr()
    graph.eliminate_zeros()
    for src in (0, len(rm.nodes) // 2, len(rm.nodes) - 1):
        ref = dijkstra(graph, indices=src)
        np.testing.assert_allclose(dist[src], ref, rtol=0, atol=1e-9)
        # every predecessor step is a roadmap edge that the distances make tight
        for v in np.flatnonzero(np.isfinite(dist[src]))[:200]:
            if v != src:
                u = pred[src, v]
                assert dist[src, u] + np.hypot(*(rm.nodes[u] - rm.nodes[v])) == pytest.approx(dist[src, v], abs=1e-9)
