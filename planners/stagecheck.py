"""Whether a stage can run in the world as it is now (eqs. 25-26 meet the world).

A stage about to start is checked against its action's precondition in the state the planner
would see; what its own plan is entitled to assume (facts no world holds, where the robot and
people are) comes from the state the plan was made from.  A stage that cannot run fails with
:data:`tasker.trace.INAPPLICABLE` in its reason (``docs/domains.md``)."""

from __future__ import annotations

from typing import Protocol

from planners.problem import CONNECTED, DomainModel
from planners.stages import Bindings
from planners.taskspec import Literal, TaskSpec
from tasker.errors import PlanningFailed
from tasker.stage import Stage
from tasker.task import TaskContext
from tasker.trace import INAPPLICABLE
from tasker.world import WorldState

LOCATION = "at"
MOVERS = frozenset({"robot", "person"})
"""Object types whose ``at`` fact the world grounds from a pose (:func:`_assumed`)."""


class CheckedTask(Protocol):
    """What the check needs of a task type (:class:`planners.pddl_task.PddlTaskType`)."""

    spec: TaskSpec
    domain: DomainModel

    def hook_facts(self, ctx: TaskContext, world: WorldState) -> list[Literal]: ...


def inapplicable(task: CheckedTask, ctx: TaskContext, stage: Stage) -> str | None:
    """Why ``stage`` cannot run now: the literals of its action's precondition that do not hold.

    Checked in the state the planner would see — the world, the request's and ``task.py``'s
    facts, Alg. 3's while suspended — except for what the stage's own plan is entitled to
    assume: facts no world holds (an apology due) and where the robot and people are (the
    world grounds those from poses, a metre from the place a plan means) are read from the
    state the plan was made from, as its stages executed so far left it.  ``connected`` is
    left out (the planner derives it from the motion model).  None when the stage can run,
    when it would change nothing, or when the precondition is not a conjunction of literals."""
    world = ctx.world
    if not isinstance(world, WorldState) or stage.action not in task.domain.actions:
        return None
    try:
        b = Bindings(ctx.args, world)
        extra = b.literals(task.spec.facts) + (b.literals(task.spec.suspended_facts) if ctx.suspended else [])
        extra += task.hook_facts(ctx, world)
    except PlanningFailed:
        return None
    facts = world.facts | frozenset(extra)
    add, delete = [tuple(f) for f in stage.data.get("add", ())], [tuple(f) for f in stage.data.get("delete", ())]
    if add and all(f in facts for f in add) and not any(f in facts for f in delete):
        return None  # it would change nothing (driving to where the robot stands): nothing to refuse
    projected = _projection(ctx, stage, frozenset(extra) - world.facts)
    if projected is not None:
        assumed, kinds = projected
        facts = frozenset(f for f in facts if not _assumed(f, kinds, world)) | assumed
    unmet = [lit for lit in task.domain.unmet(stage.action, stage.args, facts) or ()
             if (lit[1] if lit[0] == "not" else lit[0]) != CONNECTED]
    if not unmet:
        return None
    said = ", ".join(f"({' '.join(lit)})" for lit in unmet)
    return f"{INAPPLICABLE} {stage.action}({' '.join(stage.args)}) needs {said}, which does not hold"

def already_done(task: CheckedTask, ctx: TaskContext, stage: Stage) -> str | None:
    """Why ``stage`` need not run: every effect of its action holds in the world as it is now (each
    fact it adds holds, none it deletes does), or None.  A stage with no effects is never already
    done.  The agent asks it of a stage :func:`inapplicable` refuses: a door someone else closed
    makes ``close_door`` already done, not a failure."""
    world = ctx.world
    if not isinstance(world, WorldState):
        return None
    add = [tuple(str(x) for x in f) for f in stage.data.get("add", ())]
    delete = [tuple(str(x) for x in f) for f in stage.data.get("delete", ())]
    if not (add or delete) or any(f not in world.facts for f in add) or any(f in world.facts for f in delete):
        return None
    said = ", ".join([f"({' '.join(f)})" for f in add] + [f"(not ({' '.join(f)}))" for f in delete])
    return f"already done: {said} hold{'s' if len(add) + len(delete) == 1 else ''} in the world now"


def _projection(ctx: TaskContext, stage: Stage,
            extra: frozenset[Literal]) -> tuple[frozenset[Literal], frozenset[str]] | None:
    """What ``stage``'s plan may assume: the facts it was made from of the kinds :func:`_assumed` names,
    updated by the effects of the plan's stages before ``stage``; None for a stage of no plan made here."""
    world = ctx.world
    assert isinstance(world, WorldState)
    kinds = frozenset(f[0] for f in extra)
    for stages, planned_facts in reversed(ctx.memory.planned_from or ()):
        k = next((i for i, s in enumerate(stages) if s is stage), None)
        if k is None:
            continue
        state = {f for f in planned_facts | extra if _assumed(f, kinds, world)}
        for done in stages[:k]:
            state -= {tuple(f) for f in done.data.get("delete", ()) if _assumed(tuple(f), kinds, world)}
            state |= {tuple(f) for f in done.data.get("add", ()) if _assumed(tuple(f), kinds, world)}
        return frozenset(state), kinds
    return None

def _assumed(fact: Literal, extra_kinds: frozenset[str], world: WorldState) -> bool:
    """A fact a plan reads from its own projection, not from the world now: one of a kind no world
    holds (``extra_kinds``: the request's, ``task.py``'s, Alg. 3's), or where the robot or a person is
    (an abstraction of a pose that the stage which drove there has met)."""
    if fact[0] in extra_kinds:
        return True
    return fact[0] == LOCATION and len(fact) == 3 and world.objects.get(fact[1]) in MOVERS
