"""tasker: the TaskER model of robot task harmonisation, with PDDL planning.

The package is the model of the paper: dynamic agents (:mod:`tasker.agent`), the
task harmoniser (:mod:`tasker.harmoniser`), schedule algorithms
(:mod:`tasker.schedulers`), the task store and requester, the deterministic loop
and the trace.  It imports only the standard library and numpy; planners and robots
plug in through :mod:`tasker.protocols` and :mod:`tasker.task` hooks.
"""

from __future__ import annotations

from tasker.agent import DynamicAgent, Rates
from tasker.errors import BadRequest, ConfigError, PlanningFailed, RunAborted, TaskerError, UnknownName
from tasker.harmoniser import Mode, OscillationGuard, Request, TaskHarmoniser
from tasker.loop import SimulationLoop
from tasker.messages import (
    SP_COMPLETION,
    Command,
    CompletionCost,
    CostParams,
    Flag,
    FsmState,
    Report,
    ScheduleParams,
    SPRequest,
)
from tasker.requester import Requester
from tasker.stage import Purpose, Stage, StageKind, StagePlan
from tasker.store import TaskStore
from tasker.task import ArgSpec, Strategy, TaskContext, TaskType
from tasker.trace import Trace

__version__ = "0.1.0"

__all__ = [
    "SP_COMPLETION", "ArgSpec", "BadRequest", "Command", "CompletionCost", "ConfigError", "CostParams",
    "DynamicAgent", "Flag", "FsmState", "Mode", "OscillationGuard", "PlanningFailed", "Purpose", "Rates",
    "Report", "Request",
    "Requester", "RunAborted", "SPRequest", "ScheduleParams", "SimulationLoop", "Stage", "StageKind", "StagePlan",
    "Strategy", "TaskContext", "TaskHarmoniser", "TaskStore", "TaskType", "TaskerError", "Trace",
    "UnknownName", "__version__",
]
