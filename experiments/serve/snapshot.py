"""What ``GET /state`` answers: the session at one moment, read in the thread that owns the loop.

:func:`snapshot` reads the harmoniser (``exeDA``, ``irrDA``, ``idleDA``, the mode), every agent
(task type, arguments, FSM state, the schedule parameters of its last report — what Alg. 2
reads — and how it ended; the live ones first), the robot (pose, the path it follows, its trail), the people, the
doors, devices and held objects, and the hazards that hold.  It only reads: nothing it calls
changes the run (no world snapshot, whose caches belong to the run), so publishing states
changes no trace.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

from experiments.run.simulation import SimulatedWorld
from tasker.loop import SimulationLoop

TRAIL = 400
"""The robot's trail is its last this many recorded samples (thinned to half)."""


def snapshot(loop: SimulationLoop, sim: SimulatedWorld, *, ended: Mapping[str, Mapping[str, Any]],
             decision: Mapping[str, Any] | None, task_types: Sequence[Mapping[str, Any]] = ()) -> dict[str, Any]:
    """The state (JSON-ready once :func:`tasker.trace.encode` has rounded it; see the module docstring).

    ``agents`` lists the live ones first, then the ended ones (each group in the order of their
    requests); ``task_types`` is passed through (:func:`experiments.serve.examples.task_types`)."""
    harm = loop.harmoniser
    roles: dict[str | None, str] = {a: "idleDA" for a in harm.idle_da}
    roles |= {harm.exe_da: "exeDA", harm.irr_da: "irrDA"}
    agents = []
    for a in loop.all_agents:
        report = a.report
        params = report.params if report is not None else None
        agents.append({
            "id": a.id, "task": a.ctx.task_type, "args": dict(a.ctx.args), "state": a.state.value,
            "superstate": a.state.superstate, "role": roles.get(a.id), "requested_at": a.ctx.request_time,
            "params": _params(params), "ended": dict(ended[a.id]) if a.id in ended else None})
    agents.sort(key=lambda a: a["ended"] is not None)  # stable: live first, then ended, each in request order
    x, y, yaw = sim.robot_pose()
    follower = getattr(sim.skill, "follower", None)
    path = [list(p) for p in getattr(follower, "path", ())] if follower is not None else []
    trail: list[list[float]] = []
    for s in sim.trajectory[-TRAIL::2]:
        if not trail or trail[-1] != [s[1], s[2]]:  # standing still adds nothing to draw
            trail.append([s[1], s[2]])
    hazards = [{"agent": h.agent, "name": h.name, "fact": list(h.fact), "since": h.since, "budget_s": h.budget_s}
               for h in (harm.hazards() if harm.hazards is not None else ())]
    return {
        "t": loop.now, "mode": harm.mode.value, "exeDA": harm.exe_da, "irrDA": harm.irr_da,
        "idleDA": list(harm.idle_da), "agents": agents, "decision": dict(decision) if decision else None,
        "robot": {"pose": [x, y, yaw], "path": path, "trail": trail,
                  "skill": type(sim.skill).__name__.lower() if sim.skill is not None else None},
        "people": [{"name": p.name, "pose": [p.x, p.y, p.yaw], "posture": p.posture, "following": p.following,
                    "waiting": p.waiting} for p in sim.people],
        "doors": dict(sim.door_open), "devices": dict(sim.device_state), "held": sorted(sim.held),
        "hazards": hazards, "task_types": [dict(t) for t in task_types],
    }


def _params(params: Any) -> dict[str, Any] | None:
    """A report's schedule parameters by field (``cost``, ``cps``, ``c_time``, ``deadline``, ...)."""
    if params is None or not dataclasses.is_dataclass(params):
        return None
    return {f.name: getattr(params, f.name) for f in dataclasses.fields(params) if f.name != "task_type"}
