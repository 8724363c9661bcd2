"""What every scenario reader shares: the error class and the ``[settings]`` fields.

Files are read with the strict reader :mod:`tasker.support.reader` (every fault names the file,
the line, the field, what was expected and "did you mean"); this module holds only
what the robot and the synthetic scenario readers have in common.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from tasker import schedulers
from tasker.errors import ScenarioError as ScenarioError  # defined there; re-exported here
from tasker.support.reader import Table
from tasker.task import TaskType

TASKS_HINT = "to add a task type, add its folder with --path DIR or TASKER_TASKS (see 'tasker new')"
"""What an unknown task type's error adds: how to add one."""

MODES = ("IT", "CT")
STRATEGIES = ("planned", "static")
POLICIES = ("strict", "conditional")


def scheduler(s: Table) -> str:
    """``settings.scheduler``: a registered scheduler name."""
    return str(s.string("scheduler", "alg2", choices=schedulers.names()))


def scheduler_options(s: Table, name: str, task_names: list[str] | None = None) -> dict[str, Any]:
    """``settings.scheduler_options``: checked by building the scheduler; task types named in
    ``classes`` (alg2) or ``priorities`` (priority) must be known when ``task_names`` is given."""
    opts = s.table("scheduler_options", {})
    options = dict(opts.items())
    for key in options:
        why = schedulers.unknown_option(name, key)
        if why:
            raise opts.error(key, why)
    if task_names is not None:
        for key, value in options.items():
            named: list[str] = []
            if key == "classes" and isinstance(value, list):
                named = [t for c in value if isinstance(c, list) for t in c if isinstance(t, str)]
            elif key == "priorities" and isinstance(value, dict):
                named = [t for t in value if isinstance(t, str)]
            for t in named:
                if t not in task_names:
                    raise opts.error(key, f"no task type {t!r}{_suggest(t, task_names)} "
                                          f"(known: {', '.join(sorted(task_names))}); {TASKS_HINT}")
    try:
        schedulers.create(name, **options)
    except Exception as exc:  # the scheduler's own check, e.g. hysteresis out of range
        raise s.error("scheduler_options", f"{exc}") from None
    return options


def priority_classes(tasks: Iterable[TaskType]) -> list[list[str]]:
    """Alg. 2's ``classes`` from what the task types declare (:attr:`tasker.task.TaskType.priority`,
    a folder's ``[schedule] priority``): one class per priority, highest first, names sorted;
    types that declare none form the lowest class, which ``classes`` leaves unlisted."""
    by: dict[int, list[str]] = {}
    for t in tasks:
        if t.priority is not None:
            by.setdefault(t.priority, []).append(t.name)
    return [sorted(by[p]) for p in sorted(by, reverse=True)]


def scheduler_defaults(name: str, options: Mapping[str, Any], tasks: Iterable[TaskType]) -> dict[str, Any]:
    """``options`` completed with what the task types declare: ``alg2`` without ``classes`` gets
    :func:`priority_classes` (when any type declares a priority).  The model names no task type,
    so these defaults come from the folders, never from the scheduler."""
    out = dict(options)
    if name == "alg2" and "classes" not in out:
        classes = priority_classes(tasks)
        if classes:
            out["classes"] = classes
    return out


MAX_RATE_HZ = 1000.0
"""The fastest rate a scenario may set (the model's run at 1 to 10 Hz): a rate of 1e300 Hz made the
loop step forever."""


def rate(s: Table, key: str, default: float) -> float:
    return float(s.number(key, default, positive=True, max=MAX_RATE_HZ))


def _suggest(name: str, known: list[str]) -> str:
    from tasker.support.reader import suggest

    return suggest(name, known)
