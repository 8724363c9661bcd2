"""The trace's encoding is canonical, and every event kind is documented."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tasker.trace import EVENTS, Trace, encode, read

from .helpers import guide, make_loop

DOC = Path(__file__).parents[2] / "docs" / "trace.md"


def test_encoding_is_canonical() -> None:
    line = encode({"t": 1.0000004, "event": "x", "c": float("inf"), "d": -0.0, "e": (1, 2), "f": {"b": 1}})
    assert line == '{"t":1.0,"event":"x","c":"inf","d":0.0,"e":[1,2],"f":{"b":1}}'
    with pytest.raises(TypeError, match="cannot put a object"):
        encode({"t": 0, "event": "x", "o": object()})


def test_trace_round_trips_through_a_file(tmp_path: Path) -> None:
    loop = make_loop([guide()])
    loop.request(0.0, "guide")
    tr = loop.run()
    tr.write(tmp_path / "trace.jsonl")
    back = read(tmp_path / "trace.jsonl")
    assert back == [json.loads(line) for line in tr.lines()]
    assert all(e["event"] in EVENTS for e in back)


def test_every_event_kind_is_documented() -> None:
    text = DOC.read_text(encoding="utf-8")
    documented = set(re.findall(r'^### `(\w+)`', text, flags=re.M))
    assert documented == set(EVENTS)


def test_streaming_sink_matches_memory(tmp_path: Path) -> None:
    with open(tmp_path / "t.jsonl", "w", encoding="utf-8") as f:
        tr = Trace(sink=f)
        tr.emit(0.5, "mode", mode="IT")
    assert (tmp_path / "t.jsonl").read_text() == tr.dumps()
