"""The fuzz suite's bounds and its mutation of files.

Every reader gets random and mutated input and must end in one of two ways: a value, or a
:class:`~tasker.errors.TaskerError` (which the command line prints as one line, exit 2) — never
another exception (a traceback, exit 3) and never a hang (:func:`bounded` stops an example that
runs longer than a few seconds).  Hypothesis is derandomized and keeps no database, so CI runs the
same examples every time; ``max_examples`` per test keeps the whole suite under a minute on 2 cores
(``FUZZ_EXAMPLES=10`` multiplies them, for a longer search by hand).
"""

from __future__ import annotations

import os
import signal
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

SCALE = float(os.environ.get("FUZZ_EXAMPLES", "1"))

settings.register_profile("fuzz", derandomize=True, database=None, deadline=None, print_blob=True,
                          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow,
                                                 HealthCheck.data_too_large])


def examples(n: int) -> Any:
    """The fuzz profile with ``n`` examples (times ``$FUZZ_EXAMPLES``)."""
    return settings(settings.get_profile("fuzz"), max_examples=max(1, int(n * SCALE)))


class Hang(Exception):
    """An example ran longer than :func:`bounded` allows: a reader that hangs."""


@contextmanager
def bounded(seconds: float = 10.0) -> Iterator[None]:
    """Raise :class:`Hang` in this (the main) thread if the block runs longer than ``seconds``."""
    def alarm(signum: int, frame: Any) -> None:
        raise Hang(f"still running after {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


NASTY = [b"[", b"]", b"{", b"}", b"(", b")", b"=", b"\n", b"\x00", b"\xff", b"\xe9", b"\xef\xbb\xbf", b'"', b"'",
         b"#", b";", b",", b".", b"-", b"nan", b"inf", b"-1", b"0", b"1e400", b"1" + b"0" * 400, b"9" * 5000,
         b"[" * 200, b"{a = " * 70, b"(and " * 60, b"../../", b"/etc/passwd", b"/dev/zero", b"true", b"null",
         b"\\u0000", b"\t", b"\r\n", b" " * 30]


@st.composite
def mutated(draw: Any, seed: bytes) -> bytes:
    """``seed`` with up to six edits: a range deleted, duplicated or replaced by nasty or random
    bytes, a number made huge, the file cut short."""
    data = bytearray(seed)
    for _ in range(draw(st.integers(0, 6))):
        n = len(data)
        op = draw(st.sampled_from(["delete", "duplicate", "insert", "random", "number", "truncate"]))
        i = draw(st.integers(0, n))
        j = min(n, i + draw(st.integers(0, 40)))
        if op == "delete":
            del data[i:j]
        elif op == "duplicate":
            data[i:i] = data[i:j] * draw(st.integers(1, 3))
        elif op == "insert":
            data[i:i] = draw(st.sampled_from(NASTY)) * draw(st.integers(1, 3))
        elif op == "random":
            data[i:j] = draw(st.binary(max_size=20))
        elif op == "number":
            digits = [k for k in range(n) if chr(data[k]).isdigit()]
            if digits:
                k = draw(st.sampled_from(digits))
                data[k:k + 1] = draw(st.sampled_from([b"1" + b"0" * 400, b"9" * 5000, b"0.0", b"-7", b"1e308"]))
        else:
            del data[i:]
    return bytes(data)
