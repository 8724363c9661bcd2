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
