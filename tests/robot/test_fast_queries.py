"""The fast motion queries answer exactly what the plain layered search answers.

:class:`robot.motion.BasePlanner` keeps visibility memos, reads the door layer off the
all-pairs table, tests segments with :func:`robot.scene.pairs_near` and runs its shortcut in
plain floats.  :class:`robot.reference_planner.PlainPlanner` is the planner as it was before
(every segment tested by its exact distance each time, a Dijkstra per start).  Over random
start and goal pairs in every shipped world — with people standing in doorways and sitting
in rooms, one door closed, starts asked for several goals, and the scene changed under the
same planner — both are reachable alike and their path lengths agree to 1e-6.
"""

from __future__ import annotations

import numpy as np
import pytest

from robot.motion import BasePlanner
from robot.reference_planner import PlainPlanner
from robot.reference_planner import segments_clear as segments_clear_by_distance
from robot.roadmap import path_length
from robot.scene import Scene, pair_distance, pairs_near, segments_clear
from robot.spec import load_world, shipped_worlds
from robot.tiago import robot_dimensions

PAIRS = 30


def _centre(box: tuple[float, float, float, float]) -> tuple[float, float]:
    return ((box[0] + box[2]) / 2, (box[1] + box[3]) / 2)


def _scene(world: str, doorway: bool, close_one: bool, seed: int) -> Scene:
    """The world's people where the file puts them, plus someone standing in a doorway (or the
    flat's open passage) and someone sitting at a random free point; one door closed."""
    spec = load_world(world)
    scene = Scene(spec, robot_dimensions()[2])
    for p in spec.people.values():
        scene.set_person(p.name, p.pose[0], p.pose[1], p.posture)
    doors = sorted(spec.doors)
    for name in doors:
        scene.set_door(name, True)
    if close_one:
        scene.set_door(doors[0], False)
    if doorway:
        where = _centre(spec.doors[doors[-1]].box) if len(doors) > 1 else (4.0, 2.5)  # the flat: its passage
        scene.set_person("in_doorway", where[0], where[1], "standing")
    rng = np.random.default_rng(seed)
    while True:
        x, y = rng.uniform(scene.xmin, scene.xmax), rng.uniform(scene.ymin, scene.ymax)
        if scene.free(x, y) and scene.free(x + 0.5, y):
            scene.set_person("in_room", x, y, "sitting")
            return scene


def _compare(fast: BasePlanner, plain: PlainPlanner, s: tuple[float, float], g: tuple[float, float]) -> bool:
    a, b = fast.plan(s, g), plain.plan(s, g)
    assert (a is None) == (b is None), (s, g, a, b)
    if a is not None and b is not None:
        assert path_length(list(a)) == pytest.approx(path_length(list(b)), abs=1e-6), (s, g, a, b)
    return a is not None


def _random_free(scene: Scene, rng: np.random.Generator) -> tuple[float, float]:
    while True:
        p = (float(rng.uniform(scene.xmin, scene.xmax)), float(rng.uniform(scene.ymin, scene.ymax)))
        if scene.free(*p):
            return p


@pytest.mark.slow
@pytest.mark.parametrize("table_after", [0, None], ids=["door-table", "searched"])
@pytest.mark.parametrize(("doorway", "close_one"), [(True, True), (True, False), (False, True)],
                         ids=["doorway+closed", "doorway", "closed"])
@pytest.mark.parametrize("world", shipped_worlds())
def test_fast_costs_equal_the_plain_search(world: str, doorway: bool, close_one: bool,
                                           table_after: int | None) -> None:
    spec = load_world(world)
    scene = _scene(world, doorway, close_one, seed=len(world))
    fast = BasePlanner(spec, scene, table_after=table_after)
    plain = PlainPlanner(spec, scene, table_after=None)
    rng = np.random.default_rng(5)
    reached = asked = 0
    for k in range(PAIRS):
        s = _random_free(scene, rng)
        for _ in range(3 if k % 3 == 0 else 1):  # a known start, new goals: its memos are reused
            reached += _compare(fast, plain, s, _random_free(scene, rng))
            asked += 1
    # real routes (a person in the flat's only passage with its door closed cuts it in two)
    assert reached >= asked // 5


@pytest.mark.slow
@pytest.mark.parametrize("world", shipped_worlds())
def test_memos_follow_the_scene_under_one_planner(world: str) -> None:
    """Doors toggled and people moved between queries of one long-lived planner: every answer
    is still the plain search's in the scene as it is then."""
    spec = load_world(world)
    scene = _scene(world, doorway=True, close_one=False, seed=1)
    fast = BasePlanner(spec, scene, table_after=0)
    rng = np.random.default_rng(9)
    starts = [_random_free(scene, rng) for _ in range(6)]
    goals = [_random_free(scene, rng) for _ in range(6)]
    doors = sorted(spec.doors)
    for step in range(4):
        if step % 2:
            scene.set_door(doors[step % len(doors)], not scene.door_open[doors[step % len(doors)]])
        else:
            scene.set_person("in_room", *_random_free(scene, rng), "standing")
        plain = PlainPlanner(spec, scene, table_after=None)
        for s, g in zip(starts, goals, strict=True):
            if scene.free(*s) and scene.free(*g):
                _compare(fast, plain, s, g)


def test_pairs_near_is_the_exact_distance_test() -> None:
    rng = np.random.default_rng(4)
    n = 60000
    a = rng.uniform(-3, 3, (n, 2))
    b = a + rng.normal(0, 1.5, (n, 2))
    b[:3000, 0] = a[:3000, 0]  # vertical, horizontal and zero-length segments
    b[3000:6000, 1] = a[3000:6000, 1]
    b[6000:7000] = a[6000:7000]
    lo = rng.uniform(-1, 0.5, (n, 2))
    boxes = np.hstack([lo, lo + rng.uniform(0.01, 2, (n, 2))])
    for r in (0.35, 1e-6, 0.6):
        dist = pair_distance(a, b, boxes)
        near = pairs_near(a, b, boxes, r)
        differ = near != (dist < r)
        assert np.abs(dist[differ] - r).max(initial=0.0) < 1e-12  # only a rounding at the very boundary
        assert differ.sum() <= 2


def test_segments_clear_agrees_with_the_distance_version(paper) -> None:  # type: ignore[no-untyped-def]
    scene = Scene(paper, robot_dimensions()[2])
    rng = np.random.default_rng(8)
    a = rng.uniform([scene.xmin, scene.ymin], [scene.xmax, scene.ymax], (5000, 2))
    b = a + rng.normal(0, 2.0, (5000, 2))
    got = segments_clear(a, b, scene.static, scene.radius)
    assert (got == segments_clear_by_distance(a, b, scene.static, scene.radius)).all()
    assert 0 < got.sum() < len(got)


def test_node_memo_is_seeded_with_exact_answers(paper) -> None:  # type: ignore[no-untyped-def]
    """What the visibility memo takes from the roadmap (its edges; corner, door and place
    nodes that are no edge see no each other) is what the exact test says, a door closed."""
    scene = _scene("paper", doorway=False, close_one=True, seed=2)
    planner = BasePlanner(paper, scene)
    doors = planner.closed_doors()
    memo = planner._node_memo(doors)
    rm = planner.roadmap
    e = rm.edges
    exact = planner._static_free(rm.nodes[e[:, 0]], rm.nodes[e[:, 1]])
    assert (memo[e[:, 0], e[:, 1]] == exact).all() and not exact.all()  # the closed door blocks some
    first = int(rm.corner_nodes[0])
    rng = np.random.default_rng(3)
    i, j = rng.integers(first, len(rm.nodes), (2, 4000))
    known = memo[i, j] >= 0
    assert known.all()
    assert (memo[i, j] == planner._static_free(rm.nodes[i], rm.nodes[j])).all()


@pytest.mark.parametrize("leaving", [True, False])
def test_people_rule_in_plain_floats_is_the_array_rule(leaving: bool) -> None:
    """Scene.people_clear answers few pairs in plain floats, many with numpy: the same rule."""
    from robot.scene import PEOPLE_TOLERANCE, Disc, _people_clear_array, _people_clear_small

    rng = np.random.default_rng(6 + leaving)
    seen = set()
    for _ in range(300):
        n = int(rng.integers(1, 8))
        a = rng.uniform(0, 4, (n, 2))
        b = a + rng.normal(0, 1.0, (n, 2))
        discs = [Disc(f"p{k}", *rng.uniform(0, 4, 2), float(rng.choice([0.25, 0.35, 0.6])))
                 for k in range(int(rng.integers(1, 5)))]
        small = _people_clear_small(a.tolist(), b.tolist(), discs, 0.35, leaving, PEOPLE_TOLERANCE)
        assert (small == _people_clear_array(a, b, discs, 0.35, leaving, PEOPLE_TOLERANCE)).all()
        seen |= set(small.tolist())
    assert seen == {True, False}
