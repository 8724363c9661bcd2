"""The one strict reader of what a client sends: a body's bytes, a header, a query string.

Every body of ``tasker serve`` passes :func:`read_body` before anything reads its fields:

* its ``Content-Type`` must be ``application/json`` (``charset`` UTF-8 if it says one), or the
  call is refused ``415`` — a page of another origin can send ``text/plain`` without asking
  first (a "simple" request); it cannot send JSON that way;
* it is read at most :data:`MAX_BODY_BYTES` (``413`` beyond, counted while it arrives: a
  ``Content-Length`` that says more is refused before a byte is read);
* it is decoded and parsed by the project's strict reader
  (:func:`tasker.support.reader.parse_json`: UTF-8, nesting at most
  :data:`~tasker.support.reader.MAX_DEPTH`, 64-bit integers, no number of thousands of digits);
* then every value must be one the session can keep (:func:`value_problem`): no ``null`` (a
  field is given or left out: ``session.toml`` is TOML, which has no null), finite numbers only
  (``NaN``, ``1e400``), strings of Unicode scalar values (a lone surrogate such as
  ``"\\ud800"`` cannot be written as UTF-8: not to the trace, not to ``session.toml``, not to an
  event stream) of at most :data:`MAX_STRING` characters, keys alike.

What is accepted here can be written to the trace and to ``session.toml`` and read back; a
refusal is a :class:`experiments.serve.bodies.Refused` naming the body's field.
"""

from __future__ import annotations

import math
import re
from typing import Any

from experiments.serve.bodies import BAD, INVALID, Refused
from tasker.support.reader import InputError, decode, parse_json

MAX_BODY_BYTES = 64 * 1024
"""The largest body read (64 KiB): a request, a change or a world event is a few hundred bytes."""

MAX_STRING = 1024
"""The longest string a body (or ``?reason=``) may hold, in characters: names are short, a note a
sentence; a "did you mean" over a longer one, and its echo in the refusal, stay cheap."""

TOO_LARGE, UNSUPPORTED = 413, 415
"""The statuses of a body larger than :data:`MAX_BODY_BYTES` and of one that is not declared JSON."""

JSON = "application/json"

_DIGITS = re.compile(r"[0-9]{1,18}")


class _BodyError(InputError):
    """What :func:`tasker.support.reader.parse_json` raises about a body (turned into a :class:`Refused`)."""


def content_type_problem(header: str | None) -> str | None:
    """Why a ``Content-Type`` header is not JSON in UTF-8, or ``None``."""
    if header is None or not header.strip():
        return f"none given: a body must be sent as {JSON}"
    kind, _, params = header.partition(";")
    if kind.strip().lower() != JSON:
        return f"{shown(kind.strip())}: a body must be sent as {JSON}"
    for param in params.split(";"):
        name, _, value = param.partition("=")
        if name.strip().lower() == "charset" and value.strip().strip('"').lower() not in ("utf-8", "utf8"):
            return f"charset {shown(value.strip())}: JSON is UTF-8"
    return None


def declared_length(header: str | None, where: str) -> int | None:
    """A ``Content-Length`` header as a number of bytes (``None`` when absent), refused ``413``
    when it is over :data:`MAX_BODY_BYTES` and ``400`` when it is no number."""
    if header is None:
        return None
    text = header.strip()
    if not _DIGITS.fullmatch(text):
        if text.isdigit():  # 19 digits or more: a length no body here has
            raise Refused(TOO_LARGE, where, f"the body is larger than {MAX_BODY_BYTES} bytes, the most read here")
        raise Refused(BAD, where, f"Content-Length {shown(text)}: expected a number of bytes")
    n = int(text)
    if n > MAX_BODY_BYTES:
        raise Refused(TOO_LARGE, where, f"the body ({n} bytes) is larger than {MAX_BODY_BYTES} bytes, the most "
                                        "read here")
    return n


def read_body(raw: bytes, where: str) -> Any:
    """The JSON value of a body already read (at most :data:`MAX_BODY_BYTES`), checked as the module
    docstring says; :class:`Refused` ``400`` (not JSON) or ``422`` (a value the session cannot keep)."""
    if not raw.strip():
        raise Refused(BAD, where, f"the body is empty: expected a JSON object ({JSON})")
    try:
        text = decode(raw, where, _BodyError)
    except _BodyError as exc:  # "is not UTF-8 text (byte 0xff)", "is a binary file, …"
        raise Refused(BAD, where, f"the body {exc.message}") from None
    try:
        data = parse_json(text, where, _BodyError)
    except _BodyError as exc:
        message = exc.message.removeprefix("not valid JSON: ").removeprefix("not readable JSON: ")
        if exc.field:
            raise Refused(INVALID, where, message, exc.field) from None
        at = f" (line {exc.line})" if exc.line and raw.count(b"\n") else ""
        raise Refused(BAD, where, f"the body is not valid JSON: {message}{at}") from None
    problem = value_problem(data)
    if problem is not None:
        field, why = problem
        raise Refused(INVALID, where, why, field)
    return data


def value_problem(data: Any) -> tuple[str, str] | None:
    """``(field, why)`` for the first value of decoded JSON the session cannot keep (the module
    docstring), else ``None``.  Iterative: a deep value does not recurse."""
    stack: list[tuple[Any, str]] = [(data, "")]
    while stack:
        value, field = stack.pop()
        if value is None:
            return field, "null is not a value here: give the field a value or leave it out"
        if isinstance(value, float) and not math.isfinite(value):
            return field, "expected a finite number (NaN, Infinity and numbers beyond 1e308 are not)"
        if isinstance(value, str):
            why = string_problem(value)
            if why is not None:
                return field, why
        elif isinstance(value, dict):
            for key, item in value.items():
                why = string_problem(key)
                if why is not None:
                    return field, f"a key: {why}"
                stack.append((item, f"{field}.{key}" if field else key))
        elif isinstance(value, list):
            stack.extend((item, f"{field}[{i}]") for i, item in enumerate(value))
    return None


def string_problem(text: str) -> str | None:
    """Why ``text`` cannot be kept (too long, or not Unicode scalar values), or ``None``."""
    if len(text) > MAX_STRING:
        return f"a string of {len(text)} characters: at most {MAX_STRING}"
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        return (f"a string holding the lone surrogate U+{ord(text[exc.start]):04X} (character {exc.start}): "
                "not a Unicode character, it cannot be written as UTF-8")
    return None


def event_id(header: str | None) -> int | None:
    """A ``Last-Event-ID`` header as the index of a trace line (``None`` when absent or empty);
    :class:`Refused` ``400`` when it is anything but ASCII digits (``"²"`` is a digit to Python)."""
    if header is None or not header.strip():
        return None
    text = header.strip()
    if not _DIGITS.fullmatch(text):
        raise Refused(BAD, "GET /events", f"expected the id of a trace line this stream sent (a number), got "
                                          f"{shown(text)}", "Last-Event-ID")
    return int(text)


def shown(text: str, limit: int = 40) -> str:
    """``text`` quoted for a message, cut to ``limit`` characters (a refusal never echoes a long value)."""
    return repr(text) if len(text) <= limit else f"{text[:limit]!r}… ({len(text)} characters)"


def cut(text: str, limit: int = 60) -> str:
    """``text`` (a path) as a message shows it: cut to ``limit`` characters."""
    return text if len(text) <= limit else f"{text[:limit]}… ({len(text)} characters)"
