"""``tasker new``'s work: a task folder written from :data:`TEMPLATE` that loads, plans and runs at once."""

from __future__ import annotations

import re
from pathlib import Path

from tasker.errors import UsageError

TEMPLATE = Path(__file__).resolve().parent / "template"
"""The template task folder (``__TASK__`` and ``__DIR__`` are replaced)."""
TEMPORAL_TEMPLATE = Path(__file__).resolve().parent / "template_temporal"
"""What ``tasker new --temporal`` takes instead of the template's files: a PDDL 2.1 ``domain.pddl``."""


def scaffold(name: str, folder: Path, temporal: bool = False) -> list[Path]:
    """Write a task folder for ``name`` from :data:`TEMPLATE` into ``folder``; return the files.

    ``temporal``: its ``domain.pddl`` is :data:`TEMPORAL_TEMPLATE`'s, with durative actions
    (:mod:`planners.temporal`).  Besides the template's files it writes ``problem.pddl``, the
    ``[example]``'s problem, for ``tasker plan``.  The folder must not exist or be empty."""
    if not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        raise UsageError("TASK", f"expected a lower-case identifier such as fetch_cup, got {name!r}")
    taken = bundled_names()
    if name in taken:  # the folder would load beside the bundled one, and every command refuse both
        raise UsageError("TASK", f"{name!r} is the name of a bundled task type ({', '.join(sorted(taken))}): "
                                 f"a task name must be unique; choose another, e.g. my_{name}")
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise UsageError("DIR", f"{folder} exists and is not empty; choose a new folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError("DIR", f"cannot create {folder}: {exc.strerror or exc}") from None
    written = []
    for src in sorted(TEMPLATE.iterdir()):
        if src.is_file() and src.suffix in (".pddl", ".toml"):
            dst = folder / src.name
            if temporal and (TEMPORAL_TEMPLATE / src.name).is_file():
                src = TEMPORAL_TEMPLATE / src.name
            dst.write_text(src.read_text(encoding="utf-8").replace("__TASK__", name).replace("__DIR__", str(folder)),
                           encoding="utf-8")
            written.append(dst)
    written.append(_write_example_problem(folder))
    return written


def bundled_names() -> set[str]:
    """The ``[task] name`` of every bundled task folder, read from their ``task.toml`` (none loaded)."""
    from domains import BUNDLED
    from tasker.support import reader

    out = set()
    for toml in sorted(BUNDLED.glob("*/task.toml")):
        name = reader.load(toml).table("task").raw("name", None)
        if isinstance(name, str):
            out.add(name)
    return out


def _write_example_problem(folder: Path) -> Path:
    from planners.examples import example_context
    from planners.loader import load_task
    from planners.stages import Bindings

    task = load_task(folder)  # the scaffold is checked like any task folder: it loads and plans
    ctx = example_context(task)
    assert ctx is not None
    b = Bindings(ctx.args, ctx.world)
    text, _, _ = task.problem_text(ctx, ctx.world, b.literals(task.spec.goal), b.literals(task.spec.facts))
    out = folder / "problem.pddl"
    out.write_text(f"; the [example] of task.toml as a PDDL problem (written by 'tasker new')\n{text.problem}",
                   encoding="utf-8")
    return out
