"""Users extend through documented hooks; the framework owns the loop (STYLE.md 3, 13)."""

from __future__ import annotations

import inspect

from tasker import task as task_module
from tasker.agent import DynamicAgent
from tasker.harmoniser import TaskHarmoniser
from tasker.task import TaskType

HOOKS = ("check_args", "initialise", "compute_params", "request_sp", "update_task", "generate_suspension",
         "check_terminate", "on_stage_done", "leaves")


def test_the_framework_loops_are_final() -> None:
    # typing.final: mypy rejects a subclass that overrides them; at run time the flag is set
    assert getattr(DynamicAgent.step, "__final__", False)
    assert getattr(TaskHarmoniser.step, "__final__", False)


def test_every_hook_says_when_to_override_it() -> None:
    table = inspect.getdoc(task_module) or ""  # the module's "which hook when"
    for name in HOOKS:
        doc = inspect.getdoc(getattr(TaskType, name)) or ""
        assert doc.startswith("Override"), f"TaskType.{name}: {doc[:60]!r}"
        assert f"``{name}``" in table, name
    assert "do not override" in (inspect.getdoc(TaskType.validate_args) or "")
