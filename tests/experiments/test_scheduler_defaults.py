"""What the scheduler is not told, the task folders may declare: alg2's classes from their priorities.

The model names no task type (``tasker.schedulers.alg2`` has no default classes); a robot
scenario that gives alg2 no ``classes`` gets them from the folders' ``[schedule] priority``
(:func:`experiments.inputs.fields.scheduler_defaults`), which gives the bundled folders the
paper's classes, ``human_fell`` above ``guide_human``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.inputs import fields
from experiments.inputs import scenario as scenarios
from planners.bundled import task_types
from planners.checks import DefinitionError
from planners.taskspec import read_task_toml
from tasker.task import TaskType

SCENARIO = """\
kind = "robot"
world = "paper"

[settings]
scheduler = "alg2"
{options}

[[requests]]
t = 0.0
task = "guide_human"
args = {{ person = "john", destination = "bedroom" }}
"""


def _type(name: str, priority: int | None) -> TaskType:
    t = TaskType()
    t.name, t.priority = name, priority
    return t


def test_the_bundled_folders_declare_the_papers_classes() -> None:
    declared = {t.name: t.priority for t in task_types()}
    assert declared == {"human_fell": 2, "guide_human": 1, "cook": None, "carry_object": None}
    assert fields.priority_classes(task_types()) == [["human_fell"], ["guide_human"]]


def test_priority_classes_group_highest_first_and_leave_the_undeclared_lowest() -> None:
    types = [_type("b", 1), _type("a", 1), _type("c", 5), _type("d", None)]
    assert fields.priority_classes(types) == [["c"], ["a", "b"]]
    assert fields.scheduler_defaults("alg2", {"hysteresis": 0.9}, types) == {
        "hysteresis": 0.9, "classes": [["c"], ["a", "b"]]}
    assert fields.scheduler_defaults("alg2", {"classes": [["d"]]}, types) == {"classes": [["d"]]}  # the scenario's
    assert fields.scheduler_defaults("fifo", {}, types) == {}
    assert fields.scheduler_defaults("alg2", {}, [_type("d", None)]) == {}  # nothing declared: nothing added


def test_a_scenario_without_classes_gets_the_folders(tmp_path: Path) -> None:
    p = tmp_path / "s.toml"
    p.write_text(SCENARIO.format(options=""), encoding="utf-8")
    assert scenarios.load(p).scheduler_options == {"classes": [["human_fell"], ["guide_human"]]}
    p.write_text(SCENARIO.format(options='scheduler_options = { classes = [["guide_human"]] }'), encoding="utf-8")
    assert scenarios.load(p).scheduler_options == {"classes": [["guide_human"]]}


def test_a_priority_must_be_an_integer(tmp_path: Path) -> None:
    src = Path(__file__).parents[2] / "domains" / "human_fell" / "task.toml"
    bad = tmp_path / "task.toml"
    bad.write_text(src.read_text(encoding="utf-8").replace("priority = 2", 'priority = "high"'), encoding="utf-8")
    with pytest.raises(DefinitionError, match="schedule.priority"):
        read_task_toml(bad)
    assert read_task_toml(src).priority == 2
