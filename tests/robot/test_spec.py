"""World files: the shipped ones load; a bad one names the file and the field."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from robot.spec import WorldFileError, load_world, parse_world, shipped_worlds
from tasker.errors import TaskerError


@pytest.mark.parametrize("name", shipped_worlds())
def test_shipped_worlds_load(name: str) -> None:
    spec = load_world(name)
    assert spec.places and spec.obstacles
    assert load_world(Path(__file__).parents[2] / "robot" / "worlds" / f"{name}.toml") == spec


def test_paper_world_has_the_papers_people(paper) -> None:
    assert set(paper.people) == {"john", "alice", "peter", "sara"}
    assert paper.people["john"].walk, "John walks toward his destination while waiting"
    assert {"john_destination", "alice_destination"} <= set(paper.places)


def test_flat_has_a_cooker_and_a_door(flat) -> None:
    assert flat.devices["cooker"].type == "cooker"
    assert flat.doors


BASE = 'bounds = [[0, 0], [5, 5]]\n[robot]\npose = [1, 1, 0]\n'


@pytest.mark.parametrize(("text", "field"), [
    (BASE + '[people.john]\npose = [1, 2]\n', "people.john.pose: expected [x, y, yaw]"),
    (BASE + '[people.john]\npose = [1, 2, 0]\nposture = "lying"\n', "people.john.posture"),
    (BASE + '[people.john]\npose = [1, 2, 0]\nwalk = [[5, 1, 1], [2, 1, 1]]\n', "people.john.walk[1]"),
    (BASE + '[places]\nhall = [1, "a", 0]\n', "places.hall: expected [x, y, yaw]"),
    (BASE + '[furniture.sofa]\nbox = [2, 2, 1, 3]\n', "furniture.sofa.box"),
    (BASE + '[doors.d]\nbox = [1, 1, 2, 2]\nopen = "yes"\n', "doors.d.open"),
    (BASE + '[places]\nk = [1, 1, 0]\n[devices.cooker]\nplace = "kitchen"\n', "devices.cooker.place"),
    (BASE + 'colour = 3\n', "robot.colour: unknown key"),
    ('[robot]\npose = [1, 1, 0]\n', "bounds: missing"),
    ('bounds = [[0, 0], [5, 5]]\n[robot]\npose = [1, 1]\n', "robot.pose"),
])
def test_bad_world_file_names_the_field(tmp_path: Path, text: str, field: str) -> None:
    f = tmp_path / "bad.toml"
    f.write_text(text)
    with pytest.raises(WorldFileError) as err:
        load_world(f)
    assert str(err.value).startswith(str(f))
    assert field in str(err.value)
    assert err.value.field and err.value.field in field
    assert isinstance(err.value, TaskerError)


def test_invalid_toml_and_unknown_names(tmp_path: Path) -> None:
    f = tmp_path / "broken.toml"
    f.write_text("bounds = [[0, 0], [5, 5]\n")
    with pytest.raises(WorldFileError, match="broken.toml:2: not valid TOML"):
        load_world(f)
    with pytest.raises(WorldFileError, match="shipped: .*paper"):
        load_world("no_such_world")


def test_names_must_be_unique() -> None:
    data = {"bounds": [[0, 0], [5, 5]], "robot": {"pose": [1, 1, 0]}, "places": {"john": [1, 1, 0]},
            "people": {"john": {"pose": [2, 2, 0]}}}
    with pytest.raises(WorldFileError, match="used twice"):
        parse_world(data, "dup.toml")


def test_names_must_be_lower_case() -> None:
    """Plans name objects in lower case (PDDL ignores case): before, a person "John" was never the
    "john" a plan guided, silently."""
    data = {"bounds": [[0, 0], [5, 5]], "robot": {"pose": [1, 1, 0]}, "places": {"hall": [1, 1, 0]},
            "people": {"John": {"pose": [2, 2, 0]}}}
    with pytest.raises(WorldFileError, match="people.John: PDDL names ignore case .* write 'john'"):
        parse_world(data, "upper.toml")


@pytest.mark.parametrize("name", ["kit chen", "küche", "kitchen?", "1st_floor", "_hall", "hall.1"])
@pytest.mark.parametrize("what", ["places", "people", "doors", "objects"])
def test_names_must_be_pddl_names(name: str, what: str) -> None:
    """Every name is an object of the planning problems: before, a place "kit chen" or "küche"
    loaded, and every planning call of the run failed in Fast Downward's parser."""
    entry = {"places": [1, 1, 0], "people": {"pose": [2, 2, 0]}, "doors": {"box": [3, 3, 4, 4]},
             "objects": "item"}[what]
    data = {"bounds": [[0, 0], [5, 5]], "robot": {"pose": [1, 1, 0]}, what: {name: entry}}
    with pytest.raises(WorldFileError, match=f"{what}.{re.escape(name)}: .* is not a PDDL name: expected a letter"):
        parse_world(data, "names.toml")


@pytest.mark.parametrize("name", ["hall", "john_destination", "door-2", "r2d2"])
def test_pddl_names_load(name: str) -> None:
    data = {"bounds": [[0, 0], [5, 5]], "robot": {"pose": [1, 1, 0]}, "places": {name: [1, 1, 0]}}
    assert name in parse_world(data, "names.toml").places
