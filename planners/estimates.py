"""Schedule-parameter estimates (``cTime``, ``endPose``) from a plan of the state asked about.

The harmoniser asks every agent at ``repRate`` what completing its task would cost
(``compSP``/``wait``) and, in Alg. 2, what it would cost from another start pose
(``reqSP``).  The answer must describe what the task would really do from that state,
not the remainder of a plan made before it was suspended: once a guided person was
told to wait, the robot must come back, greet them again and apologise (Alg. 3).

:class:`Estimator` answers with:

* **the executing agent** (a stage of ``exeTsk`` is running, no other start pose): the
  remaining stages of its own plan, which *is* its plan from the current state,
  re-timed from the robot's current pose (the running stage less its elapsed time);
* **any other agent, or a start pose**: the plan ``upTsk`` would make from the
  *hypothetical state* — the world now, the robot moved to the start pose (its ``at``
  fact re-grounded to the nearest place), the request's facts, Alg. 3's
  ``suspended_facts`` when the task was or will be suspended, ``task.py``'s facts; for
  an agent that would be suspended to go there, its suspension (genSusp) applied
  first; and what the task before it leaves changed (``TaskContext.handover``: the
  executing task's suspension for a start now, the completion of the agent a ``cc``
  request names in ``after``) — solved with the task's planner, or the template
  ``exeTsk`` under the static strategy, then timed by :func:`walk`.

**Caching.**  Plans are cached by the symbolic problem: objects, init facts and goal,
with travel times taken from the *reference table* — place-to-place times with nobody
in the way and the doors as they are, except between places a ``door_between`` fact
joins, which are timed with that door open (the plan decides whether to open it), as
:func:`~planners.problem.travel_table` does (``estimate_ignoring_people`` and
``estimate_ignoring_doors`` of ``robot``'s estimator, else ``estimate``).  Those depend
on the building and its closed doors only, so a person walking around never invalidates
a cached plan (and a plan never drives through a closed door it did not open), and the
cached plan is a function of its key alone: the same state gives the same estimate
whatever ran before (byte-reproducible traces).  The
plan is then re-timed with the live motion model; docs/planners.md says why that is a
fair estimate.  A leg the live model finds unreachable, or an unsolvable problem, means
``inf`` (no other route exists: a path planner's reachability is transitive).
A planner time-out falls back to the template walk and says so in
:attr:`Estimate.note`.  No wall-clock value enters an estimate.
"""

from __future__ import annotations

import math
import threading
import weakref
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from enum import StrEnum
from typing import Any, Protocol

from planners.planner import PddlText, Planner
from planners.problem import PLACE_TYPE, DomainModel, closed_door_pairs, holds, render_problem, travel_table
from planners.results import PlanStatus, PlanStep
from planners.stages import Bindings, StageBuilder, robot_name
from planners.taskspec import Branch, Literal, TaskSpec
from tasker.errors import PlanningFailed
from tasker.stage import Purpose, Stage
from tasker.task import TaskContext
from tasker.world import MotionModel, Pose, WorldState

NAVIGATE = "navigate"
"""The skill whose stages are timed with the motion model (others by their duration)."""
PERSON_TYPE = "person"
"""The object type of people: a leg to one ends where they stand (see :func:`walk`)."""

Travel = dict[tuple[str, str], float]


class EstimatedTask(Protocol):
    """What an :class:`Estimator` needs of a task type: its folder's definition, its planner,
    and the planning inputs upTsk and genSusp would use.

    :class:`~planners.pddl_task.PddlTaskType` is the one tasker builds; the estimator names
    this protocol rather than that class, so the dependency goes one way (the task type
    uses its estimator).
    """

    name: str
    spec: TaskSpec
    domain: DomainModel
    builder: StageBuilder
    timeout: float

    @property
    def planner(self) -> Planner: ...

    def update_inputs(self, ctx: TaskContext) -> tuple[WorldState, list[Literal], list[Literal]]: ...

    def suspension_inputs(self, ctx: TaskContext) -> tuple[WorldState, list[Literal], Branch]: ...

    def suspension_facts(self, ctx: TaskContext, world: WorldState) -> list[Literal]: ...

    def branch(self, ctx: TaskContext, world: WorldState) -> tuple[Branch, Bindings]: ...


class Source(StrEnum):
    """Where an estimate's stages came from."""

    REMAINING = "remaining"      # the executing agent's own plan, re-timed
    PLAN = "plan"                # a plan from the hypothetical state (cached or not)
    TEMPLATE = "template"        # the static template exeTsk (static strategy or a time-out)
    DECLARED = "declared"        # no world: the template's declared durations
    UNSOLVABLE = "unsolvable"    # no plan, no pose, no path: cTime = inf


@dataclass(frozen=True, slots=True)
class Estimate:
    """``cTime`` (s, ``inf`` when the task cannot be completed), ``endPose`` and where they came from.

    ``steps`` are the ground actions timed (for tests and tools); ``note`` says why a
    fallback was taken (a planner time-out) or why the estimate is ``inf``.
    """

    c_time: float
    end_pose: Pose | None
    source: Source
    steps: tuple[PlanStep, ...] = ()
    note: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.source, Source):
            raise TypeError(f"Estimate.source must be a Source, got {self.source!r}")
        if math.isnan(self.c_time) or self.c_time < 0:
            raise ValueError(f"Estimate.c_time must be >= 0 or inf, got {self.c_time}")
        if (self.source is Source.UNSOLVABLE) != math.isinf(self.c_time):
            raise ValueError(f"Estimate: c_time {self.c_time} does not fit source {self.source.value}")


def walk(stages: Sequence[Stage], start: Pose | None, world: WorldState | None, motion: MotionModel | None,
         elapsed: float = 0.0, through_door: Callable[[Stage], bool] | None = None) -> tuple[float, Pose | None]:
    """Seconds to run ``stages`` from ``start`` and the pose at the end; ``(inf, None)`` if a leg
    is unreachable.

    A ``navigate`` stage whose target has a pose in ``world`` is timed by ``motion`` from
    the pose reached so far (with ``estimate_ignoring_doors`` when ``through_door`` says
    the leg crosses a door the plan opens, as :func:`~planners.problem.travel_table`
    does); after a leg to a person, the next leg starts where that person stands (the
    robot is with them: the person it guides is no obstacle on their own guide); any
    other stage takes its duration.  ``elapsed`` seconds of the first stage
    have already run (a navigate leg is re-timed from ``start`` instead).
    """
    pose = start
    total = 0.0
    ignoring = getattr(motion, "estimate_ignoring_doors", None)
    for k, s in enumerate(stages):
        target = world.poses.get(str(s.data.get("to"))) if (world is not None and s.skill == NAVIGATE) else None
        if target is not None and pose is not None and motion is not None:
            door = ignoring is not None and through_door is not None and through_door(s)
            est = ignoring(pose, target) if (door and ignoring is not None) else motion.estimate(pose, target)
            if not est.reachable:
                return math.inf, None
            total += float(est.time_s)
            pose = est.end_pose or target
            if world is not None and world.objects.get(str(s.data.get("to"))) == PERSON_TYPE:
                # the robot is now with this person: the next leg starts where they stand, so
                # the motion model does not route around them (a guided person follows the
                # robot, anyone else stays behind it), as the navigate skill finds on the spot
                pose = (float(target[0]), float(target[1]), float(pose[2]))
        else:
            total += max(0.0, s.duration - elapsed) if k == 0 else s.duration
            pose = target or pose
    return total, pose


def nearest_place(world: WorldState, pose: Pose) -> str | None:
    """The place (an object of type ``place`` with a pose) nearest ``pose``; ties by name."""
    best: tuple[float, str] | None = None
    for name in sorted(n for n, t in world.objects.items() if t == PLACE_TYPE and n in world.poses):
        p = world.poses[name]
        d = math.hypot(p[0] - pose[0], p[1] - pose[1])
        if best is None or d < best[0] - 1e-9:
            best = (d, name)
    return best[1] if best else None


def moved_robot(world: WorldState, pose: Pose) -> WorldState:
    """``world`` with the robot at ``pose``: its ``at`` fact re-grounded to the nearest place.

    People and objects stay where they are; what the robot holds goes with it (the
    ``holding`` facts are untouched and :func:`planners.stages.place_of` follows them).
    """
    robot = robot_name(world)
    poses = dict(world.poses)
    poses[robot] = (float(pose[0]), float(pose[1]), float(pose[2]))
    place = nearest_place(world, pose)
    facts = set(world.facts)
    if place is not None:
        facts = {f for f in facts if not (len(f) == 3 and f[0] == "at" and f[1] == robot)}
        facts.add(("at", robot, place))
    return WorldState(frozenset(facts), poses, world.objects, world.time)


def _same_pose(a: Pose | None, b: Pose | None) -> bool:
    return a is not None and b is not None and all(abs(x - y) < 1e-6 for x, y in zip(a[:3], b[:3], strict=False))


def declared_template_time(spec: TaskSpec, domain: DomainModel) -> float:
    """Without a world: the static template's declared durations, travel at ``travel_s``."""
    total = 0.0
    for t in spec.static_update:
        a, model = spec.actions[t.action], domain.actions[t.action]
        if a.travel is not None:
            total += spec.travel_s
        else:
            total += a.duration if a.duration is not None else (model.constant_cost or 0.0)
    return total


def executing(ctx: TaskContext) -> bool:
    """True while a stage of ``exeTsk`` runs: the agent's plan is its plan from the state now."""
    return ctx.plan is not None and ctx.plan.purpose is Purpose.UP_TSK and ctx.stage_started is not None


@dataclass(frozen=True, slots=True)
class _Cached:
    status: PlanStatus
    steps: tuple[PlanStep, ...] = ()


@dataclass(slots=True)
class EstimatorStats:
    """Counters (no clock): planner calls, cache hits, time-outs."""

    solves: int = 0
    hits: int = 0
    timeouts: int = 0


class Estimator:
    """Plan-based estimates for one task type (:class:`EstimatedTask`; shared by its agents).

    ``cache_size`` bounds the LRU of plans by symbolic problem (0 disables it).
    """

    def __init__(self, task: EstimatedTask, cache_size: int = 256) -> None:
        self.task = task
        self.cache_size = cache_size
        self.stats = EstimatorStats()
        self._cache: OrderedDict[str, _Cached] = OrderedDict()
        self._lock = threading.Lock()
        # (weak reference to the motion model, place poses, table): never keeps a model alive
        self._reference: tuple[weakref.ref[Any], tuple[Any, ...], Travel] | None = None

    def clear(self) -> None:
        with self._lock:
            self._cache.clear()
            self._reference = None

    # -- public -------------------------------------------------------------------------

    def estimate(self, ctx: TaskContext, start: Pose | None = None, after: str | None = None) -> Estimate:
        """``cTime`` and ``endPose`` of the task in ``ctx``, started from ``start`` (the robot's pose if None).

        ``after``: the agent whose completion this start follows (Alg. 2's ``cc``); None: the
        task would start now, replacing the executing one (see :meth:`_hypothetical`)."""
        task = self.task
        world = ctx.world if isinstance(ctx.world, WorldState) else None
        if world is None:
            return Estimate(declared_template_time(task.spec, task.domain), None, Source.DECLARED)
        here = world.poses.get(robot_name(world))
        elsewhere = start is not None and not _same_pose(start, here)
        if executing(ctx) and not elsewhere:
            elapsed = max(0.0, ctx.now - ctx.stage_started) if ctx.stage_started is not None else 0.0
            return self._timed(ctx.remaining, here, world, ctx.motion, Source.REMAINING, elapsed=elapsed)
        try:
            hypo = self._hypothetical(ctx, start if elsewhere else None, after)
            return self._from_state(hypo)
        except PlanningFailed as exc:
            return Estimate(math.inf, None, Source.UNSOLVABLE, note=str(exc))

    # -- the hypothetical state ------------------------------------------------------------

    def _hypothetical(self, ctx: TaskContext, start: Pose | None, after: str | None = None) -> TaskContext:
        """The context upTsk would see: the world now, or after a suspension with the robot at
        ``start``; and in either case with what the task before it leaves changed
        (:attr:`TaskContext.handover <tasker.task.TaskContext.handover>`: the executing task's
        suspension, or the completion of ``after``), e.g. the vase it held put down."""
        world = ctx.world
        assert isinstance(world, WorldState)
        suspended = ctx.suspended
        if start is not None and (executing(ctx) or ctx.suspended):
            # the robot leaves this task to go to ``start``: the task suspends first (genSusp)
            world = self._apply(self.suspension_stages(replace(ctx, suspended=True)), world)
            suspended = True
        effects = ctx.handover(after) if ctx.handover is not None else None
        if effects:
            world = world.updated(add=effects.add, delete=effects.delete)
        if start is not None:
            world = moved_robot(world, start)
        elif effects:  # the robot's place is read off its pose again, whatever the effects said
            here = world.poses.get(robot_name(world))
            if here is not None:
                world = moved_robot(world, here)
        return replace(ctx, world=world, suspended=suspended)

    @staticmethod
    def _apply(stages: Sequence[Stage], world: WorldState) -> WorldState:
        for s in stages:
            world = world.updated(add=[tuple(f) for f in s.data.get("add", ())],
                                  delete=[tuple(f) for f in s.data.get("delete", ())])
        return world

    def suspension_stages(self, ctx: TaskContext) -> tuple[Stage, ...]:
        """What genSusp would do now; only its effects matter here, so no travel table is built."""
        task = self.task
        if ctx.strategy.suspension not in ("static", "fallback"):  # fallback: the tree, where it can run
            world, goal, _ = task.suspension_inputs(ctx)
            steps, status, _ = self.plan(ctx, world, goal, task.suspension_facts(ctx, world))
            if status is PlanStatus.SOLVED:
                return task.builder.from_steps(steps, {}, ctx.args)
        # static, or as genSusp: an unsolvable suspension falls back to the decision list
        world = ctx.world
        assert isinstance(world, WorldState)
        branch, b = task.branch(ctx, world)
        return task.builder.from_templates(branch.stages, b, {}, ctx.suspended)

    # -- planning and timing -------------------------------------------------------------

    def _from_state(self, ctx: TaskContext) -> Estimate:
        task = self.task
        world = ctx.world
        assert isinstance(world, WorldState)
        start = world.poses.get(robot_name(world))
        if ctx.strategy.update == "static":
            return self._template(ctx, start, "")
        hworld, goal, extra = task.update_inputs(ctx)
        steps, status, note = self.plan(ctx, hworld, goal, extra)
        if status is PlanStatus.TIMEOUT:
            self.stats.timeouts += 1
            return self._template(ctx, start, "planner timed out: template walk")
        if status is not PlanStatus.SOLVED:
            return Estimate(math.inf, None, Source.UNSOLVABLE, note=note or f"no plan reaches {goal}")
        stages = task.builder.from_steps(steps, {}, ctx.args)
        return self._timed(stages, start, world, ctx.motion, Source.PLAN, steps=steps)

    def _template(self, ctx: TaskContext, start: Pose | None, note: str) -> Estimate:
        world = ctx.world
        assert isinstance(world, WorldState)
        task = self.task
        stages = task.builder.from_templates(task.spec.static_update, Bindings(ctx.args, world), {}, ctx.suspended)
        return self._timed(stages, start, world, ctx.motion, Source.TEMPLATE, note=note)

    def _timed(self, stages: Sequence[Stage], start: Pose | None, world: WorldState, motion: MotionModel | None,
               source: Source, *, elapsed: float = 0.0, steps: tuple[PlanStep, ...] | None = None,
               note: str = "") -> Estimate:
        c_time, end = walk(stages, start, world, motion, elapsed, self._door_check(world))
        if steps is None:
            steps = tuple((s.action, *s.args) for s in stages)
        if not math.isfinite(c_time):
            return Estimate(math.inf, None, Source.UNSOLVABLE, steps, note or "a leg is unreachable")
        return Estimate(c_time, end, source, steps, note)

    def _door_check(self, world: WorldState) -> Callable[[Stage], bool] | None:
        """Does a stage travel between places joined by a ``door_between`` fact through a door closed now
        (a door the plan opens)?  Through an open door a leg is timed like any other."""
        pairs = closed_door_pairs(world, opens_doors=self.task.domain.opens_doors)
        if not pairs:
            return None
        task = self.task

        def check(stage: Stage) -> bool:
            spec = task.spec.actions.get(stage.action)
            model = task.domain.actions.get(stage.action)
            if spec is None or spec.travel is None or model is None:
                return False
            bind = {f"?{p}": a for p, a in zip(model.params, stage.args, strict=False)}
            return (bind.get(spec.travel[0]), bind.get(spec.travel[1])) in pairs

        return check

    def plan(self, ctx: TaskContext, world: WorldState, goal: list[Literal], extra: list[Literal],
             travel: Travel | None = None, *, solve: bool = True) -> tuple[tuple[PlanStep, ...], PlanStatus, str]:
        """Steps reaching ``goal`` from ``world``, through the cache of symbolic problems
        (travel times from :meth:`reference_table` unless given).  ``solve=False``: only what
        the cache holds (an unsolved problem answers ``PlanStatus.ERROR``, "not planned yet")."""
        task = self.task
        if travel is None:
            travel = self.reference_table(world, ctx.motion)
        for lit in goal:
            task.domain.check_literal(lit, f"goal of task {task.name!r}")
        text, init = render_problem(task.domain, world, goal, extra_facts=extra, travel=travel, name=task.name)
        if holds(init, goal):
            return (), PlanStatus.SOLVED, ""
        if not solve:
            with self._lock:
                cached = self._cache.get(text) if self.cache_size else None
            if cached is None:
                return (), PlanStatus.ERROR, "not planned yet"
            return cached.steps, cached.status, ""
        with self._lock:
            hit = self._cache.get(text) if self.cache_size else None
            if hit is not None:
                self._cache.move_to_end(text)
                self.stats.hits += 1
        if hit is None:
            self.stats.solves += 1
            result = task.planner.solve(PddlText(task.domain.checked.text, text), timeout=task.timeout)
            hit = _Cached(result.status, result.plan or ())
            if self.cache_size and result.status is not PlanStatus.ERROR:
                with self._lock:
                    self._cache[text] = hit
                    while len(self._cache) > self.cache_size:
                        self._cache.popitem(last=False)
            if result.status is PlanStatus.ERROR:
                return (), result.status, f"planner error: {result.message}"
        return hit.steps, hit.status, ""

    def reference_table(self, world: WorldState, motion: MotionModel | None) -> Travel:
        """Place-to-place seconds with nobody in the way, remembered per motion model and set
        of closed doors: the doors as they are, except that places a ``door_between`` fact joins
        through a closed door are timed with it open (the plan decides whether to open it).

        A model without ``estimate_ignoring_people`` and ``estimate_ignoring_doors`` is asked
        with :func:`~planners.problem.travel_table` every time (it may change); without a
        model or poses, the declared ``travel_s``.
        """
        as_is: Callable[[Pose, Pose], Any] | None = getattr(motion, "estimate_ignoring_people", None)
        opened: Callable[[Pose, Pose], Any] | None = getattr(motion, "estimate_ignoring_doors", None)
        if as_is is None or opened is None:
            return travel_table(world, motion, self.task.spec.travel_s, opens_doors=self.task.domain.opens_doors)
        places = tuple(sorted((n, tuple(world.poses.get(n, ()))) for n, t in world.objects.items()
                              if t == PLACE_TYPE))
        through_door = frozenset(closed_door_pairs(world, opens_doors=self.task.domain.opens_doors))
        closed: tuple[str, ...] = tuple(getattr(motion, "closed_doors", tuple)())
        key = (places, through_door, closed)
        with self._lock:
            ref = self._reference
        if ref is not None and ref[0]() is motion and ref[1] == key:
            return ref[2]
        table: Travel = {}
        for a, pa in places:
            for b, pb in places:
                if a == b:
                    continue
                if len(pa) >= 3 and len(pb) >= 3:
                    estimate = opened if (a, b) in through_door else as_is
                    table[a, b] = float(estimate(pa, pb).time_s)  # type: ignore[arg-type]
                else:
                    table[a, b] = float(self.task.spec.travel_s)
        try:
            memo = (weakref.ref(motion), key, table)
        except TypeError:  # a model that cannot be weakly referenced is simply asked again
            return table
        with self._lock:
            self._reference = memo
        return table


_estimators: weakref.WeakKeyDictionary[Any, Estimator] = weakref.WeakKeyDictionary()
_estimators_lock = threading.Lock()


def forget_estimates() -> None:
    """Every task type's estimates and rendered problems forgotten: the next ones are made cold."""
    with _estimators_lock:
        estimators = list(_estimators.items())
    for task, est in estimators:
        est.clear()
        domain = getattr(task, "domain", None)
        if domain is not None:
            with domain.rendered_lock:
                domain.rendered.clear()


def estimator_for(task: EstimatedTask) -> Estimator:
    """The :class:`Estimator` of a task type (one per instance, so its agents share the cache)."""
    with _estimators_lock:
        est = _estimators.get(task)
        if est is None:
            est = _estimators[task] = Estimator(task)
        return est
