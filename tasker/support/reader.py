"""The one strict reader for every file a user writes (scenarios, worlds, ``task.toml``, sweep specs).

A file is read with :func:`load` into a :class:`Table`: typed access to its keys, where
every fault is an :class:`InputError` that names the file, the line (when the file has
one for the key), the dotted field and what was expected — with a "did you mean" for
misspelled names.  Reading is strict by default:

* the file must be UTF-8 text (a binary file or a stray byte is an error naming the line), a
  regular file (not ``/dev/zero``) of at most :data:`MAX_FILE_BYTES`;
* arrays and tables nest at most :data:`MAX_DEPTH` deep, integers fit in 64 bits (TOML's rule);
  :func:`parse_json` holds JSON (run records, results, traces) to the same limits;
* a number must be finite (TOML's ``nan`` and ``inf`` are refused) and of the right type
  (``true`` is not a number; an integer is accepted where a float is expected);
* :meth:`Table.done` refuses keys nobody asked for, listing the valid ones, so
  ``kindd = "blocking"`` or ``[shedule]`` cannot be silently ignored.

Each reader of a file format passes its own subclass of :class:`InputError` as
``error_class`` (``ScenarioError``, ``WorldFileError``, ``SpecError``), so callers can
catch either.  What is valid but doubtful is an :class:`InputWarning`
(:meth:`Table.warn`), located at the user's file and line.

Line numbers come from a light index of the source text (table headers and ``key =``
lines); for a key written inside an inline table the line of the enclosing key is named.
Stdlib only, like the rest of :mod:`tasker`.
"""

from __future__ import annotations

import difflib
import json
import math
import os
import re
import stat
import tomllib
import warnings
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from tasker.errors import InputError as InputError  # defined there; re-exported here
from tasker.errors import located

PathKey = tuple[str | int, ...]

MAX_SEED = 2**32 - 1
"""Seeds are integers in ``[0, MAX_SEED]``: OMPL's random generator takes no other."""

_MISSING: Any = object()
_HEADER = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")
_KEY = r"""(?:[A-Za-z0-9_\-]+|"[^"]*"|'[^']*')"""
_ASSIGN = re.compile(rf"^\s*({_KEY}(?:\s*\.\s*{_KEY})*)\s*=")
_TOML_POS = re.compile(r"\(at line (\d+), column (\d+)\)")


class InputWarning(UserWarning):
    """A user's file is accepted but probably not what was meant (a request after the horizon)."""


def warn_at(file: str | Path, line: int | None, field: str, message: str) -> str:
    """Emit an :class:`InputWarning` about ``file`` (at ``line``, ``field`` when known); returns
    its text.  Located at the user's file and line, not at the code that found it, so Python
    shows that line."""
    text = located(str(file), line, field, message)
    warnings.warn_explicit(InputWarning(text), InputWarning, str(file), line or 0, module="tasker.support.reader")
    return text


def suggest(name: str, known: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` for the closest known name, or ``""``."""
    close = difflib.get_close_matches(str(name), [str(k) for k in known], n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""


def _split_key(text: str) -> tuple[str, ...]:
    parts = re.findall(r"""[A-Za-z0-9_\-]+|"[^"]*"|'[^']*'""", text)
    return tuple(p[1:-1] if p[:1] in "\"'" else p for p in parts)


class _LineIndex:
    """Where each key of a TOML text is written: ``(table path..., key) -> line``."""

    def __init__(self, text: str) -> None:
        self.lines: dict[PathKey, int] = {}
        self._counts: dict[tuple[str, ...], int] = {}
        current: PathKey = ()
        for n, raw in enumerate(text.splitlines(), start=1):
            m = _HEADER.match(raw)
            if m and not _ASSIGN.match(raw):
                path = _split_key(m.group(2))
                if m.group(1) == "[[":
                    k = self._counts.get(path, 0)
                    self._counts[path] = k + 1
                    current = (*self._resolve(path[:-1]), path[-1], k)
                else:
                    current = self._resolve(path)
                self.lines.setdefault(current, n)
                continue
            a = _ASSIGN.match(raw)
            if a:
                self.lines.setdefault((*current, *_split_key(a.group(1))), n)

    def _resolve(self, path: tuple[str, ...]) -> PathKey:
        """A header path with array-of-tables prefixes pointing at their latest element."""
        out: list[str | int] = []
        for i, part in enumerate(path):
            out.append(part)
            k = self._counts.get(path[: i + 1])
            if k:
                out.append(k - 1)
        return tuple(out)

    def line(self, path: PathKey) -> int | None:
        for k in range(len(path), 0, -1):
            hit = self.lines.get(path[:k])
            if hit is not None:
                return hit
        return None


class Table:
    """One table of a file, read strictly.  Keys asked for are remembered for :meth:`done`."""

    def __init__(self, file: str | Path, data: Any, path: PathKey = (), index: _LineIndex | None = None,
                 error_class: type[InputError] = InputError) -> None:
        self.file = str(file)
        self.path = path
        self._index = index
        self.error_class = error_class
        if not isinstance(data, dict):
            raise error_class(self.file, f"expected a table, got {_kind(data)}", line=self.line(),
                             field=self.field() or "top level")
        self.data: dict[str, Any] = data
        self.used: set[str] = set()
        self.declared: frozenset[str] | None = None

    # -- where ----------------------------------------------------------------------
    def field(self, key: str | int | None = None) -> str:
        parts = [*self.path, *(() if key is None else (key,))]
        out = ""
        for p in parts:
            out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
        return out

    def line(self, key: str | int | None = None) -> int | None:
        if self._index is None:
            return None
        return self._index.line((*self.path, *(() if key is None else (key,))))

    def error(self, key: str | int | None, message: str) -> InputError:
        return self.error_class(self.file, message, line=self.line(key), field=self.field(key))

    def warn(self, key: str | int | None, message: str) -> str:
        """Emit an :class:`InputWarning` located like :meth:`error`; returns its text."""
        return warn_at(self.file, self.line(key), self.field(key), message)

    def at(self, key: str | int, data: Any) -> Table:
        """A table at ``key`` below this one whose value is ``data`` (e.g. an element of an array)."""
        return Table(self.file, data, (*self.path, key), self._index, self.error_class)

    # -- access ---------------------------------------------------------------------
    def __contains__(self, key: str) -> bool:
        return key in self.data

    def keys(self) -> list[str]:
        return list(self.data)

    def raw(self, key: str, default: Any = _MISSING, *, finite: bool = True) -> Any:
        """The value as written (checked for non-finite numbers unless ``finite`` is false: the
        caller then refuses every number, so ``settings = inf`` reads "expected a table"), or ``default``."""
        self.used.add(key)
        if key not in self.data:
            if default is _MISSING:
                raise self.error(key, "missing (required)" + self._misspelt(key))
            return default
        value = self.data[key]
        if finite:
            _check_finite(self, key, value)
        return value

    def string(self, key: str, default: Any = _MISSING, *, choices: Sequence[str] | None = None,
               empty: bool = False) -> Any:
        value = self.raw(key, default, finite=False)
        if value is default and key not in self.data:
            return value
        if not isinstance(value, str):
            raise self.error(key, f"expected a string, got {_show(value)}")
        if not empty and not value:
            raise self.error(key, "expected a non-empty string")
        if choices is not None and value not in choices:
            raise self.error(key, f"expected one of {list(choices)}, got {value!r}{suggest(value, choices)}")
        return value

    def boolean(self, key: str, default: Any = _MISSING) -> Any:
        value = self.raw(key, default, finite=False)
        if key in self.data and not isinstance(value, bool):
            raise self.error(key, f"expected true or false, got {_show(value)}")
        return value

    def number(self, key: str, default: Any = _MISSING, *, min: float | None = None, max: float | None = None,
               positive: bool = False, integer: bool = False) -> Any:
        value = self.raw(key, default)
        if key not in self.data:
            return value
        return check_number(self, key, value, min=min, max=max, positive=positive, integer=integer)

    def table(self, key: str, default: Any = _MISSING) -> Table:
        """A sub-table; a missing optional one reads as empty."""
        value = self.raw(key, default, finite=False)
        return Table(self.file, {} if value is None else value, (*self.path, key), self._index, self.error_class)

    def tables(self, key: str, default: Any = _MISSING) -> list[Table]:
        """An array of tables (``[[key]]``)."""
        value = self.raw(key, default)
        if key not in self.data:
            return []
        if not isinstance(value, list):
            raise self.error(key, f"expected an array of tables ([[{key}]]), got {_show(value)}")
        return [Table(self.file, v, (*self.path, key, i), self._index, self.error_class) for i, v in enumerate(value)]

    def array(self, key: str, default: Any = _MISSING, *, nonempty: bool = False) -> Any:
        """A list (``[]`` or ``default`` when absent)."""
        value = self.raw(key, default)
        if key not in self.data:
            return value
        if not isinstance(value, list):
            raise self.error(key, f"expected an array, got {_show(value)}")
        if nonempty and not value:
            raise self.error(key, "expected a non-empty array")
        return value

    def numbers(self, key: str, n: int, shape: str, default: Any = _MISSING) -> Any:
        """``n`` finite numbers, e.g. a pose ``[x, y, yaw]`` (``shape`` says which)."""
        value = self.raw(key, default)
        if key not in self.data:
            return value
        return check_numbers(self, key, value, n, shape)

    def named(self, key: str) -> list[tuple[str, Table]]:
        """A table of named tables (``[people.NAME]``): ``(name, table)`` pairs, empty when absent."""
        t = self.table(key, {})
        out = []
        for name, value in t.items():
            out.append((name, t.at(name, value)))
        return out

    def items(self) -> list[tuple[str, Any]]:
        """Every key, marked as used (for tables whose keys are names: people, places)."""
        self.used.update(self.data)
        for k, v in self.data.items():
            _check_finite(self, k, v)
        return list(self.data.items())

    def name(self, key: str, known: Iterable[str], what: str, default: Any = _MISSING) -> Any:
        """A string that must name one of ``known`` (a cross-reference), with "did you mean"."""
        value = self.string(key, default)
        if key in self.data:
            check_name(self, key, value, known, what)
        return value

    def declare(self, keys: Iterable[str]) -> None:
        """Say, before reading, every key this table may hold.  Then a required key that is
        missing names a key of the table that is none of these and close to it: ``[arivals]``
        is reported with "arrivals: missing (required)", not left for :meth:`done`, never reached."""
        self.declared = frozenset(keys)

    def _misspelt(self, key: str) -> str:
        if self.declared is None:
            return ""
        close = difflib.get_close_matches(key, [k for k in self.data if k not in self.declared], n=1, cutoff=0.6)
        if not close:
            return ""
        line = self.line(close[0])
        return f"; the file has {close[0]!r}{f' (line {line})' if line else ''}, not a valid key: did you mean {key!r}?"

    def done(self, also: Iterable[str] = ()) -> None:
        """Refuse keys nobody read, naming the valid ones (and the closest); ``also`` are valid too."""
        valid_keys = self.used | set(also)
        extra = [k for k in self.data if k not in valid_keys]
        if extra:
            k = extra[0]
            valid = ", ".join(sorted(valid_keys)) or "none"
            raise self.error(k, f"unknown key {k!r}{suggest(k, valid_keys)} (valid keys: {valid})")


def check_number(t: Table, key: str | int, value: Any, *, min: float | None = None, max: float | None = None,
                 positive: bool = False, integer: bool = False) -> float | int:
    """A finite number within bounds (``t.error(key, ...)`` otherwise)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise t.error(key, f"expected {'an integer' if integer else 'a number'}, got {_show(value)}")
    if integer and not isinstance(value, int):
        raise t.error(key, f"expected an integer, got {value!r}")
    if isinstance(value, int) and not -MAX_INT - 1 <= value <= MAX_INT:
        raise t.error(key, f"expected a 64-bit integer, got one of {len(str(abs(value)))} digits")
    if not math.isfinite(value):
        raise t.error(key, f"expected a finite number, got {value!r}")
    if positive and value <= 0:
        raise t.error(key, f"expected a number > 0, got {value!r}")
    if min is not None and value < min:
        raise t.error(key, f"expected a number >= {min:g}, got {value!r}")
    if max is not None and value > max:
        raise t.error(key, f"expected a number <= {max:g}, got {value!r}")
    return value if integer else float(value)


def check_numbers(t: Table, key: str | int, value: Any, n: int, shape: str) -> tuple[float, ...]:
    """``n`` finite numbers (``shape`` names them in the error, e.g. ``[x, y, yaw]``)."""
    if not isinstance(value, list) or len(value) != n or any(
            isinstance(v, bool) or not isinstance(v, int | float) for v in value):
        raise t.error(key, f"expected {shape}, got {_show(value)}")
    for v in value:
        if not math.isfinite(v):
            raise t.error(key, f"expected {shape} of finite numbers, got {value!r}")
    return tuple(float(v) for v in value)


def check_name(t: Table, key: str | int, value: str, known: Iterable[str], what: str, hint: str = "") -> None:
    """``value`` must be one of ``known`` (e.g. a person of the world); ``hint`` says how to add one."""
    known = sorted(set(known))
    if value not in known:
        raise t.error(key, f"no {what} {value!r}{suggest(value, known)} (known: {', '.join(known) or 'none'})"
                           + (f"; {hint}" if hint else ""))


def _check_finite(t: Table, key: str, value: Any) -> None:
    if isinstance(value, float) and not math.isfinite(value):
        raise t.error(key, f"expected a finite number, got {value!r}")
    if isinstance(value, list):
        for v in value:
            _check_finite(t, key, v)


def _kind(value: Any) -> str:
    return {dict: "a table", list: "an array", str: "a string", bool: "a boolean", int: "an integer",
            float: "a number"}.get(type(value), type(value).__name__)


def _show(value: Any) -> str:
    return f"{_kind(value)} {value!r}"


# -- reading within limits ---------------------------------------------------------------

MAX_FILE_BYTES = 64 * 2**20
"""The largest file a reader takes whole (64 MiB): far above any scenario, world, task folder,
protocol, spec or run record; a mistaken path (a disk image, ``/dev/zero``) fails at once."""

MAX_DEPTH = 64
"""Arrays and tables (JSON objects) within each other at most this deep: no file of tasker's
needs a tenth of it, and readers of deeper ones would run out of Python's recursion."""

MAX_SECONDS = 7 * 24 * 3600.0
"""The longest simulated time an input may name (a week): a horizon, a request's time, a duration,
a budget.  A run steps its clock up to the times it is given, so ``t = 1e300`` never ended."""

MAX_INT = 2**63 - 1
"""Integers are 64-bit (TOML's rule, and SQLite's): a longer one is refused where it is read,
never turned into an ``OverflowError`` by the first ``float()`` downstream."""


def _size(n: int) -> str:
    return f"{n / 2**20:g} MiB" if n >= 2**20 else f"{n} bytes"


def read_bytes(path: str | Path, error_class: type[InputError] = InputError, *,
               limit: int = MAX_FILE_BYTES) -> bytes:
    """A file's bytes, at most ``limit`` of them: a missing file, a folder, a device (``/dev/zero``
    never ends) or a file larger than ``limit`` is a clean ``error_class`` naming it.  A pipe is
    read up to the limit; one that no program writes to reads as empty (it never blocks)."""
    p = Path(path)
    if "\x00" in str(path):
        raise error_class(repr(str(path)), "is not a valid file name (it holds a NUL character)")
    try:
        mode = p.stat().st_mode
        if stat.S_ISDIR(mode):
            raise IsADirectoryError
        if not (stat.S_ISREG(mode) or stat.S_ISFIFO(mode)):
            raise error_class(p, "is not a regular file (a device or a socket), expected a file")
        # a pipe is opened without waiting for a writer (none: it reads as empty), then read as a file
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK)
        os.set_blocking(fd, True)
        with os.fdopen(fd, "rb") as f:
            data = f.read(limit + 1)
    except FileNotFoundError:
        raise error_class(p, "no such file") from None
    except IsADirectoryError:
        raise error_class(p, "is a directory, expected a file") from None
    except OSError as exc:
        raise error_class(p, f"cannot read: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise error_class(p, f"is larger than {_size(limit)}, the most a file read here may have")
    return data


def decode(data: bytes, file: str | Path, error_class: type[InputError] = InputError) -> str:
    """UTF-8 text (a byte-order mark dropped); a NUL or a byte that is no UTF-8 names its line."""
    nul = data.find(b"\x00")
    if nul >= 0:
        raise error_class(file, "is a binary file, expected UTF-8 text", line=data[:nul].count(b"\n") + 1)
    data = data.removeprefix(b"\xef\xbb\xbf")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise error_class(file, f"is not UTF-8 text (byte {data[exc.start]:#04x})", line=line) from None


def read_text(path: str | Path, error_class: type[InputError] = InputError, *, limit: int = MAX_FILE_BYTES) -> str:
    """A user's file as text (:func:`read_bytes`, :func:`decode`): missing, special, too large,
    binary and non-UTF-8 files are clean errors.  A UTF-8 byte-order mark (Windows editors write
    one) is dropped: TOML parsers would call it a syntax error."""
    return decode(read_bytes(path, error_class, limit=limit), path, error_class)


def _field(path: Sequence[str | int]) -> str:
    out = ""
    for p in path[:6]:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out + ("…" if len(path) > 6 else "")


def tree_problem(data: Any) -> tuple[tuple[str | int, ...], str] | None:
    """``(path, why)`` when decoded data nests deeper than :data:`MAX_DEPTH` or holds an integer
    outside 64 bits; else ``None``.  Iterative, so it never recurses itself."""
    stack: list[tuple[Any, tuple[str | int, ...]]] = [(data, ())]
    while stack:
        value, path = stack.pop()
        if isinstance(value, int) and not isinstance(value, bool):
            if not -MAX_INT - 1 <= value <= MAX_INT:
                return path, f"expected a 64-bit integer, got one of {len(str(abs(value)))} digits"
        elif isinstance(value, dict | list):
            if len(path) >= MAX_DEPTH:
                return path, f"nested more than {MAX_DEPTH} deep"
            items = value.items() if isinstance(value, dict) else enumerate(value)
            stack.extend((v, (*path, k)) for k, v in items)
    return None


def _long_number_line(text: str) -> int | None:
    m = re.search(r"\d{4000}", text)
    return text.count("\n", 0, m.start()) + 1 if m else None


def parse_json(text: str, file: str | Path = "<string>", error_class: type[InputError] = InputError, *,
               line: int | None = None) -> Any:
    """Decoded JSON within the limits (:data:`MAX_DEPTH`, 64-bit integers); ``line`` is where
    ``text`` starts in ``file`` (a line of a ``.jsonl``).  Faults are ``error_class`` errors."""
    at = (line or 1) - 1
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise error_class(file, f"not valid JSON: {exc.msg}", line=at + exc.lineno) from None
    except RecursionError:
        raise error_class(file, f"not readable JSON: nested more than {MAX_DEPTH} deep", line=line) from None
    except ValueError:  # Python refuses integers of more than 4300 digits
        raise error_class(file, "not readable JSON: a number of thousands of digits",
                          line=at + (_long_number_line(text) or 1)) from None
    problem = tree_problem(data)
    if problem is not None:
        path, why = problem
        raise error_class(file, why, line=line, field=_field(path))
    return data


def loads(text: str, file: str | Path = "<string>", error_class: type[InputError] = InputError) -> Table:
    """Parse TOML text into a strict :class:`Table` (syntax errors name the line; nesting deeper
    than :data:`MAX_DEPTH` and integers beyond 64 bits are refused, as TOML says)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = _TOML_POS.search(str(exc))
        msg = _TOML_POS.sub("", str(exc)).strip()
        line = int(m.group(1)) if m else (text.count("\n") + 1 if "end of document" in msg else None)
        raise error_class(file, f"not valid TOML: {msg}", line=line) from None
    except RecursionError:
        raise error_class(file, f"not readable TOML: arrays or tables nested more than {MAX_DEPTH} deep") from None
    except ValueError:  # Python refuses integers of more than 4300 digits
        raise error_class(file, "not valid TOML: expected a 64-bit integer, got one of thousands of digits",
                          line=_long_number_line(text)) from None
    index = _LineIndex(text)
    problem = tree_problem(data)
    if problem is not None:
        path, why = problem
        raise error_class(file, why, line=index.line(path), field=_field(path))
    return Table(file, data, (), index, error_class)


def load(path: str | Path, error_class: type[InputError] = InputError) -> Table:
    """Read a user's TOML (or ``.json``) file into a strict :class:`Table`.

    ``error_class`` (a subclass of :class:`InputError`) is what every fault of this file raises.
    """
    text = read_text(path, error_class)
    if str(path).endswith(".json"):
        return Table(path, parse_json(text, path, error_class), (), None, error_class)
    return loads(text, path, error_class)
