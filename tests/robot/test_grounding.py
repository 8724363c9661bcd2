"""Grounding respects walls: a thing is at the nearest place of its own room."""

from __future__ import annotations

import pytest

from robot.sim import Simulation


@pytest.fixture(scope="module")
def sim(paper) -> Simulation:
    return Simulation(paper)


@pytest.mark.parametrize(("x", "y", "place"), [
    (5.5, 1.7, "hall"),            # nearer alice_destination (living room), through the wall
    (5.6, 6.4, "hall"),            # nearer kitchen, through the wall
    (4.6, 1.7, "alice_destination"),
    (7.4, 4.6, "john_destination"),  # in the bedroom, nearer hall through the wall
    (7.4, 3.5, "bathroom"),
])
def test_robot_is_at_the_nearest_place_of_its_room(sim: Simulation, x: float, y: float, place: str) -> None:
    assert sim.nearest_place(x, y) == place


def test_people_are_grounded_in_their_room_too(sim: Simulation) -> None:
    assert sim.person_place(5.5, 1.7) == "hall"
    assert sim.person_place(1.0, 6.8) == "kitchen"  # the stove is a device's place, not a person's


def test_the_snapshot_grounds_the_robot_in_its_room(paper) -> None:
    world = type(paper)(**{**{f: getattr(paper, f) for f in paper.__dataclass_fields__},
                           "robot": type(paper.robot)(pose=(5.5, 1.7, 0.0))})
    snap = Simulation(world).snapshot()
    assert snap.holds("at", "robot", "hall") and not snap.holds("at", "robot", "alice_destination")


def test_nested_rooms_use_the_smallest(flat) -> None:
    sim = Simulation(flat)
    assert sim.room_of(0.7, 5.2) == "storage"  # the smallest room holding the point
    assert sim.nearest_place(0.7, 5.2) == "storage"


def test_remembered_places_are_the_places_computed_afresh(paper, monkeypatch: pytest.MonkeyPatch) -> None:
    import random

    import robot.places as places_module

    monkeypatch.setattr(places_module, "PLACE_MEMO", 16)  # forgotten and remembered again along the way
    sim = Simulation(paper)
    device_places = {d.place for d in paper.devices.values()}
    people_spots = {n: p for n, p in paper.places.items() if n not in device_places}
    (x0, y0), (x1, y1) = paper.bounds
    rng = random.Random(7)
    points = [(round(rng.uniform(x0, x1), 2), round(rng.uniform(y0, y1), 2)) for _ in range(40)]
    for x, y in points * 2:  # the second pass hits the memo where it still holds them
        assert sim.nearest_place(x, y) == sim.place_of(x, y, paper.places)
        assert sim.person_place(x, y) == sim.place_of(x, y, people_spots)
