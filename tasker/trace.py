"""The trace: one JSON object per line, the only record metrics and plots read.

Every event has ``t`` (simulated seconds) and ``event``; the fields of each event are
documented in ``docs/trace.md``.  Encoding is canonical so that the same run gives
the same bytes: keys in a fixed order, floats rounded to 6 decimals, infinities as
the strings ``"inf"``/``"-inf"`` (JSON has no infinity), no wall-clock values.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import IO, Any

from tasker.events import KINDS, Event, TraceError, parse
from tasker.support import reader

EVENTS = KINDS
"""Every event kind a trace may hold (:data:`tasker.events.KINDS`)."""

INAPPLICABLE = "inapplicable:"
"""How the ``reason`` of a ``stage`` ``failed`` event begins when the stage's action could not run in the
world as it was (a precondition did not hold): it was never started, and applied no effect."""

FAILED = frozenset({"failed", "error"})
"""``end`` causes of an agent that did not do its task and was not stopped on purpose: a plan
or a skill failed (``failed``), or an exception ended it (``error``); ``docs/trace.md``."""


def _norm(value: Any) -> Any:
    if isinstance(value, bool) or value is None or isinstance(value, str | int):
        return value
    if isinstance(value, float):
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        if math.isnan(value):
            return "nan"
        r = round(value, 6)
        return 0.0 if r == 0 else r
    if isinstance(value, Mapping):
        return {str(k): _norm(v) for k, v in value.items()}
    if isinstance(value, list | tuple | frozenset | set):
        items = sorted(value) if isinstance(value, frozenset | set) else value
        return [_norm(v) for v in items]
    if hasattr(value, "value") and isinstance(value.value, str):  # enums
        return value.value
    raise TypeError(f"cannot put a {type(value).__name__} in the trace: {value!r}")


def encode(event: Mapping[str, Any]) -> str:
    """One canonical JSON line (without the newline)."""
    return json.dumps(_norm(event), separators=(",", ":"), ensure_ascii=False, allow_nan=False)


class Trace:
    """Collects events in order; optionally streams them to a file and to observers.

    :meth:`emit` takes only the event types of :mod:`tasker.events`.  Observers (metrics
    collectors, the hazard monitor) get each typed event after it is recorded.
    :attr:`events` are the events as JSON-ready records (dicts), :attr:`typed` the events
    themselves.
    """

    def __init__(self, sink: IO[str] | None = None, keep: bool = True) -> None:
        self._events: list[dict[str, Any]] = []
        self._typed: list[Event] = []
        self._sink = sink
        self._keep = keep
        self._observers: list[Callable[[Event], None]] = []

    def emit(self, event: Event) -> None:
        """Record one event (its ``t`` rounded to 1 µs, as the trace writes it)."""
        if not isinstance(event, Event) or not event.KIND:
            raise TypeError(f"Trace.emit takes a tasker.events event, got {type(event).__name__}")
        t = round(event.t, 6)
        if t != event.t:  # the typed event says what the trace says
            event = dataclasses.replace(event, t=t)
        record: dict[str, Any] = {"t": t, "event": event.KIND}
        record.update(event.fields())
        if self._keep:
            self._events.append(record)
            self._typed.append(event)
        if self._sink is not None:
            self._sink.write(encode(record) + "\n")
        for obs in self._observers:
            obs(event)

    def subscribe(self, observer: Callable[[Event], None]) -> None:
        self._observers.append(observer)

    @property
    def events(self) -> list[dict[str, Any]]:
        """The events as records: ``{"t", "event", ...fields}``, as ``trace.jsonl`` has them (before rounding)."""
        return self._events

    @property
    def typed(self) -> list[Event]:
        """The events themselves, in order."""
        return self._typed

    def of(self, event: str, **match: Any) -> list[dict[str, Any]]:
        """Records of one kind whose fields equal ``match``."""
        return [e for e in self._events if e["event"] == event and all(e.get(k) == v for k, v in match.items())]

    def lines(self) -> Iterator[str]:
        for e in self._events:
            yield encode(e)

    def dumps(self) -> str:
        return "".join(line + "\n" for line in self.lines())

    def write(self, path: str | Path) -> None:
        Path(path).write_text(self.dumps(), encoding="utf-8")


def read(path: str | Path) -> list[dict[str, Any]]:
    """Read a ``trace.jsonl`` back (infinities stay as the strings ``"inf"``).

    Every line must be an event: a JSON object with ``t`` (a number) and ``event`` (a
    string).  A damaged file (cut short, a stray byte, a line that is no event, nested too
    deep, a number beyond 64 bits) is a :class:`~tasker.events.TraceError` (a ``ValueError``) naming
    the file and the line; a missing file, a folder or a device is one naming the file."""
    return [record for _, record in _records(path)]


MAX_TRACE_BYTES = 512 * 2**20
"""The largest trace read whole (a simulated day's is a few MB)."""


def _records(path: str | Path) -> Iterator[tuple[int, dict[str, Any]]]:
    try:  # a folder, a device, a huge file, a stray byte: named
        text = reader.read_text(path, limit=MAX_TRACE_BYTES)
    except reader.InputError as exc:
        raise TraceError(f"{path}:{exc.line}: {exc.message.removeprefix('is ')}" if exc.line else str(exc)) from None
    for n, line in enumerate(text.splitlines(), start=1):
        if line.strip():
            try:  # within the readers' limits: nesting, 64-bit integers
                event = reader.parse_json(line, path, line=n)
            except reader.InputError as exc:
                message = exc.message.removeprefix("not valid JSON: ").removeprefix("not readable JSON: ")
                raise TraceError(f"{path}:{n}: not a JSON object: {message}" if not exc.field
                                 else f"{path}:{n}: {exc.field}: {exc.message}") from None
            if not isinstance(event, dict):
                raise TraceError(f"{path}:{n}: not a JSON object: {line.strip()[:40]}")
            t = event.get("t")
            if not isinstance(event.get("event"), str) or isinstance(t, bool) or not isinstance(t, int | float):
                raise TraceError(f"{path}:{n}: not an event: expected \"t\" (a number) and \"event\" (a string)")
            yield n, event


def read_events(path: str | Path) -> list[Event]:
    """:func:`read`, each event typed (:func:`tasker.events.parse`): a damaged event (a missing
    or wrong field) is a :class:`~tasker.events.TraceError` naming the file, the line and the field."""
    out = []
    for n, record in _records(path):
        try:
            out.append(parse(record))
        except TraceError as exc:
            raise TraceError(f"{path}:{n}: {exc}") from None
    return out


def typed(records: Iterable[Mapping[str, Any]]) -> list[Event]:
    """Records (a live trace's :attr:`Trace.events`, or :func:`read`'s) as typed events."""
    return [parse(r) for r in records]


def number(value: Any) -> float:
    """A trace number back to a float (``"inf"`` -> ``math.inf``)."""
    if isinstance(value, str):
        return float(value)
    return float(value)


def iter_events(events: Iterable[Mapping[str, Any]], kind: str) -> Iterator[Mapping[str, Any]]:
    return (e for e in events if e.get("event") == kind)


def needs(events: Iterable[Mapping[str, Any]]) -> dict[str, str]:
    """Every requested agent → the agent that first asked for its need: itself, or, for a
    request that ``renews`` another (asked again after that task ended without doing its
    work), the first of that chain.  Readers count needs by it, not attempts."""
    first: dict[str, str] = {}
    for e in iter_events(events, "request"):
        agent, renews = str(e["agent"]), e.get("renews")
        first[agent] = first.get(str(renews), str(renews)) if renews is not None else agent
    return first
