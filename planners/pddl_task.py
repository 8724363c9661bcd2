"""A :class:`~tasker.task.TaskType` built from a task folder (``domain.pddl`` + ``task.toml``).

Hooks, and what they do here:

* ``update_task`` (upTsk) — ``planned``: a PDDL problem from ``ctx.world`` as it is now
  (R6: what the robot or a person already did is not redone), solved optimally;
  ``static``: the template ``exeTsk`` of ``[static] update`` (Alg. 3).
* ``generate_suspension`` (genSusp) — one decision list ``[[suspension]]`` (eq. 47) for
  the tree's two strategies: the first branch whose ``when`` holds in the state at
  interruption (see :meth:`PddlTaskType.branch`) gives the suspension goal; ``planned``
  plans to it from that state, ``static`` runs the branch's ``stages`` (checked at load to
  reach the same goal).  ``derived`` plans to a goal the folder's declarations give instead
  of the tree's (:meth:`PddlTaskType.derived_goal`): every hazard the task owns off, its
  person in a ``safe`` role of ``[people]``, its ``[derived] invariants``.  The method
  (plan or run the stages) and the goal's source (tree or declarations) are separate
  factors; ``ctx.strategy.policy`` decides, for all three alike, whether safety may be
  traded for time (a ``conditional`` branch; a hazard whose budget covers the expected
  interruption).
* ``compute_params`` / ``request_sp`` — ``cost = cps * (age + cTime)``: the discomfort
  accumulated by completion, with ``cTime`` and ``endPose`` from the plan upTsk would make
  from the state asked about (:mod:`planners.estimates`), timed with ``ctx.motion``;
  unreachable or unsolvable means ``inf``.  A request with ``cost_model = "taskER-2019"``
  (offered by a folder with ``[schedule.taskER-2019]``) gets the original TaskER code's
  parameters instead: path metres weighted per person (:meth:`PddlTaskType.original_params`,
  ``docs/model.md``).

An unsolvable task raises :class:`~tasker.errors.PlanningFailed`; an unsolvable
suspension or a planner time-out falls back to the static strategy, said in the note.
``sim_time`` is the declared ``planning_time_s``/``static_time_s``: never wall time.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import traceback
from collections.abc import Callable, Iterator, Mapping
from contextvars import ContextVar
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from planners import derived, fallback, original_costs, stagecheck
from planners.checks import DefinitionError
from planners.estimates import estimator_for, executing, forget_estimates
from planners.planner import PddlText, Planner
from planners.problem import (
    PLACE_TYPE,
    DomainModel,
    PortablePddl,
    holds,
    portable,
    render_problem,
    travel_table,
)
from planners.results import PlanResult, PlanStatus
from planners.stages import Bindings, StageBuilder, place_of, robot_name
from planners.taskspec import COST_MODEL_ARG, ORIGINAL, Branch, Literal, TaskSpec
from tasker.errors import BadRequest, PlanningFailed, UnknownName
from tasker.meaning import Hazard, bind, matches
from tasker.memory import INTERRUPTION_KEY as INTERRUPTION_KEY  # the old key, for code that imports it here
from tasker.messages import SP_COMPLETION, CompletionCost, CostParams, SPRequest
from tasker.stage import Purpose, Stage, StagePlan
from tasker.task import Effects, Leaving, TaskContext, TaskType
from tasker.world import Pose, WorldState

PLANNING = ("planned", "derived")
"""The suspension strategies whose genSusp always plans (a suspension may be planned ahead for them)."""
PLANS_REMEMBERED = 8
"""How many plans ``ctx.memory.planned_from`` (:mod:`planners.stagecheck`) keeps per agent."""

_shared_planner: Planner | None = None


@dataclass(frozen=True, slots=True)
class PlanningRecord:
    """One planned upTsk/genSusp of a run: the PDDL it planned from (renamed so that any reader
    takes it, :func:`planners.problem.portable`), and how it ended.  ``status`` is a
    :class:`PlanStatus` value or ``"holds"`` (the goal held: nothing was planned); ``plan``
    is in the task's own names."""

    t: float
    agent: str
    task_type: str
    purpose: str
    label: str
    pddl: PortablePddl
    status: str
    plan: tuple[tuple[str, ...], ...] | None = None
    cost: float | None = None
    message: str = ""


_journal: ContextVar[list[PlanningRecord] | None] = ContextVar("tasker_planning_journal", default=None)


@contextlib.contextmanager
def planning_journal() -> Iterator[list[PlanningRecord]]:
    """Record every planned upTsk/genSusp made inside the block (this thread/context only);
    the PDDL stays out of the trace: the runner writes it to the run's ``problems/``."""
    records: list[PlanningRecord] = []
    token = _journal.set(records)
    try:
        yield records
    finally:
        _journal.reset(token)


def forget_caches() -> None:
    """Forget what planning remembered in this process — the shared planner's answers, every task type's
    estimates and rendered problems — so the next run plans as a first run does (cold caches: how
    ``tasker results`` measures genSusp's wall time).  Answers are exact, so runs are unchanged."""
    if _shared_planner is not None:
        _shared_planner.clear_cache()
    forget_estimates()


def default_planner() -> Planner:
    """The planner task types share (so they share its cache)."""
    global _shared_planner
    if _shared_planner is None:
        _shared_planner = Planner()
    return _shared_planner


def _goal_of(purpose: Purpose, goal: list[Literal]) -> tuple[Literal, ...] | None:
    """What a plan for ``purpose`` says it aims for: genSusp's goal (judged when the suspension ends)."""
    return tuple(goal) if purpose is Purpose.GEN_SUSP else None


def hook_line(exc: BaseException, path: Path) -> int | None:
    """The line of ``path`` (a folder's ``task.py``) where ``exc`` was raised, if it was there."""
    where = path.resolve()
    return next((f.lineno for f in reversed(traceback.extract_tb(exc.__traceback__))
                 if Path(f.filename).resolve() == where), None)


class PddlTaskType(TaskType):
    """A task type defined by a folder; one instance serves every agent of the type."""

    def __init__(self, spec: TaskSpec, domain: DomainModel, hooks: dict[str, Callable[..., Any]] | None = None,
                 planner: Planner | None = None, timeout: float | None = None) -> None:
        self.name = spec.name
        self.description = spec.description
        self.arg_specs = spec.args
        self.spec = spec
        self.domain = domain
        self.hooks = hooks or {}
        self.builder = StageBuilder(spec, domain)
        self._planner = planner
        self.timeout = spec.timeout_s if timeout is None else timeout

    @property
    def planner(self) -> Planner:
        return self._planner or default_planner()

    # -- hooks ----------------------------------------------------------------------

    def adjust_args(self, given: Mapping[str, Any], args: dict[str, Any]) -> None:
        """The cost model's arguments stay out of a request that does not give them (it gets the
        default model, and its trace says what was asked), and the original model needs its factors."""
        out = args
        model = self.spec.original_costs
        if model is None:
            return
        for name in model.args:
            if given.get(name) is None:
                out.pop(name, None)
        if out.get(COST_MODEL_ARG) == ORIGINAL:
            missing = [f[1:] for f in model.factors or () if f[1:] not in out]
            if missing:
                raise BadRequest(f"task {self.name!r}: {COST_MODEL_ARG} = {ORIGINAL!r} needs the argument(s) "
                                 f"{missing} (cost per metre; docs/model.md)")
        elif any(f[1:] in out for f in model.factors or ()):
            raise BadRequest(f"task {self.name!r}: the factors {[f[1:] for f in model.factors or ()]} apply only with "
                             f"{COST_MODEL_ARG} = {ORIGINAL!r}")

    def check_args(self, args: dict[str, Any]) -> None:
        if "check_args" in self.hooks:
            try:
                self.hooks["check_args"](args)
            except BadRequest:
                raise
            except Exception as exc:  # noqa: BLE001 - the folder's code: say whose it is, not "internal error"
                path = self.spec.folder / "task.py"
                raise DefinitionError(path, f"check_args raised {type(exc).__name__}: {exc} (refuse a request "
                                            "with tasker.errors.BadRequest)", hook_line(exc, path)) from None

    def tree_names(self) -> tuple[str, ...]:
        """``default`` (``[[suspension]]``) and the names of the folder's ``[[trees.NAME]]``."""
        return self.spec.tree_names

    def check_terminate(self, ctx: TaskContext) -> str | None:
        """``ic_term``: the folder's ``task.py`` may say the task is no longer needed."""
        hook = self.hooks.get("check_terminate")
        if hook is None or ctx.world is None:
            return None
        why = hook(ctx, ctx.world)
        return str(why) if why else None

    def update_task(self, ctx: TaskContext) -> StagePlan:
        return self._planned_from(ctx, self._update_task(ctx))

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:
        return self._planned_from(ctx, self._generate_suspension(ctx))

    def _planned_from(self, ctx: TaskContext, plan: StagePlan) -> StagePlan:
        """Remember the state ``plan`` was made from (``ctx.memory``, the last few plans: an estimate may
        plan a suspension on a copy of the context meanwhile), for :meth:`inapplicable`."""
        if isinstance(ctx.world, WorldState) and plan.stages:
            made = ctx.memory.planned_from
            if made is None:
                made = ctx.memory.planned_from = []
            made.append((plan.stages, ctx.world.facts))
            del made[:-PLANS_REMEMBERED]
        return plan

    def _update_task(self, ctx: TaskContext) -> StagePlan:
        if ctx.strategy.update == "static":
            return self.static_update(ctx)
        world, goal, extra = self.update_inputs(ctx)
        outcome = self._plan(ctx, world, goal, extra, Purpose.UP_TSK)
        if isinstance(outcome, StagePlan):
            return outcome
        if outcome.status is PlanStatus.UNSOLVABLE:
            try:  # a hint only: whatever it meets, the task ends 'unsolvable' as the planner said
                hint = self._unreachable(ctx, world, goal)
            except Exception:  # noqa: BLE001
                hint = ""
            raise PlanningFailed("unsolvable", f"{self.name}: no plan reaches the goal {goal} from the world now"
                                               + hint)
        if outcome.status is PlanStatus.TIMEOUT:
            return self._fallback(self.static_update(ctx), "planner timed out for upTsk")
        raise PlanningFailed("error", f"{self.name}: planner error: {outcome.message}")

    def _generate_suspension(self, ctx: TaskContext) -> StagePlan:
        if ctx.strategy.suspension == "static":
            return self.static_suspension(ctx)
        if ctx.strategy.suspension == "fallback":
            return fallback.suspension(self, ctx)
        world, goal, branch = self.suspension_inputs(ctx)  # the tree's branch, or the derived goal
        extra = self.suspension_facts(ctx, world)
        ready = self._preplanned(ctx, world, goal, extra, branch.label)
        if ready is not None:
            return ready
        outcome = self._plan(ctx, world, goal, extra, Purpose.GEN_SUSP, label=branch.label)
        if isinstance(outcome, StagePlan):
            return outcome
        why = {PlanStatus.UNSOLVABLE: "suspension goal unsolvable", PlanStatus.TIMEOUT: "planner timed out"}
        return self._fallback(self.static_suspension(ctx),
                              f"{why.get(outcome.status, 'planner error')} for {goal}")

    def inapplicable(self, ctx: TaskContext, stage: Stage) -> str | None:
        """Why ``stage`` cannot run now, or None (:func:`planners.stagecheck.inapplicable`)."""
        return stagecheck.inapplicable(self, ctx, stage)

    def already_done(self, ctx: TaskContext, stage: Stage) -> str | None:
        """Why ``stage`` need not run, its effects holding already (:func:`planners.stagecheck.already_done`)."""
        return stagecheck.already_done(self, ctx, stage)

    def compute_params(self, ctx: TaskContext) -> CostParams:
        """``cost = cps * (age + cTime)``; cTime and endPose from :meth:`estimate` of the state now.

        While a stage of ``exeTsk`` runs under the planned suspension strategy, the
        suspension of the state now is planned here too (:meth:`_preplan_suspension`)."""
        if executing(ctx) and ctx.strategy.suspension in PLANNING and isinstance(ctx.world, WorldState):
            self._preplan_suspension(ctx)
        if self._original(ctx):
            return self.original_params(ctx)
        c_time, end = self.estimate(ctx, None)
        cost = self.spec.cps * (ctx.age + c_time) if math.isfinite(c_time) else math.inf
        return CostParams(self.name, cost=cost, cps=self.spec.cps, c_time=c_time, end_pose=end)

    def request_sp(self, ctx: TaskContext, request: SPRequest) -> CompletionCost:
        """Alg. 2's ``cc``: :meth:`estimate` with the robot moved to the request's start pose."""
        if request.sp_id != SP_COMPLETION:
            raise UnknownName("schedule parameter", request.sp_id, [SP_COMPLETION])
        pose = next((request.args[k] for k in ("pose", "start_pose", "end_pose") if request.args.get(k)), None)
        start = (float(pose[0]), float(pose[1]), float(pose[2]) if len(pose) > 2 else 0.0) if pose else None
        if self._original(ctx):
            return self.original_completion(ctx, start)
        after = request.args.get("after")
        c_time, _ = self.estimate(ctx, start, after=str(after) if after is not None else None)
        cc = self.spec.cps * (ctx.age + c_time) if math.isfinite(c_time) else math.inf
        return CompletionCost(cc=cc, ccps=self.spec.cps, c_time=c_time)

    # -- the original TaskER cost model (2019) --------------------------------------------

    def _original(self, ctx: TaskContext) -> bool:
        return self.spec.original_costs is not None and ctx.args.get(COST_MODEL_ARG) == ORIGINAL

    def original_params(self, ctx: TaskContext) -> CostParams:
        """The 2019 code's ``getSP()`` (:func:`planners.original_costs.params`)."""
        return original_costs.params(self, ctx)

    def original_completion(self, ctx: TaskContext, start: Pose | None) -> CompletionCost:
        """The 2019 code's cost and suspend conditions (:func:`planners.original_costs.completion`)."""
        return original_costs.completion(self, ctx, start)

    # -- planning inputs (public for tests and tools) -----------------------------------

    def update_inputs(self, ctx: TaskContext) -> tuple[WorldState, list[Literal], list[Literal]]:
        """upTsk: the world, the goal (with what ``[problem] restore`` asks back) and the extra init
        facts (request, Alg. 3, task.py)."""
        world = self.world_of(ctx)
        b = Bindings(ctx.args, world)
        extra = b.literals(self.spec.facts) + (b.literals(self.spec.suspended_facts) if ctx.suspended else [])
        goal = b.literals(self.spec.goal)
        goal += [lit for lit in self.restored(ctx, world) if lit not in goal]
        return world, goal, extra + self.hook_facts(ctx, world)

    def restored(self, ctx: TaskContext, world: WorldState) -> list[Literal]:
        """``[problem] restore``: ``("not", fact)`` for every ground instance of a pattern (over the
        world's objects of the predicate's types) that did not hold when this task first planned
        (remembered in ``ctx.memory``), so it leaves them as it found them."""
        if not self.spec.restore:
            return []
        robot = robot_name(world)
        patterns = [p for pat in self.spec.restore if (p := bind(pat, ctx.args, robot)) is not None]
        baseline = ctx.memory.restore_baseline
        if baseline is None:
            baseline = ctx.memory.restore_baseline = frozenset(f for p in patterns for f in matches(p, world.facts))
        out: list[Literal] = []
        for pat in patterns:
            signature = self.domain.predicates.get(pat[0], ())
            choices = []
            for tok, typ in zip(pat[1:], signature, strict=False):
                if tok.startswith("?"):
                    choices.append(sorted(n for n, t in world.objects.items() if self.domain.has_type(t, typ)))
                else:
                    choices.append([tok])
            for inst in itertools.product(*choices):
                fact = (pat[0], *inst)
                if fact not in baseline and ("not", *fact) not in out:
                    out.append(("not", *fact))
        return out

    def suspension_inputs(self, ctx: TaskContext) -> tuple[WorldState, list[Literal], Branch]:
        """genSusp: the world at interruption, the suspension goal and the branch that chose it
        (for ``derived``, a branch made of the derived goal and its label, with no stages)."""
        world = self.world_of(ctx)
        if ctx.strategy.suspension == "derived":
            goal, label = self.derived_goal(ctx, world)
            return world, goal, Branch(goal=tuple(goal), label=label)
        branch, b = self.branch(ctx, world)
        return world, b.literals(branch.goal), branch

    def owned_hazards(self, ctx: TaskContext, world: WorldState) -> list[tuple[Hazard, Literal]]:
        """The declared hazards that hold now and are this task's (:func:`planners.derived.owned_hazards`)."""
        return derived.owned_hazards(self, ctx, world)

    def plan_suspension_to(self, ctx: TaskContext, world: WorldState, goal: list[Literal],
                           label: str) -> StagePlan | PlanResult:
        """genSusp planned from ``world`` to ``goal`` (with the suspension's extra facts), or the failed result."""
        return self._plan(ctx, world, goal, self.suspension_facts(ctx, world), Purpose.GEN_SUSP, label=label)

    def derived_goal(self, ctx: TaskContext, world: WorldState) -> tuple[list[Literal], str]:
        """The ``derived`` suspension goal and a label saying what it asks for (:func:`planners.derived.goal`)."""
        return derived.goal(self, ctx, world)


    def suspension_facts(self, ctx: TaskContext, world: WorldState) -> list[Literal]:
        """genSusp's extra init facts: the request's and ``task.py``'s (e.g. carry_object's
        door-free passages), as for upTsk, but not Alg. 3's ``suspended_facts``."""
        b = Bindings(ctx.args, world)
        return b.literals(self.spec.facts) + self.hook_facts(ctx, world)

    def hook_facts(self, ctx: TaskContext, world: WorldState) -> list[Literal]:
        """``task.py``'s ``extra_facts``: ground facts as tuples of strings, checked (a string
        would become a tuple of letters, a fact nobody declares, silently left out)."""
        if "extra_facts" not in self.hooks:
            return []
        out = []
        for f in self.hooks["extra_facts"](ctx, world):
            if not isinstance(f, tuple | list) or not f or not all(isinstance(x, str) and x for x in f):
                raise DefinitionError(self.spec.folder / "task.py", f"extra_facts gave {f!r}; expected facts as "
                                                                    "tuples of strings such as ('at', 'robot', 'hall')")
            out.append(tuple(f))
        return out

    def planning_problem(self, ctx: TaskContext, purpose: Purpose) -> PddlText:
        """The PDDL problem the planned strategy solves for ``purpose`` in this context."""
        if purpose is Purpose.UP_TSK:
            world, goal, extra = self.update_inputs(ctx)
        else:
            world, goal, _ = self.suspension_inputs(ctx)
            extra = self.suspension_facts(ctx, world)
        return self.problem_text(ctx, world, goal, extra)[0]

    # -- strategies -------------------------------------------------------------------

    def static_update(self, ctx: TaskContext) -> StagePlan:
        """The template ``exeTsk`` (Alg. 3): fixed stages, variants chosen by ``ctx.suspended``."""
        world = self.world_of(ctx)
        travel = travel_table(world, ctx.motion, self.spec.travel_s, opens_doors=self.domain.opens_doors)
        stages = self._template_stages(ctx, world, travel)
        return StagePlan(stages, Purpose.UP_TSK, strategy="static", sim_time=self.spec.static_time_s,
                         note="template exeTsk" + (" (suspended variant)" if ctx.suspended else ""))

    def _template_stages(self, ctx: TaskContext, world: WorldState,
                         travel: dict[tuple[str, str], float]) -> tuple[Stage, ...]:
        return self.builder.from_templates(self.spec.static_update, Bindings(ctx.args, world), travel, ctx.suspended)

    def static_suspension(self, ctx: TaskContext) -> StagePlan:
        """The decision list ``exeSusp`` (eq. 47): the first branch whose condition holds."""
        world = self.world_of(ctx)
        branch, b = self.branch(ctx, world)
        travel = travel_table(world, ctx.motion, self.spec.travel_s, opens_doors=self.domain.opens_doors)
        stages = self.builder.from_templates(branch.stages, b, travel, ctx.suspended)
        return StagePlan(stages, Purpose.GEN_SUSP, strategy="static", sim_time=self.spec.static_time_s,
                         note=f"decision tree: {branch.label or ('save' if not stages else 'branch')}",
                         goal=tuple(b.literals(branch.goal)))

    # -- helpers ----------------------------------------------------------------------

    def _unreachable(self, ctx: TaskContext, world: WorldState, goal: list[Literal]) -> str:
        """Why a goal may be unsolvable, for the failure's reason: the places it names, and the places of
        the things it names, that the robot cannot drive to from where it is (walled off, behind a
        closed door), or ``""``."""
        robot = robot_name(world)
        here = place_of(world, robot)
        if here is None:
            return ""
        travel = travel_table(world, ctx.motion, self.spec.travel_s, opens_doors=self.domain.opens_doors)
        named = {a for lit in goal for a in lit[1:]}
        places = {a for a in named if world.objects.get(a) == PLACE_TYPE}
        places |= {p for a in named - places - {robot} if (p := place_of(world, a)) is not None}
        cut = [p for p in sorted(places) if p != here and not math.isfinite(travel.get((here, p), math.inf))]
        if not cut:
            return ""
        return (f"; the robot cannot drive from {here!r} to {', '.join(map(repr, cut))} "
                "(walled off, or behind a closed door)")

    def world_of(self, ctx: TaskContext) -> WorldState:
        if not isinstance(ctx.world, WorldState):
            raise PlanningFailed("error", f"{self.name}: needs a WorldState, got {type(ctx.world).__name__}")
        return ctx.world

    def branch(self, ctx: TaskContext, world: WorldState) -> tuple[Branch, Bindings]:
        """The suspension branch both strategies pursue (eq. 47), with ``when``'s ``?vars`` bound.

        The first branch whose ``when`` holds in the world at interruption; a
        ``conditional`` branch only under ``ctx.strategy.policy == "conditional"`` and
        when the expected interruption (``ctx.memory.interruption_s``; unknown = long)
        is at most its ``max_interruption_s``."""
        expected = ctx.memory.interruption_s
        length = math.inf if expected is None else expected
        base = Bindings(ctx.args, world)
        tree = self.spec.tree(ctx.strategy.tree)
        for br in tree:
            if br.policy == "conditional" and (ctx.strategy.policy != "conditional"
                                               or br.max_interruption_s is None or length > br.max_interruption_s):
                continue
            bound = base.match(br.when, world.facts)
            if bound is not None:
                return br, bound
        return tree[-1], base

    def problem_text(self, ctx: TaskContext, world: WorldState, goal: list[Literal],
                     extra: list[Literal]) -> tuple[PddlText, frozenset[Literal], dict[tuple[str, str], float]]:
        """The PDDL text, its init facts and the travel table for a goal in a world."""
        travel = travel_table(world, ctx.motion, self.spec.travel_s, opens_doors=self.domain.opens_doors)
        for lit in goal:
            self.domain.check_literal(lit, f"goal of task {self.name!r}")
        text, init = render_problem(self.domain, world, goal, extra_facts=extra, travel=travel, name=self.name)
        return PddlText(self.domain.checked.text, text), init, travel

    def _plan(self, ctx: TaskContext, world: WorldState, goal: list[tuple[str, ...]],
              extra: list[tuple[str, ...]], purpose: Purpose, label: str = "") -> StagePlan | PlanResult:
        """A planned StagePlan, or the failed PlanResult for the caller to handle."""
        text, init, travel = self.problem_text(ctx, world, goal, extra)
        if holds(init, goal):
            return self._holds(ctx, purpose, label, text, goal)
        result = self.planner.solve(text, timeout=self.timeout)
        self._record(ctx, purpose, label, text, result)
        if not result.solved:
            return result
        assert result.plan is not None
        stages = self.builder.from_steps(result.plan, travel, ctx.args)
        return StagePlan(stages, purpose, strategy="planned", sim_time=self.spec.planning_time_s,
                         note=label or None,
                         info={**result.trace_info(), "cached": result.cached,
                               "planner_time_s": result.wall_time_s}, goal=_goal_of(purpose, goal))

    # -- a suspension planned ahead --------------------------------------------------------

    @staticmethod
    def _suspension_key(world: WorldState, goal: list[Literal], extra: list[Literal], label: str) -> tuple[Any, ...]:
        """The symbolic suspension problem: a plan for it is valid whatever the travel times."""
        return (world.facts, frozenset(extra), tuple(goal), label)

    def _preplan_suspension(self, ctx: TaskContext) -> None:
        """Plan the suspension of the state now, while ``exeTsk`` runs, once per symbolic state
        (``ctx.memory.suspension_ahead``): a ``susp`` that arrives in the same state then finds its
        plan made and takes the static strategy's ``static_time_s``, not ``planning_time_s``.
        During a blocking stage, the state planned for is the one that stage leaves (its
        ``add``/``delete``): a ``susp`` is honoured only when it ends.
        Planned as the estimates plan (:meth:`Estimator.plan <planners.estimates.Estimator.plan>`:
        travel times with nobody in the way, a cache shared with the other agents' estimates
        of this task's suspension); journalled only if genSusp uses it (:meth:`_preplanned`)."""
        cur = ctx.current
        if cur is not None and cur.blocking and isinstance(ctx.world, WorldState):
            # a susp now is honoured only when this stage ends (eq. 25): plan for what it leaves
            ctx = replace(ctx, world=ctx.world.updated(add=[tuple(f) for f in cur.data.get("add", ())],
                                                       delete=[tuple(f) for f in cur.data.get("delete", ())]))
        world, goal, branch = self.suspension_inputs(ctx)
        extra = self.suspension_facts(ctx, world)
        key = self._suspension_key(world, goal, extra, branch.label)
        held = ctx.memory.suspension_ahead
        if held is not None and held[0] == key:
            return
        steps, status, _ = estimator_for(self).plan(ctx, world, goal, extra)
        ctx.memory.suspension_ahead = (key, steps) if status is PlanStatus.SOLVED else None

    def _preplanned(self, ctx: TaskContext, world: WorldState, goal: list[Literal], extra: list[Literal],
                    label: str) -> StagePlan | None:
        """genSusp's plan if it was made already for this very symbolic state — by
        :meth:`_preplan_suspension`, or by an estimate of this suspension for another agent
        (:meth:`leaves`, the handover) — re-timed with the travel times of the moment."""
        held = ctx.memory.suspension_ahead
        if held is not None and held[0] == self._suspension_key(world, goal, extra, label):
            steps: tuple[tuple[str, ...], ...] = held[1]
        else:  # planned already for another agent's estimate of this very suspension (handover)?
            steps, status, _ = estimator_for(self).plan(ctx, world, goal, extra, solve=False)
            if status is not PlanStatus.SOLVED:
                return None
        text, init, travel = self.problem_text(ctx, world, goal, extra)
        if not steps:  # the goal held in this very state
            return self._holds(ctx, Purpose.GEN_SUSP, label, text, goal)
        journal = _journal.get()
        if journal is not None:
            journal.append(PlanningRecord(
                ctx.now, ctx.agent, self.name, Purpose.GEN_SUSP.value, label,
                portable(self.domain, text.domain, text.problem), PlanStatus.SOLVED.value, steps, None,
                "planned ahead"))
        stages = self.builder.from_steps(steps, travel, ctx.args)
        return StagePlan(stages, Purpose.GEN_SUSP, strategy="planned", sim_time=self.spec.static_time_s,
                         note=(label + "; " if label else "") + "planned ahead",
                         info={"planner": self.planner.name, "planned_ahead": True}, goal=tuple(goal))

    def _holds(self, ctx: TaskContext, purpose: Purpose, label: str, text: PddlText,
               goal: list[Literal]) -> StagePlan:
        """The plan when the goal already holds: nothing to do, journalled as such."""
        self._record(ctx, purpose, label, text, None)
        note = "goal already holds" + (f" ({label})" if label else "")
        return StagePlan((), purpose, strategy="planned", sim_time=self.spec.static_time_s, note=note,
                         goal=_goal_of(purpose, goal))

    def _record(self, ctx: TaskContext, purpose: Purpose, label: str, text: PddlText,
                result: PlanResult | None) -> None:
        journal = _journal.get()
        if journal is not None:
            journal.append(PlanningRecord(
                ctx.now, ctx.agent, self.name, purpose.value, label, portable(self.domain, text.domain, text.problem),
                result.status.value if result else "holds", result.plan if result else (),
                result.cost if result else 0.0, result.message if result else "goal already holds"))

    @staticmethod
    def _fallback(plan: StagePlan, why: str) -> StagePlan:
        return StagePlan(plan.stages, plan.purpose, strategy="static", sim_time=plan.sim_time,
                         note=f"fallback to static: {why}", info=plan.info, goal=plan.goal)

    def estimate(self, ctx: TaskContext, start: Pose | None, after: str | None = None) -> tuple[float, Pose | None]:
        """Seconds to complete the task from ``start`` (the robot's pose if None) and the end pose.

        From a plan of the state asked about (:mod:`planners.estimates`), never from the
        stale remainder of a plan made before a suspension; ``inf`` when it cannot be done.
        ``after``: the agent whose completion the start follows (None: it would start now).
        """
        est = estimator_for(self).estimate(ctx, start, after)
        return est.c_time, est.end_pose

    def leaves(self, ctx: TaskContext, how: Leaving) -> Effects | None:
        """What the task would leave changed: for ``suspend``, the effects of the suspension
        genSusp would make now (planned or the decision list, as the strategy says); for
        ``complete``, those of the stages of ``exeTsk`` still to run."""
        if how == "suspend":
            if not isinstance(ctx.world, WorldState):
                return None
            return Effects.of(estimator_for(self).suspension_stages(replace(ctx, suspended=True))) or None
        return super().leaves(ctx, how)
