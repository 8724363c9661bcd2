"""Synthetic task types and a timed core agent: the model without a robot.

A :class:`SyntheticTask` is a template of stages with durations and kinds, a site
where it happens (a pose on the plane), a cost model, an optional suspension
decision tree and optional self-termination.  :class:`TimedExecutor` "executes" a
stage by letting its duration pass on the simulated clock.  Together they let the
harmoniser be tested and benchmarked on its own.

Cost model (the project's meaning of cost, see ``docs/model.md``): a task's cost is
the weighted time its requester will have waited by the time it completes,

    cTime = travel(robot -> site) + remaining stage durations
    cost  = weight * (age + cTime),        cps = weight
    cc(pose) = weight * (age + travel(pose -> site) + remaining),  ccps = weight

where ``travel`` is the straight-line distance over ``speed``.  ``cost_fn`` replaces
``cost`` when given.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from tasker.errors import ConfigError
from tasker.inputs import EstimateInputs
from tasker.messages import SP_COMPLETION, CompletionCost, CostParams, SPRequest
from tasker.protocols import RUNNING, SUCCEEDED, SkillStatus, failed
from tasker.stage import Purpose, Stage, StagePlan
from tasker.task import ArgSpec, TaskContext, TaskType

Pose = tuple[float, ...]


def _travel(a: Pose | None, b: Pose | None, speed: float) -> float:
    if a is None or b is None:
        return 0.0
    return math.hypot(a[0] - b[0], a[1] - b[1]) / speed


class SyntheticTask(TaskType):
    """A task type made of timed stages; see the module docstring for its cost model.

    ``suspension`` maps the action of the interrupted stage to the ``exeSusp``
    stages (a decision tree of depth one, as eq. 47), or is a callable of the
    context; ``resume_prefix`` stages are prepended to ``exeTsk`` when a suspended
    task resumes (Alg. 3).  Request arguments: ``weight``, ``site``, ``deadline``,
    ``priority`` and ``cancel_at`` (absolute time at which the task ends itself).
    """

    def __init__(
        self,
        name: str,
        stages: Sequence[Stage],
        *,
        weight: float = 1.0,
        speed: float = 1.0,
        site: Pose | None = None,
        suspension: Mapping[str, Sequence[Stage]] | Callable[[TaskContext], Sequence[Stage]] | None = None,
        resume_prefix: Sequence[Stage] = (),
        cost_fn: Callable[[TaskContext, float], float] | None = None,
        planning_time: float = 0.0,
        description: str = "",
    ) -> None:
        if not stages:
            raise ConfigError(f"synthetic task {name!r}: needs at least one stage")
        if speed <= 0:
            raise ConfigError(f"synthetic task {name!r}: speed must be > 0, got {speed}")
        self.name = name
        self.description = description or f"synthetic task of {len(stages)} stages"
        self.stages = tuple(stages)
        self._total = sum(s.duration for s in self.stages)
        self.speed = float(speed)
        self.suspension = suspension
        self.resume_prefix = tuple(resume_prefix)
        self.cost_fn = cost_fn
        self.planning_time = float(planning_time)
        self.arg_specs = (
            ArgSpec("weight", "float", required=False, default=float(weight), help="cost per second of delay"),
            ArgSpec("site", "pose", required=False, default=site, help="where the task happens"),
            ArgSpec("deadline", "float", required=False, help="absolute time the task should be done by"),
            ArgSpec("priority", "int", required=False, help="static priority, higher is more urgent"),
            ArgSpec("cancel_at", "float", required=False, help="time at which the task ends itself"),
        )

    def check_args(self, args: dict[str, Any]) -> None:
        from tasker.errors import BadRequest

        if args["weight"] < 0:
            raise BadRequest(f"task {self.name!r}, argument 'weight': expected >= 0, got {args['weight']}")

    # -- hooks ------------------------------------------------------------------------------------

    def _remaining(self, ctx: TaskContext) -> float:
        if ctx.plan is None:
            return self._total
        cached = ctx.memory.get("_suffix")
        if cached is None or cached[0] is not ctx.plan:  # suffix sums of the current plan's durations
            suffix = [0.0]
            for stage in reversed(ctx.plan.stages):
                suffix.append(suffix[-1] + stage.duration)
            cached = ctx.memory["_suffix"] = (ctx.plan, suffix[::-1])
        total = cached[1][min(ctx.stage_index, len(ctx.plan.stages))]
        if ctx.stage_started is not None and ctx.current is not None:  # progress of the running stage
            total -= min(ctx.current.duration, ctx.now - ctx.stage_started)
        return total

    def _robot_pose(self, ctx: TaskContext) -> Pose | None:
        return getattr(ctx.core, "pose", None)

    def _params(self, ctx: TaskContext, start: Pose | None) -> tuple[float, float]:
        site = ctx.args["site"]
        c_time = _travel(start, site, self.speed) + self._remaining(ctx)
        w = ctx.args["weight"]
        cost = self.cost_fn(ctx, c_time) if self.cost_fn else w * (ctx.age + c_time)
        return cost, c_time

    def compute_params(self, ctx: TaskContext) -> CostParams:
        cost, c_time = self._params(ctx, self._robot_pose(ctx))
        site = ctx.args["site"]
        return CostParams(
            self.name, cost=cost, cps=ctx.args["weight"], c_time=c_time,
            end_pose=tuple(site) if site is not None else None,
            deadline=ctx.args["deadline"], priority=ctx.args["priority"],
        )

    def request_sp(self, ctx: TaskContext, request: SPRequest) -> CompletionCost:
        if request.sp_id != SP_COMPLETION:
            raise ConfigError(f"synthetic task {self.name!r}: unknown reqSP {request.sp_id!r}")
        pose = request.args.get("pose")
        cost, c_time = self._params(ctx, tuple(pose) if pose is not None else None)
        return CompletionCost(cc=cost, ccps=ctx.args["weight"], c_time=c_time)

    def update_task(self, ctx: TaskContext) -> StagePlan:
        """Alg. 3: the template minus completed stages, with ``resume_prefix`` after a suspension."""
        rest = self.stages[len(ctx.done) :] if ctx.plan is None else ctx.remaining
        prefix = self.resume_prefix if ctx.suspended else ()
        return StagePlan(tuple(prefix) + tuple(rest), Purpose.UP_TSK, strategy="static", sim_time=self.planning_time)

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:
        """Eq. 47: choose ``exeSusp`` by the interrupted stage."""
        stages: Sequence[Stage] = ()
        if callable(self.suspension):
            stages = self.suspension(ctx)
        elif self.suspension is not None and ctx.interrupted is not None:
            stages = self.suspension.get(ctx.interrupted.action, ())
        return StagePlan(tuple(stages), Purpose.GEN_SUSP, strategy="static", sim_time=self.planning_time)

    def check_terminate(self, ctx: TaskContext) -> str | None:
        at = ctx.args["cancel_at"]
        if at is not None and ctx.now >= at:
            return "no longer needed"
        return None

    def estimate_inputs(self, ctx: TaskContext) -> EstimateInputs | None:
        """Besides the agent's own context, the estimate reads the robot's pose (the executor's
        ``version`` counts its changes), and ``ic_term`` the clock against ``cancel_at``.  None with
        a ``cost_fn`` (its cost need not be the model's) or while a stage runs (its progress is time)."""
        if self.cost_fn is not None or ctx.stage_started is not None:
            return None
        at = ctx.args["cancel_at"]
        return EstimateInputs(self._robot_pose(ctx), math.inf if at is None else float(at))


class TimedExecutor:
    """A core agent whose skills take their stage's ``duration`` of simulated time.

    ``jitter`` scales each duration by a factor drawn uniformly from
    ``[1 - jitter, 1 + jitter]`` with a generator seeded by ``(seed, agent, stage)``,
    so runs vary with the seed and repeat exactly for the same seed.  A stage whose
    ``data`` has ``"fail"`` fails with that reason when its time is up.  ``pose`` is
    the site of the last stage run (its ``data["site"]``), for travel estimates; ``version``
    counts its changes (what a parked agent's estimate reads, :mod:`tasker.inputs`).
    """

    def __init__(self, seed: int = 0, jitter: float = 0.0) -> None:
        if not 0 <= jitter < 1:
            raise ConfigError(f"jitter must be in [0, 1), got {jitter}")
        self.seed = seed
        self.jitter = jitter
        self.version = 0  # counts the changes of pose (what estimates read: tasker.inputs)
        self._pose: Pose | None = None
        self._running: dict[str, tuple[Stage, float]] = {}
        self._count: dict[str, int] = {}
        self.log: list[tuple[float, str, str, str]] = []

    @property
    def pose(self) -> Pose | None:
        return self._pose

    @pose.setter
    def pose(self, value: Pose | None) -> None:
        if value != self._pose:
            self.version += 1
        self._pose = value

    def begin(self, agent: str, stage: Stage, now: float) -> None:
        if self._running and agent not in self._running:
            other = next(iter(self._running))
            raise ConfigError(f"core agent busy: {other} runs a stage while {agent} begins one")
        n = self._count.get(agent, 0) + 1
        self._count[agent] = n
        duration = stage.duration
        if self.jitter:
            u = random.Random(f"{self.seed}:{agent}:{n}").uniform(-self.jitter, self.jitter)
            duration *= 1 + u
        self._running[agent] = (stage, now + duration)
        self.log.append((now, agent, stage.action, "begin"))

    def poll(self, agent: str, stage: Stage, now: float) -> SkillStatus:
        _, done_at = self._running[agent]
        if now + 1e-9 < done_at:
            return RUNNING
        del self._running[agent]
        if "site" in stage.data:
            self.pose = tuple(stage.data["site"])
        reason = stage.data.get("fail")
        return failed(str(reason)) if reason else SUCCEEDED

    def stop(self, agent: str, stage: Stage, now: float) -> None:
        self._running.pop(agent, None)
        self.log.append((now, agent, stage.action, "stop"))


class ManualExecutor:
    """A core agent whose stages finish only when told (:meth:`finish`); for tests."""

    def __init__(self) -> None:
        self.running: dict[str, Stage] = {}
        self._outcome: dict[str, SkillStatus] = {}
        self.pose: Pose | None = None

    def begin(self, agent: str, stage: Stage, now: float) -> None:
        if self.running and agent not in self.running:
            raise ConfigError(f"core agent busy: {sorted(self.running)} runs while {agent} begins")
        self.running[agent] = stage

    def poll(self, agent: str, stage: Stage, now: float) -> SkillStatus:
        outcome = self._outcome.pop(agent, None)
        if outcome is None:
            return RUNNING
        self.running.pop(agent, None)
        return outcome

    def stop(self, agent: str, stage: Stage, now: float) -> None:
        self.running.pop(agent, None)
        self._outcome.pop(agent, None)

    def finish(self, agent: str | None = None, reason: str | None = None) -> str | None:
        """Make the running stage (of ``agent``, or whichever runs) succeed, or fail with ``reason``."""
        if agent is None:
            if not self.running:
                return None
            agent = next(iter(self.running))
        if agent in self.running:
            self._outcome[agent] = failed(reason) if reason else SUCCEEDED
            return agent
        return None
