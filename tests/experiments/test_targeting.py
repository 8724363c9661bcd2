"""Targeted perturbations (issue 36): a change aimed at what the tree's branch depends on — a place its
stages use, a door on its route, a device it names — the same for every strategy of a variant."""

from __future__ import annotations

import pytest

from experiments.inputs.perturbation import TOGGLE, Perturbation, TargetDraw
from experiments.inputs.scenario import InterruptionGrid
from experiments.run.options import RunOptions
from experiments.run.runner import run_scenario
from experiments.run.targeting import candidates, crosses
from tasker.stage import Stage
from tasker.world import WorldState


class _Door:
    def __init__(self, box: tuple[float, float, float, float]) -> None:
        self.box = box


WORLD = WorldState(
    frozenset({("clear", "counter"), ("clear", "hall"), ("state", "cooker", "on"),
               ("door_between", "d1", "hall", "counter")}),
    objects={"counter": "place", "hall": "place", "stove": "place", "pan": "pan", "robot": "robot"})
STAGES = (
    Stage("navigate", ("robot", "hall", "counter"), skill="navigate"),
    Stage("put_down", ("robot", "pan", "counter"), skill="manipulate"),
    Stage("put_down", ("robot", "pan", "stove"), skill="manipulate"),  # stove is not clear: not a target
    Stage("turn_off", ("robot", "cooker", "stove"), skill="manipulate"),
)


def test_the_candidates_are_what_the_branch_depends_on() -> None:
    found = candidates(STAGES, WORLD, clutter=["bag", "box"], devices={"cooker": "on", "tap": "off"},
                       doors={"d1": _Door((0, 0, 1, 1)), "d2": _Door((5, 5, 6, 6)), "d3": _Door((10, 0, 11, 1))},
                       route=lambda a, b: [(-1.0, 0.5), (5.5, 5.5)], label="hot pan held",
                       needs_clear=lambda stage, place: stage.action == "put_down")
    assert [(t.what, t.value) for t in found["place"]] == [("move", ("bag", "counter"))]
    assert [(t.what, t.value) for t in found["door"]] == [("door", ("d1", TOGGLE)), ("door", ("d2", TOGGLE))]
    assert [(t.what, t.value) for t in found["device"]] == [("device", ("cooker", TOGGLE))]
    assert "hot pan held" in found["place"][0].why


def test_without_clutter_or_a_route_there_is_nothing_of_that_kind() -> None:
    found = candidates(STAGES[1:], WORLD, clutter=[], devices={}, doors={}, route=lambda a, b: [], label="",
                       needs_clear=lambda stage, place: True)
    assert found == {"place": [], "door": [], "device": []}


@pytest.mark.parametrize(("a", "b", "hit"), [((0, 0), (2, 2), True), ((0, 3), (3, 3), False),
                                             ((1.5, -1), (1.5, 5), True), ((3, 0), (4, 4), False)])
def test_a_segment_crosses_a_box_or_does_not(a: tuple[float, float], b: tuple[float, float], hit: bool) -> None:
    assert crosses(a, b, (1.0, 1.0, 2.0, 2.0)) is hit


def test_a_draw_is_the_seeds_and_within_its_window() -> None:
    p = Perturbation(mode="targeted", before_s=20.0, during_s=8.0)
    draws = [TargetDraw.of(p, f"household:{s}") for s in range(40)]
    assert draws == [TargetDraw.of(p, f"household:{s}") for s in range(40)]
    assert {d.timing for d in draws} == {"before", "during"}
    for d in draws:
        assert 0 < d.delay_s <= (20.0 if d.timing == "before" else 8.0) and sorted(d.kinds) == ["device", "door",
                                                                                                  "place"]


def test_a_targeted_perturbation_is_refused_with_a_bad_mode_or_window() -> None:
    with pytest.raises(ValueError, match="mode"):
        Perturbation(mode="aimed")
    with pytest.raises(ValueError, match="during_s"):
        Perturbation(mode="targeted", during_s=0.0)


@pytest.mark.slow
def test_every_strategy_of_a_targeted_variant_meets_the_same_change() -> None:
    grid = InterruptionGrid("requests[2]", 0.0, 180.0, 60.0)
    p = Perturbation(mode="targeted")
    seen = {}
    for suspension in ("static", "fallback"):
        opts = RunOptions(seed=4, randomize=True, interruption=grid, perturbation=p, suspension=suspension)
        events = run_scenario("household", opts, pictures=False).trace.events
        seen[suspension] = [(e["t"], e["what"], e["value"], e["note"]) for e in events
                            if e["event"] == "world" and e["note"].startswith("perturbation (targeted")]
    assert len(seen["static"]) == 1 and seen["static"] == seen["fallback"]
