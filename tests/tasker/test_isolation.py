"""``tasker`` depends on nothing but the standard library."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[2]
ALLOWED_THIRD_PARTY: set[str] = set()  # the standard library only (ARCHITECTURE.md)
PROJECT = {"tasker", "domains", "planners", "robot", "experiments"}


def test_import_tasker_with_heavy_dependencies_blocked() -> None:
    code = (
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in {'unified_planning','up_fast_downward','ompl','pinocchio','mujoco',"
        "'coal','matplotlib','dask','planners','robot','domains','experiments'}:\n"
        "            raise ImportError('blocked: ' + name)\n"
        "sys.meta_path.insert(0, Block())\n"
        "import tasker, tasker.synthetic, tasker.schedulers, tasker.support.diskcache\n"
        "names = tasker.schedulers.names()\n"  # lists entry points (lookahead-cpsat) without importing them
        "for n in tasker.schedulers._BUILTIN: tasker.schedulers.create(n)\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


def test_tasker_sources_import_only_the_standard_library_and_itself() -> None:
    stdlib = set(sys.stdlib_module_names)
    for path in sorted((ROOT / "tasker").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            for name in names:
                top = name.split(".")[0]
                assert top in stdlib or top == "tasker" or top in ALLOWED_THIRD_PARTY, f"{path}: imports {name}"
                assert top not in PROJECT - {"tasker"}, f"{path}: imports {name}"


def _tasker_imports() -> dict[str, set[str]]:
    """Every ``tasker`` module and the ``tasker`` modules it imports: any import statement, at the
    top, in a function or under ``TYPE_CHECKING``; ``from tasker import fsm`` imports ``tasker.fsm``."""
    paths = {".".join(p.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__"): p
             for p in sorted((ROOT / "tasker").rglob("*.py"))}

    def module_of(name: str) -> str | None:
        while name and name not in paths:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, set[str]] = {}
    for name, path in paths.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                found.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(parts + ([base] if base else []))
                found.update(f"{base}.{a.name}" if f"{base}.{a.name}" in paths else base for a in node.names)
        graph[name] = {m for f in found if f.split(".")[0] == "tasker" and (m := module_of(f)) not in (None, name)}
    return graph


def test_no_import_circle_inside_tasker() -> None:
    graph = _tasker_imports()
    assert "tasker.securing" not in graph["tasker.agent"] or "tasker.agent" not in graph["tasker.securing"]

    def reaches(start: str, goal: str) -> bool:
        seen, todo = set(), [start]
        while todo:
            for nxt in graph[todo.pop()] - seen:
                if nxt == goal:
                    return True
                seen.add(nxt)
                todo.append(nxt)
        return False

    circles = sorted(m for m in graph if reaches(m, m))
    assert not circles, f"modules on an import circle: {circles}"
