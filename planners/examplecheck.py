"""What a task folder's ``[example]`` shows about its goal and its suspension tree (``tasker check`` warnings).

Load checks prove each branch's stages reach the branch's goal by applying their effects;
they cannot see a stage that could not run.  With the example's plan as a witness, two
things can be shown, and are warned about (each names ``task.toml`` and the field):

* **a branch that runs an inapplicable stage**: after each prefix of the example's
  ``exeTsk`` (the states an interruption can meet), the branch the tree chooses there is
  run stage by stage from that state, each checked like a robot would
  (:meth:`PddlTaskType.inapplicable <planners.pddl_task.PddlTaskType.inapplicable>`); a
  stage whose precondition does not hold is one the static strategy fails on there (the
  planned strategy plans round it);
* **a goal that leaves a declared hazard on**: a hazard fact the example's plan made true
  and its goal leaves true — a door the task opened and never closes — stays on after the
  task ends, where no suspension can attend to it (``[problem] restore``, or the goal, can
  ask it back).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

from planners.stages import Bindings, robot_name
from tasker.errors import PlanningFailed
from tasker.meaning import bind, matches
from tasker.memory import AgentMemory
from tasker.stage import Stage
from tasker.task import Strategy, TaskContext
from tasker.world import WorldState

if TYPE_CHECKING:
    from planners.pddl_task import PddlTaskType


def _apply(world: WorldState, stage: Stage) -> WorldState:
    """The example world after ``stage``: its effects, and the robot standing at the place it went to
    (the tree binds its ``?vars`` nearest the robot first, as in a run)."""
    after = world.updated([tuple(f) for f in stage.data.get("add", ())],
                          [tuple(f) for f in stage.data.get("delete", ())])
    robot = robot_name(world)
    to = next((f[2] for f in stage.data.get("add", ()) if len(f) == 3 and f[0] == "at" and f[1] == robot), None)
    if to is not None and to in world.poses:
        after = replace(after, poses={**after.poses, robot: world.poses[to]})
    return after


def inapplicable_branches(task: PddlTaskType, ctx: TaskContext, exe: Sequence[Stage]) -> list[tuple[str, str]]:
    """``(branch label, why)`` for each branch that runs a stage it cannot run in a state its ``when``
    admits, met after a prefix of ``exe`` (the example's ``exeTsk``), under either policy."""
    out: list[tuple[str, str]] = []
    seen: set[str] = set()
    world = ctx.world
    assert isinstance(world, WorldState)
    for k in range(len(exe) + 1):
        for policy in ("strict", "conditional"):
            c = replace(ctx, world=world, strategy=Strategy("planned", "static", policy), done=list(exe[:k]),
                        interrupted=exe[k] if k < len(exe) else None, suspended=True, memory=AgentMemory())
            branch, b = task.branch(c, world)
            if branch.label in seen or not branch.stages:
                continue
            try:
                stages = task.builder.from_templates(branch.stages, b, {}, True)
            except PlanningFailed:
                continue
            state = world
            for s in stages:
                why = task.inapplicable(replace(c, world=state), s)
                if why is not None:
                    seen.add(branch.label)
                    out.append((branch.label, f"after {k} stage(s) of the [example]'s exeTsk: {why}"))
                    break
                state = _apply(state, s)
        if k < len(exe):
            world = _apply(world, exe[k])
    return out


def hazards_left_on(task: PddlTaskType, ctx: TaskContext, exe: Sequence[Stage]) -> list[str]:
    """The declared hazard facts the example's plan made true and its goal leaves true."""
    world = ctx.world
    assert isinstance(world, WorldState)
    end = world
    for s in exe:
        end = _apply(end, s)
    robot = robot_name(world)
    out = []
    for hz in task.spec.hazards:
        atom = bind(hz.fact, ctx.args, robot)
        if atom is None:
            continue
        before = set(matches(atom, world.facts))
        out += [f"{hz.name}: ({' '.join(f)})" for f in matches(atom, end.facts) if f not in before]
    return out


def check(task: PddlTaskType, ctx: TaskContext, exe: Sequence[Stage]) -> None:
    """Warn (``InputWarning`` at ``task.toml``'s line) about what the example shows (module docstring)."""
    for label, why in inapplicable_branches(task, ctx, exe):
        task.spec.warn("suspension", f"branch {label!r} runs a stage it cannot run in a state its `when` admits "
                                     f"({why}): the static strategy fails there (the planned one plans round it)")
    left = hazards_left_on(task, ctx, exe)
    if left:
        task.spec.warn("problem.goal", f"the goal leaves on what the [example]'s plan turned on: {', '.join(left)}; "
                                       "it stays on after the task ends (add it to [problem] restore, or to the goal)")


def example_stages(task: PddlTaskType, ctx: TaskContext, steps: Sequence[Sequence[str]]) -> tuple[Stage, ...]:
    """The example's plan as stages (no travel table: only their effects and preconditions matter here)."""
    return task.builder.from_steps(steps, {}, Bindings(ctx.args, ctx.world).args)
