"""The ``fallback`` suspension strategy: the tree's branch where it can run, a plan where it cannot.

genSusp under ``fallback`` (:meth:`planners.pddl_task.PddlTaskType.generate_suspension`):

* the branch of the task's decision tree is chosen as ``static`` chooses it (the first branch
  whose ``when`` holds), its stages bound in the world as it is now;
* its stages are run symbolically from the state the planner would see (the world, the request's
  and ``task.py``'s facts): each must be applicable in the state the ones before it leave
  (``connected`` aside: reachability is the travel table's, which binding the branch checked).
  A stage whose effects hold already passes, as the agent would skip it (``already_done``);
* if every stage can run, ``exeSusp`` is the branch as written (``info.fallback = "tree"``);
  if a stage cannot, if the branch cannot be reached (no place known for a thing it names, a
  place walled off or behind a closed door) or the tree's genSusp fails, it plans from the state
  as it is to the derived goal (:func:`planners.derived.goal`; ``info.fallback = "planned"``);
* asked again because a stage of its ``exeSusp`` could not run when its turn came
  (:attr:`tasker.task.TaskContext.recovering`, once per suspension), it plans to the derived goal.

The note of the plan says which and why.  A planner that times out leaves the tree's branch (it may
still partly run); one that finds no plan fails genSusp, saying both reasons.  The strategy is a
factor level of its own: ``static`` stays the pure tree.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Protocol

from planners.problem import CONNECTED, DomainModel
from planners.results import PlanResult, PlanStatus
from planners.taskspec import Literal
from tasker.errors import PlanningFailed
from tasker.stage import Stage, StagePlan
from tasker.task import TaskContext
from tasker.world import WorldState

FALLBACK = "fallback"


class FallbackTask(Protocol):
    """What the strategy needs of a task type (:class:`planners.pddl_task.PddlTaskType` has it)."""

    name: str
    domain: DomainModel

    def world_of(self, ctx: TaskContext) -> WorldState: ...

    def static_suspension(self, ctx: TaskContext) -> StagePlan: ...

    def suspension_facts(self, ctx: TaskContext, world: WorldState) -> list[Literal]: ...

    def derived_goal(self, ctx: TaskContext, world: WorldState) -> tuple[list[Literal], str]: ...

    def plan_suspension_to(self, ctx: TaskContext, world: WorldState, goal: list[Literal],
                           label: str) -> StagePlan | PlanResult: ...


def suspension(task: FallbackTask, ctx: TaskContext) -> StagePlan:
    """genSusp's ``exeSusp`` under ``fallback`` (see the module docstring)."""
    world = task.world_of(ctx)
    if ctx.recovering is not None:
        return _planned(task, ctx, world, f"a stage of exeSusp could not run ({ctx.recovering})", None)
    try:
        tree = task.static_suspension(ctx)
    except PlanningFailed as exc:
        return _planned(task, ctx, world, f"the tree's branch cannot be reached ({exc})", None)
    blocked = blocked_stage(task, ctx, world, tree.stages)
    if blocked is None:
        return replace(tree, strategy=FALLBACK, note=f"fallback: the tree's branch runs as written ({tree.note})",
                       info={"fallback": "tree"})
    return _planned(task, ctx, world, blocked, tree)


def blocked_stage(task: FallbackTask, ctx: TaskContext, world: WorldState, stages: tuple[Stage, ...]) -> str | None:
    """Why ``stages``, run in order from the state the planner would see, cannot all run: the first
    stage whose precondition does not hold where the ones before it leave the state; None if they can."""
    facts = set(world.facts) | set(task.suspension_facts(ctx, world))
    for st in stages:
        add = {tuple(str(x) for x in f) for f in st.data.get("add", ())}
        delete = {tuple(str(x) for x in f) for f in st.data.get("delete", ())}
        if (add or delete) and add <= facts and not delete & facts:
            continue  # already done: the agent skips it
        unmet = [lit for lit in task.domain.unmet(st.action, st.args, facts) or ()
                 if (lit[1] if lit[0] == "not" else lit[0]) != CONNECTED]
        if unmet:
            said = ", ".join(f"({' '.join(lit)})" for lit in unmet)
            return f"the tree's stage {st.label} needs {said}, which does not hold"
        facts -= delete
        facts |= add
    return None


def _planned(task: FallbackTask, ctx: TaskContext, world: WorldState, why: str, tree: StagePlan | None) -> StagePlan:
    goal, label = task.derived_goal(ctx, world)
    outcome = task.plan_suspension_to(ctx, world, goal, label)
    if isinstance(outcome, StagePlan):
        return replace(outcome, strategy=FALLBACK, note=f"fallback: {why}; planned to the derived goal ({label})",
                       info={**outcome.info, "fallback": "planned"})
    if outcome.status is PlanStatus.TIMEOUT and tree is not None:
        return replace(tree, strategy=FALLBACK, note=f"fallback: {why}; the planner timed out, so the tree's "
                                                     "branch runs", info={"fallback": "tree"})
    status = "unsolvable" if outcome.status is PlanStatus.UNSOLVABLE else "error"
    raise PlanningFailed(status, f"{task.name}: fallback: {why}; and no plan reaches the derived goal {goal}"
                                 + (f" ({outcome.message})" if outcome.message else ""))
