"""Every open door is used, every closed one is respected: in every shipped world and in
synthetic ones.

For each door of a world (walls, furniture and doors only; people are the people layer's
business, and a person sitting by a doorway may close it on purpose — Alice in ``paper``):

* **through the door**: points on its two sides and places in the two rooms it joins cost no
  more than going through it.  Each leg is planned *toward* the door's centre from its own
  side, and must itself come from that side (no longer than the way to the point beside the
  leaf plus the straight step into the doorway); the pair then costs at most the two legs,
  both ways round.  A path that never crosses the door can only pass by being shorter than
  one that does.  A start or goal in the doorway itself reaches each side no longer than
  through the front of the leaf on that side: a doorway point linked to one side only fails.
* **closing one door**: with any one door closed, and the others as the world has them or
  all open, two places are reachable exactly when the world's rooms and doors connect them.
  That connectivity comes from the world file, not from the planner: rooms are joined by
  the open doors between them (the rooms 0.3 m either side of the leaf) and by openings —
  stretches of a boundary two rooms share that no wall, furniture or door covers, wide
  enough for the robot.  Every room of the worlds tested is one piece of free space.

The synthetic worlds are grids of rooms with doors at random places in a random spanning
tree of the inner walls and in a third of the others (loops), a fifth of them closed, with
thin or thick walls, narrow (the robot's width + 2-6 cm) or wide doors, and furniture kept
off the doorways.  Breaking the roadmap on purpose (no corner or door milestones, door
milestones on one side only, closed doors not blocking, doorway points linked to one side
only) fails these tests.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from robot.motion import BasePlanner
from robot.roadmap import path_length
from robot.scene import Scene
from robot.spec import Box, WorldSpec, load_world, parse_world, room_of, shipped_worlds
from robot.tiago import robot_dimensions

Point = tuple[float, float]
SLACK = 0.02  # the corner arcs' chords make a roadmap path up to 2 % longer than the true one
DOOR_PROBE = 0.3  # metres either side of a leaf where its rooms are looked up (robot.describe's rule)
# seed: (wall thickness range, door width range); seeds whose doors include one whose closing
# cuts rooms off (seed 3's narrow-door world is one loop: closing any door cuts nothing)
SYNTHETIC = {
    1: ((0.08, 0.12), (0.8, 1.1)),
    2: ((0.25, 0.45), (0.8, 1.0)),
    4: ((0.08, 0.15), (0.72, 0.76)),
}


def synthetic(seed: int, walls: tuple[float, float], widths: tuple[float, float], nx: int = 3, ny: int = 2,
              room: float = 3.2) -> WorldSpec:
    """A grid of ``nx`` x ``ny`` rooms, doors in a spanning tree of its inner walls and in some
    others, furniture off the doorways and one place a room, clear of the door leaves (all
    drawn from ``seed``)."""
    rng = np.random.default_rng(seed)
    t = float(rng.uniform(*walls))
    w_all, h_all = nx * room, ny * room
    boxes: list[list[float]] = [[0, 0, w_all, t], [0, h_all - t, w_all, h_all], [0, 0, t, h_all],
                                [w_all - t, 0, w_all, h_all]]
    doors: dict[str, Any] = {}

    def wall(along_x: bool, at: float, lo: float, hi: float, door: bool) -> None:
        """A wall across ``[lo, hi]`` at ``at`` (horizontal if ``along_x``), with a door at a
        random place, or whole."""
        if not door:
            boxes.append([lo, at - t / 2, hi, at + t / 2] if along_x else [at - t / 2, lo, at + t / 2, hi])
            return
        w = float(rng.uniform(*widths))
        c = float(rng.uniform(lo + t + w / 2 + 0.1, hi - t - w / 2 - 0.1))
        name = f"door{len(doors)}"
        if along_x:
            boxes.extend([[lo, at - t / 2, c - w / 2, at + t / 2], [c + w / 2, at - t / 2, hi, at + t / 2]])
            doors[name] = {"box": [c - w / 2, at - t / 2, c + w / 2, at + t / 2]}
        else:
            boxes.extend([[at - t / 2, lo, at + t / 2, c - w / 2], [at - t / 2, c + w / 2, at + t / 2, hi]])
            doors[name] = {"box": [at - t / 2, c - w / 2, at + t / 2, c + w / 2]}
        doors[name]["open"] = bool(rng.uniform() < 0.8)

    # inner walls between neighbouring rooms; doors in a random spanning tree of them, and in a
    # third of the others (a loop: a door whose closing cuts nothing off)
    inner = [(False, i, j) for i in range(1, nx) for j in range(ny)] + [(True, i, j) for j in range(1, ny)
                                                                        for i in range(nx)]
    joined = {(i, j): (i, j) for i in range(nx) for j in range(ny)}

    def root(c: tuple[int, int]) -> tuple[int, int]:
        while joined[c] != c:
            c = joined[c]
        return c

    for k in rng.permutation(len(inner)):
        along_x, i, j = inner[k]
        a, b = ((i, j - 1), (i, j)) if along_x else ((i - 1, j), (i, j))
        tree = root(a) != root(b)
        joined[root(a)] = root(b)
        if along_x:
            wall(True, j * room, i * room, (i + 1) * room, tree or rng.uniform() < 0.33)
        else:
            wall(False, i * room, j * room, (j + 1) * room, tree or rng.uniform() < 0.33)
    rooms = {f"room{i}{j}": [i * room, j * room, (i + 1) * room, (j + 1) * room] for i in range(nx) for j in range(ny)}
    centres = [((d["box"][0] + d["box"][2]) / 2, (d["box"][1] + d["box"][3]) / 2) for d in doors.values()]
    furniture: dict[str, Any] = {}
    for k in range(3 * nx * ny):
        cx, cy = rng.uniform(0.6, w_all - 0.6), rng.uniform(0.6, h_all - 0.6)
        a, b = rng.uniform(0.3, 1.0), rng.uniform(0.3, 0.8)
        if min(math.dist((cx, cy), c) for c in centres) > 1.6:
            furniture[f"f{k}"] = {"box": [float(cx - a / 2), float(cy - b / 2), float(cx + a / 2), float(cy + b / 2)]}
    r = robot_dimensions()[2] + 0.02
    places: dict[str, list[float]] = {}
    for name, (x0, y0, x1, y1) in rooms.items():
        for _ in range(500):
            p = (round(float(rng.uniform(x0 + t, x1 - t)), 3), round(float(rng.uniform(y0 + t, y1 - t)), 3))
            if all(math.hypot(max(bx[0] - p[0], 0, p[0] - bx[2]), max(bx[1] - p[1], 0, p[1] - bx[3])) >= r
                   for bx in boxes + [f["box"] for f in furniture.values()] + [d["box"] for d in doors.values()]):
                places[f"at_{name}"] = [p[0], p[1], 0.0]
                break
    data = {"name": f"synthetic{seed}", "bounds": [[0.0, 0.0], [w_all, h_all]], "rooms": rooms, "walls": boxes,
            "furniture": furniture, "doors": doors, "places": places,
            "robot": {"pose": next(iter(places.values()))}}
    return parse_world(data, f"<synthetic world {seed}>")


def _worlds() -> list[Any]:
    return ([pytest.param(w, id=w) for w in shipped_worlds()]
            + [pytest.param(s, id=f"synthetic{s}") for s in SYNTHETIC])


def _world(which: str | int) -> WorldSpec:
    return load_world(which) if isinstance(which, str) else synthetic(which, *SYNTHETIC[which])


def _planner(spec: WorldSpec, open_all: bool = True) -> BasePlanner:
    scene = Scene(spec, robot_dimensions()[2])
    for name in spec.doors:
        scene.set_door(name, open_all or spec.doors[name].open)
    return BasePlanner(spec, scene)


def _length(planner: BasePlanner, a: Point, b: Point) -> float:
    path = planner.plan(a, b)
    return math.inf if path is None else path_length(list(path))


def _axis(box: Box) -> tuple[Point, Point, float]:
    """A leaf's centre, the unit normal across its wall and its half thickness along it."""
    x0, y0, x1, y1 = box
    centre = ((x0 + x1) / 2, (y0 + y1) / 2)
    if x1 - x0 < y1 - y0:  # a door in a vertical wall: crossed along x
        return centre, (1.0, 0.0), (x1 - x0) / 2
    return centre, (0.0, 1.0), (y1 - y0) / 2


def _beside(box: Box, offset: float, along: float = 0.0) -> tuple[Point, Point]:
    """The points ``offset`` metres beyond each face of the leaf (the low side first), moved
    ``along`` the wall."""
    (cx, cy), (nx, ny), half = _axis(box)
    d = half + offset
    return ((cx - nx * d + ny * along, cy - ny * d + nx * along), (cx + nx * d + ny * along, cy + ny * d + nx * along))


def _door_rooms(spec: WorldSpec, box: Box) -> tuple[str | None, str | None]:
    low, high = _beside(box, DOOR_PROBE)
    return room_of(spec, *low), room_of(spec, *high)


def _through(planner: BasePlanner, name: str, lows: list[Point], highs: list[Point]) -> int:
    """Check that ``lows`` (points on the door's low side) and ``highs`` (its high side) cost no
    more than going through door ``name``, each leg planned toward its centre from its own
    side; return the number of pairs checked."""
    spec_door = planner.scene.door_boxes[name]
    centre, _, _ = _axis(spec_door)
    fronts = _beside(spec_door, planner.scene.radius + 0.05)  # right in front of the leaf
    legs: list[dict[Point, float]] = [{}, {}]
    for k, (front, group) in enumerate(zip(fronts, (lows, highs), strict=True)):
        step = _length(planner, front, centre)
        assert step <= math.dist(front, centre) + 1e-3, (name, front, step)  # the doorway is linked this side
        for p in group:
            leg = _length(planner, p, centre)
            # from this side: no longer than by the point in front of the leaf
            assert leg <= (_length(planner, p, front) + step) * (1 + SLACK) + 1e-3, (name, p, leg)
            legs[k][p] = leg
    for p, lp in legs[0].items():
        for q, lq in legs[1].items():
            for s, g in ((p, q), (q, p)):
                cost = _length(planner, s, g)
                assert cost <= (lp + lq) * (1 + SLACK) + 1e-3, (name, s, g, cost, lp + lq)
    # a start or goal in the doorway itself reaches both sides, each through the front of the leaf
    _, (nx, _), _ = _axis(spec_door)
    lateral = (spec_door[3] - spec_door[1] if nx else spec_door[2] - spec_door[0]) / 2 - planner.scene.radius
    for along in (0.0, 0.6 * lateral, -0.6 * lateral):
        d = (centre[0] + (1 - nx) * along, centre[1] + nx * along)
        for front, group in zip(fronts, (lows, highs), strict=True):
            if not planner.scene.segments_free(np.array([d]), np.array([front]))[0]:
                continue
            for p in group:
                bound = (math.dist(d, front) + _length(planner, front, p)) * (1 + SLACK) + 1e-3
                assert _length(planner, d, p) <= bound and _length(planner, p, d) <= bound, (name, d, p, bound)
    return len(legs[0]) * len(legs[1])


@pytest.mark.slow
@pytest.mark.parametrize("which", _worlds())
def test_points_either_side_of_an_open_door_go_through_it(which: str | int) -> None:
    """Points in front of the leaf, beside it within the doorway's width and beyond the jambs
    (no straight way to the other side), near and farther from the wall."""
    spec = _world(which)
    planner = _planner(spec)
    scene = planner.scene
    for name, door in spec.doors.items():
        _, (nx, _), _ = _axis(door.box)
        width = door.box[3] - door.box[1] if nx else door.box[2] - door.box[0]
        lateral = width / 2 - scene.radius  # how far off the centre line the robot fits through
        rooms = _door_rooms(spec, door.box)
        sides: list[list[Point]] = [[], []]
        for offset in (scene.radius + 0.05, 0.8):
            for along in (0.0, 0.6 * lateral, -0.6 * lateral, width / 2 + 0.7, -width / 2 - 0.7):
                for k, p in enumerate(_beside(door.box, offset, along)):
                    if scene.free(*p) and room_of(spec, *p) == rooms[k]:
                        sides[k].append(p)
        assert _through(planner, name, *sides) >= 4, (spec.name, name, sides)


@pytest.mark.parametrize("which", _worlds())
def test_places_in_the_rooms_an_open_door_joins_cost_no_more_than_through_it(which: str | int) -> None:
    spec = _world(which)
    planner = _planner(spec)
    pairs = 0
    for name, door in spec.doors.items():
        rooms = _door_rooms(spec, door.box)
        groups = [[p[:2] for p in spec.places.values() if room_of(spec, *p[:2]) == room] for room in rooms]
        pairs += _through(planner, name, *groups)
    assert pairs >= len(spec.doors) // 2, (spec.name, pairs)


def _openings(spec: WorldSpec, radius: float) -> Iterator[tuple[str, str]]:
    """Pairs of rooms joined without a door: a stretch of their shared boundary that no wall,
    furniture or door leaf covers, wider than the robot."""
    covers = [o.box for o in spec.obstacles] + [d.box for d in spec.doors.values()]
    names = sorted(spec.rooms)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            ra, rb = spec.rooms[a], spec.rooms[b]
            for axis in (0, 1):  # a shared boundary at x (axis 0) or at y (axis 1)
                other = 1 - axis
                for lo_room, hi_room in ((ra, rb), (rb, ra)):
                    if lo_room[axis + 2] != hi_room[axis]:
                        continue
                    at = hi_room[axis]
                    span = (max(ra[other], rb[other]), min(ra[other + 2], rb[other + 2]))
                    cut = sorted((c[other], c[other + 2]) for c in covers if c[axis] <= at <= c[axis + 2])
                    free, reach = [], span[0]
                    for c0, c1 in cut:
                        if c0 > reach:
                            free.append(min(c0, span[1]) - reach)
                        reach = max(reach, c1)
                    free.append(span[1] - reach)
                    if max(free) > 2 * radius:
                        yield a, b


def _components(spec: WorldSpec, open_doors: set[str], radius: float) -> dict[str, int]:
    """Each room's piece of the apartment: rooms joined by ``open_doors`` and by openings."""
    part = {r: r for r in spec.rooms}

    def find(r: str) -> str:
        while part[r] != r:
            r = part[r]
        return r

    joins = list(_openings(spec, radius))
    for name in sorted(open_doors):
        low, high = _door_rooms(spec, spec.doors[name].box)
        if low is not None and high is not None:
            joins.append((low, high))
    for a, b in joins:
        part[find(a)] = find(b)
    roots = sorted({find(r) for r in spec.rooms})
    return {r: roots.index(find(r)) for r in spec.rooms}


@pytest.mark.parametrize("others_open", [False, True], ids=["others-as-shipped", "others-open"])
@pytest.mark.parametrize("which", _worlds())
def test_closing_one_door_cuts_off_only_what_it_alone_joined(which: str | int, others_open: bool) -> None:
    spec = _world(which)
    planner = _planner(spec, open_all=others_open)
    scene = planner.scene
    places = {n: p[:2] for n, p in spec.places.items()}
    room = {n: room_of(spec, *p) for n, p in places.items()}
    assert None not in room.values(), room
    cut_off = reached = 0
    for closed in sorted(spec.doors):
        before = dict(scene.door_open)
        scene.set_door(closed, False)
        piece = _components(spec, {n for n, o in scene.door_open.items() if o}, scene.radius)
        for a, pa in places.items():
            for b, pb in places.items():
                if a == b:
                    continue
                joined = piece[str(room[a])] == piece[str(room[b])]
                got = planner.plan(pa, pb) is not None
                assert got == joined, (spec.name, "closed", closed, a, b, "planner", got, "rooms and doors", joined)
                reached += joined
                cut_off += not joined
        for name, was in before.items():
            scene.set_door(name, was)
    assert reached  # real routes, and (the worlds have doors that matter) real cuts
    assert cut_off or not spec.doors


def test_the_openings_are_read_from_the_walls(flat: WorldSpec, paper: WorldSpec) -> None:
    r = robot_dimensions()[2]
    assert sorted(_openings(flat, r)) == [("kitchen", "living")]  # the flat's doorless passage
    assert list(_openings(paper, r)) == []  # every way between the paper's rooms has a door
    assert list(_openings(synthetic(1, *SYNTHETIC[1]), r)) == []
