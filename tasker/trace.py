"""The trace: one JSON object per line, the only record metrics and plots read.

Every event has ``t`` (simulated seconds) and ``event``; the fields of each event are
documented in ``docs/trace.md``.  Encoding is canonical so that the same run gives
the same bytes: keys in a fixed order, floats rounded to 6 decimals, infinities as
the strings ``"inf"``/``"-inf"`` (JSON has no infinity), no wall-clock values.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import IO, Any

EVENTS = (
    "run", "request", "transition", "command", "roles", "decision", "plan",
    "stage", "mode", "change", "world", "hazard", "role", "secure", "end",
)

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

    Observers (metrics collectors) get each event dict after it is recorded; they
    must not modify it.
    """

    def __init__(self, sink: IO[str] | None = None, keep: bool = True) -> None:
        self._events: list[dict[str, Any]] = []
        self._sink = sink
        self._keep = keep
        self._observers: list[Callable[[dict[str, Any]], None]] = []

    def emit(self, t: float, event: str, **fields: Any) -> None:
        record: dict[str, Any] = {"t": round(t, 6), "event": event}
        record.update(fields)
        if self._keep:
            self._events.append(record)
        if self._sink is not None:
            self._sink.write(encode(record) + "\n")
        for obs in self._observers:
            obs(record)

    def subscribe(self, observer: Callable[[dict[str, Any]], None]) -> None:
        self._observers.append(observer)

    @property
    def events(self) -> list[dict[str, Any]]:
        return self._events

    def of(self, event: str, **match: Any) -> list[dict[str, Any]]:
        """Events of one kind whose fields equal ``match``."""
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
    string).  A damaged file (cut short, a stray byte, a line that is no event) is a
    ``ValueError`` naming the file and the line."""
    data = Path(path).read_bytes()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        at = data[: exc.start].count(b"\n") + 1
        raise ValueError(f"{path}:{at}: not UTF-8 text (byte {data[exc.start]:#04x})") from None
    out = []
    for n, line in enumerate(text.splitlines(), start=1):
        if line.strip():
            try:
                event = json.loads(line)
            except json.JSONDecodeError as exc:
                raise ValueError(f"{path}:{n}: not a JSON object: {exc.msg}") from None
            if not isinstance(event, dict):
                raise ValueError(f"{path}:{n}: not a JSON object: {line.strip()[:40]}")
            t = event.get("t")
            if not isinstance(event.get("event"), str) or isinstance(t, bool) or not isinstance(t, int | float):
                raise ValueError(f"{path}:{n}: not an event: expected \"t\" (a number) and \"event\" (a string)")
            out.append(event)
    return out


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
