"""Errors live in one module (house style 15): ``tasker/errors.py``; the old import paths still work."""

from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path

import pytest

from tasker import errors

ROOT = Path(__file__).resolve().parents[2]
PRODUCT = ("tasker", "planners", "robot", "experiments", "domains")
PRIVATE = {("experiments/serve/strict.py", "_BodyError")}
"""Error classes that stay in their module: ``_BodyError`` is the strict JSON reader's signal inside
:mod:`experiments.serve.strict`, turned into a :class:`~tasker.errors.Refused` before it leaves it."""

OLD_HOMES = {
    "tasker.support.reader": ["InputError"],
    "tasker.events": ["TraceError"],
    "planners.loader": ["HookExited"],
    "planners.temporal.portfolio": ["EngineNotInstalled"],
    "planners.schema": ["SchemaError"],
    "planners.checks": ["DefinitionError", "PddlError"],
    "robot.spec": ["WorldFileError"],
    "experiments.metrics.store": ["StoreError"],
    "experiments.serve.bodies": ["Refused"],
    "experiments.report.explain": ["ExplainError"],
    "experiments.sweep.driver": ["SweepError"],
    "experiments.sweep.spec": ["SpecError"],
    "experiments.cli.world": ["BadInput"],
    "experiments.inputs.fields": ["ScenarioError"],
    "experiments.inputs.scenario": ["ScenarioError"],
}


def _exception_classes_outside_errors() -> list[tuple[str, str]]:
    """Classes outside tasker/errors.py whose bases name an error (``...Error``, ``Exception``, a class of it)."""
    known = {name for name, obj in vars(errors).items() if inspect.isclass(obj) and issubclass(obj, BaseException)}
    known |= {"Exception", "ValueError", "RuntimeError", "KeyError", "TypeError", "BaseException"}
    found = []
    for pkg in PRODUCT:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            if rel == "tasker/errors.py":
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.ClassDef):
                    bases = {b.attr if isinstance(b, ast.Attribute) else getattr(b, "id", "") for b in node.bases}
                    if bases & known or any(b.endswith("Error") for b in bases):
                        found.append((rel, node.name))
    return found


def test_no_error_class_is_defined_outside_tasker_errors() -> None:
    assert set(_exception_classes_outside_errors()) == PRIVATE


@pytest.mark.parametrize(("module", "names"), sorted(OLD_HOMES.items()))
def test_an_old_import_path_gives_the_same_class(module: str, names: list[str]) -> None:
    mod = importlib.import_module(module)
    for name in names:
        assert getattr(mod, name) is getattr(errors, name)


def test_every_error_but_the_interrupt_is_a_tasker_error() -> None:
    """A command line catches one class: everything raised on purpose is a ``TaskerError``."""
    classes = [obj for obj in vars(errors).values() if inspect.isclass(obj) and issubclass(obj, BaseException)]
    assert len(classes) >= 25
    assert {c.__name__ for c in classes if not issubclass(c, errors.TaskerError)} == {"RunInterrupted"}


def test_input_error_reads_file_line_field() -> None:
    assert str(errors.ScenarioError("s.toml", "expected a number", line=3, field="requests[0].t")) == \
        "s.toml:3: requests[0].t: expected a number"
    assert str(errors.InputError("a whole message")) == "a whole message"
    assert str(errors.PddlError("d.pddl", "bad", 4, 2)) == "d.pddl:4:2: bad"
    assert errors.Refused(404, "GET /x", "no such agent", "agent").to_json() == \
        {"detail": "GET /x: agent: no such agent", "field": "agent", "message": "no such agent"}
