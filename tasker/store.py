"""The task store: task types registered by name.

Task types come from

* the entry-point group ``tasker.tasks`` (the bundled ``domains`` package registers
  itself there; so can any installed plugin): each entry point is a callable that
  returns task types;
* a folder a user points at (:meth:`TaskStore.load_folder`): every loader in the
  entry-point group ``tasker.loaders`` (the PDDL task-folder loader of ``planners``
  is one) is offered the folder; ``*.py`` files that define ``task_types()`` are
  loaded directly;
* Python code (:meth:`TaskStore.register`).

A name registered twice is an error naming both sources.  A plugin that fails to
import raises: it is never silently skipped.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable, Iterable, Mapping
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

from tasker.errors import ConfigError, UnknownName
from tasker.task import TaskType, missing_hooks


class TaskStore:
    """Task types by name; validates requests against them."""

    def __init__(self, tasks: Iterable[TaskType] = ()) -> None:
        self._types: dict[str, TaskType] = {}
        self._sources: dict[str, str] = {}
        for t in tasks:
            self.register(t)

    def register(self, task: TaskType, source: str = "python") -> None:
        if not isinstance(task, TaskType):
            raise ConfigError(f"{source}: expected a TaskType instance, got {type(task).__name__}")
        if not task.name or not task.name.replace("_", "").replace("-", "").isalnum():
            raise ConfigError(f"{source}: task type name must be a simple identifier, got {task.name!r}")
        missing = missing_hooks(task)
        if missing:
            raise ConfigError(f"{source}: task type {task.name!r} ({type(task).__name__}) does not implement "
                              f"{', '.join(missing)}, a hook every task type must override (tasker.task.TaskType)")
        if task.name in self._types:
            raise ConfigError(
                f"task type {task.name!r} is registered twice: by {self._sources[task.name]} and by {source}"
            )
        self._types[task.name] = task
        self._sources[task.name] = source

    def get(self, name: str) -> TaskType:
        try:
            return self._types[name]
        except KeyError:
            raise UnknownName("task type", name, list(self._types)) from None

    def __contains__(self, name: object) -> bool:
        return name in self._types

    def names(self) -> list[str]:
        return sorted(self._types)

    def source(self, name: str) -> str:
        self.get(name)
        return self._sources[name]

    def validate(self, name: str, args: Mapping[str, Any]) -> dict[str, Any]:
        """Check a request: the type must be known and the arguments fit it."""
        return self.get(name).validate_args(args)

    # -- loading -----------------------------------------------------------------------------

    def load_entry_points(self, group: str = "tasker.tasks") -> None:
        for ep in sorted(entry_points(group=group), key=lambda e: e.name):
            provider = ep.load()
            tasks = provider() if callable(provider) else provider
            for t in _as_list(tasks, f"entry point {ep.name!r} ({ep.value})"):
                self.register(t, source=f"entry point {ep.name!r}")

    def load_folder(self, path: str | Path) -> list[str]:
        """Register every task type found in ``path``; return their names."""
        folder = Path(path)
        if not folder.is_dir():
            raise ConfigError(f"{folder}: not a folder of task types")
        found: list[TaskType] = []
        for ep in sorted(entry_points(group="tasker.loaders"), key=lambda e: e.name):
            loader: Callable[[Path], Iterable[TaskType]] = ep.load()
            found.extend(_as_list(loader(folder), f"loader {ep.name!r}"))
        for py in sorted(folder.glob("*.py")):
            found.extend(_load_python(py))
        if not found:
            raise ConfigError(f"{folder}: no task types found (expected task folders or *.py with task_types())")
        names = []
        for t in found:
            self.register(t, source=str(folder))
            names.append(t.name)
        return names

    @classmethod
    def default(cls) -> TaskStore:
        """A store with every task type of the ``tasker.tasks`` entry points."""
        store = cls()
        store.load_entry_points()
        return store


def _as_list(tasks: Any, where: str) -> list[TaskType]:
    if isinstance(tasks, TaskType):
        return [tasks]
    try:
        out = list(tasks)
    except TypeError:
        raise ConfigError(f"{where}: expected task types, got {type(tasks).__name__}") from None
    for t in out:
        if not isinstance(t, TaskType):
            raise ConfigError(f"{where}: expected TaskType instances, got {type(t).__name__}")
    return out


def _load_python(path: Path) -> list[TaskType]:
    spec = importlib.util.spec_from_file_location(f"tasker_user_tasks.{path.stem}", path)
    if spec is None or spec.loader is None:
        raise ConfigError(f"{path}: cannot be imported")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    provider = getattr(module, "task_types", None)
    if provider is None:
        return []
    return _as_list(provider(), str(path))
