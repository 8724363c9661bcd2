"""Every task folder of the experiment has two trees written from different assumptions, and
``tasker check``'s report (:func:`planners.treecheck.reports`) finds each complete on the folder's
``[example]``: at every interruption point the chosen branch reaches its goal and leaves no owned
hazard on, and no ``when`` names a fact the world never has (issue 36, item 6).

Expected trees, branches and stages are read off the folders by hand: each ``[example]``'s plan
is written in the folder's comments (e.g. water_plants: the can is held with the tap running
before fill and before turn_off, in the bathroom, and the nearest clear surface is the bedroom;
hot_pot: the pot is held at the stove and, past the kitchen door, in the living room)."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest

from planners.loader import load_task
from planners.pddl_task import PddlTaskType
from planners.treecheck import TreeReport, report, reports

ROOT = Path(__file__).resolve().parents[2]
DOMAINS = ROOT / "domains"
SPEC_TASKS = ROOT / "experiments" / "sweep" / "specs" / "tasks"
FOLDERS = {
    "carry_object": DOMAINS / "carry_object",
    "cook": DOMAINS / "cook",
    "guide_human": DOMAINS / "guide_human",
    "human_fell": DOMAINS / "human_fell",
    "water_plants": SPEC_TASKS / "water_plants",
    "hot_pot": SPEC_TASKS / "hot_pot",
}
TREES = {
    "carry_object": ("default", "destination"),
    "cook": ("default", "cooker"),
    "guide_human": ("default", "arrive"),
    "human_fell": ("default", "help_first"),
    "water_plants": ("default", "can_first"),
    "hot_pot": ("default", "stove"),
}
CHOSEN = {  # the branches each tree chooses at the [example]'s interruption points
    ("guide_human", "default"): {"apologise: person following", "apologise: person greeted", "save"},
    ("guide_human", "arrive"): {"following, at the destination: say goodbye",
                                "following, no door on the way: guide them on, say goodbye",
                                "greeted: ask them to wait", "save"},
    ("human_fell", "default"): {"checked: call for help, reassure", "beside the person: reassure", "save"},
    ("human_fell", "help_first"): {"beside the person: call for help, reassure", "save"},
    ("water_plants", "default"): {"can held, tap running: tap off, then the can on the nearest clear surface",
                                  "can held: put it on the nearest clear surface", "save"},
    ("water_plants", "can_first"): {"can held, tap running: the can on the nearest clear surface, then the tap off",
                                    "can held: put it on the nearest clear surface", "save"},
    ("hot_pot", "default"): {"pot held: put it on the nearest clear heat-proof spot", "save"},
    ("hot_pot", "stove"): {"pot held at the stove: put it back",
                           "pot held, the stove through an open door: back through it, put it on the stove", "save"},
}


def _load(folder: Path) -> PddlTaskType:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_task(folder, use_cache=False)


def _known_facts() -> list[tuple[str, ...]]:
    """What the shipped worlds can hold, as ``tasker check`` reads them (trees may read those facts)."""
    from experiments.cli.check import world_facts
    from robot.spec import load_world, shipped_worlds

    return [f for name in shipped_worlds() for f in world_facts(load_world(name))]


def _reports(name: str) -> tuple[PddlTaskType, list[TreeReport]]:
    task = _load(FOLDERS[name])
    return task, reports(task, world_facts=_known_facts())


def _warned(task: PddlTaskType, rep: TreeReport) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep.warn(task)
    return [str(w.message) for w in caught]


def _chosen(rep: TreeReport) -> set[str]:
    return {r.label for r in rep.runs if r.policy == "strict"}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(FOLDERS))
def test_every_tree_of_the_folder_is_complete_on_its_example(name: str) -> None:
    task, got = _reports(name)
    assert tuple(r.tree for r in got) == TREES[name]
    for rep in got:
        assert rep.complete, rep.lines()
        assert _warned(task, rep) == []
        assert rep.runs and all(r.branch >= 0 for r in rep.runs)  # the tree was read at every point
        if (name, rep.tree) in CHOSEN:
            assert _chosen(rep) == CHOSEN[name, rep.tree]


def _stages_where(rep: TreeReport, label: str) -> list[tuple[str, ...]]:
    return [r.stages for r in rep.runs if r.label == label]


@pytest.mark.slow
def test_water_plants_trees_turn_the_tap_off_and_put_the_can_down_in_either_order() -> None:
    _, (tap_first, can_first) = _reports("water_plants")
    both = [("navigate(robot bathroom bathroom)", "turn_off(robot tap bathroom)",
             "navigate(robot bathroom bedroom)", "put_down(robot can bedroom)")] * 2  # before fill, before turn_off
    assert _stages_where(tap_first, sorted(CHOSEN["water_plants", "default"])[0]) == both
    assert _stages_where(can_first, sorted(CHOSEN["water_plants", "can_first"])[0]) == [
        ("navigate(robot bathroom bedroom)", "put_down(robot can bedroom)",
         "navigate(robot bedroom bathroom)", "turn_off(robot tap bathroom)")] * 2


def test_hot_pot_trees_put_the_pot_on_the_nearest_spot_or_back_on_the_stove() -> None:
    _, (nearest, stove) = _reports("hot_pot")
    assert sorted(_stages_where(nearest, "pot held: put it on the nearest clear heat-proof spot")) == [
        ("navigate(robot living living)", "put_pot(robot pot living)"),   # past the door: the table itself
        ("navigate(robot stove stove)", "put_pot(robot pot stove)")]      # just lifted: where it was
    assert _stages_where(stove, "pot held, the stove through an open door: back through it, put it on the stove") == [
        ("navigate_through(robot living_kitchen living stove)", "put_pot(robot pot stove)")]


@pytest.mark.slow
def test_guide_humans_arrive_tree_is_complete_where_a_door_is_on_the_way(tmp_path: Path) -> None:
    """The [example] has no door (four estimator tests pin its plans); a copy whose kitchen is through
    an open door, as the paper world's rooms are, reads the branch that passes it."""
    folder = tmp_path / "guide_human"
    shutil.copytree(FOLDERS["guide_human"], folder)
    toml = folder / "task.toml"
    text = toml.read_text()
    old = 'livingroom = "place" }\nfacts = [["at", "robot", "livingroom"], '
    assert text.count(old) == 1
    door = ('["door_at", "d", "hall"], ["door_at", "d", "kitchen"], ["open", "d"], '
            '["door_between", "d", "hall", "kitchen"], ["door_between", "d", "kitchen", "hall"], ')
    toml.write_text(text.replace(old, old.replace('"place" }', '"place", d = "door" }') + door))
    task = _load(folder)
    rep = report(task, world_facts=_known_facts(), tree="arrive")
    assert rep.complete, rep.lines()
    label = "following, the destination through an open door: guide them through it, say goodbye"
    assert _stages_where(rep, label) == [
        ("guide_through(robot john d hall kitchen)", "say_goodbye(robot john kitchen)")]


@pytest.mark.slow
def test_the_hot_pot_scenario_runs_and_a_static_suspension_puts_the_pot_back() -> None:
    """Peter falls at 30 s as the robot lifts the pot off the stove (pick_pot is blocking, so the
    suspension waits for it): the default tree puts the pot back where it was, the judge finds the
    suspension safe, and the pot reaches the table once Peter is helped."""
    from experiments.run.options import RunOptions
    from experiments.run.runner import run_scenario
    from experiments.trace.timeline import Timeline

    result = run_scenario(ROOT / "experiments" / "sweep" / "specs" / "scenarios" / "hot_pot.toml",
                          RunOptions(suspension="static", task_paths=(str(FOLDERS["hot_pot"]),)), pictures=False)
    tl = Timeline.of(result.trace.events)
    assert {a.task_type: a.end.cause if a.end else None for a in tl.agents.values()} == {
        "hot_pot": "finished", "human_fell": "finished"}
    (susp,) = tl.agents["d1"].suspensions
    assert [(s.action, tuple(s.args), s.status) for s in susp.stages] == [
        ("navigate", ("robot", "stove", "stove"), "done"), ("put_pot", ("robot", "pot", "stove"), "done")]
    assert result.metrics["suspensions"]["all_safe"] is True
    put = susp.stages[-1].end
    assert put is not None
    held = [h for h in tl.hazards if h.hazard == "pot_held" and h.start < put]
    assert held and all(h.end is not None and h.end <= put + 1e-9 for h in held)  # off once it is put down
