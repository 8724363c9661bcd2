"""Benchmark: what a plan-based estimate costs per report, against the old stale walk.

    python benchmarks/bench_estimates.py [--repeat N]

For each case, a waiting agent whose plan is stale (it was suspended after ``k`` stages,
the robot went elsewhere) is asked for its schedule parameters, as ``wait`` does at
``repRate``.  Measured in the same run, medians per report:

* ``stale walk`` — the old estimate: the remaining stages of the old plan walked with
  the motion model (the baseline; it is fast and wrong);
* ``cold`` — a plan from the hypothetical state with every cache empty (planner call);
* ``cached`` — the same state again (the symbolic cache answers, legs re-timed);
* ``person moved`` — the symbolic state is unchanged but a person moved, so the live
  motion model is asked afresh (in the MuJoCo world its cache is keyed on the scene).

Cases: the four bundled task types on their ``[example]`` worlds with the straight-line
stand-in motion model, and guide_human / human_fell in the paper's apartment with the
OMPL-roadmap motion model of ``robot/``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from planners.bundled import task_types  # noqa: E402
from planners.estimates import Estimator, moved_robot, walk  # noqa: E402
from planners.examples import StraightLineMotion, example_context  # noqa: E402
from planners.pddl_task import PddlTaskType  # noqa: E402
from planners.stages import robot_name  # noqa: E402
from tasker.task import Strategy, TaskContext  # noqa: E402
from tasker.world import WorldState  # noqa: E402


def median_s(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def stale_context(task: PddlTaskType, ctx: TaskContext) -> TaskContext:
    """``ctx`` after the first half of its plan ran, a suspension, and the robot leaving."""
    plan = task.update_task(ctx)
    world = ctx.world
    assert isinstance(world, WorldState)
    k = max(1, len(plan.stages) // 2)
    for s in plan.stages[:k]:
        world = world.updated([tuple(f) for f in s.data["add"]], [tuple(f) for f in s.data["delete"]])
    suspension = task.generate_suspension(_with(ctx, world=world, plan=plan, stage_index=k, suspended=True))
    for s in suspension.stages:
        world = world.updated([tuple(f) for f in s.data["add"]], [tuple(f) for f in s.data["delete"]])
    places = sorted(n for n, t in world.objects.items() if t == "place" and n in world.poses)
    here = next((f[2] for f in world.matching("at") if f[1] == robot_name(world)), None)
    elsewhere = next((p for p in reversed(places) if p != here), places[0])
    return _with(ctx, world=moved_robot(world, world.poses[elsewhere]), plan=plan, stage_index=k, suspended=True)


def _with(ctx: TaskContext, **kw: object) -> TaskContext:
    out = TaskContext(ctx.agent, ctx.task_type, dict(ctx.args), ctx.request_time, ctx.rng, ctx.strategy,
                      ctx.now, ctx.world, ctx.core, ctx.motion, ctx.memory)
    for k, v in kw.items():
        setattr(out, k, v)
    return out


def nudged(ctx: TaskContext, dx: float) -> TaskContext:
    """The same symbolic state with every person ``dx`` metres further east."""
    world = ctx.world
    assert isinstance(world, WorldState)
    poses = dict(world.poses)
    for n, t in world.objects.items():
        if t == "person" and n in poses:
            x, y, yaw = poses[n]
            poses[n] = (x + dx, y, yaw)
    return _with(ctx, world=WorldState(world.facts, poses, world.objects, world.time), plan=ctx.plan,
                 stage_index=ctx.stage_index, suspended=ctx.suspended)


def measure(label: str, task: PddlTaskType, ctx: TaskContext, repeat: int,
            scene_nudge: Callable[[float], None] | None = None) -> dict[str, float]:
    """Medians per report; "moved" alternates people by 10 cm before each report, so a motion
    model that caches by scene (robot/) answers afresh, as it does while people walk."""
    world = ctx.world
    assert isinstance(world, WorldState)
    pose = world.poses[robot_name(world)]
    moved = [nudged(ctx, 0.1), ctx]
    flip = [0]

    def step() -> TaskContext:
        flip[0] ^= 1
        if scene_nudge is not None:
            scene_nudge(0.1 if flip[0] else 0.0)
        return moved[flip[0] ^ 1]

    def stale(c: TaskContext) -> object:
        w = c.world
        assert isinstance(w, WorldState)
        return walk(c.remaining, pose, w, c.motion)

    def cold() -> object:
        task.planner.clear_cache()
        return Estimator(task).estimate(ctx)

    warm = Estimator(task)
    warm.estimate(ctx)
    row = {"stale walk": median_s(lambda: stale(ctx), repeat),
           "stale walk, moved": median_s(lambda: stale(step()), repeat),
           "cold": median_s(cold, max(3, repeat // 10)),
           "cached": median_s(lambda: warm.estimate(ctx), repeat),
           "cached, moved": median_s(lambda: warm.estimate(step()), repeat)}
    if scene_nudge is not None:
        scene_nudge(0.0)
    old, _ = stale(ctx)
    new = warm.estimate(ctx)
    print(f"{label:32s} " + "  ".join(f"{k} {v * 1e3:7.3f}" for k, v in row.items())
          + f"   cTime stale {old:5.1f} s, plan {new.c_time:5.1f} s")
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=200)
    args = ap.parse_args(argv)
    tasks = {t.name: t for t in task_types()}
    rows = []
    print("median ms per report (one estimate); cold = planner call with empty caches")
    for name, task in sorted(tasks.items()):
        assert isinstance(task, PddlTaskType)
        ctx = example_context(task, motion=StraightLineMotion(), strategy=Strategy())
        if ctx is None:
            continue
        rows.append(measure(f"{name} (example world)", task, stale_context(task, ctx), args.repeat))
    from robot.sim import Simulation  # the MuJoCo world; imported late (slow)

    sim = Simulation("paper")
    for name, request in (("guide_human", {"person": "alice", "destination": "alice_destination"}),
                          ("human_fell", {"person": "sara"})):
        task = tasks[name]
        assert isinstance(task, PddlTaskType)
        snap = sim.snapshot()
        if name == "human_fell":
            snap = snap.updated([("fallen", request["person"])])
        ctx = example_context(task, motion=sim.motion, world=snap)
        assert ctx is not None
        ctx.args = task.validate_args(request)

        def scene_nudge(dx: float) -> None:
            for p in sim.people:
                sim.scene.set_person(p.name, p.x + dx, p.y, p.posture)

        rows.append(measure(f"{name} (paper world, OMPL)", task, stale_context(task, ctx),
                            max(20, args.repeat // 10), scene_nudge))
    for key, base in (("cold", "stale walk"), ("cached", "stale walk"), ("cached, moved", "stale walk, moved")):
        ratios = [r[key] / r[base] for r in rows]
        print(f"{key:13s} / {base:17s}: median {statistics.median(ratios):8.1f}x  "
              f"(min {min(ratios):.1f}x, max {max(ratios):.1f}x)")
    worst = max(r["cached, moved"] for r in rows)
    print(f"worst cached estimate with people moving: {worst * 1e3:.2f} ms per report")
    return 0


if __name__ == "__main__":
    sys.exit(main())
