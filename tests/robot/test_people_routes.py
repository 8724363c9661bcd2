"""People walk round walls and furniture, never through them (robot.people, Simulation.person_route)."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest

from robot.people import Person
from robot.scene import segments_clear
from robot.sim import Simulation
from robot.spec import PersonSpec, WorldSpec, load_world, room_of, shipped_worlds


def _walls(spec: WorldSpec) -> np.ndarray:
    return np.array([o.box for o in spec.obstacles if o.kind == "wall"], dtype=float).reshape(-1, 4)


def _through_walls(spec: WorldSpec, pts: list[tuple[float, float]]) -> list[int]:
    """Indices of the polyline's segments whose centre line crosses a wall."""
    if len(pts) < 2:
        return []
    a, b = np.array(pts[:-1], float), np.array(pts[1:], float)
    return [int(i) for i in np.flatnonzero(~segments_clear(a, b, _walls(spec), 1e-9))]


@pytest.fixture(scope="module", params=shipped_worlds())
def world(request: pytest.FixtureRequest) -> tuple[WorldSpec, Simulation]:
    spec = load_world(request.param)
    return spec, Simulation(dataclasses.replace(spec, people={}))


def test_routes_between_places_cross_no_wall(world: tuple[WorldSpec, Simulation]) -> None:
    spec, sim = world
    pairs = list(itertools.permutations(sorted(spec.places), 2))
    routed = 0
    for a, b in pairs:
        pa, pb = spec.places[a][:2], spec.places[b][:2]
        route = list(sim.person_route(pa, pb))
        assert route[0] == pa and route[-1] == pb, (a, b)
        if not sim.motion.estimate_ignoring_doors((*pa, 0.0), (*pb, 0.0)).reachable:
            assert route == [pa, pb]  # a walled-off room: no way round, the script as written
            continue
        routed += len(route) > 2
        assert not _through_walls(spec, route), f"{spec.name}: {a} -> {b} walks through a wall: {route}"
    assert routed  # some pairs needed a way round


def test_a_clear_straight_leg_stays_as_written(paper: WorldSpec) -> None:
    sim = Simulation(dataclasses.replace(paper, people={}))
    a, b = paper.places["living"][:2], paper.places["alice_destination"][:2]
    assert not _through_walls(paper, [a, b])
    assert sim.person_route(a, b) == (a, b)


def _across_rooms(spec: WorldSpec) -> tuple[tuple[float, float], tuple[float, float]]:
    """The two places of different rooms farthest apart whose straight line crosses a wall."""
    best = None
    for a, b in itertools.combinations(sorted(spec.places), 2):
        pa, pb = spec.places[a][:2], spec.places[b][:2]
        if room_of(spec, *pa) != room_of(spec, *pb) and _through_walls(spec, [pa, pb]):
            d = math.dist(pa, pb)
            if best is None or d > best[0]:
                best = (d, pa, pb)
    assert best is not None
    return best[1], best[2]


def _walked(sim: Simulation, name: str, until: float) -> list[tuple[float, float]]:
    pts = []
    t = 0.0
    while t < until:
        t = round(t + 0.1, 6)
        sim.advance(t)
        p = sim.people[name]
        pts.append((p.x, p.y))
    return pts


@pytest.mark.slow
@pytest.mark.parametrize("world_name", shipped_worlds())
def test_a_scripted_walk_across_rooms_goes_through_doorways(world_name: str) -> None:
    spec = load_world(world_name)
    a, b = _across_rooms(spec)
    walk = ((5.0, a[0], a[1]), (5.0 + 4 * math.dist(a, b) / 0.5, b[0], b[1]))  # a slow walk: on time
    people = {"p": PersonSpec("p", (a[0], a[1], 0.0), "standing", 0.5, walk, ())}
    sim = Simulation(dataclasses.replace(spec, people=people))
    assert len(sim.people["p"].walk) > 2  # routed: corners between the two ends
    pts = _walked(sim, "p", walk[-1][0] + 1.0)
    assert not _through_walls(spec, [a, *pts])
    assert math.dist(pts[-1], b) < 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("world_name", shipped_worlds())
def test_a_walk_event_goes_through_doorways_at_the_person_s_speed(world_name: str) -> None:
    spec = load_world(world_name)
    a, b = _across_rooms(spec)
    people = {"p": PersonSpec("p", (a[0], a[1], 0.0), "standing", 0.5, (), ())}
    sim = Simulation(dataclasses.replace(spec, people=people))
    sim.people["p"].go_to(0.0, b[0], b[1])
    route = sim.person_route(a, b)
    length = sum(math.dist(p, q) for p, q in itertools.pairwise(route))
    assert sim.people["p"].walk[-1][0] == pytest.approx(length / 0.5)
    pts = _walked(sim, "p", length / 0.5 + 1.0)
    assert not _through_walls(spec, [a, *pts])
    assert math.dist(pts[-1], b) < 1e-6


def test_a_person_behind_the_script_goes_round_the_corner() -> None:
    """Held back (here: a script faster than they walk), a person heads for the script's point
    of now along the route, not straight across what stands between."""
    tip = (0.5, 1.0)  # a wall along x = 0.5 below y = 1: from one side to the other, round its tip

    def route(a: tuple[float, float], b: tuple[float, float]) -> tuple[tuple[float, float], ...]:
        if (a[0] < 0.5) != (b[0] < 0.5) and a[1] < 1 and b[1] < 1:
            return (a, tip, b)
        return (a, b)

    spec = PersonSpec("p", (0.0, 0.0, 0.0), "standing", 1.0, ((0.0, 0.0, 0.0), (1.0, 1.0, 0.0)), ())
    p = Person(spec, route)
    assert p.walk == ((0.0, 0.0, 0.0), (0.5, 0.5, 1.0), (1.0, 1.0, 0.0))  # the corner timed by distance
    p.walk = ((0.0, 0.0, 0.0), (0.1, 1.0, 0.0))  # a script far too fast for them
    seen = [(0.0, 0.0)]
    for k in range(1, 30):
        p.step(k * 0.1, 0.1, (9.0, 9.0))
        seen.append((p.x, p.y))
    for (x0, y0), (x1, y1) in itertools.pairwise(seen):
        if (x0 < 0.5) != (x1 < 0.5):  # crossing x = 0.5 round the tip (within a step: sampled per step)
            assert y0 + (y1 - y0) * (0.5 - x0) / (x1 - x0) >= 1.0 - 0.1
    assert seen[-1] == pytest.approx((1.0, 0.0))
