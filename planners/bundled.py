"""The task types shipped in ``domains/``, and those named by ``$TASKER_TASKS``.

This is what the core's task store loads through the ``tasker.tasks`` entry point.
It lives here, not in ``domains``, so that ``domains`` stays data and task hooks that
import only ``tasker`` (the design's dependency rule).
"""

from __future__ import annotations

import functools
import os
from collections.abc import Iterable
from pathlib import Path

from domains import BUNDLED
from planners.loader import load_task, load_task_folder
from planners.pddl_task import PddlTaskType
from tasker.errors import ConfigError
from tasker.task import TaskType

ENV_VAR = "TASKER_TASKS"


@functools.cache
def _bundled() -> tuple[TaskType, ...]:
    return tuple(load_task(p) for p in sorted(BUNDLED.iterdir()) if (p / "task.toml").is_file())


def task_types(extra: Iterable[str | Path] = ()) -> list[TaskType]:
    """Bundled task types, then those of ``$TASKER_TASKS`` and ``extra``; names must be unique."""
    out = list(_bundled())
    paths = [p for p in os.environ.get(ENV_VAR, "").split(os.pathsep) if p] + [str(p) for p in extra]
    for p in paths:
        out.extend(load_task_folder(p))
    # a folder reached twice (in $TASKER_TASKS and --path, or as itself and in its parent) is one definition
    files: dict[str, list[Path]] = {}
    unique = []
    for t in out:
        toml = (t.spec.folder / "task.toml").resolve() if isinstance(t, PddlTaskType) else None
        if toml is not None and toml in files.get(t.name, []):
            continue
        files.setdefault(t.name, []).extend([toml] if toml is not None else [])
        unique.append(t)
    names = [t.name for t in unique]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        where = "; ".join(f"{n!r} by {' and '.join(map(str, files[n])) or 'two task types'}" for n in dup)
        raise ConfigError(f"task type name(s) defined twice: {where} (a [task] name must be unique)")
    return unique
