"""What arrives over HTTP, read as ``tasker check`` reads a scenario's actions.

A body of ``POST /requests`` is a ``[[requests]]`` entry, one of ``POST /world`` a
``[[world_events]]`` entry, one of ``PATCH /requests/{id}`` the ``args`` of a ``[[changes]]``
entry: each is read by the scenario's own reader (:func:`experiments.inputs.actions.read_actions`)
and checked against the world and the task types by the scenario's own cross-references
(:func:`experiments.inputs.crossref.check_robot`), so a refusal carries the message ``tasker
check`` gives for the same entry in a file, located at the body's field (``args.person``)
instead of a file's line.  A refusal is a :class:`Refused` with its HTTP status.
"""

from __future__ import annotations

import dataclasses
import json
import math
import warnings
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

from experiments.inputs.actions import NO_REQUESTS, TimedAction, read_actions
from experiments.inputs.crossref import arg_problem, arg_types, check_robot, validate_request, world_objects
from experiments.inputs.fields import ScenarioError
from experiments.inputs.robot_scenario import RobotScenario
from tasker.errors import Refused as Refused  # defined there; re-exported here
from tasker.support.reader import InputError, Table
from tasker.task import TaskType

if TYPE_CHECKING:
    from robot.spec import WorldSpec

BAD, NOT_FOUND, CONFLICT, INVALID, UNAVAILABLE = 400, 404, 409, 422, 503
"""The HTTP statuses of a refusal: not JSON, no such agent, the agent has ended, a field is wrong,
the session is stopping."""

REQUEST_FIELDS = ("priority", "deadline")
"""Schedule parameters a request body may give beside ``args`` (they are request arguments,
:mod:`experiments.inputs.request_fields`, and are moved into ``args``)."""


def _located(exc: InputError, where: str, prefix: str) -> Refused:
    """The reader's fault at the body's own field (``requests[0].args.person`` -> ``args.person``)."""
    field = exc.field
    if field == prefix:
        field = ""
    elif field.startswith(prefix + "."):
        field = field[len(prefix) + 1:]
    return Refused(INVALID, where, exc.message, field)


def _object(body: Any, where: str) -> dict[str, Any]:
    if not isinstance(body, dict):
        raise Refused(INVALID, where, f"expected a JSON object, got {json.dumps(body)[:80]}")
    if "t" in body:
        raise Refused(INVALID, where, "an action happens when it arrives: the session sets its time, "
                                      "so a body gives no t", "t")
    return body


def _checked(scn: RobotScenario, key: str, entry: dict[str, Any], t: float, where: str,
             tasks: Iterable[TaskType]) -> tuple[TimedAction, list[str]]:
    """``entry`` as the one ``[[key]]`` of a scenario like ``scn``, read and cross-checked; its warnings."""
    data: dict[str, Any] = {key: [{"t": t, **entry}]}
    if scn.objects:  # the scenario's own objects and devices: a request or an event may name them
        data["objects"] = {n: dict(o) for n, o in scn.objects.items()}
    if scn.devices:
        data["devices"] = {n: dict(d) for n, d in scn.devices.items()}
    top = Table(where, data, error_class=ScenarioError)
    try:
        actions = read_actions(top, world_events=True)
        one = dataclasses.replace(scn, source=where, actions=actions, people={}, strategies={},
                                  scheduler_options={}, horizon=math.inf)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_robot(one, top, list(tasks))
    except InputError as exc:
        raise _located(exc, where, f"{key}[0]") from None
    said = [str(w.message).removeprefix(f"{where}: ").removeprefix(f"{key}[0].") for w in caught]
    return actions[0], [s for s in said if NO_REQUESTS not in s]


def read_request(body: Any, *, t: float, scn: RobotScenario, tasks: Iterable[TaskType]
                 ) -> tuple[TimedAction, list[str]]:
    """``POST /requests``: ``{"task", "args", "priority"?, "deadline"?}`` as a ``[[requests]]`` entry at ``t``."""
    where = "POST /requests"
    entry = dict(_object(body, where))
    args = entry.get("args", {})
    for name in REQUEST_FIELDS:
        if name in entry:
            if isinstance(args, dict) and name in args:
                raise Refused(INVALID, where, f"given twice, here and in args.{name}: give it once", name)
            entry["args"] = args = {**(args if isinstance(args, dict) else {}), name: entry.pop(name)}
    return _checked(scn, "requests", entry, t, where, tasks)


def read_world(body: Any, *, t: float, scn: RobotScenario, tasks: Iterable[TaskType]) -> tuple[TimedAction, list[str]]:
    """``POST /world``: one event of the world's vocabulary (``{"posture": ["peter", "fallen"]}``,
    ``{"door": ["d1", false]}``, ...) as a ``[[world_events]]`` entry at ``t``."""
    where = "POST /world"
    entry = _object(body, where)
    if "after" in entry:
        raise Refused(INVALID, where, "a live event happens when it arrives: post it once the task has "
                                      "finished (no after)", "after")
    return _checked(scn, "world_events", entry, t, where, tasks)


def read_change(body: Any, *, where: str, task: TaskType, args: Mapping[str, Any], world: WorldSpec) -> dict[str, Any]:
    """``PATCH /requests/{id}``: ``{"priority"?, "deadline"?, "args"?}`` — the arguments to change,
    checked as a ``[[changes]]`` entry is: the whole new set by the task type, and each one given
    that names a thing against the world (``world``: the run's :class:`robot.spec.WorldSpec`)."""
    f = Table(where, _object(body, where), error_class=ScenarioError)
    try:
        given = dict(f.table("args", {}).items())
        for name in REQUEST_FIELDS:
            if name in f:
                if name in given:
                    raise f.error(name, f"given twice, here and in args.{name}: give it once")
                given[name] = f.raw(name)
        f.done()
        if not given:
            raise f.error(None, f"nothing to change: give {', '.join(REQUEST_FIELDS)} or args")
        checked = Table(where, {"args": given}, error_class=ScenarioError)
        validate_request(checked, task, {**args, **given})
        types = arg_types(task)
        for name, value in given.items():
            problem = arg_problem(task, name, value, types, world_objects(world), world.name)
            if problem is not None:
                raise checked.table("args").error(name, problem)
    except InputError as exc:
        raise _located(exc, where, "") from None
    return given


def read_reason(reason: str | None, who: str) -> str:
    """A termination's reason (``?reason=``), or who asked."""
    return reason if reason else f"terminated by {who}"
