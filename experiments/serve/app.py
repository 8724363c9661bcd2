"""The HTTP API of a live session (FastAPI; its OpenAPI schema is at ``/openapi.json``).

Every handler either reads what the session published (``GET /state``, ``GET /events``,
``GET /``) or queues an :class:`experiments.serve.session.Ask` for the session's thread and
waits for its answer: a handler never touches the loop.  :func:`create_app` puts together, each
in a function of its own:

* who may call (:class:`experiments.serve.guard.Guard`: the Host allow-list, same origin only,
  the token);
* how a body is read (:func:`json_body`: declared JSON, size-limited while it is read, then the
  strict reader of :mod:`experiments.serve.strict`; the session reads its fields as a scenario's,
  :mod:`experiments.serve.bodies`);
* the routes, the event stream, and how a refusal is answered: a 4xx whose JSON body is
  ``{"detail", "field", "message"}`` — never a traceback, and a 5xx only for a bug, which fails
  that one call while the session goes on.

Answers are encoded as the trace encodes (:func:`tasker.trace.encode`): times rounded to 1 µs.
"""

from __future__ import annotations

import asyncio
import re
import weakref
from collections.abc import AsyncIterator, Callable
from typing import Annotated, Any

from fastapi import Depends, FastAPI, Query, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import HTMLResponse, JSONResponse, Response, StreamingResponse
from starlette.exceptions import HTTPException

from experiments.serve import schemas, strict
from experiments.serve.bodies import BAD, NOT_FOUND, Refused
from experiments.serve.guard import LOOPBACK_NAMES, Guard
from experiments.serve.session import Ask, Session
from experiments.serve.strict import MAX_BODY_BYTES, TOO_LARGE, UNSUPPORTED, cut, read_body, shown
from tasker.trace import encode

REPLY_S = 120.0
"""How long a handler waits for the session's answer (it builds the robot first, a few seconds)."""

POLL_S = 0.1
"""How often ``GET /events`` looks for new trace lines."""

MAX_STREAMS = 100
"""The most ``GET /events`` streams open at once; one more is refused ``503`` (each idle stream
wakes every :data:`POLL_S`: a thousand would take the event loop from ``GET /state``)."""

UNAVAILABLE = 503

AGENT = re.compile(r"d[1-9][0-9]{0,8}")
"""What a task's id looks like (``d1``, ``d2``, …): anything else names no task."""


def create_app(session: Session, *, page: Callable[[], str], token: str | None = None,
               hosts: frozenset[str] | None = frozenset(LOOPBACK_NAMES)) -> FastAPI:
    """The API of ``session``; ``page`` gives the live page's HTML; ``token`` (if any) is required;
    ``hosts``: the names a ``Host`` header may give (:func:`experiments.serve.guard.allowed_hosts`)."""
    app = FastAPI(title="tasker serve", version="1", docs_url=None, redoc_url=None,  # their pages load from a CDN
                  description="A live TaskER controller: request, change and terminate tasks while the robot "
                              "runs; watch it; stop to save a scenario that replays the session byte for byte "
                              "(docs/serve.md).")
    app.add_middleware(Guard, hosts=hosts, token=token)
    _refusals(app)
    _reads(app, session, page)
    _writes(app, session)
    return app


def _where(request: Request) -> str:
    return f"{request.method} {cut(request.url.path)}"


def _refused(exc: Refused) -> Response:
    return JSONResponse(exc.to_json(), status_code=exc.status)


def _refusals(app: FastAPI) -> None:
    """Every refusal in the API's style: FastAPI's own (a bad query value, an unknown path) too."""

    @app.exception_handler(Refused)
    async def refused(request: Request, exc: Refused) -> Response:
        return _refused(exc)

    @app.exception_handler(RequestValidationError)
    async def invalid(request: Request, exc: RequestValidationError) -> Response:
        first = exc.errors()[0] if exc.errors() else {}
        field = ".".join(str(p) for p in first.get("loc", ())[1:]) or str(first.get("loc", ("",))[0])
        return _refused(Refused(422, _where(request), str(first.get("msg", "invalid")), field))

    @app.exception_handler(Exception)
    async def bug(request: Request, exc: Exception) -> Response:  # a bug: that call fails, the session goes on
        return JSONResponse({"detail": f"{_where(request)}: internal error, not a fault of the request "
                                       f"({type(exc).__name__}); the session goes on"}, status_code=500)

    @app.exception_handler(HTTPException)
    async def http(request: Request, exc: HTTPException) -> Response:
        message = "no such call (GET /openapi.json lists them)" if exc.status_code == 404 else str(exc.detail)
        return _refused(Refused(exc.status_code, _where(request), message))


async def json_body(request: Request) -> Any:
    """The body of a call that takes one: declared ``application/json`` (``415``), at most
    :data:`~experiments.serve.strict.MAX_BODY_BYTES` counted while it is read (``413``), then
    :func:`experiments.serve.strict.read_body`."""
    where = _where(request)
    problem = strict.content_type_problem(request.headers.get("content-type"))
    if problem is not None:
        raise Refused(UNSUPPORTED, where, problem, "Content-Type")
    strict.declared_length(request.headers.get("content-length"), where)
    chunks, size = [], 0
    async for chunk in request.stream():
        size += len(chunk)
        if size > MAX_BODY_BYTES:
            raise Refused(TOO_LARGE, where, f"the body is larger than {MAX_BODY_BYTES} bytes, the most read here")
        chunks.append(chunk)
    return read_body(b"".join(chunks), where)


async def no_body(request: Request) -> None:
    """A call that takes no body refuses one (``415`` if it is not even declared JSON)."""
    where = _where(request)
    length = strict.declared_length(request.headers.get("content-length"), where)
    if not length and "transfer-encoding" not in request.headers:
        return
    problem = strict.content_type_problem(request.headers.get("content-type"))
    if problem is not None:
        raise Refused(UNSUPPORTED, where, problem, "Content-Type")
    async for chunk in request.stream():
        if chunk.strip():
            raise Refused(BAD, where, "this call takes no body")


JsonBody = Annotated[Any, Depends(json_body)]
"""A route's parameter for its body, read by :func:`json_body`."""


def _agent(agent: str, where: str) -> str:
    if not AGENT.fullmatch(agent):
        raise Refused(NOT_FOUND, where, f"no task {shown(agent)}: tasks are d1, d2, … (GET /state lists them)")
    return agent


async def _answer(session: Session, ask: Ask, status: int) -> Response:
    """Queue ``ask``, wait for the session's answer, and send it (or its refusal)."""
    try:
        result = await asyncio.wait_for(asyncio.wrap_future(session.ask(ask)), REPLY_S)
    except Refused as exc:
        return _refused(exc)
    except TimeoutError:
        return JSONResponse({"detail": f"{ask.kind}: the session did not answer within {REPLY_S:g} s"},
                            status_code=504)
    except Exception as exc:  # a bug, not the body: say so, the session goes on
        return JSONResponse({"detail": f"{ask.kind}: internal error, not a fault of the request "
                                       f"({type(exc).__name__}: {exc}); the session goes on"}, status_code=500)
    return Response(encode(result), status_code=status, media_type="application/json")


def _reads(app: FastAPI, session: Session, page: Callable[[], str]) -> None:
    """The calls that only read what the session published: the page, the state, the event stream."""

    @app.get("/", response_class=HTMLResponse, summary="The live page: the apartment, the robot, the queue",
             responses=schemas.GUARDED)
    async def live_page() -> HTMLResponse:
        return HTMLResponse(page())

    @app.get("/state", summary="The session now: time, exeDA/irrDA/idleDA, agents, robot, people, hazards",
             responses={200: {"content": {"application/json": {}}}, **schemas.GUARDED})
    async def state() -> Response:
        return Response(session.state_json(), media_type="application/json")

    streams = _Streams()

    @app.get("/events", summary="The trace as server-sent events, one trace.jsonl line each, id = its index",
             response_class=StreamingResponse, responses={**schemas.GUARDED, 503: schemas.REFUSED})
    async def events(request: Request, first: int = Query(0, alias="from", ge=0, le=2**63 - 1,
                                                          description="the index of the first line to send")
                     ) -> StreamingResponse:
        last = strict.event_id(request.headers.get("last-event-id"))
        start = first if last is None else last + 1  # a reconnecting EventSource goes on where it was
        if streams.open >= MAX_STREAMS:
            raise Refused(UNAVAILABLE, _where(request), f"{streams.open} event streams are open, the most this "
                                                        "server keeps: close one, or poll GET /state")
        return StreamingResponse(streams.stream(session, request, start), media_type="text/event-stream",
                                 headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"})


class _Streams:
    """The ``GET /events`` streams of one app, counted from the call that opens one (so that a burst of
    them is counted before any has started) until it ends or is dropped unstarted."""

    def __init__(self) -> None:
        self.open = 0

    def stream(self, session: Session, request: Request, start: int) -> AsyncIterator[str]:
        self.open += 1
        released = False

        def release() -> None:
            nonlocal released
            if not released:
                released = True
                self.open -= 1

        lines = _lines(session, request, start, release)
        weakref.finalize(lines, release)  # a stream whose client left before it started never runs its finally
        return lines


async def _lines(session: Session, request: Request, start: int, release: Callable[[], None]) -> AsyncIterator[str]:
    try:
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
    finally:
        release()


def _writes(app: FastAPI, session: Session) -> None:
    """The calls that change the session: each queues an :class:`Ask` and answers with the session's answer."""
    first = next((a.fields for a in session.scenario.actions if a.kind == "request"), None)

    @app.post("/requests", status_code=201, summary="Request a task; 201 {id, t, warnings}",
              openapi_extra=schemas.body(schemas.with_example(schemas.REQUEST_SCHEMA, first)),
              responses=schemas.WITH_BODY)
    async def post_request(body: JsonBody) -> Response:
        return await _answer(session, Ask("request", body), 201)

    @app.delete("/requests/{agent}", status_code=202, summary="Terminate a task (term: it suspends safely first)",
                responses={404: schemas.REFUSED, 409: schemas.REFUSED, **schemas.GUARDED},
                dependencies=[Depends(no_body)])
    async def delete_request(request: Request, agent: str, reason: str | None = None) -> Response:
        where = _where(request)
        why = None if reason is None else strict.string_problem(reason)
        if why is not None:
            raise Refused(422, where, why, "reason")
        return await _answer(session, Ask("terminate", agent=_agent(agent, where), reason=reason), 202)

    @app.patch("/requests/{agent}", status_code=202, summary="Change a task's priority, deadline or arguments (R2)",
               openapi_extra=schemas.body(schemas.CHANGE_SCHEMA),
               responses={404: schemas.REFUSED, 409: schemas.REFUSED, **schemas.WITH_BODY})
    async def patch_request(request: Request, agent: str, body: JsonBody) -> Response:
        return await _answer(session, Ask("change", body, agent=_agent(agent, _where(request))), 202)

    @app.post("/world", status_code=202, summary="An event of the world's vocabulary (someone falls, a door closes)",
              openapi_extra=schemas.body(schemas.WORLD_SCHEMA), responses=schemas.WITH_BODY)
    async def post_world(body: JsonBody) -> Response:
        return await _answer(session, Ask("world", body), 202)

    @app.post("/stop", status_code=202, summary="Stop: write the run folder and session.toml, then exit",
              responses=schemas.GUARDED, dependencies=[Depends(no_body)])
    async def stop() -> Response:
        return await _answer(session, Ask("stop", reason="POST /stop"), 202)
