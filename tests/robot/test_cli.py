"""The ``world`` and ``cost`` subcommands: JSON shapes, exit statuses, pictures."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from robot.cli import register


def cli(argv: list[str]) -> int:
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return args.func(args)


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
    assert doc["reachable"] and doc["time_s"] > 0 and doc["distance_m"] > 0 and len(doc["path"]) >= 2
    assert cli(["cost", "flat", "living", "storage", "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["reachable"] is False
    assert cli(["cost", "flat", "5.0,2.0", "2.5,1.8,0"]) == 0
    capsys.readouterr()
    for bad in (["cost", "flat", "living", "attic"], ["cost", "nowhere", "a", "b"], ["world", "x.toml"]):
        assert cli(bad) == 2
        captured = capsys.readouterr()
        assert captured.err.startswith("error: ") and "Traceback" not in captured.err
