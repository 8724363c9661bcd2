"""The ``derived`` suspension goal: the one a task folder's declarations give, not its tree.

Every hazard the task owns off, its person in a ``safe`` role of ``[people]``, its
``[derived] invariants`` (``docs/domains.md``).  :class:`planners.pddl_task.PddlTaskType`
plans to it in genSusp when ``ctx.strategy.suspension == "derived"``."""

from __future__ import annotations

import math

from planners.estimates import EstimatedTask, estimator_for
from planners.results import PlanStatus
from planners.stages import Bindings, robot_name
from planners.taskspec import Literal
from tasker.errors import PlanningFailed
from tasker.meaning import Hazard, bind, matches
from tasker.meaning import holds as holds_literal
from tasker.memory import INTERRUPTION_KEY as INTERRUPTION_KEY  # the old key, for code that imports it here
from tasker.task import TaskContext
from tasker.world import WorldState


def owned_hazards(task: EstimatedTask, ctx: TaskContext, world: WorldState) -> list[tuple[Hazard, Literal]]:
    """The declared hazards that hold now and are this task's, as the hazard monitor owns them
    (:class:`tasker.meaning.Monitor`): a pattern with ``$args`` through the request's arguments; one
    without, when the monitor gives it to this agent (``ctx.hazards``) or a stage of this task made it
    true (its ``add`` effects) and it still holds."""
    robot = robot_name(world)
    mine = {(name, tuple(f)) for name, f in (ctx.hazards() if ctx.hazards is not None else ())}
    made = {tuple(f) for s in ctx.done for f in s.data.get("add", ())}
    out: list[tuple[Hazard, Literal]] = []
    for hz in task.spec.hazards:
        atom = bind(hz.fact, ctx.args, robot)
        if atom is None:
            continue
        by_args = any(tok.startswith("$") and tok != "$robot" for tok in hz.fact)
        for f in matches(atom, world.facts):
            if by_args or (hz.name, f) in mine or f in made:
                out.append((hz, f))
    return out


def goal(task: EstimatedTask, ctx: TaskContext, world: WorldState) -> tuple[list[Literal], str]:
    """The ``derived`` suspension goal and a label saying what it asks for.

    * every hazard this task owns (:func:`owned_hazards`) off — under the ``conditional``
      policy, a hazard whose ``budget_s`` is at least the expected interruption
      (``ctx.memory.interruption_s``; unknown means long) may stay on;
    * the task's person in one of the ``safe`` roles of ``[people]``: if none holds, the
      role literal the planner reaches most cheaply (each is planned as the estimates plan);
    * the ``[derived] invariants``."""
    expected = ctx.memory.interruption_s
    length = math.inf if expected is None else expected
    out: list[Literal] = []
    said: list[str] = []
    for hz, fact in owned_hazards(task, ctx, world):
        if ctx.strategy.policy == "conditional" and length <= hz.budget_s:
            said.append(f"{hz.name}({', '.join(fact[1:])}) left on")
            continue
        out.append(("not", *fact))
        said.append(f"{hz.name}({', '.join(fact[1:])}) off")
    b = Bindings(ctx.args, world)
    out += [lit for lit in b.literals(task.spec.invariants) if lit not in out]
    if task.spec.invariants:
        said.append("invariants")
    people = task.spec.people
    if people is not None and people.safe:
        robot = robot_name(world)
        options = [lit for role in people.safe for pat in people.roles[role]
                   if (lit := bind(pat, ctx.args, robot)) is not None]
        if options and not any(holds_literal(lit, world.facts) for lit in options):
            chosen = _cheapest(task, ctx, world, out, options)
            if chosen is not None:
                out.append(chosen)
                said.append(f"{ctx.args.get(people.person)} {' '.join(chosen)}")
        else:
            said.append(f"{ctx.args.get(people.person)} safe")
    return out, "derived: " + (", ".join(said) if said else "nothing to make safe")


def _cheapest(task: EstimatedTask, ctx: TaskContext, world: WorldState, goal: list[Literal],
              options: list[Literal]) -> Literal | None:
    """Of ``options`` (a safe role's literals), the one added to ``goal`` the planner reaches at
    the lowest cost (planned as the estimates plan: cached, travel with nobody in the way); the
    first one if it reaches none (genSusp will then say it is unsolvable)."""
    extra = task.suspension_facts(ctx, world)
    travel = estimator_for(task).reference_table(world, ctx.motion)
    best: tuple[float, int] | None = None
    for k, lit in enumerate(options):
        steps, status, _ = estimator_for(task).plan(ctx, world, [*goal, lit], extra)
        if status is not PlanStatus.SOLVED:
            continue
        try:
            cost = sum(s.duration for s in task.builder.from_steps(steps, travel, ctx.args))
        except PlanningFailed:  # a leg the robot cannot drive now
            continue
        if best is None or (cost, k) < best:
            best = (cost, k)
    return options[best[1] if best is not None else 0]
