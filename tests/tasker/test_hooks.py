"""Users extend through documented hooks; the framework owns the loop (STYLE.md 3, 13)."""

from __future__ import annotations

import importlib
import inspect
from collections.abc import Mapping
from typing import Any

import pytest

from experiments.inputs.request_fields import WithRequestFields
from tasker import task as task_module
from tasker.agent import DynamicAgent
from tasker.errors import BadRequest, ConfigError
from tasker.harmoniser import TaskHarmoniser
from tasker.stage import Purpose, StagePlan
from tasker.store import TaskStore
from tasker.task import ArgSpec, TaskContext, TaskType, missing_hooks

HOOKS = ("check_args", "adjust_args", "initialise", "compute_params", "request_sp", "update_task",
         "generate_suspension", "check_terminate", "on_stage_done", "leaves")


def test_the_framework_loops_are_final() -> None:
    # typing.final: mypy rejects a subclass that overrides them; at run time the flag is set
    assert getattr(DynamicAgent.step, "__final__", False)
    assert getattr(TaskHarmoniser.step, "__final__", False)
    assert getattr(TaskType.validate_args, "__final__", False)


def test_every_hook_says_when_to_override_it() -> None:
    table = inspect.getdoc(task_module) or ""  # the module's "which hook when"
    for name in HOOKS:
        doc = inspect.getdoc(getattr(TaskType, name)) or ""
        assert doc.startswith("Override"), f"TaskType.{name}: {doc[:60]!r}"
        assert f"``{name}``" in table, name
    assert "typing.final" in (inspect.getdoc(TaskType.validate_args) or "")


# -- validate_args is the framework's; update_task is required --------------------------------------


def _product_task_types() -> list[type]:
    for module in ("experiments.days.robot_work", "experiments.inputs.request_fields", "planners.pddl_task",
                   "tasker.synthetic"):  # where the product's task types are defined
        importlib.import_module(module)
    out, todo = [], [TaskType]
    while todo:
        for sub in todo.pop().__subclasses__():
            if sub.__module__.split(".")[0] in ("tasker", "planners", "experiments", "robot", "domains"):
                out.append(sub)
            todo.append(sub)
    return out


def test_no_product_task_type_overrides_validate_args() -> None:
    found = _product_task_types()
    assert {c.__name__ for c in found} >= {"PddlTaskType", "SyntheticTask", "WithRequestFields", "DrawnWork"}
    assert [c.__name__ for c in found if "validate_args" in vars(c)] == []


class _NoUpdate(TaskType):
    name = "no_update"

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:  # a hook, but not the required one
        return StagePlan((), Purpose.GEN_SUSP)


class _Minimal(TaskType):
    name = "minimal"

    def update_task(self, ctx: TaskContext) -> StagePlan:
        return StagePlan((), Purpose.UP_TSK)


def test_a_type_without_update_task_is_refused_when_registered() -> None:
    store = TaskStore()
    with pytest.raises(ConfigError, match=r"plugin x: task type 'no_update' \(_NoUpdate\) does not implement "
                                          r"update_task, a hook every task type must override"):
        store.register(_NoUpdate(), source="plugin x")
    assert "no_update" not in store
    assert missing_hooks(_NoUpdate()) == ["update_task"] and missing_hooks(_Minimal()) == []
    store.register(_Minimal())
    assert store.names() == ["minimal"]


class _Costed(_Minimal):
    """A type whose ``model`` argument stays out of a request that does not give it (as a task folder's cost model)."""

    name = "costed"
    arg_specs = (ArgSpec("person"), ArgSpec("model", required=False, default="ours"), ArgSpec("n", "int", False, 1))

    def adjust_args(self, given: Mapping[str, Any], args: dict[str, Any]) -> None:
        if given.get("model") is None:
            args.pop("model")


def test_adjust_args_runs_after_check_args_and_through_a_wrapper() -> None:
    plain = _Costed()
    assert plain.validate_args({"person": "john"}) == {"person": "john", "n": 1}
    assert plain.validate_args({"person": "john", "model": "ours"}) == {"person": "john", "model": "ours", "n": 1}
    wrapped = WithRequestFields(_Costed())
    out = wrapped.validate_args({"priority": 3, "person": "john", "n": 2})
    assert list(out.items()) == [("person", "john"), ("n", 2), ("deadline", None), ("priority", 3), ("death_at", None)]
    with pytest.raises(BadRequest, match="unknown argument"):
        wrapped.validate_args({"person": "john", "colour": "red"})
    with pytest.raises(BadRequest, match="missing required argument 'person'"):
        wrapped.validate_args({"priority": 3})
