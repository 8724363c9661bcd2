"""What ``GET /state`` says of each task type: its arguments, and a request of it the world can take.

The live page's request form lists every task type of the session and starts on the first one
the world can take, with that request's arguments filled in: a new user's first click should
not be refused.  :func:`task_types` finds, for each type, the served scenario's first request of
it, or else arguments made of the first object of the world (or the scenario) of the type each
argument names — and keeps it only if the session's own check of a request body
(:func:`experiments.serve.bodies.read_request`) accepts it; otherwise it says why not (carrying
an item in a world without items, cooking without a pan).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

from experiments.inputs.crossref import arg_problem, arg_types, world_objects
from experiments.inputs.robot_scenario import RobotScenario
from experiments.serve import bodies
from tasker.task import TaskType

if TYPE_CHECKING:
    from robot.spec import WorldSpec


def task_types(scn: RobotScenario, tasks: Iterable[TaskType], world: WorldSpec) -> list[dict[str, Any]]:
    """For each task type: ``name``, ``args`` (name, type, required), ``example`` (arguments of a
    request the world takes, or ``None``) and ``refused`` (why there is none, or ``None``).
    ``world``: the session's :class:`robot.spec.WorldSpec`."""
    tasks = list(tasks)
    objects = world_objects(world) | {n: o["type"] for n, o in scn.objects.items()} \
        | {n: d["type"] for n, d in scn.devices.items()}
    out = []
    for task in tasks:
        given = next((a.fields["args"] for a in scn.actions if a.kind == "request"
                      and a.fields["task"] == task.name), None)
        args = dict(given) if given is not None else _made_up(task, objects, world.name)
        try:
            bodies.read_request({"task": task.name, "args": args}, t=0.0, scn=scn, tasks=tasks)
            example, refused = args, None
        except bodies.Refused as exc:
            example, refused = None, str(exc).removeprefix("POST /requests: ")
        out.append({"name": task.name, "args": [{"name": s.name, "type": s.type, "required": s.required}
                                                for s in task.arg_specs],
                    "example": example, "refused": refused})
    return out


def _made_up(task: TaskType, objects: Mapping[str, str], world: str) -> dict[str, Any]:
    """Each required argument that names an object: the first object (by name) it may name."""
    types = arg_types(task)
    args: dict[str, Any] = {}
    for spec in task.arg_specs:
        if spec.required and spec.name in types:
            fits = (n for n in sorted(objects) if arg_problem(task, spec.name, n, types, objects, world) is None)
            first = next(fits, None)
            if first is not None:
                args[spec.name] = first
    return args
