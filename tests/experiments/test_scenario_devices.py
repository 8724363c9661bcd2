"""A robot scenario may add devices to its world (``[devices.NAME]``), as it adds objects: each
is checked at load (a new name, a type of the task types' domains, a place of the world, a
state string) with the file, the line and the field, and reaches the simulated world as if
the world file listed it."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.inputs import scenario as scenarios
from experiments.inputs.fields import ScenarioError
from experiments.run.options import RunOptions
from experiments.run.runner import build_robot

SCENARIO = """\
kind = "robot"
world = "paper"

[settings]
horizon = 60.0

[devices.kettle]
{device}

[[requests]]
t = 0.0
task = "cook"
"""
GOOD = 'type = "cooker"\nplace = "kitchen"\nstate = "on"'


def _write(tmp_path: Path, device: str) -> Path:
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO.format(device=device), encoding="utf-8")
    return path


def test_a_scenario_device_is_in_the_world_where_and_as_declared(tmp_path: Path) -> None:
    scn = scenarios.load(_write(tmp_path, GOOD))
    assert scn.devices == {"kettle": {"type": "cooker", "place": "kitchen", "state": "on"}}
    _, sim = build_robot(scn, RunOptions(seed=1))
    facts = sim.snapshot().facts
    assert ("at", "kettle", "kitchen") in facts and ("state", "kettle", "on") in facts
    assert sim.objects()["kettle"] == "cooker"
    default = scenarios.load(_write(tmp_path, 'type = "cooker"\nplace = "kitchen"'))
    assert default.devices["kettle"]["state"] == "off"  # as a world file's device


@pytest.mark.parametrize(("device", "line", "field", "fragment"), [
    ('typ = "cooker"\nplace = "kitchen"', 8, "devices.kettle.typ", "did you mean 'type'"),
    ('place = "kitchen"', 7, "devices.kettle.type", "missing"),
    ('type = "coker"\nplace = "kitchen"', 8, "devices.kettle.type", "did you mean 'cooker'"),
    ('type = "cooker"\nplace = "kitchn"', 9, "devices.kettle.place", "did you mean 'kitchen'"),
    ('type = "cooker"\nplace = "kitchen"\nstate = 1', 10, "devices.kettle.state", "expected a string"),
])
def test_a_malformed_device_names_its_line_and_field(tmp_path: Path, device: str, line: int, field: str,
                                                      fragment: str) -> None:
    path = _write(tmp_path, device)
    with pytest.raises(ScenarioError) as info:
        scenarios.load(path)
    err = info.value
    assert (err.file, err.line, err.field) == (str(path), line, field), str(err)
    assert fragment in err.message, str(err)


def test_a_device_may_not_take_a_name_the_world_uses(tmp_path: Path) -> None:
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO.replace("[devices.kettle]", "[devices.cooker]").format(device=GOOD), encoding="utf-8")
    with pytest.raises(ScenarioError, match=r"s\.toml:7: devices\.cooker: the name 'cooker' is already a cooker"):
        scenarios.load(path)
