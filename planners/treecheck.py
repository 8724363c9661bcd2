"""``tasker check`` reads a suspension tree as a planner would: per branch, at the ``[example]``'s states.

Two things are reported (``docs/domains.md``, "What `tasker check` says about a tree"):

* **conditions the tree can never see** (:func:`unseen_conditions`).  The tree is read
  against the world's facts (:meth:`PddlTaskType.branch <planners.pddl_task.PddlTaskType.branch>`
  matches ``when`` on ``ctx.world.facts``), and the world holds only what a world file or
  scenario states, what its ``[[bindings]]`` read off physics, ``at`` from poses, and the
  unconditional effects of the stages that ran.  A ``when`` literal whose predicate only
  ``task.py``'s ``extra_facts``, the request's ``[problem] facts``, Alg. 3's
  ``suspended_facts`` or the problem builder (``connected``) makes — or nothing — can never
  hold (never fail, negated): the planner's problem gets those facts, the tree does not.
* **completeness per branch** (:func:`report`).  The ``[example]``'s ``exeTsk`` (planned,
  and the ``[static] update`` template) is walked stage by stage; at the state before each
  stage — where an interruption meets the task — the branch the tree chooses there
  (first match, as at run time) is run stage by stage with the project's own stage
  machinery (each stage checked like a robot's, :mod:`planners.stagecheck`; its grounded
  effects applied as the executor applies them).  The branch is *complete* there when every
  stage ran, its goal holds, and no declared hazard the task owns
  (:func:`planners.derived.owned_hazards`, the judge's rule) is left on.  Under the
  ``conditional`` policy, a conditional branch is run with the longest interruption it
  accepts, and a hazard whose ``budget_s`` covers it may stay on.

Every tree of the folder is read (``[[suspension]]`` and each ``[[trees.NAME]]``: one report a tree).
Where a branch is not complete, or a condition can never be seen, :meth:`TreeReport.warn`
gives an :class:`~tasker.support.reader.InputWarning` at the branch's line of ``task.toml``,
naming the branch, the state, the hazard or the fact: a warning, not an error (the run is
valid; ``derived`` and ``planned`` may still make it safe).
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from planners import derived
from planners.examplecheck import _apply as apply_stage  # the example world after a stage, as its check walks it
from planners.examplecheck import example_stages
from planners.examples import example_context
from planners.problem import CONNECTED
from planners.problem import holds as holds_all
from planners.stagecheck import LOCATION
from planners.taskspec import DEFAULT_TREE, Branch, Literal
from tasker.errors import PlanningFailed
from tasker.memory import AgentMemory
from tasker.stage import Stage
from tasker.task import POLICIES, Strategy, TaskContext
from tasker.world import Fact, WorldState

if TYPE_CHECKING:
    from planners.pddl_task import PddlTaskType

EXES = ("planned", "template")
"""The ``exeTsk`` walked: the example's plan, then ``[static] update`` (states it adds)."""


class Maker(enum.Enum):
    """What makes the facts of a ``when`` literal the tree can never see."""

    TASK_PY = "only task.py's extra_facts makes it"
    REQUEST = "only the request's [problem] facts (or Alg. 3's suspended_facts) make it"
    PLANNER = "only the problem builder makes it (for the planner, from the motion model)"
    NOTHING = ("nothing makes it: no action of this domain (nor of a task type checked with it) adds it, no "
               "[[bindings]] entry reads it off the world, and neither the [example] nor a known world or scenario "
               "holds it")


@dataclass(frozen=True, slots=True)
class UnseenCondition:
    """A ``when`` literal of branch ``branch`` over a predicate the world never holds (module docstring)."""

    branch: int
    label: str
    literal: Literal
    maker: Maker
    seen: Fact | None = None
    """A fact ``task.py`` made on the ``[example]`` (for the message), if any."""

    def __post_init__(self) -> None:
        if self.branch < 0:
            raise ValueError(f"UnseenCondition.branch is an index of [[suspension]], got {self.branch}")
        if not self.literal or self.literal[0] == "not" and len(self.literal) < 2:
            raise ValueError(f"UnseenCondition.literal must be a literal, got {list(self.literal)}")

    @property
    def negated(self) -> bool:
        return self.literal[0] == "not"

    def message(self) -> str:
        atom = self.literal[1:] if self.negated else self.literal
        example = f" (e.g. ({' '.join(self.seen)}) on the [example])" if self.seen else ""
        effect = (f"so {list(self.literal)} always holds there and tells no state apart" if self.negated else
                  f"so this `when` never matches and branch {self.label!r} is never chosen")
        return (f"branch {self.label!r}: `when` {list(self.literal)} names a fact the world never has: "
                f"{self.maker.value}{example}; the tree is read against the world's facts at interruption "
                f"(PddlTaskType.branch), which never hold {atom[0]!r}, {effect} (state the condition with facts the "
                "world holds, as the [example] and the [[bindings]] give them, or let planned/derived plan round it)")


@dataclass(frozen=True, slots=True)
class Point:
    """Where an interruption meets the ``[example]``'s task: before stage ``after`` (0-based) of an ``exeTsk``."""

    exe: str
    after: int
    stage: str
    """The stage about to run there, e.g. ``pick_pot(robot pot stove)``."""

    def __post_init__(self) -> None:
        if self.exe not in EXES:
            raise ValueError(f"Point.exe must be one of {list(EXES)}, got {self.exe!r}")
        if self.after < 0:
            raise ValueError(f"Point.after counts the stages done, got {self.after}")

    def describe(self) -> str:
        return f"before stage {self.after + 1} {self.stage} of the [example]'s {self.exe} exeTsk"


@dataclass(frozen=True, slots=True)
class HazardOn:
    """A declared hazard the task owns, on as its suspension ends."""

    name: str
    fact: Fact
    budget_s: float

    def describe(self) -> str:
        return f"{self.name} ({' '.join(self.fact)})"


@dataclass(frozen=True, slots=True)
class BranchRun:
    """The branch the tree chose at one point, and what its stages leave.

    ``branch`` is its index in ``[[suspension]]`` (-1: the tree could not be read there);
    ``blocked`` why a stage could not run (the static strategy fails there, its task ends);
    ``missed`` the goal literals that do not hold at the end; ``left_on`` the owned hazards on
    beyond what the policy allows; ``tolerated`` those a conditional branch may leave on (their
    budget covers ``interruption_s``)."""

    point: Point
    branch: int
    label: str
    policy: str = "strict"
    interruption_s: float | None = None
    stages: tuple[str, ...] = ()
    blocked: str | None = None
    missed: tuple[Literal, ...] = ()
    left_on: tuple[HazardOn, ...] = ()
    tolerated: tuple[HazardOn, ...] = ()

    def __post_init__(self) -> None:
        if self.policy not in POLICIES:
            raise ValueError(f"BranchRun.policy must be one of {list(POLICIES)}, got {self.policy!r}")
        if (self.policy == "conditional") != (self.interruption_s is not None):
            raise ValueError("BranchRun.interruption_s is the interruption a conditional run assumes, and only "
                             f"such a run has one (policy {self.policy!r}, interruption_s {self.interruption_s!r})")
        if self.tolerated and self.policy != "conditional":
            raise ValueError("BranchRun.tolerated: only the conditional policy leaves a hazard on within its budget")

    @property
    def complete(self) -> bool:
        """Every stage ran, the goal holds, and no owned hazard is on beyond what the policy allows."""
        return self.blocked is None and not self.missed and not self.left_on

    def verdict(self) -> str:
        if self.complete:
            kept = ", ".join(h.describe() for h in self.tolerated)
            return "reaches its goal and leaves no hazard on" + (f"; left on within budget: {kept}" if kept else "")
        said = []
        if self.blocked is not None:
            said.append(self.blocked)
        if self.missed:
            said.append(f"misses its goal {[list(g) for g in self.missed]}")
        if self.left_on:
            said.append(f"leaves on {', '.join(h.describe() for h in self.left_on)}")
        return "; ".join(said)

    def describe(self) -> str:
        under = ""
        if self.interruption_s is not None:
            under = f" (conditional policy, a {self.interruption_s:g} s interruption)"
        return f"{self.point.describe()}{under}: {self.verdict()}"


@dataclass(frozen=True, slots=True)
class TreeReport:
    """What ``tasker check`` says about one task folder's tree (module docstring)."""

    task: str
    branches: tuple[Branch, ...]
    walked: tuple[tuple[str, int], ...]
    """Each ``exeTsk`` walked and its number of stages."""
    runs: tuple[BranchRun, ...]
    unseen: tuple[UnseenCondition, ...]
    notes: tuple[str, ...] = ()
    """Why part of the report is missing (no ``[example]``, an unsolvable one, a failing hook)."""
    tree: str = DEFAULT_TREE
    """Which tree: ``default`` (``[[suspension]]``) or the name of a ``[[trees.NAME]]``."""

    @property
    def where(self) -> str:
        """Where the tree is written in ``task.toml``: ``suspension`` or ``trees.NAME``."""
        return "suspension" if self.tree == DEFAULT_TREE else f"trees.{self.tree}"

    def runs_of(self, branch: int) -> tuple[BranchRun, ...]:
        return tuple(r for r in self.runs if r.branch == branch)

    def failing(self) -> tuple[BranchRun, ...]:
        return tuple(r for r in self.runs if not r.complete)

    @property
    def complete(self) -> bool:
        """Every run complete and every condition seen."""
        return not self.failing() and not self.unseen

    def lines(self) -> list[str]:
        """The report, one line each (``tasker check`` prints them)."""
        walked = ", ".join(f"{exe} {n} stage(s)" for exe, n in self.walked) or "none"
        points = len({r.point for r in self.runs})
        which = "suspension tree" if self.tree == DEFAULT_TREE else f"suspension tree {self.tree!r}"
        out = [f"{which} of {self.task!r} at {points} interruption point(s) of the [example]'s exeTsk "
               f"(walked: {walked})"]
        out += [f"  {note}" for note in self.notes]
        for k, b in enumerate(self.branches):
            name = f"{self.where}[{k}] {b.label or '(no label)'!r}"
            runs = self.runs_of(k)
            bad = [r for r in runs if not r.complete]
            if not runs:
                out.append(f"  {name}: not chosen at any point")
            elif not bad:
                out.append(f"  {name}: complete at {len(runs)} point(s)")
            else:
                out.append(f"  {name}: NOT complete at {len(bad)} of {len(runs)} point(s)")
                out += [f"    {r.describe()}" for r in bad]
        out += [f"  {r.describe()}" for r in self.runs_of(-1)]
        out += [f"  {self.where}[{u.branch}]: `when` {list(u.literal)}: the world never has it ({u.maker.value})"
                for u in self.unseen]
        return out

    def warn(self, task: PddlTaskType) -> None:
        """One :class:`~tasker.support.reader.InputWarning` per branch that is not complete, and per
        condition the tree never sees, at the branch's line of ``task.toml``."""
        for u in self.unseen:
            task.spec.warn(f"{self.where}[{u.branch}]", u.message())
        for k in sorted({r.branch for r in self.failing()}):
            bad = [r for r in self.failing() if r.branch == k]
            more = f" (and at {len(bad) - 1} more point(s), listed in the tree report)" if len(bad) > 1 else ""
            if k < 0:  # genSusp fails there, whatever the strategy
                task.spec.warn(self.where, f"the tree cannot be read on the [example]: {bad[0].describe()}{more}")
                continue
            task.spec.warn(f"{self.where}[{k}]", f"branch {bad[0].label!r} is not complete on the [example]: "
                                               f"{bad[0].describe()}{more}; the static strategy leaves it so (give "
                                               "the state its own branch, or state what the branch assumes in its "
                                               "`when`)")


# -- conditions the tree never sees ------------------------------------------------------------


def _world_predicates(task: PddlTaskType, world_facts: Iterable[Fact], others: Iterable[PddlTaskType]) -> set[str]:
    """Predicates the world can hold at interruption (module docstring): ``at`` (from poses), what a
    binding reads off physics, what a stage's unconditional effect adds (the executor applies only
    those; ``others``' stages act on the same world), and what the ``[example]`` and the caller's
    known worlds and scenarios state."""
    out = {LOCATION, *(b.fact[0] for b in task.spec.bindings), *(f[0] for f in world_facts if f)}
    out |= {e.fluent for t in (task, *others) for a in t.domain.actions.values() for e in a.effects if e.positive}
    if task.spec.example is not None:
        out |= {f[0] for f in task.spec.example.facts}
    return out


def unseen_conditions(task: PddlTaskType, world_facts: Iterable[Fact] = (), hook_facts: Iterable[Fact] = (),
                      others: Iterable[PddlTaskType] = (), tree: str | None = None) -> tuple[UnseenCondition, ...]:
    """The ``when`` literals over a predicate the world never holds, and what makes it instead.

    ``world_facts``: facts of worlds and scenarios the task may run in, besides its ``[example]``;
    ``hook_facts``: what ``task.py``'s ``extra_facts`` made on the example's states; ``others``:
    task types that may run beside it (their stages' effects reach the same world)."""
    visible = _world_predicates(task, world_facts, others)
    by_hook: dict[str, Fact] = {}
    for f in hook_facts:
        by_hook.setdefault(f[0], f)
    requested = {lit[0] for lit in (*task.spec.facts, *task.spec.suspended_facts) if lit and lit[0] != "not"}
    out = []
    for k, b in enumerate(task.spec.tree(tree)):
        for lit in b.when:
            pred = lit[1] if lit[0] == "not" else lit[0]
            if pred in visible:
                continue
            if pred in by_hook:
                maker = Maker.TASK_PY
            elif pred in requested:
                maker = Maker.REQUEST
            elif pred == CONNECTED:
                maker = Maker.PLANNER
            else:
                maker = Maker.NOTHING
            out.append(UnseenCondition(k, b.label or f"suspension[{k}]", lit, maker, by_hook.get(pred)))
    return tuple(out)


# -- the example's states ------------------------------------------------------------------------


def _label(stage: Stage) -> str:
    return f"{stage.action}({' '.join(stage.args)})"


def _exes(task: PddlTaskType, ctx: TaskContext, notes: list[str]) -> list[tuple[str, tuple[Stage, ...]]]:
    """The example's planned ``exeTsk`` and its template one (each as far as it is found)."""
    out: list[tuple[str, tuple[Stage, ...]]] = []
    try:
        world, goal, extra = task.update_inputs(ctx)
        text, _, _ = task.problem_text(ctx, world, goal, extra)
        result = task.planner.solve(text, timeout=task.timeout)
        if result.solved and result.plan is not None:
            out.append(("planned", example_stages(task, ctx, result.plan)))
        else:
            notes.append(f"the [example]'s exeTsk is not planned ({result.status.value}): only the template is walked")
    except Exception as exc:  # noqa: BLE001 - task.py's hooks: the load check has warned already
        notes.append(f"the [example]'s exeTsk cannot be planned ({type(exc).__name__}: {exc})")
    if task.spec.static_update:
        try:
            out.append(("template", task.static_update(ctx).stages))
        except PlanningFailed as exc:
            notes.append(f"the [static] update template cannot be grounded on the [example]: {exc}")
    return out


@dataclass(frozen=True, slots=True)
class _State:
    point: Point
    world: WorldState
    done: tuple[Stage, ...]


def _states(task: PddlTaskType, ctx: TaskContext, exes: Sequence[tuple[str, tuple[Stage, ...]]],
            notes: list[str]) -> list[_State]:
    """The state before each stage of each ``exeTsk`` (a stage that cannot run ends its walk); a
    state met before (same facts, same facts made by the task) is not repeated."""
    out: list[_State] = []
    seen: set[tuple[frozenset[Fact], frozenset[Fact]]] = set()
    start = ctx.world
    assert isinstance(start, WorldState)
    for exe, stages in exes:
        world = start
        for k, stage in enumerate(stages):
            key = (world.facts, frozenset(tuple(f) for s in stages[:k] for f in s.data.get("add", ())))
            if key not in seen:
                seen.add(key)
                out.append(_State(Point(exe, k, _label(stage)), world, stages[:k]))
            try:
                why = task.inapplicable(replace(ctx, world=world, done=list(stages[:k])), stage)
            except Exception as exc:  # noqa: BLE001 - task.py's hooks
                why = f"{type(exc).__name__}: {exc}"
            if why is not None:
                notes.append(f"the {exe} exeTsk stops before stage {k + 1}: {why}")
                break
            world = apply_stage(world, stage)
    return out


# -- running a branch ----------------------------------------------------------------------------


def _run(task: PddlTaskType, ctx: TaskContext, state: _State, policy: str, interruption: float | None,
         tree: str | None = None) -> BranchRun:
    """The branch tree ``tree`` chooses in ``state`` under ``policy``, run stage by stage."""
    memory = AgentMemory()
    memory.interruption_s = interruption
    c = replace(ctx, world=state.world, strategy=Strategy("planned", "static", policy, tree), done=list(state.done),
                interrupted=None, suspended=True, memory=memory)
    try:
        branch, b = task.branch(c, state.world)
    except PlanningFailed as exc:
        return BranchRun(state.point, -1, "", policy, interruption, blocked=f"the tree cannot be read: {exc}")
    k = next(i for i, x in enumerate(task.spec.tree(tree)) if x is branch)
    label = branch.label or f"suspension[{k}]"
    world, blocked = state.world, None
    ran: list[Stage] = []
    stages: tuple[Stage, ...] = ()
    try:
        goal = b.literals(branch.goal)
        stages = task.builder.from_templates(branch.stages, b, {}, True)
    except PlanningFailed as exc:
        goal, blocked = [], f"its stages cannot be grounded: {exc}"
    for s in stages:
        try:
            why = task.inapplicable(replace(c, world=world, done=[*state.done, *ran]), s)
        except Exception as exc:  # noqa: BLE001 - task.py's hooks: the stage could not be checked, nor run
            why = f"task.py fails before {_label(s)}: {type(exc).__name__}: {exc}"
        if why is not None:
            blocked = why
            break
        world = apply_stage(world, s)
        ran.append(s)
    end = replace(c, world=world, done=[*state.done, *ran])
    facts = set(world.facts)
    try:  # the goal is planned with the request's and task.py's facts too
        facts |= set(task.suspension_facts(end, world))
    except Exception:  # noqa: BLE001 - task.py's hooks: the load check has warned already
        pass
    missed = tuple(g for g in goal if not holds_all(facts, [g]))
    on = [HazardOn(hz.name, f, hz.budget_s) for hz, f in derived.owned_hazards(task, end, world)]
    ok = [h for h in on if policy == "conditional" and interruption is not None and interruption <= h.budget_s]
    return BranchRun(state.point, k, label, policy, interruption, tuple(_label(s) for s in stages), blocked, missed,
                     tuple(h for h in on if h not in ok), tuple(ok))


def report(task: PddlTaskType, *, world_facts: Iterable[Fact] = (), others: Iterable[PddlTaskType] = (),
           tree: str | None = None) -> TreeReport:
    """The report of ``task``'s tree ``tree`` (None: ``[[suspension]]``) on its ``[example]`` (module
    docstring); ``world_facts`` (facts of the worlds and scenarios the task may run in) and ``others``
    (task types that may run beside it) are for :func:`unseen_conditions`."""
    world_facts, others = tuple(world_facts), tuple(others)
    name = tree or DEFAULT_TREE
    branches = task.spec.tree(tree)
    notes: list[str] = []
    ctx = example_context(task)
    if ctx is None:
        notes.append("no [example]: completeness is not checked (add one: a world and a request)")
        unseen = unseen_conditions(task, world_facts, others=others, tree=tree)
        return TreeReport(task.name, branches, (), (), unseen, tuple(notes), name)
    exes = _exes(task, ctx, notes)
    states = _states(task, ctx, exes, notes)
    made: list[Fact] = []
    for s in states or [_State(Point("planned", 0, "-"), ctx.world, ())]:
        try:
            made += task.hook_facts(replace(ctx, world=s.world), s.world)
        except Exception:  # noqa: BLE001 - task.py's hooks: the load check has warned already
            break
    limits = sorted({b.max_interruption_s for b in branches
                     if b.policy == "conditional" and b.max_interruption_s is not None})
    runs: list[BranchRun] = []
    for s in states:
        runs.append(_run(task, ctx, s, "strict", None, tree))
        for limit in limits:  # a conditional branch, at the longest interruption it accepts
            run = _run(task, ctx, s, "conditional", limit, tree)
            if run.branch >= 0 and branches[run.branch].policy == "conditional":
                runs.append(run)
    return TreeReport(task.name, branches, tuple((exe, len(st)) for exe, st in exes), tuple(runs),
                      unseen_conditions(task, world_facts, made, others, tree), tuple(notes), name)


def reports(task: PddlTaskType, *, world_facts: Iterable[Fact] = (),
            others: Iterable[PddlTaskType] = ()) -> list[TreeReport]:
    """One :func:`report` for each of ``task``'s trees, ``[[suspension]]`` first."""
    world_facts, others = tuple(world_facts), tuple(others)
    return [report(task, world_facts=world_facts, others=others, tree=name) for name in task.spec.tree_names]

