"""Request fields (deadline, priority, death time) in a robot scenario file reach every scheduler."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.inputs import scenario as scenarios
from experiments.inputs.request_fields import asked_for
from experiments.run.runner import run_scenario
from tasker.trace import read

TWO_GUIDES = """
kind = "robot"
world = "paper"
[settings]
scheduler = "edf"
horizon = 3.0
[[requests]]
t = 0.0
task = "guide_human"
args = {{ person = "john", destination = "bedroom"{john} }}
[[requests]]
t = 0.0
task = "guide_human"
args = {{ person = "alice", destination = "living"{alice} }}
"""


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "s.toml"
    p.write_text(text)
    return p


def first_start(tmp_path: Path, john: str, alice: str) -> str:
    scn = scenarios.load(write(tmp_path, TWO_GUIDES.format(john=john, alice=alice)))
    run_scenario(scn, out=tmp_path / "out", pictures=False)
    return next(e["agent"] for e in read(tmp_path / "out" / "trace.jsonl")
                if e["event"] == "command" and e["flag"] == "start")


@pytest.mark.slow
def test_a_deadline_written_in_a_scenario_file_orders_edf(tmp_path: Path) -> None:
    """EDF starts the later request first when its deadline is earlier; without deadlines, the first."""
    assert first_start(tmp_path, ", deadline = 500.0", ", deadline = 100.0") == "d2"
    assert first_start(tmp_path, "", "") == "d1"


def test_only_files_that_give_a_field_wrap_their_task_types(tmp_path: Path) -> None:
    plain = scenarios.load(write(tmp_path, TWO_GUIDES.format(john="", alice="")))
    given = scenarios.load(write(tmp_path, TWO_GUIDES.format(john=", priority = 2", alice="")))
    assert not asked_for(plain.actions) and asked_for(given.actions)


def test_a_misspelt_field_is_located_and_named(tmp_path: Path) -> None:
    path = write(tmp_path, TWO_GUIDES.format(john=", dedline = 100.0", alice=""))
    with pytest.raises(scenarios.ScenarioError) as err:
        scenarios.load(path)
    msg = str(err.value)
    assert f"{path}:10" in msg and "dedline" in msg and "did you mean 'deadline'" in msg
    assert "any request may also give deadline, priority, death_at" in msg


def test_tasker_check_takes_the_fields_the_run_takes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``tasker check`` refused ``deadline`` in a request's args ("unknown argument(s)") that load and run take."""
    from experiments.cli import main

    path = write(tmp_path, TWO_GUIDES.format(john=", deadline = 100.0, priority = 2", alice=", death_at = 50.0"))
    assert main(["check", str(path)]) == 0, capsys.readouterr().out
    assert "0 problems" in capsys.readouterr().out


def test_a_field_beside_args_says_to_write_it_in_args(tmp_path: Path) -> None:
    """``deadline = 100.0`` beside ``args`` got "unknown key 'deadline' (valid keys: args, t, task)"."""
    path = write(tmp_path, TWO_GUIDES.format(john="", alice="").replace('"bedroom" }', '"bedroom" }\ndeadline = 100.0'))
    with pytest.raises(scenarios.ScenarioError) as err:
        scenarios.load(path)
    msg = str(err.value)
    assert f"{path}:11" in msg and "requests[0].deadline" in msg and "args = { …, deadline = 100.0 }" in msg
