"""The recorded comparisons of step 3, recomputed by both cost models on hand-made geometry.

The original verification recorded, at t = 2512.7 and 2521.1, Alg. 2 comparing guide John
(``dac``, suspended with *save*) with guide Alice (``exeDA``, still approaching her).
:func:`geometry` puts the robot, John and Alice where those rows put them, with
straight-line distances equal to the ones the record implies (the layout of
:func:`experiments.paper.reconstruction.derive`); :func:`compare` runs our Alg. 2 on the
parameters the bundled ``guide_human`` computes there under a cost model, with
:class:`~planners.examples.StraightLineMotion` as the motion model: the record's robot, at the
speed :func:`experiments.paper.reconstruction.derive` reads off the record (its step 7; the
world file of ``paper-2019`` drives at it too), turning at ours (1 rad/s: the record shows no turn).
Under the original model the result must be the recorded one; under ours it says what our
model makes of the very situation the record describes (``docs/paper.md``).
"""

from __future__ import annotations

import random
from typing import Any

import numpy as np

from experiments.paper import reconstruction as rec

RECORDED = {2512.7: (5.967, 2.640), 2521.1: (2.248, 2.861)}
"""(c_switch, c_wait) of guide John over guide Alice at the two rows, as recorded."""
PERSONS = ("john", "alice")


def geometry(t: float) -> Any:
    """The world at row ``t`` (a :class:`tasker.world.WorldState`): the robot on the two circles
    the row's remaining paths give (the first intersection), John where the reconstruction
    has him, Alice seated, each at a place of their own."""
    from tasker.world import WorldState

    lay = rec.derive()
    john = dict(lay.john_walk).get(t, lay.john_waited)
    _, sj, sa, _ = next(r for r in rec.RECORD_WALK if r[0] == t)
    j, a, dj = np.array(john), np.array(lay.alice), np.array(lay.john_dest)
    robot = rec._circles(j, sj - float(np.linalg.norm(j - dj)), a, sa - float(np.linalg.norm(a)))[0]
    r = (float(robot[0]), float(robot[1]), 0.0)
    poses = {"robot": r, "robot_spot": r, "john": (*john, 0.0), "john_spot": (*john, 0.0),
             "alice": (*lay.alice, 0.0), "alice_spot": (*lay.alice, 0.0),
             "alice_destination": (*lay.alice_dest, 0.0), "john_destination": (*lay.john_dest, 0.0)}
    places = ("alice_destination", "john_destination", "robot_spot", "john_spot", "alice_spot")
    objects = {"robot": "robot", "john": "person", "alice": "person", **{p: "place" for p in places}}
    facts = frozenset({("at", "robot", "robot_spot"), ("at", "john", "john_spot"),
                       ("at", "alice", "alice_spot")})
    return WorldState(facts, poses, objects, t)


def compare(t: float, model: str, hysteresis: float = 1.0) -> dict[str, Any]:
    """Alg. 2's record of guide John (dac) over guide Alice (exeDA) at row ``t`` under ``model``."""
    from experiments.paper.report import ORIGINAL_FACTORS
    from planners.bundled import task_types
    from planners.examples import StraightLineMotion
    from planners.pddl_task import PddlTaskType
    from planners.taskspec import COST_MODEL_ARG, COST_MODELS
    from tasker.schedulers.alg2 import Alg2
    from tasker.schedulers.base import Candidate, ScheduleView
    from tasker.task import Strategy, TaskContext

    task = next(tt for tt in task_types() if isinstance(tt, PddlTaskType) and tt.spec.original_costs is not None
                and tt.spec.original_costs.destination is not None)
    costs = task.spec.original_costs
    assert costs is not None
    world = geometry(t)
    motion = StraightLineMotion(speed=rec.derive().robot_speed)
    ctx = {}
    for k, person in enumerate(PERSONS):
        args: dict[str, Any] = {costs.person[1:]: person, (costs.destination or "$")[1:]: f"{person}_destination"}
        if model != COST_MODELS[0]:
            args[COST_MODEL_ARG] = model
            args.update(zip((f[1:] for f in costs.factors or ()), ORIGINAL_FACTORS[person], strict=True))
        c = TaskContext(agent=person, task_type=task.name, args=task.validate_args(args), request_time=t,
                        rng=random.Random(k), strategy=Strategy(), world=world, motion=motion)
        c.suspended = person == "john"  # guide John was suspended (save) when guide Alice took over
        c.now = t
        ctx[person] = c
    cands = {p: Candidate(p, task.name, task.compute_params(c), t, k) for k, (p, c) in enumerate(ctx.items())}
    view = ScheduleView(now=t, exe=cands["alice"], candidates=[cands["john"]],
                        req_sp=lambda agent, req: task.request_sp(ctx[agent], req),
                        fresh=lambda agent: task.compute_params(ctx[agent]))
    record = Alg2(hysteresis=hysteresis).schedule(view).record
    assert record is not None and record["rule"] == "cost"
    return dict(record)


def rows() -> list[tuple[float, str, float, float, float | None, float | None]]:
    """``(t, model, c_switch, c_wait, recorded c_switch, recorded c_wait)`` for both rows and models."""
    from planners.taskspec import COST_MODELS

    out = []
    for t, (cs, cw) in sorted(RECORDED.items()):
        for model in reversed(COST_MODELS):
            r = compare(t, model)
            original = model != COST_MODELS[0]
            out.append((t, model, float(r["c_switch"]), float(r["c_wait"]), cs if original else None,
                        cw if original else None))
    return out
