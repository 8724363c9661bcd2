"""The readers' limits: depth, size, 64-bit integers, special files, UTF-8 — each a clean
:class:`~tasker.support.reader.InputError` naming the file (and the line, the field and the limit
where there is one), never a ``RecursionError``, an ``OverflowError`` or memory filled by ``/dev/zero``."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tasker.support import reader
from tasker.support.reader import MAX_DEPTH, InputError


def _toml(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "f.toml"
    p.write_text(text, encoding="utf-8")
    return p


@pytest.mark.parametrize(("text", "fragment", "line"), [
    ("a = " + "[" * 100_000 + "]" * 100_000 + "\n", "nested more than 64 deep", None),
    ("a = " + "[" * 300 + "]" * 300 + "\n", "nested more than 64 deep", 1),
    ("x = 1\na = " + "{b = " * 200 + "1" + "}" * 200 + "\n", "nested more than 64 deep", 2),
    ("x = 1\n" + "".join(f"[{'.'.join('t' * (k + 1) for k in range(n))}]\n" for n in (70,)), "nested more than", None),
    ("kind = 'x'\nseed = " + "9" * 5000 + "\n", "thousands of digits", 2),
    ("kind = 'x'\n\nseed = 1" + "0" * 400 + "\n", "expected a 64-bit integer, got one of 401 digits", 3),
    ("pose = [1, 2, -1" + "0" * 30 + "]\n", "expected a 64-bit integer", 1),
    ("[t]\nn = 9223372036854775808\n", "expected a 64-bit integer", 2),
])
def test_toml_beyond_the_limits_is_a_clean_error(tmp_path: Path, text: str, fragment: str, line: int | None) -> None:
    p = _toml(tmp_path, text)
    with pytest.raises(InputError) as info:
        reader.load(p)
    assert fragment in str(info.value) and str(p) in str(info.value)
    assert info.value.line == line


def test_the_largest_64_bit_integer_and_depth_are_accepted(tmp_path: Path) -> None:
    deep = "[" * (MAX_DEPTH - 1) + "]" * (MAX_DEPTH - 1)
    t = reader.load(_toml(tmp_path, f"n = {2**63 - 1}\nm = {-2**63}\na = {deep}\n"))
    assert t.number("n", integer=True) == 2**63 - 1 and t.number("m", integer=True) == -2**63


def test_a_number_out_of_range_is_named_where_it_is_read() -> None:
    """check_number took the value's float: a huge int was an OverflowError."""
    t = reader.Table("f.toml", {"horizon": 10**400})
    with pytest.raises(InputError, match="horizon: expected a 64-bit integer"):
        t.number("horizon", positive=True)


@pytest.mark.parametrize(("text", "fragment", "line"), [
    ("[" * 100_000 + "]" * 100_000, "nested more than 64 deep", None),
    ('{"a": ' * 100 + "1" + "}" * 100, "nested more than 64 deep", None),
    ('{"t": 1' + "0" * 5000 + "}", "thousands of digits", 1),
    ('\n\n{"t": 1' + "0" * 400 + "}", "expected a 64-bit integer", None),
    ('[1, 2', "not valid JSON", 1),
])
def test_json_beyond_the_limits_is_a_clean_error(text: str, fragment: str, line: int | None) -> None:
    with pytest.raises(InputError) as info:
        reader.parse_json(text, "x.json")
    assert fragment in str(info.value) and str(info.value).startswith("x.json")
    assert info.value.line == line


def test_a_json_line_is_named_at_its_line_of_the_file() -> None:
    with pytest.raises(InputError, match=r"^days\.jsonl:7: not valid JSON"):
        reader.parse_json("{", "days.jsonl", line=7)
    with pytest.raises(InputError, match=r"^days\.jsonl:7: t: expected a 64-bit integer"):
        reader.parse_json('{"t": ' + "9" * 30 + "}", "days.jsonl", line=7)


def test_a_device_is_refused_without_reading_it() -> None:
    """``/dev/zero`` never ends: read whole, it filled the memory."""
    for loader in (reader.read_text, reader.load):
        with pytest.raises(InputError, match="is not a regular file"):
            loader("/dev/zero")


def test_a_file_larger_than_the_limit_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "big.toml"
    p.write_text("a = 1\n" * 100)
    with pytest.raises(InputError, match="is larger than 64 bytes"):
        reader.read_text(p, limit=64)
    assert reader.read_text(p, limit=600) == "a = 1\n" * 100


def test_a_pipe_nobody_writes_to_is_empty_not_a_hang(tmp_path: Path) -> None:
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    assert reader.read_bytes(fifo) == b""  # before: open() waited for a writer, forever
    assert reader.load(fifo).keys() == []


@pytest.mark.parametrize(("data", "fragment", "line"), [
    (b"a = 1\nb = '\xe9'\n", "is not UTF-8 text (byte 0xe9)", 2),
    (b"a = 1\n\nb\x00 = 2\n", "is a binary file", 3),
    (b"\xef\xbb\xbfa = 1\n", None, None),
])
def test_text_that_is_not_utf8_names_its_line(tmp_path: Path, data: bytes, fragment: str | None,
                                              line: int | None) -> None:
    p = tmp_path / "f.toml"
    p.write_bytes(data)
    if fragment is None:
        assert reader.load(p).number("a") == 1.0
        return
    with pytest.raises(InputError) as info:
        reader.load(p)
    assert fragment in str(info.value) and info.value.line == line


def test_a_name_with_a_nul_is_a_clean_error() -> None:
    with pytest.raises(InputError, match="not a valid file name"):
        reader.read_text("a\x00b.toml")
