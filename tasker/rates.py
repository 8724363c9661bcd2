"""The agent's timers: its rates (``repRate``, ``taskExeRate``, ``SPupRate``) and the one grid
every agent's timers fire on."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tasker.errors import ConfigError


@dataclass(frozen=True, slots=True)
class Rates:
    """The agent's rates in Hz: ``repRate``, ``taskExeRate`` and ``SPupRate`` of the paper."""

    rep_rate: float = 1.0
    task_exe_rate: float = 10.0
    sp_up_rate: float = 1.0

    def __post_init__(self) -> None:
        for name in ("rep_rate", "task_exe_rate", "sp_up_rate"):
            v = getattr(self, name)
            if not isinstance(v, int | float) or not math.isfinite(v) or v <= 0:
                raise ConfigError(f"Rates.{name} must be a positive number of Hz, got {v!r}")


def next_tick_of(now: float, rate: float) -> float:
    """The next instant of ``timer(rate)``: timers fire on one grid shared by every agent.

    Aligning all agents' timers makes their reports arrive in the same tick, so the
    harmoniser schedules once per period rather than once per agent.
    """
    return (math.floor(now * rate + 1e-9) + 1) / rate


__all__ = ["Rates", "next_tick_of"]
