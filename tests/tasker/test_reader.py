"""The strict reader: every fault names the file, the line, the field and what was expected."""

from __future__ import annotations

from pathlib import Path

import pytest

from tasker.support import reader
from tasker.support.reader import InputError

TEXT = """\
name = "demo"

[task]
kindd = "blocking"

[[args]]
name = "a"

[[args]]
name = "b"
typo = 1

[schedule]
cps = nan
count = 3.5
flag = 1
"""


def doc() -> reader.Table:
    return reader.loads(TEXT, "task.toml")


def test_unknown_key_names_line_field_valid_keys_and_suggestion() -> None:
    t = doc().table("task")
    t.string("kind", "suspendable")
    with pytest.raises(InputError) as e:
        t.done()
    assert str(e.value).startswith("task.toml:4: task.kindd: unknown key 'kindd'; did you mean 'kind'?")
    assert e.value.line == 4 and e.value.field == "task.kindd"


def test_array_of_tables_elements_have_their_own_lines() -> None:
    second = doc().tables("args")[1]
    second.string("name")
    with pytest.raises(InputError, match=r"task.toml:11: args\[1\].typo: unknown key"):
        second.done()


@pytest.mark.parametrize(("key", "kw", "expected"), [
    ("cps", {}, "expected a finite number, got nan"),
    ("count", {"integer": True}, "expected an integer, got 3.5"),
    ("flag", {}, None),
    ("count", {"max": 2}, "expected a number <= 2, got 3.5"),
])
def test_numbers_are_finite_typed_and_in_range(key: str, kw: dict, expected: str | None) -> None:
    t = doc().table("schedule")
    if expected is None:
        assert t.number(key, **kw) == 1.0
        return
    with pytest.raises(InputError, match=expected):
        t.number(key, **kw)


def test_a_boolean_is_not_a_number() -> None:
    t = reader.loads("x = true\n", "f.toml")
    with pytest.raises(InputError, match="f.toml:1: x: expected a number, got a boolean True"):
        t.number("x")


def test_names_are_checked_with_did_you_mean() -> None:
    t = reader.loads('person = "jhon"\n', "s.toml")
    with pytest.raises(InputError, match=r"s.toml:1: person: no person 'jhon'; did you mean 'john'\?"):
        t.name("person", ["john", "alice"], "person")


def test_missing_required_key() -> None:
    with pytest.raises(InputError, match="f.toml: world: missing"):
        reader.loads("", "f.toml").string("world")


def test_a_missing_key_names_the_misspelling_of_it_among_the_declared_keys() -> None:
    """'[arivals]' was reported as "arrivals: missing (required)" alone: the misspelt table, the
    cause, was named only by done(), which the error kept from running."""
    t = reader.loads('name = "x"\npick_s = 1\n\n[arivals]\nprocess = "uniform"\n', "f.toml")
    with pytest.raises(InputError, match=r"^f\.toml: arrivals: missing \(required\)$"):
        t.raw("arrivals")  # nothing declared: as before
    t.declare(("name", "arrivals", "pick_s", "place_s"))
    with pytest.raises(InputError, match=r"^f\.toml: arrivals: missing \(required\); the file has 'arivals' "
                                         r"\(line 4\), not a valid key: did you mean 'arrivals'\?$"):
        t.raw("arrivals")
    with pytest.raises(InputError, match=r"^f\.toml: place_s: missing \(required\)$"):
        t.raw("place_s")  # pick_s is close, but a valid key of its own: never offered for another


def test_syntax_error_names_the_line(tmp_path: Path) -> None:
    p = tmp_path / "bad.toml"
    p.write_text("a = 1\nb = [1,\n")
    with pytest.raises(InputError, match=r"bad.toml:\d+: not valid TOML"):
        reader.load(p)


@pytest.mark.parametrize(("content", "message"), [
    (b"a = 1\n\x00\x01", "binary file"),
    (b'a = "ok"\nb = "\xff"\n', "bad.toml:2: is not UTF-8"),
])
def test_binary_and_non_utf8_files(tmp_path: Path, content: bytes, message: str) -> None:
    p = tmp_path / "bad.toml"
    p.write_bytes(content)
    with pytest.raises(InputError, match=message):
        reader.load(p)


def test_missing_file_and_directory(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no such file"):
        reader.load(tmp_path / "nope.toml")
    with pytest.raises(InputError, match="is a directory"):
        reader.load(tmp_path)


def test_not_a_table() -> None:
    t = reader.loads("task = 3\n", "f.toml")
    with pytest.raises(InputError, match="f.toml:1: task: expected a table, got an integer"):
        t.table("task")


@pytest.mark.parametrize(("read", "expected"), [
    (lambda t: t.table("x"), "f.toml:1: x: expected a table, got a number"),
    (lambda t: t.string("x"), "f.toml:1: x: expected a string, got a number inf"),
    (lambda t: t.boolean("x"), "f.toml:1: x: expected true or false, got a number inf"),
    (lambda t: t.number("x"), "f.toml:1: x: expected a finite number, got inf"),
])
def test_a_non_finite_number_where_no_number_belongs_says_what_was_expected(read, expected: str) -> None:  # type: ignore[no-untyped-def]
    """``settings = inf`` was 'expected a finite number', as if a number were wanted there."""
    t = reader.loads("x = inf\n", "f.toml")
    with pytest.raises(InputError) as info:
        read(t)
    assert str(info.value) == expected


def test_a_utf8_byte_order_mark_is_not_a_syntax_error(tmp_path: Path) -> None:
    """Before: ``bad.toml:1: not valid TOML: Invalid statement`` for a file saved with a BOM."""
    p = tmp_path / "bom.toml"
    p.write_bytes(b'\xef\xbb\xbfname = "demo"\n')
    assert reader.load(p).string("name") == "demo"
