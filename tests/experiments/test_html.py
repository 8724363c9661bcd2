"""report.html: self-contained, deterministic, and drawn from what the run saved."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
from plotly.offline import get_plotlyjs

from experiments.inputs import synthetic
from experiments.report import run_page as report_html
from experiments.report import timeline_figures as html_timeline
from experiments.report import world_figure as html_world
from experiments.run.runner import run_scenario
from robot.spec import load_world

DEMO = Path(__file__).resolve().parents[2] / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml"
HAZARD = {"event": "hazard", "agent": "d1", "hazard": "device_on", "args": ["cooker"], "fact": ["device_on", "cooker"],
          "budget_s": 30.0, "severity": 1.0}


@pytest.fixture(scope="module")
def events() -> list[dict[str, Any]]:
    return synthetic.run(synthetic.load(DEMO), seed=1).events


def _names(fig: Any) -> set[str]:
    return {t.name for t in fig.data}


@pytest.mark.slow
def test_the_run_writes_a_self_contained_page(tmp_path: Path) -> None:
    run_scenario(DEMO, out=tmp_path)
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")
    assert not re.search(r"<script[^>]+src=", page), "scripts must be inlined, not fetched"
    assert get_plotlyjs() in page  # plotly.js itself is in the page (works offline)
    for div in ("timeline", "gantt"):
        assert f'id="{div}"' in page and f'Plotly.newPlot(                        "{div}"' in page
    assert "This run has no world" in page
    assert "synthetic-demo" in page


@pytest.mark.slow
def test_same_run_same_bytes(events: list[dict[str, Any]], tmp_path: Path) -> None:
    world = load_world("paper")
    trajectory = [(0.0, 1.0, 1.0, 0.0), (5.0, 2.0, 1.5, 0.5), (9.0, 3.0, 2.0, 1.0)]
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        out.mkdir()
        report_html.write_run(out, events, world=world, trajectory=trajectory)
    assert (a / "report.html").read_bytes() == (b / "report.html").read_bytes()


@pytest.mark.slow
def test_timeline_separates_costs_rates_roles_and_hazards(events: list[dict[str, Any]]) -> None:
    trace = [*events, {"t": 3.0, **HAZARD, "status": "on"}, {"t": 9.0, **HAZARD, "status": "off"}]
    hazards = report_html.hazards_of(trace, None)
    assert [(h.owner, h.label, h.start, h.end) for h in hazards] == [("d1", "device_on cooker", 3.0, 9.0)]
    fig = html_timeline.timeline_figure(trace, hazards)
    by_axis: dict[str, set[str]] = {}
    for t in fig.data:
        by_axis.setdefault(t.yaxis or "y", set()).add(t.name)
    assert by_axis["y"] >= {"cost_dac", "c_switch"} and not by_axis["y"] & {"ccps_dac", "cps_dac"}
    assert by_axis["y2"] >= {"ccps_dac"} and not by_axis["y2"] & {"cost_dac"}
    kind = hazards[0].kind  # whether d1 attended it then is the trace's: one bar of that kind
    assert by_axis["y3"] >= {"exeDA", "idleDA", f"hazard {kind}"}
    bar = next(t for t in fig.data if t.name == f"hazard {kind}")
    assert list(bar.base) == [3.0] and list(bar.x) == [6.0] and list(bar.y) == ["d1 hazard: device_on cooker"]
    susp = [s for s in fig.layout.shapes if s.line.dash == "dash"]  # susp commands
    n_susp = sum(1 for e in events if e["event"] == "command" and e["flag"] == "susp")
    assert n_susp and len(susp) == 3 * n_susp  # one line per panel


def test_timeline_without_cost_decisions_shows_the_decisions() -> None:
    trace = [{"t": 0.0, "event": "request", "agent": "d1", "task_type": "a", "args": {}, "requester": "x"},
             {"t": 1.0, "event": "decision", "algorithm": "priority", "rule": "priority", "dac": "d2",
              "exeDA": "d1", "switch": True}]
    fig = html_timeline.timeline_figure(trace)
    other = next(t for t in fig.data if t.name == "other decisions")
    assert list(other.x) == [1.0] and list(other.y) == ["priority"]


def test_hazards_fall_back_to_metric_episodes() -> None:
    metrics = {"safety": {"episodes": [{"agent": "d1", "hazard": "cooker_on", "subject": "cooker", "start": 2.0,
                                        "end": 5.0}]}}
    trace = [{"t": 6.0, "event": "mode", "mode": "IT"}]
    got = report_html.hazards_of(trace, metrics)  # an older run folder: drawn whole, unattended
    assert [(h.owner, h.label, h.start, h.end, h.kind) for h in got] == [("d1", "cooker_on cooker", 2.0, 5.0,
                                                                          "unattended")]


def test_gantt_names_every_stage(events: list[dict[str, Any]]) -> None:
    fig = html_timeline.gantt_figure(events)
    names = next(t for t in fig.data if t.name == "stage names")
    begun = [e["action"] for e in events if e["event"] == "stage" and e["status"] == "begin"]
    assert sorted(names.text) == sorted(begun)
    assert {"exeTsk stage", "exeSusp stage"} <= _names(fig)


def test_world_slider_follows_the_trajectory(events: list[dict[str, Any]]) -> None:
    world = load_world("paper")
    robot = [(float(t), 1.0 + 0.1 * t, 1.0, 0.0) for t in range(60)]
    people = {"peter": [(0.0, 8.0, 5.0, "standing"), (30.0, 8.0, 5.0, "fallen")]}
    trace = [*events, {"t": 10.0, **HAZARD, "status": "on"}]
    fig = html_world.world_figure(world, robot, people, trace, report_html.hazards_of(trace, None))
    frames = fig["frames"]
    assert len(frames) == len(fig["layout"]["sliders"][0]["steps"]) >= 2
    last = frames[-1]
    robot_trace = last["data"][1]
    assert robot_trace["name"] == "robot" and robot_trace["x"][0] == pytest.approx(1.0 + 0.1 * 59)
    assert "peter (fallen)" in last["data"][2]["text"]
    assert "device_on cooker (d1, " in last["layout"]["title"]["text"]
    assert "hazards on: none" in frames[0]["layout"]["title"]["text"]
    assert [t["name"] for t in fig["data"]][3:] == [t["name"] for t in last["data"]]  # frames update traces 3-5
    susp = next(t for t in fig["data"] if t["name"] == "robot at susp")
    n_susp = sum(1 for e in events if e["event"] == "command" and e["flag"] == "susp")
    assert len(susp["x"]) == n_susp and list(susp["text"])[0].startswith("susp d")


def test_recorded_trajectory_of_the_robot_recorder_is_read(tmp_path: Path) -> None:
    lines = [{"format": "tasker-trajectory/1", "world": "paper", "rate_hz": 10.0,
              "fields": {"robot": ["x", "y", "yaw"], "people": ["x", "y", "yaw", "posture"]}},
             {"t": 0.0, "robot": [1.0, 2.0, 0.5], "people": {"peter": [3.0, 4.0, 0.0, "standing"]}},
             {"t": 0.1, "mark": "manipulated", "object": "pan", "action": "pick_pan", "at": [1.0, 2.0]},
             {"t": 0.1, "robot": [1.5, 2.0, 0.5], "people": {"peter": [3.0, 4.0, 0.0, "fallen"]}}]
    (tmp_path / "trajectory.jsonl").write_text("".join(json.dumps(r) + "\n" for r in lines))
    assert html_world.read_trajectory(tmp_path) == (
        [(0.0, 1.0, 2.0, 0.5), (0.1, 1.5, 2.0, 0.5)],
        {"peter": [(0.0, 3.0, 4.0, "standing"), (0.1, 3.0, 4.0, "fallen")]})


@pytest.mark.parametrize("kind", ["jsonl", "csv"])
def test_recorded_trajectory_files_are_read(kind: str, tmp_path: Path) -> None:
    if kind == "jsonl":
        rows = [{"t": 0.0, "robot": {"x": 1.0, "y": 2.0, "yaw": 0.5},
                 "people": {"peter": {"pose": [3.0, 4.0, 0.0], "posture": "standing"}}},
                {"t": 1.0, "robot": [1.5, 2.0, 0.5], "people": {"peter": {"x": 3.0, "y": 4.0, "posture": "fallen"}}}]
        (tmp_path / "trajectory.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    else:
        (tmp_path / "trajectory.csv").write_text("t,x,y,yaw\n0.0,1.0,2.0,0.5\n1.0,1.5,2.0,0.5\n")
    got = html_world.read_trajectory(tmp_path)
    assert got is not None
    robot, people = got
    assert robot == [(0.0, 1.0, 2.0, 0.5), (1.0, 1.5, 2.0, 0.5)]
    if kind == "jsonl":
        assert people == {"peter": [(0.0, 3.0, 4.0, "standing"), (1.0, 3.0, 4.0, "fallen")]}


def test_unknown_trajectory_format_falls_back(tmp_path: Path) -> None:
    assert html_world.read_trajectory(tmp_path) is None
    (tmp_path / "trajectory.jsonl").write_text('{"time": 1}\n')
    assert html_world.read_trajectory(tmp_path) is None


def test_hazards_nobody_owns_share_one_row(events: list[dict[str, Any]]) -> None:
    """Before: each door open in the world file had a row of its own, always on."""
    doors = [{"t": 0.0, "event": "hazard", "agent": None, "hazard": "door_open", "args": [d], "fact": ["door_open", d],
              "status": "on", "budget_s": 60.0, "severity": 1.0} for d in ("a", "b", "c", "d", "e")]
    trace = [*events, *doors]
    fig = html_timeline.timeline_figure(trace, report_html.hazards_of(trace, None))
    bar = next(t for t in fig.data if t.name == "hazard nobody's")
    assert set(bar.y) == {"nobody's hazards"} and len(bar.y) == 5
    assert all("so in the world file" in text for text in bar.customdata)  # and why nobody owns them
