"""The ``world`` and ``cost`` subcommands: JSON shapes, exit statuses, pictures."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments.cli import main as cli
from robot.spec import load_world, shipped_worlds


@pytest.mark.slow
def test_world_json_and_picture(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    png = tmp_path / "paper.png"
    assert cli(["world", "paper", "--json", "--out", str(png)]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["format"] == "tasker.world/1" and doc["bounds"] == [[0.0, 0.0], [12.0, 8.0]]
    assert doc["places"]["hall"] == {"pose": [6.0, 4.0, 1.5708], "room": "hall"}
    assert set(doc["people"]) == {"john", "alice", "peter", "sara"}
    assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow
@pytest.mark.parametrize("world", shipped_worlds())
def test_world_json_describes_every_part_of_the_world(world: str, capsys: pytest.CaptureFixture[str]) -> None:
    spec = load_world(world)
    assert cli(["world", world, "--json"]) == 0
    out = capsys.readouterr().out
    doc = json.loads(out)
    assert list(doc["places"]) == list(spec.places)  # every place, in the file's order
    for name, place in doc["places"].items():
        assert place["pose"] == list(spec.places[name]) and place["room"] in spec.rooms
        assert name in doc["rooms"][place["room"]]["places"]
    assert set(doc["rooms"]) == set(spec.rooms) and set(doc["devices"]) == set(spec.devices)
    assert set(doc["people"]) == set(spec.people) and doc["objects"] == dict(spec.objects)
    for name, door in doc["doors"].items():
        assert door["open"] == spec.doors[name].open and len(door["rooms"]) == 2
        assert all(name in doc["rooms"][r]["doors"] for r in door["rooms"] if r is not None)
    assert len(doc["walls"]) == sum(o.kind == "wall" for o in spec.obstacles)
    assert doc["robot"]["pose"] == list(spec.robot.pose) and doc["robot"]["room"] in spec.rooms
    rm = doc["roadmap"]
    assert rm["nodes"] > rm["ompl_milestones"] > 0 and rm["edges"] > rm["nodes"] and rm["components"] >= 1
    assert cli(["world", world, "--json"]) == 0
    assert capsys.readouterr().out == out  # the same world, the same bytes


def test_world_json_roadmap_is_optional_and_seeded(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli(["world", "flat", "--json", "--no-roadmap"]) == 0
    assert "roadmap" not in json.loads(capsys.readouterr().out)
    assert cli(["world", "flat", "--json", "--seed", "4"]) == 0
    rm = json.loads(capsys.readouterr().out)["roadmap"]
    assert rm["seed"] == 4 and rm["places_unlinked"] == ["storage"]  # flat's storage is walled off
    assert cli(["world", "flat", "--json", "--seed", "-1"]) == 2
    assert "--seed" in capsys.readouterr().err


@pytest.mark.parametrize(("text", "expected"), [
    ('name = "x"\nbounds = [[0, 0], [5, 5]]\nwals = []\n', ":3: wals: unknown key 'wals'; did you mean 'walls'?"),
    ('name = "x"\nbounds = [[0, 0], [5, 5]\n', ":3: not valid TOML"),
    ('name = "x"\nbounds = [[0, 0], [5, 5]]\n[places]\nhall = [1, 2]\n', ":4: places.hall: expected [x, y, yaw]"),
])
def test_world_json_bad_world_file_is_one_clear_line(tmp_path: Path, text: str, expected: str,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    assert cli(["world", str(bad), "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "Traceback" not in captured.err
    assert captured.err.startswith(f"tasker world: error: {bad}{expected}"), captured.err


def test_cost_exit_statuses(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli(["cost", "flat", "living", "kitchen", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["reachable"] == [[True, True], [True, True]] and doc["time_s"][0][1] > 0 and doc["distance_m"][0][1] > 0
    assert cli(["cost", "flat", "living", "storage", "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["reachable"][0][1] is False
    assert cli(["cost", "flat", "5.0,2.0", "2.5,1.8,0"]) == 0
    capsys.readouterr()
    for bad in (["cost", "flat", "living", "attic"], ["cost", "nowhere", "a", "b"], ["world", "x.toml"]):
        assert cli(bad) == 2
        captured = capsys.readouterr()
        assert captured.err.startswith(f"tasker {bad[0]}: error: ") and "Traceback" not in captured.err


def test_cost_matrix_in_one_call_matches_pairwise(capsys: pytest.CaptureFixture[str]) -> None:
    places = ["living", "kitchen", "stove"]
    assert cli(["cost", "flat", *places, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["points"] == places and len(doc["time_s"]) == 3 and all(len(r) == 3 for r in doc["time_s"])
    assert cli(["cost", "flat", "kitchen", "stove", "--json"]) == 0
    pair = json.loads(capsys.readouterr().out)
    assert pair["time_s"][0][1] == doc["time_s"][1][2]
    assert cli(["cost", "flat", *places]) == 0
    assert "travel time (s), from row to column" in capsys.readouterr().out


def test_cost_suggests_a_place_and_a_world(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli(["cost", "flat", "living", "kitchn"]) == 2
    assert "did you mean 'kitchen'?" in capsys.readouterr().err
    assert cli(["cost", "flta", "living", "kitchen"]) == 2
    assert "did you mean 'flat'?" in capsys.readouterr().err


@pytest.mark.parametrize(("point", "why"), [
    ("50,50", "is outside the world's bounds"),
    ("0.05,3", "is inside wall"),
    ("1.5,0.5", "is inside furniture 'sofa'"),
    ("1e308,2", "is outside the world's bounds"),
    ("-1,-1", "is outside the world's bounds"),  # a negative point is an argument, not an option
    ("-.5,2,0", "is outside the world's bounds"),
])
def test_cost_refuses_a_point_where_no_robot_can_be(point: str, why: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Such a point is a wrong argument (exit 2, saying why), not an 'unreachable' pair (exit 1)."""
    assert cli(["cost", "paper", point, "kitchen", "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith(f"tasker cost: error: argument PLACE: {point!r} {why}"), captured.err


@pytest.mark.parametrize("name", ["flat.txt", "flat.svg", "flat"])
def test_world_out_must_be_a_png_file_name(tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Before: ``--out flat.txt`` drew the world and then failed in matplotlib (exit 3, "a bug in
    tasker"), ``flat.svg`` likewise, and ``flat`` exited 0 with the picture in ``flat.png``."""
    assert cli(["world", "flat", "--out", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tasker world: error: argument --out: ") and "ending in .png" in err
    assert not list(tmp_path.iterdir())


def test_cost_point_without_room_for_the_robot_is_bad_input(capsys: pytest.CaptureFixture[str]) -> None:
    """Before: 0.15,2.0 (clear of flat's wall, but not by the robot's radius) exited 1 after printing
    a reachable path from it: as a goal it was unreachable, as a start it was moved."""
    assert cli(["cost", "flat", "0.15,2.0", "5.0,2.0"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tasker cost: error: argument PLACE: '0.15,2.0': the robot (radius ") and "room" in err
