"""Facts the world derives (a place is ``clear`` while no movable object rests there) and what a person
moving an object does to the facts about it (issue 36: no stale relation left behind)."""

from __future__ import annotations

from robot.sim import Simulation


def test_a_place_is_clear_while_no_movable_object_rests_there() -> None:
    sim = Simulation("flat", seed=1)
    facts = sim.snapshot().facts
    assert ("at", "vase", "kitchen") in facts and ("clear", "kitchen") not in facts
    assert ("at", "box", "storage") in facts and ("clear", "storage") not in facts
    assert {("clear", p) for p in ("living", "bedroom", "stove")} <= facts
    assert not any(f[0] == "clear" and f[1] == "cooker" for f in facts)  # a device is not a place's load


def test_an_effect_on_a_derived_fact_is_ignored_the_world_keeps_deriving_it() -> None:
    sim = Simulation("flat", seed=1)
    sim.apply(delete=[("clear", "living")], add=[("clear", "kitchen")])
    facts = sim.snapshot().facts
    assert ("clear", "living") in facts and ("clear", "kitchen") not in facts


def test_a_moved_object_leaves_its_relations_behind_it_and_keeps_its_properties() -> None:
    sim = Simulation("flat", seed=1)
    sim.apply(add=[("on_cooker", "vase", "cooker"), ("fragile", "vase"), ("near", "box", "vase")])
    assert sim.move("vase", "living")
    facts = sim.snapshot().facts
    assert ("at", "vase", "living") in facts and ("at", "vase", "kitchen") not in facts
    assert ("on_cooker", "vase", "cooker") not in facts and ("near", "box", "vase") not in facts
    assert ("fragile", "vase") in facts  # a property of the vase itself goes with it
    assert ("clear", "kitchen") in facts and ("clear", "living") not in facts


def test_an_object_the_robot_holds_is_not_moved() -> None:
    sim = Simulation("flat", seed=1)
    sim.held.add("vase")
    before = sim.snapshot().facts
    assert not sim.move("vase", "living")
    assert sim.snapshot().facts == before
