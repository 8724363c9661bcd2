"""Estimates come from a plan of the state asked about, never from a stale remainder.

Every check compares an estimate with the plan the task would actually execute from the
same state (``update_task``), timed the same way: navigate legs by the motion model from
the start pose, other stages by their durations (:func:`timed`, written out here apart
from :func:`planners.estimates.walk`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

import domains
from planners.bundled import task_types
from planners.estimates import (
    Estimate,
    Estimator,
    Source,
    declared_template_time,
    estimator_for,
    moved_robot,
    nearest_place,
    walk,
)
from planners.examples import StraightLineMotion
from planners.pddl_task import PddlTaskType
from planners.results import PlanResult, PlanStatus
from tasker.messages import SP_COMPLETION, CompletionCost, SPRequest
from tasker.stage import Stage
from tasker.task import TaskContext
from tasker.world import MotionEstimate, Pose, WorldState
from tests.domains.conftest import MOTION, make_ctx


@pytest.fixture(scope="module")
def tasks() -> dict[str, PddlTaskType]:
    return {t.name: t for t in task_types()}  # type: ignore[misc]


@pytest.fixture(params=domains.bundled_names())
def task(request: pytest.FixtureRequest, tasks: dict[str, PddlTaskType]) -> PddlTaskType:
    return tasks[request.param]


def timed(stages: Sequence[Stage], world: WorldState, start: Pose) -> float:
    """The reference timing: motion from ``start`` for navigate legs, durations otherwise."""
    pose, total = start, 0.0
    for s in stages:
        if s.skill == "navigate" and str(s.data["to"]) in world.poses:
            est = MOTION.estimate(pose, world.poses[str(s.data["to"])])
            total, pose = total + est.time_s, est.end_pose or pose
        else:
            total += s.duration
    return total


def advance(world: WorldState, stages: Sequence[Stage]) -> WorldState:
    """The world after ``stages`` succeeded: their effects, and whoever moved stands at their new place."""
    for s in stages:
        world = world.updated([tuple(f) for f in s.data["add"]], [tuple(f) for f in s.data["delete"]])
    poses = dict(world.poses)
    for f in world.matching("at"):
        if len(f) == 3 and f[1] in poses and f[2] in world.poses:
            poses[f[1]] = world.poses[f[2]]
    return WorldState(world.facts, poses, world.objects, world.time)


def executed(task: PddlTaskType, ctx: TaskContext) -> float:
    """Duration of what upTsk would execute from ``ctx``, timed from the robot's pose."""
    world = ctx.world
    assert isinstance(world, WorldState)
    return timed(task.update_task(ctx).stages, world, world.poses["robot"])


def test_fresh_request_equals_the_plan_executed(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    est = estimator_for(task).estimate(ctx)
    assert est.source is Source.PLAN
    assert est.c_time == pytest.approx(executed(task, ctx))
    assert task.compute_params(ctx).c_time == est.c_time


def test_part_done_equals_the_plan_from_that_state(task: PddlTaskType) -> None:
    """Whatever was done (by the robot or anyone), the estimate is the plan of what is left."""
    ctx0 = make_ctx(task)
    full = task.update_task(ctx0)
    for k in range(1, len(full.stages)):
        ctx = make_ctx(task, world=advance(ctx0.world, full.stages[:k]))
        ctx.plan, ctx.stage_index = full, 0  # a stale plan on the agent must not matter
        c_time, _ = task.estimate(ctx, None)
        assert c_time == pytest.approx(executed(task, ctx)), f"after {k} stage(s)"
        assert c_time < executed(task, ctx0) + 1e-9


def test_from_another_start_pose_equals_the_plan_from_there(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    world = ctx.world
    assert isinstance(world, WorldState)
    places = sorted(n for n, t in world.objects.items() if t == "place" and n in world.poses)
    for place in places:
        start = world.poses[place]
        moved = make_ctx(task, world=moved_robot(world, start))
        assert moved.world.holds("at", "robot", place)
        ctx.now = 10.0
        answer = task.request_sp(ctx, SPRequest(SP_COMPLETION, {"pose": list(start)}))
        assert isinstance(answer, CompletionCost)
        assert answer.cc == pytest.approx(task.spec.cps * (10.0 + executed(task, moved))), place


def test_person_told_to_wait_is_greeted_again(tasks: dict[str, PddlTaskType]) -> None:
    """Alg. 3: after a suspension the plan re-approaches and greets with an apology."""
    task = tasks["guide_human"]
    ctx0 = make_ctx(task)
    full = task.update_task(ctx0)
    assert [s.action for s in full.stages] == ["approach", "greet", "ask_to_follow", "guide", "say_goodbye"]
    # John was greeted and asked to follow, then told to wait; the robot went to the bedroom
    world = advance(ctx0.world, full.stages[:3])
    world = world.updated([("told_to_wait", "john")], [("following", "john")])
    world = moved_robot(world, world.poses["bedroom"])
    ctx = make_ctx(task, world=world, suspended=True)
    est = estimator_for(task).estimate(ctx)
    assert [s[0] for s in est.steps] == ["approach", "greet_and_apologise", "ask_to_follow", "guide", "say_goodbye"]
    assert est.c_time == pytest.approx(executed(task, ctx))


def test_stale_remainder_regression(tasks: dict[str, PddlTaskType]) -> None:
    """Alice's cc fell once she was greeted because the stale remainder (guide, goodbye) ended
    where another task's did.  A suspended guide task must pay for re-approaching and greeting."""
    task = tasks["guide_human"]
    ctx0 = make_ctx(task)
    full = task.update_task(ctx0)
    world = advance(ctx0.world, full.stages[:3])  # approached, greeted, following
    world = world.updated([("told_to_wait", "john")], [("following", "john")])  # genSusp: ask_to_wait
    kitchen = world.poses["kitchen"]  # the robot served another task in the kitchen (the destination)
    world = moved_robot(world, kitchen)
    ctx = make_ctx(task, world=world, suspended=True)
    ctx.plan, ctx.stage_index = full, 3  # remaining: guide(hall, kitchen), say_goodbye
    stale, _ = walk(ctx.remaining, kitchen, world, MOTION)  # the old estimate: ~2 s, robot already there
    c_time, end = task.estimate(ctx, None)
    assert c_time == pytest.approx(executed(task, ctx))
    approach = MOTION.estimate(kitchen, world.poses["john"]).time_s
    greet = task.domain.actions["greet_and_apologise"].constant_cost
    assert greet is not None and c_time >= stale + approach + greet - 1e-9
    assert end is not None and math.dist(end[:2], kitchen[:2]) < 1e-9
    # and Alg. 2's cc from that pose, asked of the waiting agent, is the same plan
    cc = task.request_sp(ctx, SPRequest(SP_COMPLETION, {"pose": kitchen}))
    assert cc.cc == pytest.approx(task.spec.cps * (ctx.age + c_time))


def test_executing_agent_retimes_its_own_remainder(tasks: dict[str, PddlTaskType]) -> None:
    task = tasks["guide_human"]
    ctx = make_ctx(task)
    full = task.update_task(ctx)
    ctx.world = advance(ctx.world, full.stages[:2])  # approached and greeted; asking to follow
    ctx.plan, ctx.stage_index, ctx.stage_started, ctx.now = full, 2, 4.0, 5.0
    est = estimator_for(task).estimate(ctx)
    assert est.source is Source.REMAINING
    remaining = full.stages[2:]
    expected = timed(remaining, ctx.world, ctx.world.poses["robot"]) - 1.0  # 1 s of ask_to_follow ran
    assert est.c_time == pytest.approx(expected)


def test_executing_agent_asked_from_elsewhere_is_suspended_first(tasks: dict[str, PddlTaskType]) -> None:
    """Alg. 2 asks exeDA's cc from dac's end pose: exeDA would suspend (ask John to wait), go
    there, then resume: come back, apologise, ask again — never ``inf`` for 'following'."""
    task = tasks["guide_human"]
    ctx = make_ctx(task)
    full = task.update_task(ctx)
    ctx.world = advance(ctx.world, full.stages[:3])  # John follows
    ctx.plan, ctx.stage_index, ctx.stage_started, ctx.now = full, 3, 0.0, 0.0
    bedroom = ctx.world.poses["bedroom"]
    est = estimator_for(task).estimate(ctx, bedroom)
    assert [s[0] for s in est.steps] == ["approach", "greet_and_apologise", "ask_to_follow", "guide", "say_goodbye"]
    after = ctx.world.updated([("told_to_wait", "john")], [("following", "john")])
    resumed = make_ctx(task, world=moved_robot(after, bedroom), suspended=True)
    assert est.c_time == pytest.approx(executed(task, resumed))


def test_static_strategy_estimates_its_template(task: PddlTaskType) -> None:
    ctx = make_ctx(task, strategy="static")
    est = estimator_for(task).estimate(ctx)
    assert est.source is Source.TEMPLATE
    assert est.c_time == pytest.approx(executed(task, ctx))


def test_unsolvable_state_is_infinite_never_a_crash(tasks: dict[str, PddlTaskType]) -> None:
    task = tasks["guide_human"]
    ctx = make_ctx(task)
    world = ctx.world.updated(delete=[("at", "john", "hall")])  # nobody knows where John is
    est = estimator_for(task).estimate(make_ctx(task, world=world))
    assert est.source is Source.UNSOLVABLE and est.c_time == math.inf and est.end_pose is None
    blocked = StraightLineMotion(blocked=frozenset({ctx.world.poses["kitchen"]}))  # destination unreachable
    params = task.compute_params(make_ctx(task, motion=blocked))
    assert params.c_time == math.inf and params.cost == math.inf


class _TimingOut:
    name = "timing-out"

    def solve(self, problem: object, timeout: float | None = None) -> PlanResult:
        return PlanResult(PlanStatus.TIMEOUT, None, None, self.name, 0.0, message="time-out")


def test_planner_timeout_falls_back_to_the_template_walk(tasks: dict[str, PddlTaskType]) -> None:
    base = tasks["guide_human"]
    task = PddlTaskType(base.spec, base.domain, dict(base.hooks), planner=_TimingOut())  # type: ignore[arg-type]
    est = Estimator(task).estimate(make_ctx(task))
    assert est.source is Source.TEMPLATE and "timed out" in est.note
    assert est.c_time == pytest.approx(executed(base, make_ctx(base, strategy="static")))


def test_cached_by_symbolic_state_and_retimed_when_people_move(tasks: dict[str, PddlTaskType]) -> None:
    task = tasks["guide_human"]
    estimator = Estimator(task)
    ctx = make_ctx(task)
    first = estimator.estimate(ctx)
    assert (estimator.stats.solves, estimator.stats.hits) == (1, 0)
    poses = dict(ctx.world.poses)
    poses["john"] = (0.5, 0.5, 0.0)  # John shuffles within the hall: same symbolic state
    moved = make_ctx(task, world=WorldState(ctx.world.facts, poses, ctx.world.objects))
    second = estimator.estimate(moved)
    assert (estimator.stats.solves, estimator.stats.hits) == (1, 1)
    assert second.steps == first.steps and second.c_time != first.c_time
    assert second.c_time == pytest.approx(executed(task, moved))


def test_estimate_does_not_depend_on_what_was_cached_before(tasks: dict[str, PddlTaskType]) -> None:
    """The cached plan is a function of its key: a cache warmed elsewhere gives the same answer."""
    task = tasks["guide_human"]
    ctx = make_ctx(task)
    cold = Estimator(task).estimate(ctx)
    warm = Estimator(task)
    slow = make_ctx(task, motion=StraightLineMotion(speed=0.1))
    warm.estimate(slow)
    warm.estimate(make_ctx(task, world=moved_robot(ctx.world, ctx.world.poses["kitchen"])))
    assert warm.estimate(ctx) == cold


def test_nearest_place_breaks_ties_by_name() -> None:
    world = WorldState(objects={"b": "place", "a": "place", "r": "robot"},
                       poses={"a": (0.0, 0.0, 0.0), "b": (2.0, 0.0, 0.0)})
    assert nearest_place(world, (1.0, 0.0, 0.0)) == "a"
    assert nearest_place(world, (1.5, 0.0, 0.0)) == "b"
    assert nearest_place(WorldState(), (0.0, 0.0, 0.0)) is None


def test_estimate_checks_fire() -> None:
    with pytest.raises(ValueError, match="c_time"):
        Estimate(-1.0, None, Source.PLAN)
    with pytest.raises(ValueError, match="c_time"):
        Estimate(math.nan, None, Source.PLAN)
    with pytest.raises(ValueError, match="does not fit"):
        Estimate(math.inf, None, Source.PLAN)
    with pytest.raises(ValueError, match="does not fit"):
        Estimate(1.0, None, Source.UNSOLVABLE)
    with pytest.raises(TypeError, match="Source"):
        Estimate(1.0, None, "plan")  # type: ignore[arg-type]


def test_without_world_the_declared_template_time(task: PddlTaskType) -> None:
    ctx = replace(make_ctx(task), world=None)
    est = estimator_for(task).estimate(ctx)
    assert est.source is Source.DECLARED and est.c_time == declared_template_time(task.spec, task.domain) > 0


class _ClosedDoors:
    """Straight lines, but the bedroom is behind a closed door unless doors are ignored."""

    def __init__(self, bedroom: Pose) -> None:
        self.closed = StraightLineMotion(blocked=frozenset({bedroom}))
        self.open = StraightLineMotion()
        self.ignoring = 0

    def estimate(self, start: Pose, goal: Pose) -> object:
        return self.closed.estimate(start, goal)

    def estimate_ignoring_doors(self, start: Pose, goal: Pose) -> object:
        self.ignoring += 1
        return self.open.estimate(start, goal)


def test_a_leg_through_a_door_the_plan_opens_is_timed_with_the_door_open(tasks: dict[str, PddlTaskType]) -> None:
    task = tasks["carry_object"]
    ctx = make_ctx(task)
    motion = _ClosedDoors(ctx.world.poses["bedroom"])
    est = Estimator(task).estimate(make_ctx(task, motion=motion))
    assert est.source is Source.PLAN and math.isfinite(est.c_time), est.note
    assert est.c_time == pytest.approx(executed(task, ctx))  # the same legs as with no door at all
    assert motion.ignoring > 0


@pytest.mark.slow
def test_paper_scenario_trace_does_not_depend_on_what_earlier_runs_cached() -> None:
    """The estimator's cache lives as long as the task type: a second run in the same process
    (warm caches) must write the same trace, byte for byte, as the first."""
    import json

    from experiments.inputs import scenario as scenarios
    from experiments.run.runner import run_scenario

    scn = replace(scenarios.load(scenarios.resolve("paper")), horizon=40.0)  # Alice greeted, decisions on
    runs = [run_scenario(scn, pictures=False).trace.events for _ in range(2)]
    assert any(e["event"] == "decision" and e.get("rule") == "cost" for e in runs[0])
    assert [json.dumps(e, sort_keys=True) for e in runs[0]] == [json.dumps(e, sort_keys=True) for e in runs[1]]


def test_static_strategy_asked_from_elsewhere_applies_the_decision_list(tasks: dict[str, PddlTaskType]) -> None:
    task = tasks["guide_human"]
    ctx = make_ctx(task, strategy="static")
    full = task.update_task(ctx)
    ctx.world = advance(ctx.world, full.stages[:3])  # John follows; eq. 47 says: ask him to wait
    ctx.plan, ctx.stage_index, ctx.stage_started, ctx.now = full, 3, 0.0, 0.0
    est = estimator_for(task).estimate(ctx, ctx.world.poses["bedroom"])
    assert est.source is Source.TEMPLATE
    assert [s[0] for s in est.steps] == ["approach", "greet_and_apologise", "ask_to_follow", "guide", "say_goodbye"]


def test_a_guide_plan_never_moves_with_another_tasks_person(tasks: dict[str, PddlTaskType]) -> None:
    """While another task guides Alice, John's plan gets the robot to John by approaching him,
    not by 'guiding' Alice there (found in the paper run: guide John's estimate walked Alice
    to the hall).  Every step of John's plan is about John."""
    task = tasks["guide_human"]
    ctx0 = make_ctx(task)
    world = ctx0.world
    assert isinstance(world, WorldState)
    world = world.updated([("at", "alice", "livingroom"), ("greeted", "alice"), ("following", "alice")],
                          [("at", "alice", "bedroom")])
    poses = dict(world.poses)
    poses["alice"] = poses["livingroom"]
    world = WorldState(world.facts, poses, world.objects, world.time)
    for suspended in (False, True):
        est = estimator_for(task).estimate(make_ctx(task, world=world, suspended=suspended))
        assert est.steps and all("alice" not in step[1:] for step in est.steps), est.steps


def test_the_robots_first_leg_is_timed_from_where_it_is_not_from_its_place() -> None:
    """The robot's ``at`` fact is its nearest place, possibly metres away (a navigation cut
    between places).  upTsk's travel table times legs leaving that place from the robot's
    real pose: timed from the place's pose, a direct leg was priced through people standing
    there and the plan detoured (session-1 paper scenario, Alice sent to John's destination:
    without it guide Alice was predicted 21.6 s and took 88.6 s)."""
    from planners.problem import travel_table

    objects = {"robot": "robot", "a": "place", "b": "place", "c": "place"}
    poses = {"a": (0.0, 0.0, 0.0), "b": (10.0, 0.0, 0.0), "c": (0.0, 10.0, 0.0), "robot": (6.0, 0.0, 0.0)}
    world = WorldState(frozenset({("at", "robot", "a")}), poses, objects)
    motion = StraightLineMotion()
    table = travel_table(world, motion, 12.0, opens_doors=False)
    assert table["a", "b"] == pytest.approx(motion.estimate(poses["robot"], poses["b"]).time_s)
    assert table["a", "c"] == pytest.approx(motion.estimate(poses["robot"], poses["c"]).time_s)
    assert table["b", "c"] == pytest.approx(motion.estimate(poses["b"], poses["c"]).time_s)  # other legs as before


def test_after_a_leg_to_a_person_the_next_leg_starts_where_they_stand() -> None:
    """The robot stops ``APPROACH`` metres short of a person, who then follows it: the next leg
    is timed from the person's position, so the live motion model does not route around the
    very person being guided (session-1 paper scenario: without it guide Alice was predicted
    43 s and took 99 s)."""
    starts: list[Pose] = []

    class Recording(StraightLineMotion):
        def estimate(self, start: Pose, goal: Pose) -> Any:
            starts.append(start)
            est = super().estimate(start, goal)
            # stop 1 m short, like an approach pose
            d = math.dist(start[:2], goal[:2])
            k = max(0.0, (d - 1.0) / d) if d > 0 else 0.0
            end = (start[0] + k * (goal[0] - start[0]), start[1] + k * (goal[1] - start[1]), 0.0)
            return replace(est, end_pose=end)

    objects = {"robot": "robot", "john": "person", "dest": "place"}
    poses = {"robot": (0.0, 0.0, 0.0), "john": (5.0, 0.0, 0.0), "dest": (5.0, 5.0, 0.0)}
    world = WorldState(frozenset(), poses, objects)
    stages = [Stage("approach", ("robot", "john"), skill="navigate", data={"to": "john"}),
              Stage("guide", ("robot", "john", "dest"), skill="navigate", data={"to": "dest"})]
    walk(stages, poses["robot"], world, Recording())
    assert [s[:2] for s in starts] == [(0.0, 0.0), (5.0, 0.0)]


def test_a_plan_estimated_across_a_closed_door_opens_it() -> None:
    """The reference table keeps closed doors closed (but for door_between pairs, which the
    plan may open): carry's first estimate is a plan through the door it opens, and finite."""
    from experiments.inputs import scenario as scenarios
    from experiments.run.options import RunOptions
    from experiments.run.runner import build_robot

    loop, _ = build_robot(scenarios.load(scenarios.resolve("carry")), RunOptions(seed=1))
    trace = loop.run(until=0.5)
    start = next(e for e in trace.events if e["event"] == "command" and e["flag"] == "start")
    assert isinstance(start["predicted_s"], float) and math.isfinite(start["predicted_s"])


class _Crowded:
    """Straight lines; the bedroom is unreachable while people stand in the way, not otherwise."""

    def __init__(self, bedroom: Pose) -> None:
        self.crowded = StraightLineMotion(blocked=frozenset({bedroom}))
        self.free = StraightLineMotion()

    def estimate(self, start: Pose, goal: Pose) -> object:
        return self.crowded.estimate(start, goal)

    def estimate_ignoring_people(self, start: Pose, goal: Pose) -> object:
        return self.free.estimate(start, goal)


def test_people_in_the_way_slow_a_leg_but_never_cut_it(tasks: dict[str, PddlTaskType]) -> None:
    """upTsk's travel table: a leg unreachable only because of people gets the free
    building's time (they move; the skill waits for them), so the plan exists; a leg the
    motion model calls unreachable with nobody in the way stays cut."""
    from planners.problem import travel_table

    ctx = make_ctx(tasks["guide_human"])
    world = ctx.world
    bedroom = world.poses["bedroom"]
    table = travel_table(world, _Crowded(bedroom), 10.0, opens_doors=True)
    free = travel_table(world, StraightLineMotion(), 10.0, opens_doors=True)
    into = [(a, b) for (a, b) in table if b == "bedroom"]
    assert into and all(table[k] == pytest.approx(free[k]) for k in into)
    walled = travel_table(world, StraightLineMotion(blocked=frozenset({bedroom})), 10.0, opens_doors=True)
    assert all(math.isinf(walled[k]) for k in into)  # no estimate_ignoring_people: nothing to fall back on


@pytest.mark.slow
def test_a_waiting_task_is_estimated_from_the_state_the_executing_task_leaves() -> None:
    """Compound: while carry holds the vase, cook (which needs an empty hand and knows no
    vase) was estimated from the world now and came out unsolvable, so every decision
    between them compared inf with inf.  Estimated from what carry's suspension (for a
    start now) or completion (for Alg. 2's cc after it) leaves, cook is finite."""
    from pathlib import Path

    from experiments.inputs import scenario as scenarios
    from experiments.run.options import RunOptions
    from experiments.run.runner import build_robot

    path = Path(__file__).resolve().parents[2] / "experiments" / "sweep" / "specs" / "scenarios" / "compound.toml"
    loop, _ = build_robot(scenarios.load(scenarios.resolve(str(path))), RunOptions(seed=1))
    trace = loop.run(until=35.001)  # the first decision after cook's request at 35, carry holding the vase
    held = [e for e in trace.events if e["event"] == "decision" and e.get("dac") == "d2" and e.get("exeDA") == "d1"]
    assert held, "cook must be compared with carry while carry runs"
    for e in held:
        assert all(math.isfinite(float(e[k])) for k in ("cTime_dac", "cc_dac", "c_switch", "c_wait")), e
    # the handover itself: carry's suspension puts the vase down, its completion too
    h = loop.harmoniser
    effects = h.handover("d2")
    assert effects is not None and any(f[0] == "hand_empty" for f in effects.add)
    assert h.handover("d1") is None  # the executing task assumes nothing about itself


class _ShutDoor:
    """A motion model with one closed door on the way from ``a`` to ``b``: ``estimate`` finds no path,
    ``estimate_ignoring_doors`` the path with the door open (robot.estimator.MotionEstimator's pair)."""

    def __init__(self) -> None:
        self.free = StraightLineMotion()

    def estimate(self, start: Pose, goal: Pose) -> object:
        if {start[0], goal[0]} == {0.0, 10.0}:
            return MotionEstimate(False, math.inf, math.inf, None)
        return self.free.estimate(start, goal)

    def estimate_ignoring_doors(self, start: Pose, goal: Pose) -> object:
        return self.free.estimate(start, goal)


def test_a_closed_door_is_a_wall_for_a_domain_that_cannot_open_it(tasks: dict[str, PddlTaskType]) -> None:
    """The world's door facts describe the house; only a domain whose plans can open a door times a leg
    through a closed one as open (water_plants once planned through a door it had no action to open,
    and its move failed on the spot)."""
    from planners.loader import load_task
    from planners.problem import travel_table

    objects = {"robot": "robot", "d": "door", "a": "place", "b": "place"}
    poses = {"a": (0.0, 0.0, 0.0), "b": (10.0, 0.0, 0.0)}
    facts = frozenset({("door_between", "d", "a", "b"), ("door_between", "d", "b", "a")})
    world = WorldState(facts, poses, objects)
    assert math.isinf(travel_table(world, _ShutDoor(), 5.0, opens_doors=False)["a", "b"])
    assert travel_table(world, _ShutDoor(), 5.0, opens_doors=True)["a", "b"] == pytest.approx(
        StraightLineMotion().estimate(poses["a"], poses["b"]).time_s)
    opened = WorldState(facts | {("open", "d")}, poses, objects)  # an open door: the leg as the model times it
    assert travel_table(opened, StraightLineMotion(), 5.0, opens_doors=True)["a", "b"] == pytest.approx(
        StraightLineMotion().estimate(poses["a"], poses["b"]).time_s)
    assert all(tasks[n].domain.opens_doors for n in ("cook", "carry_object", "guide_human", "human_fell"))
    plants = load_task(Path(__file__).resolve().parents[2] / "experiments/sweep/specs/tasks/water_plants")
    assert not plants.domain.opens_doors
