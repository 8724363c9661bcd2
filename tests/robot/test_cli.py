"""The ``world`` and ``cost`` subcommands: JSON shapes, exit statuses, pictures."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments.cli import main as cli


def test_world_json_and_picture(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    png = tmp_path / "paper.png"
    assert cli(["world", "paper", "--json", "--out", str(png)]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["bounds"] == [[0.0, 0.0], [12.0, 8.0]]
    assert doc["places"]["hall"] == [6.0, 4.0, 1.5708]
    assert set(doc["people"]) == {"john", "alice", "peter", "sara"}
    assert png.read_bytes()[:4] == b"\x89PNG"


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
