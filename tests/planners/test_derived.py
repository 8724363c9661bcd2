"""Suspension goals derived from what a task folder declares; static stages checked like a robot would;
what the [example] shows about a folder's tree and goal; doors left as the task found them."""

from __future__ import annotations

import shutil
import warnings
from dataclasses import replace
from pathlib import Path

import pytest

from planners.examples import example_context
from planners.loader import load_task
from tasker.stage import Purpose
from tasker.task import Strategy
from tasker.trace import INAPPLICABLE
from tasker.world import WorldState

DOMAINS = Path(__file__).resolve().parents[2] / "domains"


def _folder(tmp_path: Path, name: str, edit: dict[str, str] | None = None, drop: tuple[str, ...] = ()) -> Path:
    folder = tmp_path / name
    shutil.copytree(DOMAINS / "carry_object", folder)
    text = (folder / "task.toml").read_text().replace('name = "carry_object"', f'name = "{name}"')
    for old, new in (edit or {}).items():
        assert old in text
        text = text.replace(old, new)
    text = "\n".join(line for line in text.splitlines() if not line.startswith(drop) or not drop) + "\n"
    (folder / "task.toml").write_text(text)
    return folder


def _loaded(folder: Path) -> tuple[object, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        task = load_task(folder, use_cache=False)
    return task, [str(w.message) for w in caught]


@pytest.mark.slow
def test_a_goal_that_leaves_its_own_hazard_on_is_warned_about_and_restore_asks_it_back(tmp_path: Path) -> None:
    _, said = _loaded(_folder(tmp_path, "no_restore", drop=("restore",)))
    assert any("the goal leaves on what the [example]'s plan turned on: door_open: (open door1)" in s for s in said)
    task, said = _loaded(_folder(tmp_path, "with_restore"))
    assert not any("leaves on" in s for s in said)
    ctx = example_context(task)  # type: ignore[arg-type]
    _, goal, _ = task.update_inputs(ctx)  # type: ignore[attr-defined]
    assert ("not", "open", "door1") in goal  # closed when it first planned: closed at its goal


@pytest.mark.slow
def test_a_branch_whose_stage_cannot_run_is_warned_about(tmp_path: Path) -> None:
    """A branch that puts the object down wherever the robot is: not a surface in every state."""
    folder = _folder(tmp_path, "bad_branch", edit={
        '{ action = "place", args = ["$robot", "$item", "$at:robot"] },\n  { action = "navigate"':
        '{ action = "place", args = ["$robot", "$item", "hall"] },\n  { action = "navigate"'})
    _, said = _loaded(folder)
    assert any("runs a stage it cannot run" in s and "place(robot vase hall)" in s and "(at robot hall)" in s
               for s in said), said


def test_a_static_stage_whose_precondition_fails_is_inapplicable_and_one_that_changes_nothing_is_not() -> None:
    task = load_task(DOMAINS / "carry_object")
    ctx = example_context(task)
    assert ctx is not None and isinstance(ctx.world, WorldState)
    place = task.builder.from_steps([("place", "robot", "vase", "hall")], {}, ctx.args)[0]
    why = task.inapplicable(ctx, place)
    assert why is not None and why.startswith(INAPPLICABLE) and "(at robot hall)" in why
    stay = task.builder.from_steps([("navigate", "robot", "livingroom", "livingroom")], {}, ctx.args)[0]
    assert task.inapplicable(ctx, stay) is None
    go = task.builder.from_steps([("navigate", "robot", "livingroom", "kitchen")], {}, ctx.args)[0]
    assert task.inapplicable(ctx, go) is None  # a free passage (task.py's extra facts count)


def test_the_derived_goal_turns_off_what_the_task_owns_and_keeps_what_a_short_interruption_allows() -> None:
    task = load_task(DOMAINS / "cook")
    ctx = example_context(task, strategy=Strategy("planned", "derived", "strict"))
    assert ctx is not None and isinstance(ctx.world, WorldState)
    on = replace(ctx, world=ctx.world.updated([("cooker_on", "cooker"), ("holding", "robot", "pan")],
                                              [("hand_empty", "robot")]))
    goal, label = task.derived_goal(on, on.world)
    assert ("not", "cooker_on", "cooker") in goal and ("not", "holding", "robot", "pan") in goal
    assert label.startswith("derived:")
    on.memory["interruption_s"] = 30.0  # shorter than the cooker's 60 s budget, longer than the pan's 0 s
    short = replace(on, strategy=Strategy("planned", "derived", "conditional"))
    goal, label = task.derived_goal(short, short.world)
    assert ("not", "cooker_on", "cooker") not in goal and ("not", "holding", "robot", "pan") in goal
    assert "cooker_on(cooker) left on" in label
    plan = task.generate_suspension(replace(on, suspended=True))
    assert plan.purpose is Purpose.GEN_SUSP and plan.strategy == "planned"
    assert {s.action for s in plan.stages} >= {"turn_off"}


def test_a_door_the_task_did_not_open_is_not_its_to_close() -> None:
    task = load_task(DOMAINS / "carry_object")
    ctx = example_context(task, strategy=Strategy("planned", "derived", "strict"))
    assert ctx is not None and isinstance(ctx.world, WorldState)
    opened = replace(ctx, world=ctx.world.updated([("open", "door1")], []))
    assert task.derived_goal(opened, opened.world)[0] == []  # someone else's door: nobody's hazard
    mine = replace(opened, done=task.builder.from_steps([("open_door", "robot", "door1", "hall")], {}, ctx.args))
    assert ("not", "open", "door1") in task.derived_goal(mine, mine.world)[0]
    given = replace(opened, hazards=lambda: (("door_open", ("open", "door1")),))
    assert ("not", "open", "door1") in task.derived_goal(given, given.world)[0]


def test_a_guided_person_is_left_in_a_safe_role() -> None:
    task = load_task(DOMAINS / "guide_human")
    ctx = example_context(task, strategy=Strategy("planned", "derived", "strict"))
    assert ctx is not None and isinstance(ctx.world, WorldState)
    person = ctx.args["person"]
    # the robot guides John through the hall: both there, John greeted and following
    here = [("greeted", person), ("following", person), ("at", "robot", "hall")]
    following = replace(ctx, world=ctx.world.updated(here, [("at", "robot", "livingroom")]))
    goal, label = task.derived_goal(following, following.world)
    assert ("not", "following", person) in goal and ("told_to_wait", person) in goal  # the reachable safe literal
    waiting = replace(ctx, world=ctx.world.updated([], []))  # not greeted yet: already in a safe role
    assert task.derived_goal(waiting, waiting.world)[0] == []


@pytest.mark.slow
@pytest.mark.parametrize(("edit", "message"), [
    ({'told_to_wait = [["told_to_wait", "$person"]]': 'told_to_wait = [["told_to_wait", "$person"]]\n'
      'bad = 1'}, "unknown key 'bad'"),
    ({'safe = ["waiting"]': 'safe = ["folowing"]'}, "'folowing' is not a role this \\[people\\] declares"),
    ({'restore = [["open", "?d"]]': 'restore = [["not", "open", "?d"]]'}, "problem.restore"),
    ({'[[bindings]]': '[derived]\ninvariants = [["teleported", "$robot"]]\n\n[[bindings]]'}, "derived.invariants"),
])
def test_bad_declarations_name_their_field(tmp_path: Path, edit: dict[str, str], message: str) -> None:
    from planners.checks import DefinitionError

    folder = tmp_path / "g"
    shutil.copytree(DOMAINS / "guide_human", folder)
    text = (folder / "task.toml").read_text().replace('name = "guide_human"', 'name = "g"')
    for old, new in edit.items():
        text = text.replace(old, new, 1)
    (folder / "task.toml").write_text(text)
    with pytest.raises(DefinitionError, match=message):
        load_task(folder, use_cache=False)
