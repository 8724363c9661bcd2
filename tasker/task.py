"""Task types: what a user writes to add a task to the store.

A task type is a class with **hooks**; the dynamic agent owns the loop
(:meth:`tasker.agent.DynamicAgent.step`, ``typing.final``) and calls them at the
moments the paper defines.  Override the hooks you need:

=====================  ===============================  ===================================
hook                   called in (paper)                 returns
=====================  ===============================  ===================================
``initialise``         ``initComm``                      nothing; set up ``ctx.memory``
``compute_params``     ``compSP``, ``wait`` (eq. 22,      :class:`~tasker.messages.ScheduleParams`
                       27) and ``exeTsk`` (eq. 24)
``request_sp``         on the harmoniser's ``reqSP``      the requested parameter, e.g.
                       (eqs. 20-23)                       :class:`~tasker.messages.CompletionCost`
``update_task``        ``upTsk``                         the ``exeTsk`` :class:`~tasker.stage.StagePlan`
``generate_suspension`` ``genSusp``                      the ``exeSusp`` :class:`~tasker.stage.StagePlan`
``check_terminate``    ``compSP``, ``exeTsk``, ``wait``   a reason to end itself (``ic_term``) or None
``estimate_inputs``    ``compSP``, ``wait``              what the two above read (:mod:`tasker.inputs`)
``on_stage_done``      after each completed stage        nothing
``leaves``             another agent's estimate          the facts it would leave changed
                       (:attr:`TaskContext.handover`)     (:class:`Effects`) or None
``check_args``         :meth:`TaskType.validate_args`     nothing; raise ``BadRequest``
``adjust_args``        :meth:`TaskType.validate_args`     nothing; change the completed
                       (after ``check_args``)             arguments in place
=====================  ===============================  ===================================

Which hook when:

* ``update_task`` is the one every task type must override: it turns the world as it is
  now into the stages still to run (R6: what is done already is not planned again).
* ``generate_suspension`` when being interrupted leaves something unsafe or undone (a
  device on, an object held, a person waiting); the default suspends with nothing to do.
* ``compute_params`` when the default cost (age plus the expected duration left) does not
  say how urgent the task is; ``request_sp`` when the answer to ``cc`` depends on where
  the robot starts (the default ignores the pose).
* ``check_terminate`` when the task can become pointless on its own (the person got up).
* ``estimate_inputs`` when you can say what ``compute_params`` and ``check_terminate`` read:
  a waiting agent is then not stepped while none of it changes (its cost aged in closed form).
* ``initialise`` for per-agent set-up, never ``__init__``: one instance serves every agent,
  so per-agent state lives in ``ctx.memory``.
* ``on_stage_done`` to note progress; ``leaves`` when what the task changes matters to the
  next task's estimates; ``check_args`` for checks the :class:`ArgSpec` types cannot make;
  ``adjust_args`` when the completed arguments depend on what the request gave, not only on
  its values (a default the request did not ask for left out; a wrapping type handing its
  inner type the inner's arguments).

``update_task`` and ``generate_suspension`` may raise
:class:`~tasker.errors.PlanningFailed`: the agent then ends (upTsk) with the reason in
the trace.  A task type that wants a fallback (e.g. a static suspension when the
planner fails) does it inside the hook and says so in ``StagePlan.note``.

The framework's own method :meth:`TaskType.validate_args` checks a request's arguments
against the declared :class:`ArgSpec` tuple and then calls ``check_args`` and ``adjust_args``:
extend the checks there; it is ``typing.final``, so mypy refuses an override.
``update_task`` is abstract: :meth:`tasker.store.TaskStore.register` refuses a type that does not
implement it (:func:`missing_hooks`), when it is registered rather than when it first runs.
"""

from __future__ import annotations

import random
from abc import abstractmethod
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, final

from tasker.errors import BadRequest, ConfigError
from tasker.inputs import EstimateInputs
from tasker.meaning import NO_MEANING, Meaning
from tasker.memory import AgentMemory
from tasker.messages import CompletionCost, CostParams, ScheduleParams, SPRequest
from tasker.protocols import CoreAgent
from tasker.stage import Purpose, Stage, StagePlan
from tasker.world import Fact, MotionModel

Leaving = Literal["suspend", "complete"]
"""How a task is left, for :meth:`TaskType.leaves`: suspended now, or completed."""


@dataclass(frozen=True, slots=True)
class Effects:
    """What a task leaves changed in the world: facts it adds and facts it deletes (net)."""

    add: tuple[Fact, ...] = ()
    delete: tuple[Fact, ...] = ()

    @classmethod
    def of(cls, stages: Iterable[Stage]) -> Effects:
        """The net effect of ``stages`` run in order (their ``add``/``delete`` data)."""
        net: dict[Fact, bool] = {}
        for s in stages:
            for f in s.data.get("delete", ()):
                net[tuple(str(x) for x in f)] = False
            for f in s.data.get("add", ()):
                net[tuple(str(x) for x in f)] = True
        return cls(tuple(f for f, v in net.items() if v), tuple(f for f, v in net.items() if not v))

    def __bool__(self) -> bool:
        return bool(self.add or self.delete)


DEFAULT_TREE = "default"
"""The name of a task's default decision tree (a task folder's ``[[suspension]]``; :attr:`Strategy.tree` None)."""
POLICIES = ("strict", "conditional")
UPDATES = ("planned", "static")
"""How upTsk builds exeTsk: plan from the world as it is, or the template (Alg. 3)."""
SUSPENSIONS = ("planned", "static", "derived", "fallback")
"""How genSusp builds exeSusp: plan to the decision tree's goal, run its stages, plan to the goal
derived from the task's declarations, or run the tree's stages where they can run and plan to the
derived goal where they cannot (``fallback``)."""
"""Suspension policies (:attr:`Strategy.policy`)."""

_ARG_TYPES: dict[str, type] = {"str": str, "float": float, "int": int, "bool": bool, "pose": tuple}


@dataclass(frozen=True, slots=True)
class ArgSpec:
    """One argument of a task request: its name, type and whether it is required."""

    name: str
    type: str = "str"
    required: bool = True
    default: Any = None
    help: str = ""
    choices: tuple[Any, ...] | None = None

    def __post_init__(self) -> None:
        if not self.name.isidentifier():
            raise ConfigError(f"ArgSpec.name must be an identifier, got {self.name!r}")
        if self.type not in _ARG_TYPES:
            raise ConfigError(f"ArgSpec {self.name!r}: type must be one of {sorted(_ARG_TYPES)}, got {self.type!r}")

    def coerce(self, task: str, value: Any) -> Any:
        """Check ``value`` and return it in its canonical form; raise :class:`BadRequest`."""
        where = f"task {task!r}, argument {self.name!r}"
        if self.type == "float":
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise BadRequest(f"{where}: expected a number, got {value!r}")
            value = float(value)
        elif self.type == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                raise BadRequest(f"{where}: expected an integer, got {value!r}")
        elif self.type == "bool":
            if not isinstance(value, bool):
                raise BadRequest(f"{where}: expected true or false, got {value!r}")
        elif self.type == "pose":
            if not isinstance(value, list | tuple) or len(value) not in (2, 3) or not all(
                isinstance(v, int | float) and not isinstance(v, bool) for v in value
            ):
                raise BadRequest(f"{where}: expected a pose [x, y] or [x, y, yaw], got {value!r}")
            value = tuple(float(v) for v in value)
        elif not isinstance(value, str) or not value:
            raise BadRequest(f"{where}: expected a non-empty string, got {value!r}")
        if self.choices is not None and value not in self.choices:
            raise BadRequest(f"{where}: expected one of {list(self.choices)}, got {value!r}")
        return value


@dataclass(frozen=True, slots=True)
class Strategy:
    """How a task builds its FSMs: ``update`` in upTsk, ``suspension`` in genSusp.

    Each is ``"planned"`` (call a planner on the world as it is) or ``"static"``
    (the task's template ``exeTsk``, Alg. 3, and decision-tree ``exeSusp``, eq. 47); both
    pursue the goal of the decision tree's branch.  ``suspension`` may also be ``"derived"``:
    plan to a goal derived from what the task declares (every hazard it owns off, every
    person it affects in a safe role, its invariants), not from the tree; or ``"fallback"``:
    run the tree's branch where its stages can run in the world as it is, and plan from the
    state as it is to the derived goal where they cannot (a stage inapplicable, the branch out
    of reach, genSusp failing, or a stage of ``exeSusp`` that cannot run when its turn comes).
    ``policy`` is a separate factor applied to all: ``"strict"`` always reaches the safe
    state; ``"conditional"`` also allows the branches a task declares as trading safety for
    time (e.g. leave a device on for a short interruption).  ``tree`` names which of the
    task's decision trees genSusp reads (None: its default tree).
    """

    update: str = "planned"
    suspension: str = "planned"
    policy: str = "strict"
    tree: str | None = None

    def __post_init__(self) -> None:
        if self.update not in UPDATES:
            raise ConfigError(f"Strategy.update must be one of {list(UPDATES)}, got {self.update!r}")
        if self.suspension not in SUSPENSIONS:
            raise ConfigError(f"Strategy.suspension must be one of {list(SUSPENSIONS)}, got {self.suspension!r}")
        if self.policy not in POLICIES:
            raise ConfigError(f"Strategy.policy must be one of {list(POLICIES)}, got {self.policy!r}")
        if self.tree is not None and (not isinstance(self.tree, str) or not self.tree.isidentifier()):
            raise ConfigError(f"Strategy.tree must be a tree's name (an identifier), got {self.tree!r}")


@dataclass(slots=True)
class TaskContext:
    """What a hook may read and write about its agent: the agent's memory ``c_dy``.

    ``world`` is whatever the run's world offers (:meth:`tasker.protocols.World.snapshot`,
    a :class:`~tasker.world.WorldState` for robots in this project, or ``None``
    without a world); ``core`` is the robot's core agent and ``motion`` its
    :class:`~tasker.world.MotionModel`, if any.  ``done``
    lists the stages of ``exeTsk`` completed so far, across suspensions;
    ``interrupted`` is the stage during which the last suspension happened;
    ``suspended`` is true once the task has been suspended (Alg. 3's *suspended*);
    ``stage_started`` is when the running stage of ``exeTsk`` began (None between stages).
    ``handover(after)`` (set by the loop; None without a harmoniser) tells an estimate
    what another task would leave changed before this one could start: with ``after=None``,
    what the executing task's suspension would change if this task replaced it now; with
    an agent's id, what that agent leaves changed when it completes (the start Alg. 2's
    ``cc`` asks about).  None when there is nothing to assume.
    """

    agent: str
    task_type: str
    args: dict[str, Any]
    request_time: float
    rng: random.Random
    strategy: Strategy = field(default_factory=Strategy)
    now: float = 0.0
    world: Any = None
    core: CoreAgent | None = None
    motion: MotionModel | None = None
    memory: AgentMemory = field(default_factory=AgentMemory)
    """The agent's memory: the framework's typed fields (``memory.interruption_s``, :mod:`tasker.memory`)
    and the task type's own keys (``memory["key"]``); a plain ``dict`` given here is wrapped."""
    plan: StagePlan | None = None
    stage_index: int = 0
    done: list[Stage] = field(default_factory=list)
    interrupted: Stage | None = None
    stage_started: float | None = None
    suspended: bool = False
    terminating: bool = False
    recovering: str | None = None
    """In a ``genSusp`` asked again because a stage of ``exeSusp`` could not run (the ``fallback``
    strategy, :meth:`TaskType.recovers_suspension`): why that stage could not run; else None."""
    handover: Callable[[str | None], Effects | None] | None = None
    hazards: Callable[[], Sequence[tuple[str, tuple[str, ...]]]] | None = None
    """The hazards this agent owns that hold now, as ``(hazard name, ground fact)`` (set by the loop
    from the harmoniser's hazard source; None without one): what a derived suspension turns off."""

    def __post_init__(self) -> None:
        if not isinstance(self.memory, AgentMemory):  # a caller's plain dict: the same keys, typed fields empty
            self.memory = AgentMemory(self.memory)

    @property
    def current(self) -> Stage | None:
        """The stage of ``exeTsk`` the agent is at (or would resume), if any."""
        if self.plan is None or self.stage_index >= len(self.plan.stages):
            return None
        return self.plan.stages[self.stage_index]

    @property
    def remaining(self) -> tuple[Stage, ...]:
        """Stages of the current ``exeTsk`` not yet completed (empty before the first upTsk)."""
        if self.plan is None:
            return ()
        return self.plan.stages[self.stage_index :]

    @property
    def age(self) -> float:
        """Seconds since the task was requested."""
        return self.now - self.request_time


class TaskType:
    """Base class of a task type; see the module docstring for the hooks.

    Subclasses set :attr:`name`, :attr:`arg_specs` and :attr:`description`, and
    override hooks (the module docstring says which hook when).  One instance serves
    every agent of the type, so per-agent state belongs in ``ctx.memory``, never on
    ``self``.  :attr:`meaning` declares what the task means for safety and people
    (hazards, roles, physical bindings; see :mod:`tasker.meaning`): the trace and the
    metrics read it, never the task's name.  :attr:`priority` declares how urgent the
    type is against others, for schedulers that rank task types in classes.
    """

    name: str = ""
    description: str = ""
    arg_specs: tuple[ArgSpec, ...] = ()
    meaning: Meaning = NO_MEANING
    priority: int | None = None
    """The type's priority class, higher is more urgent; None: the lowest.  Alg. 2's classes
    come from it when a scenario names none (a task folder declares it as ``[schedule] priority``)."""

    # -- framework-owned ------------------------------------------------------------

    @final
    def validate_args(self, args: Mapping[str, Any]) -> dict[str, Any]:
        """Check a request's arguments; return them completed with defaults.

        Raises :class:`~tasker.errors.BadRequest` naming the argument at fault.  The
        framework's (``typing.final``): add checks in :meth:`check_args` and adjustments in
        :meth:`adjust_args`, which it calls in that order.
        """
        if not isinstance(args, Mapping):
            raise BadRequest(f"task {self.name!r}: arguments must be a mapping, got {type(args).__name__}")
        known = {a.name: a for a in self.arg_specs}
        unknown = sorted(set(args) - set(known))
        if unknown:
            raise BadRequest(
                f"task {self.name!r}: unknown argument(s) {unknown}; expected {sorted(known) or 'none'}"
            )
        out: dict[str, Any] = {}
        for spec in self.arg_specs:
            if spec.name in args and not (args[spec.name] is None and not spec.required):
                out[spec.name] = spec.coerce(self.name, args[spec.name])
            elif spec.required:
                raise BadRequest(f"task {self.name!r}: missing required argument {spec.name!r}")
            else:
                out[spec.name] = spec.default
        self.check_args(out)
        self.adjust_args(args, out)
        return out

    # -- hooks ----------------------------------------------------------------------

    def check_args(self, args: dict[str, Any]) -> None:
        """Override to check what the :class:`ArgSpec` types cannot (e.g. two arguments differ);
        raise :class:`~tasker.errors.BadRequest`.  Called by :meth:`validate_args` with the
        arguments already typed and completed.  Default: nothing more to check."""

    def adjust_args(self, given: Mapping[str, Any], args: dict[str, Any]) -> None:
        """Override to change the completed arguments ``args`` in place where they depend on what the
        request ``given`` held, not only on its values (e.g. leave out an argument's default the
        request did not ask for); raise :class:`~tasker.errors.BadRequest`.  Called by
        :meth:`validate_args` after :meth:`check_args`.  Default: nothing."""

    def initialise(self, ctx: TaskContext) -> None:
        """Override to set up this agent's ``ctx.memory``; called once, in ``initComm``.

        Use it, not ``__init__``, for anything per request: one instance serves every agent.
        Default: nothing."""

    def compute_params(self, ctx: TaskContext) -> ScheduleParams:
        """Override to say how urgent the task is now: its schedule parameters (eq. 19).

        Called in ``compSP`` and ``wait`` at ``repRate`` and in ``exeTsk`` at ``SPupRate``
        (eqs. 22, 24, 27), and when the harmoniser decides from one moment: it may be called more
        than once at the same time, so what it returns should depend on ``ctx`` only.  Default: ``CostParams`` with
        cost = age + cTime, cps = 1, cTime = the expected duration of the stages left."""
        remaining = ctx.remaining if ctx.plan is not None else ()
        c_time = sum(s.duration for s in remaining)
        return CostParams(self.name, cost=ctx.age + c_time, cps=1.0, c_time=c_time)

    def estimate_inputs(self, ctx: TaskContext) -> EstimateInputs | None:
        """Override to say what :meth:`compute_params` and :meth:`check_terminate` read besides the clock.

        Asked after a waiting agent (``compSP``, ``wait``) reported: while the returned key is
        unchanged (and before its ``until``), the agent is not stepped and its cost is aged in
        closed form (:mod:`tasker.inputs`), which requires the model's cost, ``cps * (ctx.age +
        c_time)``.  The key may read ``ctx`` and what the core agent's and the world's ``version``
        counters cover.  Default: None (not said): the agent computes its parameters at every report."""
        return None

    def request_sp(self, ctx: TaskContext, request: SPRequest) -> Any:
        """Override to answer the harmoniser's argument-dependent request ``[spID, args]`` (eqs. 20-23).

        Alg. 2 asks ``cc``: the cost if the task started from ``args["pose"]``.  Default:
        ``cc`` and ``ccps`` from :meth:`compute_params`, whatever the pose."""
        params = self.compute_params(ctx)
        if isinstance(params, CostParams):
            return CompletionCost(cc=params.cost, ccps=params.cps)
        raise NotImplementedError(f"task type {self.name!r} does not answer reqSP {request.sp_id!r}")

    @abstractmethod
    def update_task(self, ctx: TaskContext) -> StagePlan:
        """Override (required: abstract, checked when the type is registered): build ``exeTsk`` from
        the world as it is now; called in ``upTsk``.

        Return the stages still to run (none if the work is done already, R6), or raise
        :class:`~tasker.errors.PlanningFailed`, which ends the task with the reason traced."""
        raise NotImplementedError(f"task type {self.name!r} does not implement update_task")

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:
        """Override when an interruption would leave something unsafe or undone: build ``exeSusp``.

        Called in ``genSusp`` (after ``susp``, a ``term``, the task's own ``ic_term``, a
        failed stage, or to secure a hazard while waiting); ``ctx.interrupted``,
        ``ctx.terminating`` and ``ctx.strategy.policy`` say which.  Default: nothing to do
        (the ``save`` behaviour of eq. 47)."""
        return StagePlan((), Purpose.GEN_SUSP, strategy="static")

    def check_terminate(self, ctx: TaskContext) -> str | None:
        """Override when the task can become pointless on its own: return why (``ic_term``), or None.

        Called in ``compSP`` and ``wait`` at ``repRate`` and during each stage of ``exeTsk``;
        in ``exeTsk`` the task then suspends safely before it ends.  Default: never."""
        return None

    def inapplicable(self, ctx: TaskContext, stage: Stage) -> str | None:
        """Why ``stage`` cannot run in the world as it is now (``ctx.world``), or None if it can.

        Asked before every stage begins, static and planned alike, as a robot would find out:
        a stage whose action's precondition does not hold fails without running (its reason
        starts with :data:`tasker.trace.INAPPLICABLE`) and applies no effect.  Override it for
        a task type that knows its actions' preconditions (a PDDL task folder does); the
        default knows none."""
        return None

    def already_done(self, ctx: TaskContext, stage: Stage) -> str | None:
        """Why ``stage`` need not run: its effects already hold in the world as it is (a door someone
        else closed, a device someone else switched off), or None.

        Asked only for a stage that cannot run (:meth:`inapplicable` gave a reason): such a stage is
        traced ``already_done`` and skipped, never a failure.  Override it with
        :meth:`inapplicable` (a PDDL task folder does, from its actions' effects); the default
        knows no effects."""
        return None

    def tree_names(self) -> tuple[str, ...]:
        """The names of the decision trees genSusp may read (:attr:`Strategy.tree`); empty when the
        task type has no tree to choose.  A task folder's: ``default`` and its ``[[trees.NAME]]``."""
        return ()

    def recovers_suspension(self, ctx: TaskContext) -> bool:
        """Whether a stage of ``exeSusp`` that cannot run is planned around — ``genSusp`` again,
        from the world as it is, with :attr:`TaskContext.recovering` saying why — rather than
        ending the task.  Asked once per suspension.  Default: under the ``fallback``
        suspension strategy."""
        return ctx.strategy.suspension == "fallback"

    def on_stage_done(self, ctx: TaskContext, stage: Stage) -> None:
        """Override to note progress in ``ctx.memory``; called after each stage of ``exeTsk`` or
        ``exeSusp`` completes.  Default: nothing."""

    def leaves(self, ctx: TaskContext, how: Leaving) -> Effects | None:
        """Override when what this task changes matters to the next task's estimates: what it would
        leave changed if left now (``suspend``: its genSusp would run; ``complete``: it runs to
        its end).  Called for another agent's estimate (:attr:`TaskContext.handover`).
        Default: nothing for a suspension (the ``save`` behaviour); for a completion, the
        ``add``/``delete`` data of the stages of ``exeTsk`` still to run."""
        if how == "complete":
            return Effects.of(ctx.remaining) or None
        return None


REQUIRED_HOOKS = ("update_task",)
"""The hooks every task type must implement (abstract in :class:`TaskType`)."""


def missing_hooks(task: TaskType) -> list[str]:
    """The required hooks (:data:`REQUIRED_HOOKS`) ``task``'s class leaves abstract: what registration refuses."""
    return [h for h in REQUIRED_HOOKS if getattr(getattr(type(task), h, None), "__isabstractmethod__", False)]


def adjust_inner(inner: TaskType, own: frozenset[str], given: Mapping[str, Any], args: dict[str, Any]) -> None:
    """:meth:`TaskType.adjust_args` of a type that wraps ``inner`` and adds the arguments ``own``:
    ``inner`` adjusts its arguments, the wrapper's own follow them in ``args`` (the order a trace
    records them in)."""
    mine = {k: v for k, v in args.items() if k in own}
    theirs = {k: v for k, v in args.items() if k not in own}
    inner.adjust_args({k: v for k, v in given.items() if k not in own}, theirs)
    args.clear()
    args.update(theirs)
    args.update(mine)
