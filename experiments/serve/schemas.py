"""The OpenAPI description of the live API's bodies and refusals (``/openapi.json``).

The bodies are read by the scenario file's own reader (:mod:`experiments.serve.bodies`), not
by these schemas: they document, for a client, what that reader takes.
"""

from __future__ import annotations

from typing import Any

from experiments.serve.strict import MAX_BODY_BYTES

_ARGS = {"type": "object", "description": "the task type's arguments (``tasker domains``)",
         "additionalProperties": True}
REQUEST_SCHEMA: dict[str, Any] = {
    "type": "object", "required": ["task"], "additionalProperties": False,
    "properties": {"task": {"type": "string", "description": "a task type of the session"}, "args": _ARGS,
                   "priority": {"type": "integer", "description": "static priority, higher is more urgent"},
                   "deadline": {"type": "number", "description": "absolute simulated time to be done by [s]"}}}
"""A request's body; its ``example`` is the served scenario's first request (:func:`with_example`)."""
CHANGE_SCHEMA: dict[str, Any] = {
    "type": "object", "additionalProperties": False,
    "properties": {"priority": REQUEST_SCHEMA["properties"]["priority"],
                   "deadline": REQUEST_SCHEMA["properties"]["deadline"], "args": _ARGS},
    "example": {"priority": 3}}
WORLD_SCHEMA: dict[str, Any] = {
    "type": "object", "description": "exactly one of posture, door, walk, add, delete, device, move "
                                     "(docs/scenarios.md, [[world_events]]), and an optional note",
    "properties": {"posture": {"type": "array", "description": "[person, standing|sitting|fallen]"},
                   "door": {"type": "array", "description": "[door, true|false]"},
                   "walk": {"type": "array", "description": "[person, x, y]"},
                   "device": {"type": "array", "description": "[device, state]"},
                   "move": {"type": "array", "description": "[object, place]"},
                   "add": {"type": "array", "description": "facts to add"},
                   "delete": {"type": "array", "description": "facts to delete"},
                   "note": {"type": "string"}},
    "example": {"posture": ["peter", "fallen"], "note": "Peter falls"}}

Responses = dict[int | str, dict[str, Any]]
"""What FastAPI's ``responses=`` takes."""

REFUSED: dict[str, Any] = {"description": "refused: the body's field and what was expected",
           "content": {"application/json": {"example": {
               "detail": "POST /requests: args.person: no person 'jon' in world 'paper'; did you mean 'john'?",
               "field": "args.person", "message": "no person 'jon' in world 'paper'; did you mean 'john'?"}}}}
GUARDED: Responses = {400: {"description": "the Host header is not this server's (or a malformed call)"},
           401: {"description": "the session has a token and the call does not carry it"},
           403: {"description": "the call comes from a page of another origin"}}
"""What every call may be refused with (:mod:`experiments.serve.guard`)."""
WITH_BODY: Responses = {**GUARDED, 413: {"description": f"the body is larger than {MAX_BODY_BYTES} bytes"},
             415: {"description": "the body is not sent as application/json"}, 422: REFUSED}


def body(schema: dict[str, Any]) -> dict[str, Any]:
    """The ``openapi_extra`` of a call that takes ``schema`` as its JSON body."""
    return {"requestBody": {"required": True, "content": {"application/json": {"schema": schema}}}}


def with_example(schema: dict[str, Any], first: dict[str, Any] | None) -> dict[str, Any]:
    """``schema`` with ``first`` (the served scenario's first request, if any) as its example."""
    return schema if first is None else {**schema, "example": {"task": first["task"], "args": first["args"]}}
