"""The synthetic backend's day task types: timed stages built from each request and from where the robot is.

:class:`DayTask` is one protocol task type (:class:`experiments.days.protocol.TaskSpec`) as a
synthetic task: a motion stage lasts the distance over the speed of whoever sets the pace (the
robot, the person it escorts, or the carry speed of a pick-and-place), the other stages take
what the protocol or the request says.  A type the protocol declares not preemptive
(``preemptive = false``: TaBSA's falls and pick-and-place) runs every stage blocking, so no
scheduler can interrupt it once it has started — the task's property, as in TaBSA, not a
scheduler's choice.
"""

from __future__ import annotations

import math
from typing import Any

from experiments.days.protocol import Pose, Protocol, TaskSpec
from tasker.messages import SP_COMPLETION, CompletionCost, CostParams, SPRequest
from tasker.stage import Purpose, Stage, StageKind, StagePlan
from tasker.synthetic import SyntheticTask
from tasker.task import ArgSpec, TaskContext

SUSP, BLOCK = StageKind.SUSPENDABLE, StageKind.BLOCKING
_ESTIMATES = "_estimates"
"""``ctx.memory`` key of the estimates remembered per start pose (:meth:`DayTask._c_time`)."""
_RESUME_STAGES = ("go_back", "apologise", "pick_again")


def _dist(a: Pose | None, b: Pose | None) -> float:
    if a is None or b is None:
        return 0.0
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _move(action: str, target: Pose, speed: float, origin: Pose | None = None, kind: StageKind = SUSP) -> Stage:
    """A motion stage; ``origin`` set means the motion has a fixed start (escort, carry)."""
    return Stage(action, kind=kind, duration=0.0 if origin is None else _dist(origin, target) / speed,
                 skill="timed", data={"site": target, "from": origin, "speed": speed})


def _seconds(drawn: Any, fixed: float | tuple[float, float]) -> float:
    """A stage's seconds: the request's drawn value, else the protocol's fixed one."""
    if drawn is not None:
        return float(drawn)
    if isinstance(fixed, tuple):
        raise ValueError("a duration the protocol draws per request is missing from the request")
    return float(fixed)


class DayTask(SyntheticTask):
    """A protocol task type; its stages come from the request (site, dest, work, walk speed).

    ``transport``: go to the person, greet (blocking), escort at the person's pace to
    ``dest``, goodbye (blocking); suspended while escorting, the robot asks the person to
    wait (blocking) and apologises on return.  ``fall``: go to the person, help for
    ``work`` seconds (blocking: not interruptible).  ``pick_place``: go to the object,
    pick (blocking), carry to ``dest`` (at the request's ``carry_speed``, else the robot's),
    place (blocking); suspended while carrying, the robot puts the object down and picks it
    up again on return.  The pick and place take the request's ``pick`` and ``place``
    seconds when it gives them (drawn per request), else the protocol's.

    A motion with a load (an escort, a carry) stopped by a suspension resumes from where it
    was stopped: the person waits there, the object is set down there, and on resumption the
    robot goes back to that point, apologises or picks the object up again, and goes on
    (TaBSA keeps a transport's progress too).  The point is the origin moved toward the
    target by the share of the stage's time that had run, as the task last saw it (its
    schedule parameters are computed every step).  The timed executor knows a robot's
    position only at the end of a completed motion, so the robot travels back from there.
    """

    def __init__(self, spec: TaskSpec, robot_speed: float, planning_time: float) -> None:
        super().__init__(spec.kind, [Stage("placeholder")], weight=spec.weight, speed=robot_speed,
                         planning_time=planning_time)
        self.spec = spec
        self.description = f"protocol task {spec.kind!r}"
        self.arg_specs = (*self.arg_specs,
                          ArgSpec("dest", "pose", required=False, help="where the person or object goes"),
                          ArgSpec("work", "float", required=False, default=0.0, help="seconds of work on site"),
                          ArgSpec("walk_speed", "float", required=False, default=robot_speed,
                                  help="pace of the escorted person (m/s)"),
                          ArgSpec("death_at", "float", required=False,
                                  help="time the person is dead if not helped (falls; for metrics)"))
        # only what the protocol draws per request: a protocol that draws none keeps its traces as they were
        if isinstance(spec.pick_s, tuple):
            self.arg_specs += (ArgSpec("pick_s", "float", required=False, help="seconds the pick takes"),)
        if isinstance(spec.place_s, tuple):
            self.arg_specs += (ArgSpec("place_s", "float", required=False, help="seconds the place takes"),)
        if spec.carry_speed is not None:
            self.arg_specs += (ArgSpec("carry_speed", "float", required=False, help="speed of the carry, m/s"),)

    # -- stages -------------------------------------------------------------------------------------
    def _template(self, args: dict[str, Any]) -> list[Stage]:
        s, site, dest = self.spec, args["site"], args["dest"]
        move = SUSP if s.preemptive else BLOCK  # a non-preemptive type is blocking from its first stage on
        go = _move("go_to", site, self.speed, kind=move)
        if s.kind == "transport":
            return [go, Stage("meet", kind=BLOCK, duration=s.greet_s),
                    _move("escort", dest, args["walk_speed"], site, move),
                    Stage("goodbye", kind=BLOCK, duration=s.goodbye_s)]
        if s.kind == "fall":
            return [go, Stage("help", kind=BLOCK, duration=args["work"])]
        carry = args.get("carry_speed") or self.speed
        return [go, Stage("pick_up", kind=BLOCK, duration=_seconds(args.get("pick_s"), s.pick_s)),
                _move("carry", dest, carry, site, move),
                Stage("place", kind=BLOCK, duration=_seconds(args.get("place_s"), s.place_s))]

    def _build(self, ctx: TaskContext, start: Pose | None, resume: bool) -> list[Stage]:
        rest = list(ctx.remaining) if ctx.plan is not None else self._template(ctx.args)
        rest = [st for st in rest if st.action not in _RESUME_STAGES]  # an unfinished resume is rebuilt below
        out: list[Stage] = []
        pose = start
        first = rest[0] if rest else None
        reached = ctx.memory.get("reached")
        if first is not None and reached is not None and reached[0] == first.action:  # goes on from there
            first = Stage(first.action, kind=first.kind, duration=first.duration, skill=first.skill,
                          data={**first.data, "from": tuple(reached[1])})
            rest[0] = first
        if resume and first is not None and first.data.get("from") is not None:
            origin = first.data["from"]
            out.append(Stage("go_back", kind=SUSP, duration=_dist(pose, origin) / self.speed, skill="timed",
                             data={"site": origin, "from": None, "speed": self.speed}))
            pose = origin
            if self.spec.resume_s:
                action = "apologise" if self.spec.kind == "transport" else "pick_again"
                out.append(Stage(action, kind=BLOCK, duration=self.spec.resume_s))
        for st in rest:
            if "speed" in st.data:
                origin = st.data["from"]
                d = _dist(pose if origin is None else origin, st.data["site"]) / st.data["speed"]
                st = Stage(st.action, kind=st.kind, duration=d, skill="timed", data=st.data)
                pose = st.data["site"]
            out.append(st)
        return out

    def update_task(self, ctx: TaskContext) -> StagePlan:
        ctx.memory["waiting"] = False
        stages = self._build(ctx, self._robot_pose(ctx), resume=ctx.suspended)
        ctx.memory.pop("reached", None)  # the plan's motion starts there now
        return StagePlan(tuple(stages), Purpose.UP_TSK, strategy="static", sim_time=self.planning_time)

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:
        ctx.memory["waiting"] = True
        stopped = ctx.interrupted
        moving = ctx.memory.pop("moving", None)
        if stopped is not None and stopped.data.get("from") is not None and moving is not None \
                and moving[0] == ctx.stage_index and stopped.duration > 0:
            share = min(1.0, max(0.0, (ctx.now - moving[1]) / stopped.duration))
            a, b = stopped.data["from"], stopped.data["site"]
            ctx.memory["reached"] = (stopped.action, tuple(round(x + share * (y - x), 3) for x, y in zip(a, b,
                                                                                                          strict=True)))
        stages: tuple[Stage, ...] = ()
        if stopped is not None and stopped.data.get("from") is not None and self.spec.suspend_s:
            action = "ask_to_stay" if self.spec.kind == "transport" else "set_down"
            stages = (Stage(action, kind=BLOCK, duration=self.spec.suspend_s),)
        return StagePlan(stages, Purpose.GEN_SUSP, strategy="static", sim_time=self.planning_time)

    # -- estimates ----------------------------------------------------------------------------------
    def _c_time(self, ctx: TaskContext, start: Pose | None) -> float:
        started = ctx.plan is not None and not ctx.memory.get("waiting", False)
        if started and start is None:
            return self._remaining(ctx)  # executing: what is left of the current plan
        # not started, waiting, or asked "from another pose" (i.e. resumed later): the plan it would build,
        # remembered per start while what _build reads of the agent (plan, stage, arguments, resume point) holds
        resume = started or ctx.suspended
        memo: tuple[Any, int, Any, Any, dict[tuple[Pose | None, bool], float]] | None = ctx.memory.get(_ESTIMATES)
        reached = ctx.memory.get("reached")
        if memo is None or memo[0] is not ctx.plan or memo[1] != ctx.stage_index or memo[2] is not ctx.args \
                or memo[3] != reached:
            memo = ctx.memory[_ESTIMATES] = (ctx.plan, ctx.stage_index, ctx.args, reached, {})
        c_time = memo[4].get((start, resume))
        if c_time is None:
            stages = self._build(ctx, start, resume=resume)
            c_time = memo[4][start, resume] = sum(s.duration for s in stages) + self.planning_time
        return c_time

    def _end_pose(self, ctx: TaskContext) -> Pose | None:
        return ctx.args["dest"] if ctx.args["dest"] is not None else ctx.args["site"]

    def compute_params(self, ctx: TaskContext) -> CostParams:
        current = ctx.current
        if ctx.stage_started is not None and current is not None and current.data.get("from") is not None:
            ctx.memory["moving"] = (ctx.stage_index, ctx.stage_started)  # a suspension knows how far it got
        c_time = self._c_time(ctx, None if ctx.plan is not None and not ctx.memory.get("waiting")
                              else self._robot_pose(ctx))
        w = ctx.args["weight"]
        return CostParams(self.name, cost=w * (ctx.age + c_time), cps=w, c_time=c_time, end_pose=self._end_pose(ctx),
                          deadline=ctx.args["deadline"], priority=ctx.args["priority"])

    def request_sp(self, ctx: TaskContext, request: SPRequest) -> CompletionCost:
        if request.sp_id != SP_COMPLETION:
            return super().request_sp(ctx, request)
        pose = request.args.get("pose")
        c_time = self._c_time(ctx, tuple(pose) if pose is not None else self._robot_pose(ctx))
        w = ctx.args["weight"]
        return CompletionCost(cc=w * (ctx.age + c_time), ccps=w, c_time=c_time)


def task_types(protocol: Protocol) -> tuple[DayTask, ...]:
    """The protocol's task types for the synthetic backend."""
    return tuple(DayTask(spec, protocol.robot_speed, protocol.planning_time_s) for spec in protocol.tasks.values())
