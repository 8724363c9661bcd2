"""Builders of small synthetic systems for the core tests."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from tasker import schedulers
from tasker.agent import Rates
from tasker.harmoniser import Mode
from tasker.loop import SimulationLoop
from tasker.stage import Stage, StageKind
from tasker.store import TaskStore
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.task import TaskType

SUSP = StageKind.SUSPENDABLE
BLOCK = StageKind.BLOCKING


def st(action: str, duration: float, kind: StageKind = SUSP, **data: Any) -> Stage:
    return Stage(action, kind=kind, duration=duration, data=data)


def make_loop(
    tasks: Sequence[TaskType],
    *,
    scheduler: str = "alg2",
    mode: Mode | str = Mode.IT,
    core: Any = None,
    seed: int = 0,
    rates: Rates | None = None,
    **options: Any,
) -> SimulationLoop:
    return SimulationLoop(
        TaskStore(tasks),
        schedulers.create(scheduler, **options),
        mode=mode,
        core=core if core is not None else TimedExecutor(seed=seed),
        seed=seed,
        rates=rates or Rates(rep_rate=1.0, task_exe_rate=10.0, sp_up_rate=1.0),
    )


def first(events: list[dict[str, Any]], **match: Any) -> dict[str, Any]:
    for e in events:
        if all(e.get(k) == v for k, v in match.items()):
            return e
    raise AssertionError(f"no event matching {match}")


def guide(name: str = "guide", weight: float = 1.0) -> SyntheticTask:
    """Approach (suspendable), greet (blocking), guide (suspendable), goodbye (blocking)."""
    return SyntheticTask(name, [st("approach", 5), st("greet", 2, BLOCK), st("guide", 10), st("goodbye", 2, BLOCK)],
                         weight=weight)
