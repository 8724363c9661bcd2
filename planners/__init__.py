"""Planning for tasker: unified-planning + Fast Downward, task folders, and their checks.

* :class:`Planner` — solve with any UP one-shot engine by name, cached (:mod:`planners.planner`);
* ``tasker-fd`` — the fast optimal Fast Downward engine, registered with UP's factory
  when this package is imported (:mod:`planners.engine`);
* :func:`load_task_folder` — task folders (``domain.pddl`` + ``task.toml`` [+ ``task.py``])
  to :class:`~tasker.task.TaskType` instances, checked before any run.

Importing the package also silences UP's credits banner (``credits_stream = None``).
"""

from __future__ import annotations

from unified_planning.environment import get_environment

from planners.checks import DefinitionError, PddlError, load_domain, load_problem
from planners.engine import ENGINE_NAME, TaskerFastDownward, register_engine
from planners.loader import load_task, load_task_folder, store_loader
from planners.pddl_task import PddlTaskType
from planners.planner import DEFAULT_PLANNER, PddlText, Planner, oneshot_planners
from planners.results import PlanResult, PlanStatus

get_environment().credits_stream = None
register_engine()

__all__ = [
    "DEFAULT_PLANNER", "ENGINE_NAME", "DefinitionError", "PddlError", "PddlTaskType", "PddlText", "PlanResult",
    "PlanStatus", "Planner", "TaskerFastDownward", "load_domain", "load_problem", "load_task", "load_task_folder",
    "oneshot_planners", "register_engine", "store_loader",
]
