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
from tasker.meaning import Binding
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
    check_bindings(unique)
    return unique


def _where(t: TaskType) -> str:
    return str(t.spec.folder / "task.toml") if isinstance(t, PddlTaskType) else f"task type {t.name!r}"


def check_bindings(types: Iterable[TaskType]) -> None:
    """The world reads a bound fact from one physical state, whichever task type bound it
    (:meth:`robot.sim.Simulation.bind`): two task types that bind a predicate differently — another
    kind, object or device state — for the same objects would have the first one win silently.
    A :class:`ConfigError` naming both folders."""
    seen: dict[tuple[str, int], list[tuple[Binding, TaskType]]] = {}
    for t in types:
        for b in t.meaning.bindings:
            key = (b.predicate, len(b.fact))
            for other, owner in seen.get(key, []):
                if owner is t:
                    continue
                same = (b.kind, b.fact.index(b.object), b.state, b.otherwise) == (
                    other.kind, other.fact.index(other.object), other.state, other.otherwise)
                overlap = not b.types or not other.types or set(b.types) & set(other.types)
                if not same and overlap:
                    raise ConfigError(f"{b.predicate!r} is bound as {other.kind} of {other.object} by "
                                      f"{_where(owner)} and as {b.kind} of {b.object} by {_where(t)}: the world "
                                      "reads a fact from one physical state (bind it the same way in both, or "
                                      "name the predicate differently in one domain)")
            seen.setdefault(key, []).append((b, t))
