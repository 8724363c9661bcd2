"""The trace's encoding is canonical, and every event kind is documented."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tasker.events import ModeChanged
from tasker.trace import EVENTS, Trace, encode, read

from .helpers import guide, make_loop

DOC = Path(__file__).parents[2] / "docs" / "trace.md"


def test_encoding_is_canonical() -> None:
    line = encode({"t": 1.0000004, "event": "x", "c": float("inf"), "d": -0.0, "e": (1, 2), "f": {"b": 1}})
    assert line == '{"t":1.0,"event":"x","c":"inf","d":0.0,"e":[1,2],"f":{"b":1}}'
    # six decimals, no more and no fewer: each value below is written otherwise at 5 or 7 decimals
    line = encode({"t": 2.7182818, "event": "x", "a": 0.1234567, "b": -0.0000004, "c": 12.3456789,
                   "d": [1.2345674], "e": {"f": -3.0000006}, "g": float("-inf"), "h": 7})
    assert line == ('{"t":2.718282,"event":"x","a":0.123457,"b":0.0,"c":12.345679,"d":[1.234567],'
                    '"e":{"f":-3.000001},"g":"-inf","h":7}')
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


@pytest.mark.parametrize(("content", "message"), [
    (b'{"t":0.0,"event":"run"}\n{"t":1.0,"ev', r"trace\.jsonl:2: not a JSON object: Unterminated string"),
    (b'{"t":0.0,"event":"run"}\n5\n', r"trace\.jsonl:2: not a JSON object: 5"),
    (b'{"t":0.0,"event":"run"}\n{"event":"end"}\n', r"trace\.jsonl:2: not an event: expected \"t\" \(a number\)"),
    (b'{"t":"soon","event":"run"}\n', r"trace\.jsonl:1: not an event"),
    (b'{"t":0.0,"event":"run"}\n{"t":1.0,"event":"x\xff"}\n', r"trace\.jsonl:2: not UTF-8 text \(byte 0xff\)"),
])
def test_a_damaged_trace_names_its_line(tmp_path: Path, content: bytes, message: str) -> None:
    """A trace cut short, with a stray byte or a line that is no event, is a ValueError at its
    line (which commands report), not a TypeError or KeyError in whatever reads it next."""
    (tmp_path / "trace.jsonl").write_bytes(content)
    with pytest.raises(ValueError, match=message):
        read(tmp_path / "trace.jsonl")


def test_every_event_kind_is_documented() -> None:
    text = DOC.read_text(encoding="utf-8")
    documented = set(re.findall(r'^### `(\w+)`', text, flags=re.M))
    assert documented == set(EVENTS)


def test_streaming_sink_matches_memory(tmp_path: Path) -> None:
    with open(tmp_path / "t.jsonl", "w", encoding="utf-8") as f:
        tr = Trace(sink=f)
        tr.emit(ModeChanged(0.5, "IT"))
    assert (tmp_path / "t.jsonl").read_text() == tr.dumps()
