"""Scenario files: checked at load time, errors name the file and the field."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments.cli import main
from experiments.inputs import scenario as scenarios
from experiments.inputs.synthetic import ScenarioError

GOOD = """
kind = "robot"
world = "paper"
[settings]
scheduler = "alg2"
[[requests]]
t = 0.0
task = "guide_human"
args = { person = "john", destination = "bedroom" }
"""


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "s.toml"
    p.write_text(text)
    return p


def test_shipped_scenarios_load() -> None:
    scn = scenarios.load("paper")
    assert scn.world == "paper" and [a.kind for a in scn.actions].count("request") == 4


@pytest.mark.parametrize("change, field", [
    ('world = "paper"', None),
    ('t = 0.0', None),
])
def test_good_file_loads(tmp_path: Path, change: str, field: str | None) -> None:
    assert scenarios.load(write(tmp_path, GOOD)).name == "s"


@pytest.mark.parametrize("old, new, message", [
    ('t = 0.0', 't = "soon"', "requests[0].t: expected a number"),
    ('t = 0.0', 't = -1.0', "requests[0].t: expected a number >= 0"),
    ('scheduler = "alg2"', 'scheduler = "roundrobin"', "settings.scheduler: expected one of"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nmode = "XT"', "settings.mode: expected one of ['IT', 'CT']"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nsuspension = "random"', "settings.suspension: expected one of"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nrep_rate = 0', "settings.rep_rate: expected a number > 0"),
    ('kind = "robot"', 'kind = "robot"\ncolour = "red"', "colour: unknown key"),
    ('task = "guide_human"', '', "requests[0].task: missing"),
    ('world = "paper"', 'world = "nowhere.toml"', "world: no world file"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nscheduler_options = { hysteresis = 3 }', "scheduler_options"),
])
def test_bad_fields_are_named(tmp_path: Path, old: str, new: str, message: str) -> None:
    with pytest.raises(ScenarioError, match=message.replace("[", r"\[").replace("]", r"\]").replace("(", r"\(")):
        scenarios.load(write(tmp_path, GOOD.replace(old, new, 1)))


def test_bad_world_event_is_named(tmp_path: Path) -> None:
    text = GOOD + '[[world_events]]\nt = 3.0\nposture = ["peter"]\n'
    with pytest.raises(ScenarioError, match=r"world_events\[0\].posture: expected \[person, posture\]"):
        scenarios.load(write(tmp_path, text))


def test_terminating_an_agent_never_requested_is_refused(tmp_path: Path) -> None:
    text = GOOD + '[[terminations]]\nt = 3.0\nagent = "d7"\n'
    with pytest.raises(ScenarioError, match="terminations.0..agent: no agent 'd7'.*agents are d1..d1"):
        scenarios.load(write(tmp_path, text))


def test_unknown_scenario_name_lists_shipped_ones() -> None:
    with pytest.raises(ScenarioError, match="paper"):
        scenarios.resolve("no_such_scenario")


def test_randomize_is_deterministic_and_varies_with_the_seed() -> None:
    scn = scenarios.load("paper")
    a, b, c = scenarios.randomize(scn, 3), scenarios.randomize(scn, 3), scenarios.randomize(scn, 4)
    assert a == b and a != c
    assert [x.kind for x in a.actions] == [x.kind for x in scn.actions]


def test_cli_bad_scenario_exits_2_with_the_field(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    p = write(tmp_path, GOOD.replace("t = 0.0", 't = "soon"'))
    assert main(["run", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "requests[0].t" in err and "Traceback" not in err


def test_cli_runs_a_synthetic_scenario(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "demo"
    assert main(["run", "synthetic_demo", "--out", str(out), "--seed", "3"]) == 0
    for name in ("trace.jsonl", "run.json", "metrics.json", "timeline.png", "gantt.png"):
        assert (out / name).stat().st_size > 0, name
    record = json.loads((out / "run.json").read_text())
    for key in ("scenario", "seed", "settings", "host", "date", "tasker_version"):
        assert key in record
    assert record["seed"] == 3
    assert "4 tasks" in capsys.readouterr().out


def test_a_synthetic_runs_trace_and_run_json_name_the_same_strategy(tmp_path: Path) -> None:
    """Issue 39: the trace's ``run`` event said planned while run.json said static. Synthetic tasks run
    their timed stages (static); every stage plan in the trace says so too."""
    from experiments.run.runner import run_scenario

    run_scenario("synthetic_demo", out=tmp_path, pictures=False)
    events = [json.loads(line) for line in (tmp_path / "trace.jsonl").read_text().splitlines()]
    settings = json.loads((tmp_path / "run.json").read_text())["settings"]
    assert events[0]["event"] == "run"
    assert (events[0]["update"], events[0]["suspension"]) == ("static", "static")
    assert (settings["update"], settings["suspension"]) == ("static", "static")
    plans = [e for e in events if e["event"] == "plan"]
    assert plans and {e["strategy"] for e in plans} == {"static"}


@pytest.mark.parametrize(("line", "name"), [('name = "fetch_demo"', "fetch_demo"), ('name = "../up"', "mine"),
                                            ("name = 3", "mine"), ("", "mine"), ('name = "', "mine")])
def test_a_scenario_names_its_output_folder_when_its_name_is_a_plain_folder_name(
        line: str, name: str, tmp_path: Path) -> None:
    from experiments.inputs.scenario import name_of

    path = tmp_path / "mine.toml"
    path.write_text(f'kind = "robot"\n{line}\n')
    assert name_of(path) == name
