"""Held-out checks of issue 26 on a user's task folder whose tree forgets a hazard.

``tests/domains/fixtures/water_plants_forgets_tap`` (water_plants as it was first written)
declares the tap it turns on as a hazard (``tap_running``) and writes a ``[[suspension]]`` tree
that only puts the can down.  Run in
``experiments/sweep/specs/scenarios/water_plants.toml`` (Peter falls while the tap runs):

* ``derived`` plans to what the folder declares, so when the interrupting task starts its
  first stage no hazard of the suspended task is on;
* ``static`` and ``planned`` pursue the tree's branch, so the tap is left running: the
  tree's blind spot, asserted as observed;
* over a grid of interruption times (this task's stages, and the bundled ``carry``'s),
  every stage a static suspension gave the robot was applicable in the state it began in —
  judged by unified-planning's simulator on the PDDL problem of that state, not by the
  runtime's own check — and every stage the runtime refused failed with the
  ``INAPPLICABLE`` reason without reaching the robot.

Runs are cut by a horizon a little after the interruption, so each takes seconds.
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import pytest
from unified_planning.exceptions import UPInvalidActionError

from experiments.inputs import scenario as scenarios
from experiments.run.options import RunOptions
from experiments.run.runner import build_robot
from experiments.trace.timeline import Timeline
from planners.checks import PddlError, load_problem_text
from planners.pddl_task import PddlTaskType
from planners.problem import PLACE_TYPE, render_problem
from planners.validate import state_after
from tasker.agent import DynamicAgent
from tasker.fsm import S
from tasker.stage import Stage
from tasker.trace import INAPPLICABLE
from tasker.world import WorldState

pytestmark = pytest.mark.slow  # each test runs a robot scenario to its end

ROOT = Path(__file__).resolve().parents[2]
FOLDER = ROOT / "tests" / "domains" / "fixtures" / "water_plants_forgets_tap"
WATER = ROOT / "experiments" / "sweep" / "specs" / "scenarios" / "water_plants.toml"
PATHS = (str(FOLDER),)
AFTER_S = 45.0  # the horizon after the interruption: enough for every suspension here to reach wait
# Interruption times across water_plants' stages (undisturbed: navigate 0.5-20.7, pick 20.7-26.7,
# navigate 26.7-66.1, turn_on 66.1-68.1, fill 68.1-88.1, turn_off 88.1-90.1, navigate 90.1-120.1) and
# carry's (open_door 0.5-6.6, navigate 6.6-23.4, pick 23.4-31.4, navigate 31.4-49.4, navigate_through
# 49.4-66.4; then place and close_door, both blocking, until it ends at 80.4).
WATER_TIMES = (24.0, 50.0, 67.0, 75.0, 89.0, 105.0)
CARRY_TIMES = (3.0, 15.0, 28.0, 52.0, 58.0, 63.0)
DERIVED_TIMES = (24.0, 67.0, 75.0, 89.0)  # water_plants: the can held; the tap turned on, running, turned off


def _at(source: Path | str, t: float) -> scenarios.RobotScenario:
    """The scenario with its interruption (the last request, and what happens at its time) moved to ``t``."""
    scn = scenarios.load(source, task_paths=PATHS)
    was = [a for a in scn.actions if a.kind == "request"][-1].t
    actions = tuple(dataclasses.replace(a, t=t) if a.t == was else a for a in scn.actions)
    return dataclasses.replace(scn, actions=actions, horizon=t + AFTER_S)


class Witness:
    """Every stage a static suspension hands the robot, with UP's verdict on it in the state it begins in.

    The state is the agent's world at that moment (refreshed from the simulation just before the
    stage starts) with the task's own extra facts, rendered as the PDDL problem the planner would
    read; every pair of places counts as ``connected`` (reachability is the motion model's
    question, not the precondition's).  UP's ``SequentialSimulator`` applies the stage or says
    it is not applicable.  A stage that would change nothing — driving to the place the robot
    is at, which a tree's ``navigate($at:robot, ?p)`` gives when ``?p`` is that place — is not
    asked of UP (PDDL's move needs two connected places, so UP grounds it as invalid): a robot
    can always be where it is, and the runtime lets it run for that reason.  The witness never
    raises into the run: whatever fails is its verdict."""

    def __init__(self, agents: list[DynamicAgent], sim: object) -> None:
        self.agents = agents
        self.begun: list[tuple[str, str, str, tuple[str, ...], float]] = []  # (agent, fsm, action, args, t)
        self.verdicts: list[tuple[str, str, str | None]] = []  # (agent, action(args), why not applicable)
        self.no_ops: list[str] = []  # stages judged applicable because they would change nothing
        self._begin = sim.begin  # type: ignore[attr-defined]
        sim.begin = self.begin  # type: ignore[attr-defined]

    def begin(self, agent_id: str, stage: Stage, now: float) -> None:
        agent = next(a for a in self.agents if a.id == agent_id)
        self.begun.append((agent_id, agent.state.value, stage.action, tuple(stage.args), now))
        if agent.state is S.EXE_SUSP and agent.ctx.strategy.suspension == "static":
            try:
                why = self._why_not(agent, stage)
            except Exception as exc:  # noqa: BLE001 -- a verdict, not a stage failure of the run
                why = f"the witness could not judge it: {type(exc).__name__}: {exc}"
            self.verdicts.append((agent_id, f"{stage.action}({' '.join(stage.args)})", why))
        self._begin(agent_id, stage, now)

    def _why_not(self, agent: DynamicAgent, stage: Stage) -> str | None:
        task, ctx = agent.task, agent.ctx
        assert isinstance(task, PddlTaskType) and isinstance(ctx.world, WorldState)
        world = ctx.world
        places = sorted(n for n, ty in world.objects.items() if ty == PLACE_TYPE)
        travel = {(a, b): 1.0 for a in places for b in places if a != b}
        text, init = render_problem(task.domain, world, [], extra_facts=task.suspension_facts(ctx, world),
                                    travel=travel, name=task.name)
        add, delete = task.domain.ground(stage.action, stage.args)
        if all(tuple(f) in init for f in add) and not any(tuple(f) in init for f in delete):
            self.no_ops.append(f"{stage.action}({' '.join(stage.args)})")
            return None
        problem = load_problem_text(task.domain.checked, text)
        try:
            state_after(problem, [(stage.action, *stage.args)])
        except (PddlError, UPInvalidActionError) as exc:  # not applicable (UP's grounder: statically so)
            return f"{type(exc).__name__}: {exc}"
        return None


def _run(scn: scenarios.RobotScenario, suspension: str) -> tuple[Timeline, Witness]:
    loop, sim = build_robot(scn, RunOptions(seed=scn.seed, suspension=suspension, task_paths=PATHS))
    witness = Witness(loop.all_agents, sim)
    return Timeline.of(loop.run().events), witness


def _interrupter_starts(tl: Timeline) -> float:
    """When the interrupting task (human_fell) begins its first stage."""
    fell = next(a for a in tl.agents.values() if a.task_type == "human_fell")
    assert fell.stages, f"{fell.id} never started a stage before the horizon"
    return fell.stages[0].begin


def _owned_on(tl: Timeline, agent: str, t: float) -> list[str]:
    return sorted(f"{h.hazard}({', '.join(h.args)})" for h in tl.hazards
                  if h.owner == agent and h.start <= t and (h.end is None or t < h.end))


SOURCES: dict[str, Path | str] = {"water_plants": WATER, "carry": "carry"}


@functools.cache
def _outcome(scenario: str, t: float, strategy: str) -> tuple[Timeline, Witness]:
    """One run, shared by the tests that read it (a run takes a few CPU seconds)."""
    return _run(_at(SOURCES[scenario], t), strategy)


@pytest.mark.parametrize("t", DERIVED_TIMES)
def test_derived_leaves_no_hazard_of_the_suspended_task_on_when_the_interrupting_task_starts(t: float) -> None:
    tl, _ = _outcome("water_plants", t, "derived")
    assert _owned_on(tl, "d1", _interrupter_starts(tl)) == []


def test_derived_turns_off_the_tap_the_tree_forgets() -> None:
    """Peter falls at 75 s, while the can fills: the can is held and the tap runs."""
    tl, _ = _outcome("water_plants", 75.0, "derived")
    assert _owned_on(tl, "d1", 75.0) == ["can_held(robot, can)", "tap_running(tap)"]
    (susp,) = tl.agents["d1"].suspensions
    assert [(r.action, r.status) for r in susp.stages] == [("put_down", "done"), ("turn_off", "done")]
    assert susp.plan is not None and "tap_running(tap) off" in (susp.plan.note or "")  # the declared hazard


@pytest.mark.parametrize("strategy", ["static", "planned"])
def test_the_tree_leaves_the_tap_running_under_static_and_planned(strategy: str) -> None:
    """The tree's blind spot: its branch puts the can down and nothing turns the tap off, so the tap
    runs unattended past its budget while Peter is helped."""
    tl, _ = _outcome("water_plants", 75.0, strategy)
    t = _interrupter_starts(tl)
    assert _owned_on(tl, "d1", t) == ["tap_running(tap)"]
    (susp,) = tl.agents["d1"].suspensions
    assert [(r.action, r.status) for r in susp.stages] == [("put_down", "done")]
    tap = next(h for h in tl.hazards if h.hazard == "tap_running")
    assert t + tap.budget_s < 75.0 + AFTER_S and "tap_running(tap)" in _owned_on(tl, "d1", t + tap.budget_s)
    assert tl.exe_at(t + tap.budget_s) != "d1"  # unattended then: another task executes


@pytest.mark.parametrize(("scenario", "t"), [("water_plants", t) for t in WATER_TIMES] +
                         [("carry", t) for t in CARRY_TIMES])
def test_static_suspension_never_applies_an_inapplicable_stage(scenario: str, t: float) -> None:
    tl, witness = _outcome(scenario, t, "static")
    for agent, stage, why in witness.verdicts:
        assert why is None, f"{agent} ran {stage}, which UP finds inapplicable in the state it began in: {why}"
    ran = [r for a in tl.agents.values() for s in a.suspensions for r in s.stages]
    refused = [r for r in ran if r.status == "failed" and (r.reason or "").startswith(INAPPLICABLE)]
    for r in refused:  # failed as it began, and never given to the robot: nothing of it was applied
        assert r.end == r.begin
        given = (r.agent, "exeSusp", r.action, tuple(r.args), r.begin)
        assert given not in witness.begun, f"{r.action}{r.args} reached the robot"
    assert len(witness.verdicts) == len(ran) - len(refused)  # every other stage reached the robot and was judged
