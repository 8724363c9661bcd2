"""planners/ has no import circles: every dependency between its modules goes one way."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import planners

ROOT = Path(planners.__file__).parent


def _imports() -> dict[str, set[str]]:
    """Every planners module and the planners modules it imports anywhere: at the top, in a
    function, or under ``TYPE_CHECKING`` (a circle there is still a circle of the design)."""
    modules = {f"planners.{p.stem}" for p in ROOT.glob("*.py") if p.stem != "__init__"}
    graph: dict[str, set[str]] = {}
    for path in ROOT.glob("*.py"):
        if path.stem == "__init__":
            continue
        deps: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and not node.level:
                deps |= {node.module} | {f"{node.module}.{a.name}" for a in node.names}
            elif isinstance(node, ast.Import):
                deps |= {a.name for a in node.names}
        graph[f"planners.{path.stem}"] = {d for d in deps if d in modules} - {f"planners.{path.stem}"}
    return graph


def test_no_two_planners_modules_import_each_other() -> None:
    graph = _imports()
    assert "planners.planner" in graph and graph["planners.pddl_task"], "the scan sees the package"
    pairs = sorted({tuple(sorted((a, b))) for a, deps in graph.items() for b in deps if a in graph.get(b, set())})
    assert pairs == []


@pytest.mark.slow
def test_the_engine_and_the_facade_meet_only_in_registration() -> None:
    graph = _imports()
    assert "planners.registration" in graph["planners.engine"] and "planners.registration" in graph["planners.planner"]
    assert "planners.planner" not in graph["planners.engine"] and "planners.engine" not in graph["planners.planner"]
