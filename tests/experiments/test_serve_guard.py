"""Who may call ``tasker serve`` and what a body may hold, through FastAPI's TestClient against a
stand-in session (no robot: fast): the token on every endpoint, the Host allow-list, same origin
only, JSON only, bounded bodies, the strict reader, and a fuzz of bodies that never gets a 5xx
and never lets through a value that cannot be written to ``session.toml`` and the trace."""

from __future__ import annotations

import json
import threading
import tomllib
from collections.abc import Iterator
from concurrent.futures import Future
from typing import Any

import pytest
import tomli_w
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from experiments.serve.app import create_app
from experiments.serve.guard import allowed_hosts
from experiments.serve.session import Ask
from experiments.serve.strict import MAX_BODY_BYTES, MAX_STRING
from tasker.trace import encode

BASE = "http://127.0.0.1:8765"
TOKEN = "s3cret-token"


class StandIn:
    """What the app reads of a session: it answers every ask at once, and keeps them."""

    def __init__(self) -> None:
        from experiments.inputs.robot_scenario import RobotScenario

        self.scenario = RobotScenario(name="t", source="t", world="paper", actions=(), scheduler="alg2")
        self.asks: list[Ask] = []
        self.lines = ['{"t":0.0,"event":"a"}', '{"t":0.1,"event":"b"}', '{"t":0.2,"event":"c"}']
        self.stopped = threading.Event()
        self.stopped.set()  # GET /events sends what there is, then ends
        self.answer: dict[str, Any] = {"t": 0.1 + 0.2, "warnings": []}

    def ask(self, ask: Ask) -> Future[dict[str, Any]]:
        self.asks.append(ask)
        ask.reply.set_result({**self.answer, "id": ask.agent or "d1"} if ask.kind != "stop" else dict(self.answer))
        return ask.reply

    def state_json(self) -> bytes:
        return b'{"status":"running"}'


def client(token: str | None = None, hosts: frozenset[str] | None = allowed_hosts("127.0.0.1"),
           base: str = BASE) -> tuple[TestClient, StandIn]:
    session = StandIn()
    app = create_app(session, page=lambda: "<html>live</html>", token=token, hosts=hosts)  # type: ignore[arg-type]
    return TestClient(app, base_url=base), session


JSON = {"content-type": "application/json"}
REQUEST = json.dumps({"task": "human_fell", "args": {"person": "peter"}}).encode()
ENDPOINTS = [  # every call of the API: method, path, body (None: none)
    ("GET", "/", None), ("GET", "/state", None), ("GET", "/events", None), ("GET", "/openapi.json", None),
    ("POST", "/requests", REQUEST), ("PATCH", "/requests/d1", b'{"priority": 2}'),
    ("DELETE", "/requests/d1", None), ("POST", "/world", b'{"posture": ["peter", "fallen"]}'),
    ("POST", "/stop", None)]
CHANGING = [e for e in ENDPOINTS if e[0] != "GET"]


def call(c: TestClient, method: str, path: str, body: bytes | None, headers: dict[str, str] | None = None,
         ) -> Any:
    return c.request(method, path, content=body, headers={**(JSON if body is not None else {}), **(headers or {})})


def refusal(r: Any, status: int, field: str) -> dict[str, Any]:
    assert r.status_code == status, (r.status_code, r.text)
    said = r.json()
    assert said["field"] == field and said["detail"].endswith(said["message"]), said
    return dict(said)


# -- the token -------------------------------------------------------------------------------

@pytest.mark.parametrize(("method", "path", "body"), ENDPOINTS)
def test_with_a_token_every_endpoint_refuses_a_call_without_it_or_with_a_wrong_one(method: str, path: str,
                                                                                   body: bytes | None) -> None:
    c, session = client(token=TOKEN)
    for headers in ({}, {"Authorization": "Bearer wrong"}, {"Authorization": f"Basic {TOKEN}"},
                    {"Authorization": f"Bearer {TOKEN}x"}):
        r = call(c, method, path, body, headers)
        said = refusal(r, 401, "token")
        assert r.headers["www-authenticate"] == "Bearer" and TOKEN not in said["detail"]
    assert refusal(call(c, method, path + "?token=wrong", body), 401, "token")
    assert session.asks == []  # nothing reached the session


@pytest.mark.parametrize(("method", "path", "body"), ENDPOINTS)
def test_with_a_token_every_endpoint_answers_a_call_that_carries_it(method: str, path: str,
                                                                   body: bytes | None) -> None:
    c, session = client(token=TOKEN)
    by_header = call(c, method, path, body, {"Authorization": f"Bearer {TOKEN}"})
    by_query = call(c, method, f"{path}?token={TOKEN}", body)
    assert 200 <= by_header.status_code < 300 and 200 <= by_query.status_code < 300, (by_header.text, by_query.text)
    assert len(session.asks) == (2 if method != "GET" else 0)


@pytest.mark.parametrize(("method", "path", "body"), ENDPOINTS)
def test_without_a_token_no_endpoint_asks_for_one(method: str, path: str, body: bytes | None) -> None:
    c, _ = client(token=None)
    r = call(c, method, path, body)
    assert 200 <= r.status_code < 300, r.text


# -- Host and Origin ---------------------------------------------------------------------------

@pytest.mark.parametrize(("method", "path", "body"), ENDPOINTS)
@pytest.mark.parametrize("host", ["evil.example:8765", "attacker.localhost", "127.0.0.2:8765", "", "a b",
                                  "127.0.0.1:8765@evil.example", "[::2]:8765"])
def test_a_foreign_host_header_is_refused_on_every_endpoint(method: str, path: str, body: bytes | None,
                                                            host: str) -> None:
    """DNS rebinding: a page whose own name resolves to 127.0.0.1 sends that name in Host."""
    c, session = client()
    said = refusal(call(c, method, path, body, {"Host": host}), 400, "Host")
    assert "evil" not in said["message"] or len(said["message"]) < 300
    assert session.asks == []


@pytest.mark.parametrize("host", ["127.0.0.1:8765", "localhost:8765", "LocalHost", "[::1]:8765", "127.0.0.1"])
def test_the_loopback_names_are_this_servers(host: str) -> None:
    c, session = client()
    assert c.post("/requests", content=REQUEST, headers={**JSON, "Host": host}).status_code == 201
    assert len(session.asks) == 1


def test_the_allowed_hosts_are_the_loopback_names_and_the_address_served() -> None:
    assert allowed_hosts("127.0.0.1") == {"localhost", "127.0.0.1", "::1"}
    assert allowed_hosts("192.168.1.20") == {"localhost", "127.0.0.1", "::1", "192.168.1.20"}
    assert allowed_hosts("[FE80::1]") == {"localhost", "127.0.0.1", "::1", "fe80::1"}
    assert allowed_hosts("0.0.0.0") is None and allowed_hosts("::") is None  # any name: the token protects it
    c, session = client(hosts=allowed_hosts("192.168.1.20"), base="http://192.168.1.20:8765")
    assert c.post("/requests", content=REQUEST, headers=JSON).status_code == 201
    assert refusal(c.post("/requests", content=REQUEST, headers={**JSON, "Host": "evil.example"}), 400, "Host")


@pytest.mark.parametrize(("method", "path", "body"), ENDPOINTS)
@pytest.mark.parametrize("origin", ["http://evil.example", "null", "http://127.0.0.1:8766", "https://127.0.0.1:8765",
                                    "http://localhost:8765", "file://", "http://127.0.0.1:8765/x"])
def test_a_call_from_another_origin_is_refused_bodiless_ones_too(method: str, path: str, body: bytes | None,
                                                                 origin: str) -> None:
    """A page of another origin (another port, scheme or name is another origin) can neither change
    the session — a ``no-cors`` POST, a bare POST /stop — nor read it."""
    c, session = client()
    refusal(call(c, method, path, body, {"Origin": origin}), 403, "Origin")
    assert session.asks == []


@pytest.mark.parametrize(("method", "path", "body"), CHANGING)
def test_a_no_cors_text_plain_post_from_another_page_changes_nothing(method: str, path: str,
                                                                     body: bytes | None) -> None:
    """What Chromium sent in the report: ``fetch(url, {method: "POST", mode: "no-cors", body})``."""
    c, session = client()
    r = c.request(method, path, content=body or b"x", headers={"Content-Type": "text/plain;charset=UTF-8",
                                                                 "Origin": "http://evil.example",
                                                                 "Sec-Fetch-Site": "cross-site",
                                                                 "Sec-Fetch-Mode": "no-cors"})
    assert r.status_code == 403 and session.asks == []
    r = c.request(method, path, content=body or b"x", headers={"Content-Type": "text/plain", "Sec-Fetch-Site":
                                                                 "cross-site"})  # no Origin: the fetch metadata
    assert r.status_code == 403 and session.asks == []
    r = c.request(method, path, content=body or b"x", headers={"Content-Type": "application/json",
                                                                 "Sec-Fetch-Site": "same-site"})  # a sibling host
    assert r.status_code == 403 and session.asks == []


@pytest.mark.parametrize(("method", "path", "body"), ENDPOINTS)
def test_the_live_pages_own_calls_are_answered(method: str, path: str, body: bytes | None) -> None:
    """Same origin, as Chromium sends it from the live page (Origin, Sec-Fetch-Site: same-origin)."""
    c, _ = client()
    r = call(c, method, path, body, {"Origin": BASE, "Sec-Fetch-Site": "same-origin"})
    assert 200 <= r.status_code < 300, r.text


# -- bodies --------------------------------------------------------------------------------------

@pytest.mark.parametrize(("method", "path", "body"), [e for e in CHANGING if e[2] is not None])
@pytest.mark.parametrize("content_type", [None, "text/plain", "application/x-www-form-urlencoded",
                                          "multipart/form-data; boundary=x", "application/json; charset=latin-1",
                                          "application/jsonx", "text/json"])
def test_a_body_not_sent_as_json_is_refused_415(method: str, path: str, body: bytes, content_type: str | None
                                                ) -> None:
    c, session = client()
    headers = {} if content_type is None else {"Content-Type": content_type}
    refusal(c.request(method, path, content=body, headers=headers), 415, "Content-Type")
    assert session.asks == []
    assert c.request(method, path, content=body, headers={"Content-Type": "application/json; charset=UTF-8"}
                     ).status_code in (201, 202)


@pytest.mark.parametrize("path", ["/stop", "/requests/d1"])
def test_a_call_that_takes_no_body_refuses_one(path: str) -> None:
    c, session = client()
    method = "POST" if path == "/stop" else "DELETE"
    refusal(c.request(method, path, content=b"stop", headers={"Content-Type": "text/plain"}), 415, "Content-Type")
    assert c.request(method, path, content=b'{"a": 1}', headers=JSON).status_code == 400
    assert session.asks == []
    assert c.request(method, path, headers=JSON).status_code == 202  # the live page's own: JSON declared, no body


def test_a_body_over_the_limit_is_refused_413_whether_it_says_its_length_or_not() -> None:
    c, session = client()
    big = b'{"task": "' + b"x" * MAX_BODY_BYTES + b'"}'
    said = refusal(c.post("/requests", content=big, headers=JSON), 413, "")
    assert str(MAX_BODY_BYTES) in said["message"]

    def chunks() -> Iterator[bytes]:  # no Content-Length: counted while it arrives
        yield b'{"task": "'
        for _ in range(100):
            yield b"x" * 4096
        yield b'"}'

    refusal(c.post("/requests", content=chunks(), headers=JSON), 413, "")
    refusal(c.post("/requests", content=b"{}", headers={**JSON, "Content-Length": "99999999999999999999999"}),
            413, "")
    assert session.asks == []


@pytest.mark.parametrize(("raw", "status", "field", "says"), [
    (b'{"task": "human_fell", "args": {"person": "\\ud800"}}', 422, "args.person", "lone surrogate U+D800"),
    (b'{"task": "human_fell", "\\udfff": 1}', 422, "", "a key: a string holding the lone surrogate U+DFFF"),
    (b'{"task": "human_fell", "args": {"person": "peter", "priority": null}}', 422, "args.priority", "null"),
    (b'{"task": "human_fell", "args": {"person": "peter", "priority": 18446744073709551616}}', 422,
     "args.priority", "64-bit integer"),
    (b'{"task": "human_fell", "args": {"deadline": 1' + b"0" * 400 + b'.5}}', 422, "args.deadline", "finite"),
    (b'{"task": "human_fell", "args": {"deadline": NaN}}', 422, "args.deadline", "finite"),
    (b'{"task": "human_fell", "args": {"deadline": -Infinity}}', 422, "args.deadline", "finite"),
    (b'{"task": "human_fell", "args": {"deadline": 1e999}}', 422, "args.deadline", "finite"),
    (b'{"task": "' + b"x" * (MAX_STRING + 1) + b'"}', 422, "task", f"at most {MAX_STRING}"),
    (b'{"task": "human_fell", "args": {"person": 1' + b"2" * 5000 + b'}}', 400, "", "thousands of digits"),
    (b"[" * 10_000 + b"]" * 10_000, 400, "", "nested more than 64 deep"),
    (b'{"task": ', 400, "", "not valid JSON"),
    (b"\xff\xfe{}", 400, "", "not UTF-8"),
    (b"", 400, "", "empty"),
])
def test_every_body_goes_through_the_strict_reader(raw: bytes, status: int, field: str, says: str) -> None:
    c, session = client()
    for method, path in (("POST", "/requests"), ("POST", "/world"), ("PATCH", "/requests/d1")):
        said = refusal(c.request(method, path, content=raw, headers=JSON), status, field)
        assert says in said["message"] and len(said["detail"]) < 400, said
    assert session.asks == []


def test_a_long_task_id_is_not_echoed_and_a_long_reason_is_refused() -> None:
    c, session = client()
    said = refusal(c.delete("/requests/" + "d" * 5000), 404, "")
    assert len(said["detail"]) < 300
    refusal(c.delete("/requests/d1", params={"reason": "r" * (MAX_STRING + 1)}), 422, "reason")
    assert session.asks == []
    assert c.delete("/requests/d1", params={"reason": "done\u2028by hand"}).status_code == 202
    assert session.asks[0].reason == "done\u2028by hand"


# -- headers, the stream, answers ---------------------------------------------------------------

@pytest.mark.parametrize("last", [b"\xb2", b"abc", b"-1", b"1e3", b"9" * 40, b"1 2"])
def test_a_last_event_id_that_is_not_a_line_index_is_refused_400(last: bytes) -> None:
    c, _ = client()
    refusal(c.get("/events", headers={"Last-Event-ID": last}), 400, "Last-Event-ID")  # type: ignore[dict-item]


def test_the_stream_goes_on_after_the_last_event_id() -> None:
    c, _ = client()
    text = c.get("/events", headers={"Last-Event-ID": "0"}).text
    assert text.startswith('id: 1\nevent: trace\ndata: {"t":0.1,"event":"b"}\n\n') and text.endswith("event: end\n"
                                                                                                     "data: {}\n\n")
    assert c.get("/events?from=2").text.startswith("id: 2\n")
    assert c.get("/events", headers={"Last-Event-ID": " "}).text.startswith("id: 0\n")  # empty: from the start
    refusal(c.get("/events?from=-1"), 422, "from")
    refusal(c.get("/events?from=x"), 422, "from")


def test_answers_round_times_as_the_trace_does() -> None:
    c, session = client()
    session.answer = {"t": 0.1 + 0.2, "warnings": [], "x": 1 / 3}
    said = c.post("/stop").json()
    assert said == {"t": 0.3, "warnings": [], "x": 0.333333}
    assert c.post("/stop").text == '{"t":0.3,"warnings":[],"x":0.333333}'


def test_an_unknown_call_is_a_refusal_in_the_apis_style() -> None:
    c, _ = client()
    said = refusal(c.get("/nope"), 404, "")
    assert said["detail"] == "GET /nope: no such call (GET /openapi.json lists them)"
    assert c.put("/stop").status_code == 405


# -- the fuzz ------------------------------------------------------------------------------------

JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(min_value=-2**70, max_value=2**70) | st.floats(allow_nan=True)
    | st.text(max_size=20) | st.sampled_from(["peter", "human_fell", "guide_human", "\ud800", "x" * 2000]),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8) | st.sampled_from(
        ["task", "args", "person", "priority", "deadline", "note", "posture"]), inner, max_size=4),
    max_leaves=12)


def _dumps(value: Any) -> bytes:
    return json.dumps(value, ensure_ascii=True).encode()  # NaN and lone surrogates as JSON writes them


@pytest.mark.slow  # 300 bodies; the guard's own cases above stay in the fast lane
@settings(max_examples=300, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(body=JSON_VALUES | st.binary(max_size=40), where=st.sampled_from(["/requests", "/world", "/requests/d1"]))
def test_fuzz_no_body_gets_a_5xx_and_what_passes_can_be_saved(body: Any, where: str) -> None:
    """Whatever the body: 2xx or 4xx with a message, never 5xx; and a body that reaches the session
    holds only what ``session.toml`` (TOML) and the trace (JSON lines, UTF-8) can hold and read back."""
    c, session = _FUZZ
    session.asks.clear()
    raw = body if isinstance(body, bytes) else _dumps(body)
    r = c.request("PATCH" if where == "/requests/d1" else "POST", where, content=raw, headers=JSON)
    assert r.status_code < 500, r.text
    if r.status_code >= 400:
        assert r.json()["detail"] and session.asks == []
        return
    value = session.asks[0].body
    assert tomllib.loads(tomli_w.dumps({"v": value})) == {"v": value}
    assert json.loads(encode({"v": value}).encode("utf-8")) == json.loads(encode({"v": value}))


_FUZZ = client()


def test_event_streams_past_the_most_kept_open_are_refused_503_and_an_ended_one_frees_its_place(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from experiments.serve import app as app_module

    monkeypatch.setattr(app_module, "MAX_STREAMS", 1)
    c, _ = client()
    assert c.get("/events").text.endswith("event: end\ndata: {}\n\n")  # ran, ended: its place is free again
    assert c.get("/events").status_code == 200
    monkeypatch.setattr(app_module, "MAX_STREAMS", 0)
    said = refusal(c.get("/events"), 503, "")
    assert "0 event streams are open" in said["message"]


def test_an_event_stream_is_counted_from_the_call_that_opens_it_until_it_ends_or_is_dropped() -> None:
    import asyncio
    import gc

    from experiments.serve.app import _Streams

    streams, session = _Streams(), StandIn()
    first, second = (streams.stream(session, None, 0) for _ in range(2))  # type: ignore[arg-type]
    assert streams.open == 2  # counted before either has started: a burst of opens is refused in time

    async def drain() -> list[str]:
        return [x async for x in first]

    assert asyncio.run(drain())[-1] == "event: end\ndata: {}\n\n" and streams.open == 1
    del second  # its client left before it started: it never runs, and frees its place
    gc.collect()
    assert streams.open == 0
