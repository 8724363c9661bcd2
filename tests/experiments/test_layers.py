"""``experiments/`` is layered: a sub-package imports only the layers below it (and itself).

The order, lowest first, is :data:`LAYERS`; ``sweep`` is below ``days`` (a day runs as
sweep jobs), ``days`` and ``paper`` share a level, ``cli`` is on top, and modules directly
in ``experiments/`` (the facade) may use every layer but ``cli``.  Every import counts:
module level, inside functions, and under ``TYPE_CHECKING``.  No two project modules
import each other, in any package.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LAYERS = {"inputs": 0, "trace": 1, "metrics": 2, "analysis": 3, "report": 4, "run": 5, "sweep": 6,
          "days": 7, "paper": 7, "serve": 7, "cli": 9}
FACADE = 8
PACKAGES = ("tasker", "planners", "robot", "experiments", "domains")


def _modules() -> dict[str, Path]:
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            name = ".".join(path.relative_to(ROOT).with_suffix("").parts)
            out[name.removesuffix(".__init__")] = path
    return out


MODULES = _modules()


def _resolve(name: str) -> str | None:
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _imports(name: str) -> set[str]:
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {m for a in node.names if (m := _resolve(a.name))}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[: len(parts) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            for alias in node.names:
                m = _resolve(f"{base}.{alias.name}") if base else None
                if m and m != _resolve(base):
                    found.add(m)
                elif (b := _resolve(base)) is not None:
                    found.add(b)
    return {m for m in found if m != name}


def _rank(module: str) -> int | None:
    parts = module.split(".")
    if parts[0] != "experiments" or len(parts) == 1:
        return None
    return LAYERS.get(parts[1], FACADE)


def test_every_experiments_module_lives_in_a_known_layer_or_is_the_facade() -> None:
    layered = [name.split(".") for name in MODULES if name.startswith("experiments.") and name.count(".") > 1]
    assert len(layered) > 50  # the scan found the modules of experiments/'s layers (89 on 60ed0ea)
    wrong = [".".join(parts) for parts in layered if parts[1] not in LAYERS]
    assert not wrong, f"not in a layer of experiments/ ({sorted(LAYERS)}): {wrong}"


def test_layers_import_only_downward() -> None:
    wrong = []
    for name in MODULES:
        mine = _rank(name)
        if mine is None:
            continue
        for dep in _imports(name):
            theirs = _rank(dep)
            if theirs is not None and theirs > mine:
                wrong.append(f"{name} imports {dep}")
    assert not wrong, "\n".join(wrong)


@pytest.mark.slow
def test_no_other_package_imports_experiments() -> None:
    wrong = [f"{n} imports {d}" for n in MODULES if not n.startswith("experiments")
             for d in _imports(n) if d.startswith("experiments")]
    assert not wrong, "\n".join(wrong)


@pytest.mark.slow
def test_no_two_modules_import_each_other() -> None:
    graph = {n: {d for d in _imports(n) if not d.startswith(n + ".") and not n.startswith(d + ".")}
             for n in MODULES}
    pairs = sorted({tuple(sorted((a, b))) for a in graph for b in graph[a] if a in graph.get(b, ())})
    assert not pairs, pairs


def test_benchmarks_import_nothing_from_tests() -> None:
    wrong = []
    for path in sorted((ROOT / "benchmarks").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module] if isinstance(node, ast.ImportFrom) and node.module else [])
            wrong += [f"{path.name} imports {n}" for n in names if n.split(".")[0] == "tests"]
    assert not wrong, wrong


@pytest.mark.slow
def test_the_generated_docs_are_up_to_date() -> None:
    """docs/trace.md's event fields and docs/metrics.md's registry are generated (`tasker docs`)."""
    from experiments.report.reference import update

    stale = update(ROOT, check=True)
    assert not stale, f"out of date: {stale}; run 'tasker docs'"


@pytest.mark.slow
def test_argparse_lives_only_in_cli() -> None:
    users = sorted(n for n, p in MODULES.items() if not n.startswith("experiments.cli")
                   and any(isinstance(x, ast.Import | ast.ImportFrom) and "argparse" in
                           ([a.name for a in x.names] if isinstance(x, ast.Import) else [x.module or ""])
                           for x in ast.walk(ast.parse(p.read_text(encoding="utf-8")))))
    assert users == [], users


@pytest.mark.slow
def test_every_documented_event_is_emitted_somewhere() -> None:
    """docs/trace.md documents every type of tasker.events; each must be made by some module (none
    reserved today), and the scan must see the emits it claims to (a broken scan is not silence)."""
    from experiments.report.reference import emitters

    made = emitters()
    assert "tasker/harmoniser.py" in made["Decision"] and "tasker/agent.py" in made["Transition"]
    assert not [name for name, where in made.items() if not where]
