"""Checks for command-line arguments, shared by every ``tasker`` subcommand.

The subcommands live in the packages they drive (``experiments``, ``planners``,
``robot``), which may import ``tasker`` but not each other, so the checks every one of
them needs live here: seeds, time-outs, counts, output paths, "did you mean", and the
exit statuses.  Standard library only, like the rest of ``tasker``.

An ``argparse`` ``type=`` function raises ``argparse.ArgumentTypeError`` (argparse
then prints ``tasker CMD: error: argument --seed: …`` and exits 2); a check made after
parsing raises :class:`UsageError`, whose message starts with the argument's name.
"""

from __future__ import annotations

import argparse
import difflib
import math
import os
import re
import sys
import tempfile
import traceback
import warnings
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, NoReturn, TypeVar

from experiments.inputs.fields import TASKS_HINT
from tasker.errors import TaskerError, UnknownName, UsageError
from tasker.support.reader import InputWarning

EXIT_OK = 0
"""The command did what it was asked."""
EXIT_FAILED = 1
"""It ran, but the outcome is a failure: a task failed (``run --strict``), the run aborted, no plan,
an unreachable goal, ``check`` found problems, sweep jobs failed."""
EXIT_USAGE = 2
"""Bad input: an argument, a file, or a name; nothing was run."""
EXIT_INTERNAL = 3
"""A bug in tasker (``--verbose`` shows the traceback)."""
EXIT_INTERRUPTED = 130
"""Interrupted (Ctrl-C)."""

EXIT_EPILOG = """\
exit status:
  0    ok
  1    the work ran but failed: a task failed (run --strict), the run aborted, no plan,
       an unreachable pair (cost), problems found (check), sweep jobs failed, a day failed (day)
  2    bad input: an argument, a file or a name; nothing was run
  3    internal error: a bug in tasker (--verbose shows the traceback)
  130  interrupted (Ctrl-C)"""

SEED_LIMIT = 2**32
"""Seeds are ``0 <= seed < 2**32``: what NumPy, OMPL and MuJoCo all accept."""

MAX_TIMEOUT_S = 24 * 3600.0
"""The longest time-out an option may give (a day): a larger one (1e300) overflowed the clock."""

MAX_WORKERS = 1024
"""The most local worker processes an option may ask for (a huge count overflowed, or forked on)."""


def shown(value: object) -> str:
    """A value as an error shows it: a number of hundreds of digits by its length."""
    text = str(value)
    return text if len(text) <= 30 else f"an integer of {len(text.lstrip('-'))} digits"


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """``" (did you mean 'x'?)"`` for the closest known name, or ``""``."""
    close = difflib.get_close_matches(name, list(known), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def seed_error(value: object) -> str | None:
    """Why ``value`` is not a seed, or ``None`` when it is one."""
    if isinstance(value, bool) or not isinstance(value, int):
        return f"expected an integer seed 0 <= seed < 2**32, got {value!r}"
    if not 0 <= value < SEED_LIMIT:
        return f"expected a seed 0 <= seed < 2**32, got {shown(value)}"
    return None


def seed(text: str) -> int:
    """``type=`` for ``--seed``: an integer ``0 <= s < 2**32``."""
    try:
        value = int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer seed 0 <= seed < 2**32, got {shown(repr(text))}") \
            from None
    why = seed_error(value)
    if why:
        raise argparse.ArgumentTypeError(why)
    return value


_T = TypeVar("_T")


def _read(text: str, cast: Callable[[str], _T], expected: str, got: str | None = None) -> _T:
    """``cast(text)``, or the ``type=`` error "expected EXPECTED, got ``got`` (the text's repr)"."""
    try:
        return cast(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected {expected}, got {repr(text) if got is None else got}") from None


def positive_seconds(text: str) -> float:
    """``type=`` for time-outs: a finite number of seconds greater than zero."""
    value = _read(text, float, "a number of seconds")
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a finite number of seconds > 0, got {text!r}")
    if value > MAX_TIMEOUT_S:
        raise argparse.ArgumentTypeError(f"expected at most {MAX_TIMEOUT_S:g} s (a day), got {text!r}")
    return value


def non_negative_seconds(text: str) -> float:
    """``type=`` for simulated times such as ``--at``: a finite number of seconds >= 0."""
    value = _read(text, float, "a number of seconds")
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"expected a finite number of seconds >= 0, got {text!r}")
    return value


def speed(text: str) -> float:
    """``type=`` for ``tasker serve --speed``: simulated seconds per wall second, finite and > 0."""
    value = _read(text, float, "a number of simulated seconds per second")
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a speed > 0 (simulated seconds per wall second), got {text!r}")
    return value


def port(text: str) -> int:
    """``type=`` for ``--port``: 0 (any free one) to 65535."""
    value = _read(text, int, "a port number")
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port 0..65535 (0: any free one), got {value}")
    return value


def positive_int(text: str) -> int:
    """``type=`` for counts such as ``--days``: an integer >= 1."""
    value = _read(text, int, "a positive integer", shown(repr(text)))
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {shown(value)}")
    return value


def workers(text: str) -> int:
    """``type=`` for ``--workers``: an integer in ``1 … MAX_WORKERS``."""
    value = positive_int(text)
    if value > MAX_WORKERS:
        raise argparse.ArgumentTypeError(f"expected at most {MAX_WORKERS} worker processes, got {shown(value)}")
    return value


def non_negative_int(text: str) -> int:
    """``type=`` for indices such as ``--after``: an integer >= 0."""
    value = _read(text, int, "an integer >= 0")
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {shown(value)}")
    return value


def writable_dir(path: str | Path, argument: str) -> Path:
    """Make sure ``path`` is (or can be made) a folder this process can write into, before any work.

    The folder is created; a probe file is written and removed, so a read-only or full
    location fails now rather than after a long run.
    """
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise UsageError(argument, f"{p} exists and is not a folder")
    try:
        p.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=p, prefix=".tasker-probe-"):
            pass
    except OSError as exc:
        raise UsageError(argument, f"cannot write into {p}: {exc.strerror or exc}") from None
    return p


def writable_file(path: str | Path, argument: str) -> Path:
    """Make sure ``path`` can be written (its folder exists or is made, and is writable)."""
    p = Path(path)
    if p.is_dir():
        raise UsageError(argument, f"{p} is a folder; expected a file name")
    if p.exists() and not os.access(p, os.W_OK):
        raise UsageError(argument, f"cannot write {p}: permission denied")
    writable_dir(p.parent if str(p.parent) else Path("."), argument)
    return p




_NEGATIVE_POINT = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?,")
"""A point argument ``x,y(,yaw)`` whose ``x`` is negative, e.g. ``-1,2``: an argument, not an option."""


class Parser(argparse.ArgumentParser):
    """``argparse`` with "did you mean" on a misspelt subcommand or choice, and points with a
    negative first coordinate (``-1,2``) read as arguments rather than unknown options."""

    def _parse_optional(self, arg_string: str) -> Any:
        if _NEGATIVE_POINT.match(arg_string):
            return None
        return super()._parse_optional(arg_string)

    def error(self, message: str) -> NoReturn:
        m = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
        if m:
            known = re.findall(r"'([^']*)'", m.group(2))
            message += did_you_mean(m.group(1), known)
        super().error(message)


def error_text(exc: BaseException) -> str:
    """The one-line message for an error the user can fix, with a hint where there is one."""
    if isinstance(exc, UnknownName):
        text = str(exc) + did_you_mean(exc.name, exc.known)
        return text + (f"; {TASKS_HINT}" if exc.kind == "task type" else "")
    if isinstance(exc, OSError):
        where = f"{exc.filename}: " if exc.filename else ""
        return f"{where}{exc.strerror or exc}"
    return str(exc)


def _aborted(exc: BaseException) -> bool:
    # tasker.errors.RunAborted: matched by name so this works whether or not that class is in this build
    return any(c.__name__ == "RunAborted" for c in type(exc).__mro__)


def run_handler(handler: Callable[[argparse.Namespace], Any], args: argparse.Namespace) -> int:
    """Call a subcommand's handler; every exception becomes one line on stderr and an exit status."""
    command = getattr(args, "command", None) or "?"
    verbose = int(getattr(args, "verbose", 0) or 0)
    try:
        with warnings.catch_warnings():
            default = warnings.showwarning

            def show(message: Warning | str, category: type[Warning], *rest: Any, **kw: Any) -> None:
                if issubclass(category, InputWarning):  # valid but doubtful input: one line, our format
                    if not getattr(args, "quiet", False):
                        print(f"tasker {command}: warning: {message}", file=sys.stderr)
                else:
                    default(message, category, *rest, **kw)

            warnings.showwarning = show
            return int(handler(args))
    except KeyboardInterrupt:
        print(f"tasker {command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except TaskerError as exc:
        print(f"tasker {command}: error: {error_text(exc)}", file=sys.stderr)
        if verbose > 1:
            traceback.print_exc()
        return EXIT_FAILED if _aborted(exc) else EXIT_USAGE
    except OSError as exc:
        print(f"tasker {command}: error: {error_text(exc)}", file=sys.stderr)
        return EXIT_USAGE
    except SystemExit as exc:  # code that is not tasker's (a plugin) ended the program: say so, not a bare status
        print(f"tasker {command}: internal error: sys.exit({'' if exc.code is None else repr(exc.code)}) was "
              "called while the command ran" + ("" if verbose else " (--verbose shows where)"), file=sys.stderr)
        if verbose:
            traceback.print_exc()
        return EXIT_INTERNAL
    except Exception as exc:  # noqa: BLE001 - a command line never shows a traceback unasked
        print(f"tasker {command}: internal error: {type(exc).__name__}: {exc}"
              + ("" if verbose else " (a bug in tasker; --verbose shows the traceback)"), file=sys.stderr)
        if verbose:
            traceback.print_exc()
        return EXIT_INTERNAL


def show_progress(args: argparse.Namespace) -> bool:
    """Progress bars only on a terminal, and never with ``--quiet``."""
    return sys.stderr.isatty() and not getattr(args, "quiet", False)


def note(args: argparse.Namespace, text: str) -> None:
    """An informational line on stderr (``--quiet`` drops it)."""
    if not getattr(args, "quiet", False):
        print(text, file=sys.stderr)
