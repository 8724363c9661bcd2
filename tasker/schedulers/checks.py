"""Typed checks of scheduler options, each failure a ConfigError that names the option.

A scheduler's options arrive from configuration (a scenario, a protocol, the ``tasker day``
table), so a wrong value is the user's error, not a traceback: each check says which
scheduler, which option, what range or choices were expected and what came instead, e.g.
``tabsa-simple: hesitance must be a number in [0, 1], got 1.5``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from tasker.errors import ConfigError
from tasker.support.reader import suggest


def _is_number(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, int | float) and not math.isnan(value)


def number(algorithm: str, name: str, value: Any, *, low: float = -math.inf, high: float = math.inf,
           low_open: bool = False, high_open: bool = False) -> float:
    """``value`` as a float within ``low``..``high`` (``*_open``: that bound excluded)."""
    ok = _is_number(value) and (value > low if low_open else value >= low) \
        and (value < high if high_open else value <= high)
    if not ok:
        lo = "(" if low_open else "["
        hi = ")" if high_open else "]"
        span = f"{lo}{_show(low)}, {_show(high)}{hi}"
        raise ConfigError(f"{algorithm}: {name} must be a number in {span}, got {value!r}")
    return float(value)


def integer(algorithm: str, name: str, value: Any, *, low: int | None = None) -> int:
    """``value`` as an int (a bool is not one), at least ``low`` when given."""
    if isinstance(value, bool) or not isinstance(value, int) or (low is not None and value < low):
        need = "an integer" if low is None else f"an integer >= {low}"
        raise ConfigError(f"{algorithm}: {name} must be {need}, got {value!r}")
    return value


def choice(algorithm: str, name: str, value: Any, choices: Sequence[str]) -> str:
    """``value``, one of ``choices`` (with a "did you mean" for a near miss)."""
    if not isinstance(value, str) or value not in choices:
        hint = suggest(value, choices) if isinstance(value, str) else ""
        raise ConfigError(f"{algorithm}: {name} must be one of {', '.join(map(repr, choices))}, "
                          f"got {value!r}{hint}")
    return value


def names(algorithm: str, name: str, value: Any) -> tuple[str, ...]:
    """``value``, a list of task type names (a lone string is refused: it would read as its letters)."""
    if isinstance(value, str | bytes) or not isinstance(value, Sequence) \
            or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{algorithm}: {name} must be a list of task type names, got {value!r}")
    return tuple(value)


def _show(x: float) -> str:
    if x == math.inf:
        return "inf"
    if x == -math.inf:
        return "-inf"
    return f"{x:g}"
