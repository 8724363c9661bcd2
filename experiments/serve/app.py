"""The HTTP API of a live session (FastAPI; its OpenAPI schema is at ``/openapi.json``).

Every handler either reads what the session published (``GET /state``, ``GET /events``,
``GET /``) or queues an :class:`experiments.serve.session.Ask` for the session's thread and
waits for its answer: a handler never touches the loop.  Bodies are read by
:mod:`experiments.serve.bodies` (the scenario reader's messages); a refusal is a 4xx whose JSON
body is ``{"detail", "field", "message"}``.  With a token, every call must carry it, as
``Authorization: Bearer TOKEN`` or ``?token=TOKEN`` (the live page passes on its own).
"""

from __future__ import annotations

import asyncio
import hmac
from collections.abc import AsyncIterator, Awaitable, Callable
from typing import Any

from fastapi import FastAPI, Query, Request
from fastapi.responses import HTMLResponse, JSONResponse, Response, StreamingResponse

from experiments.serve import bodies
from experiments.serve.bodies import Refused
from experiments.serve.session import Ask, Session

REPLY_S = 120.0
"""How long a handler waits for the session's answer (it builds the robot first, a few seconds)."""

POLL_S = 0.1
"""How often ``GET /events`` looks for new trace lines."""

_ARGS = {"type": "object", "description": "the task type's arguments (``tasker domains``)",
         "additionalProperties": True}
REQUEST_SCHEMA = {
    "type": "object", "required": ["task"], "additionalProperties": False,
    "properties": {"task": {"type": "string", "description": "a task type of the session"}, "args": _ARGS,
                   "priority": {"type": "integer", "description": "static priority, higher is more urgent"},
                   "deadline": {"type": "number", "description": "absolute simulated time to be done by [s]"}}}
"""A request's body; its ``example`` is the served scenario's first request (:func:`create_app`)."""
CHANGE_SCHEMA = {
    "type": "object", "additionalProperties": False,
    "properties": {"priority": REQUEST_SCHEMA["properties"]["priority"],  # type: ignore[index]
                   "deadline": REQUEST_SCHEMA["properties"]["deadline"], "args": _ARGS},  # type: ignore[index]
    "example": {"priority": 3}}
WORLD_SCHEMA = {
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
_REFUSED = {"description": "refused: the body's field and what was expected",
            "content": {"application/json": {"example": {
                "detail": "POST /requests: args.person: no person 'jon' in world 'paper'; did you mean 'john'?",
                "field": "args.person", "message": "no person 'jon' in world 'paper'; did you mean 'john'?"}}}}


def _body(schema: dict[str, Any]) -> dict[str, Any]:
    return {"requestBody": {"required": True, "content": {"application/json": {"schema": schema}}}}


def _with_example(schema: dict[str, Any], session: Session) -> dict[str, Any]:
    """``schema`` with the served scenario's first request as its example (a world alone has none)."""
    first = next((a.fields for a in session.scenario.actions if a.kind == "request"), None)
    return schema if first is None else {**schema, "example": {"task": first["task"], "args": first["args"]}}


def create_app(session: Session, *, page: Callable[[], str], token: str | None = None) -> FastAPI:
    """The API of ``session``; ``page`` gives the live page's HTML; ``token`` (if any) is required."""
    app = FastAPI(title="tasker serve", version="1", docs_url=None, redoc_url=None,  # their pages load from a CDN
                  description="A live TaskER controller: request, change and terminate tasks while the robot "
                              "runs; watch it; stop to save a scenario that replays the session byte for byte "
                              "(docs/serve.md).")

    @app.middleware("http")
    async def require_token(request: Request, call_next: Callable[[Request], Awaitable[Response]]) -> Response:
        if token is not None:
            given = request.query_params.get("token", "")
            auth = request.headers.get("authorization", "")
            if auth.lower().startswith("bearer "):
                given = auth[7:].strip()
            if not hmac.compare_digest(given.encode(), token.encode()):
                return JSONResponse({"detail": f"{request.method} {request.url.path}: a token is required "
                                               "(Authorization: Bearer TOKEN, or ?token=TOKEN): tasker serve "
                                               "printed it when it started", "field": "token",
                                     "message": "missing or wrong token"}, status_code=401)
        return await call_next(request)

    async def answer(ask: Ask, status: int) -> Response:
        try:
            result = await asyncio.wait_for(asyncio.wrap_future(session.ask(ask)), REPLY_S)
        except Refused as exc:
            return JSONResponse(exc.to_json(), status_code=exc.status)
        except TimeoutError:
            return JSONResponse({"detail": f"{ask.kind}: the session did not answer within {REPLY_S:g} s"},
                                status_code=504)
        except Exception as exc:  # a bug, not the body: say so, the session goes on
            return JSONResponse({"detail": f"{ask.kind}: internal error, not a fault of the request "
                                           f"({type(exc).__name__}: {exc}); the session goes on"}, status_code=500)
        return JSONResponse(result, status_code=status)

    async def with_body(request: Request, where: str, kind: str, status: int, agent: str | None = None) -> Response:
        """Read the JSON body (a malformed one is refused here), then ask the session."""
        try:
            body = bodies.parse_json(await request.body(), where)
        except Refused as exc:
            return JSONResponse(exc.to_json(), status_code=exc.status)
        return await answer(Ask(kind, body, agent=agent), status)

    @app.get("/", response_class=HTMLResponse, summary="The live page: the apartment, the robot, the queue")
    async def live_page() -> HTMLResponse:
        return HTMLResponse(page())

    @app.get("/state", summary="The session now: time, exeDA/irrDA/idleDA, agents, robot, people, hazards",
             responses={200: {"content": {"application/json": {}}}})
    async def state() -> Response:
        return Response(session.state_json(), media_type="application/json")

    @app.post("/requests", status_code=201, summary="Request a task; 201 {id, t, warnings}",
              openapi_extra=_body(_with_example(REQUEST_SCHEMA, session)), responses={400: _REFUSED, 422: _REFUSED})
    async def post_request(request: Request) -> Response:
        return await with_body(request, "POST /requests", "request", 201)

    @app.delete("/requests/{agent}", status_code=202, summary="Terminate a task (term: it suspends safely first)",
                responses={404: _REFUSED, 409: _REFUSED})
    async def delete_request(agent: str, reason: str | None = None) -> Response:
        return await answer(Ask("terminate", agent=agent, reason=reason), 202)

    @app.patch("/requests/{agent}", status_code=202, summary="Change a task's priority, deadline or arguments (R2)",
               openapi_extra=_body(CHANGE_SCHEMA), responses={404: _REFUSED, 409: _REFUSED, 422: _REFUSED})
    async def patch_request(agent: str, request: Request) -> Response:
        return await with_body(request, f"PATCH /requests/{agent}", "change", 202, agent=agent)

    @app.post("/world", status_code=202, summary="An event of the world's vocabulary (someone falls, a door closes)",
              openapi_extra=_body(WORLD_SCHEMA), responses={400: _REFUSED, 422: _REFUSED})
    async def post_world(request: Request) -> Response:
        return await with_body(request, "POST /world", "world", 202)

    @app.post("/stop", status_code=202, summary="Stop: write the run folder and session.toml, then exit")
    async def stop() -> Response:
        return await answer(Ask("stop", reason="POST /stop"), 202)

    @app.get("/events", summary="The trace as server-sent events, one trace.jsonl line each, id = its index",
             response_class=StreamingResponse)
    async def events(request: Request, first: int = Query(0, alias="from", ge=0,
                                                          description="the index of the first line to send")
                     ) -> StreamingResponse:
        last = request.headers.get("last-event-id", "")
        start = int(last) + 1 if last.isdigit() else first  # a reconnecting EventSource goes on where it was

        async def stream() -> AsyncIterator[str]:
            i = start
            while True:
                lines = session.lines[i:]
                for line in lines:
                    yield f"id: {i}\nevent: trace\ndata: {line}\n\n"
                    i += 1
                if not lines:
                    if session.stopped.is_set() or await request.is_disconnected():
                        yield "event: end\ndata: {}\n\n"
                        return
                    await asyncio.sleep(POLL_S)

        return StreamingResponse(stream(), media_type="text/event-stream",
                                 headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"})

    return app
