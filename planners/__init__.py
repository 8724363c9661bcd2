"""Planning for tasker: unified-planning + Fast Downward, task folders, and their checks.

* :class:`Planner` — solve with any UP one-shot engine by name, cached (:mod:`planners.planner`);
* ``tasker-fd`` — the fast optimal Fast Downward engine (:mod:`planners.engine`), registered
  with UP's factory by :func:`register_engine` (:mod:`planners.registration`; a :class:`Planner`
  does it when it needs UP's factory, and so does asking this package for any engine-related name);
* :func:`load_task_folder` — task folders (``domain.pddl`` + ``task.toml`` [+ ``task.py``])
  to :class:`~tasker.task.TaskType` instances, checked before any run.

The names below are imported lazily (PEP 562): ``import planners.fd`` must not pay for
unified-planning's engine framework (ConfigSpace, scipy.stats: about 0.9 s), which the
command line's path to Fast Downward never needs.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "DEFAULT_PLANNER": "planners.planner", "ENGINE_NAME": "planners.registration", "DefinitionError": "planners.checks",
    "PddlError": "planners.checks", "PddlTaskType": "planners.pddl_task", "PddlText": "planners.planner",
    "PlanResult": "planners.results", "PlanStatus": "planners.results", "Planner": "planners.planner",
    "TaskerFastDownward": "planners.engine", "load_domain": "planners.checks", "load_problem": "planners.checks",
    "load_task": "planners.loader", "load_task_folder": "planners.loader", "oneshot_planners": "planners.registration",
    "register_engine": "planners.registration", "store_loader": "planners.loader",
}

_ENGINE_NAMES = frozenset({"ENGINE_NAME", "TaskerFastDownward", "register_engine"})
"""Asking for one of these registers ``tasker-fd`` with UP's factory first."""

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'planners' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    if name in _ENGINE_NAMES:
        importlib.import_module("planners.registration").register_engine()
    globals()[name] = value
    return value
