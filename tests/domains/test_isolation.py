"""No module of ``experiments/`` or ``robot/`` names a bundled task's task type, action or
predicate: the task folders own their meaning (hazards, roles, bindings) and the trace
carries it.  The names are read from the bundled folders, so the test stays true when
the domains change.  World vocabulary (places, doors, postures) and the robot's skills
are the contract between the world and the domains, and may be named."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import domains
from planners.loader import load_task_folder
from planners.taskspec import SKILLS
from robot.sim import WORLD_PREDICATES
from robot.spec import POSTURES
from tasker.meaning import ROLES

ROOT = Path(__file__).parents[2]
PACKAGES = ("experiments", "robot")
WORLD_VOCABULARY = (frozenset({"at", "connected", "open", "door", "place", "person", "robot"})
                    | frozenset(SKILLS) | frozenset(POSTURES) | frozenset(ROLES) | WORLD_PREDICATES)
"""Words the world and the framework speak: where things are, doors (and the door facts a world file
states), what the world derives (``clear``), postures, the robot's skills, and people's roles
(:data:`tasker.meaning.ROLES`, which a task folder maps to its own predicates)."""


def bundled_names() -> dict[str, str]:
    out: dict[str, str] = {}
    for task in load_task_folder(domains.BUNDLED):
        out[task.name] = f"task type of {task.spec.folder.name}"
        out |= {a: f"action of {task.name}" for a in task.domain.actions}
        out |= {p: f"predicate of {task.name}" for p in task.domain.predicates}
    return {n: why for n, why in out.items() if n not in WORLD_VOCABULARY}


def string_constants(path: Path) -> list[tuple[int, str]]:
    """Every string literal that is not a docstring, with its line."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                docstrings.add(id(first.value))
    return [(n.lineno, n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docstrings]


def test_the_bundled_names_are_found() -> None:
    names = bundled_names()
    assert len(names) > 10  # a broken loader must not make the test below vacuous


@pytest.mark.slow
@pytest.mark.parametrize("package", PACKAGES)
def test_no_module_names_a_bundled_task_action_or_predicate(package: str) -> None:
    names = bundled_names()
    hits = [f"{path.relative_to(ROOT)}:{line}: {value!r} ({names[value]})"
            for path in sorted((ROOT / package).rglob("*.py"))
            for line, value in string_constants(path) if value in names]
    assert not hits, "\n".join(hits)
