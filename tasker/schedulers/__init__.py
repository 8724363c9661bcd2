"""Schedule algorithms (``pf_schedule``) in a name-keyed registry, loaded lazily.

>>> from tasker import schedulers
>>> {"alg2", "lookahead", "simple", "simple2", "distance"} <= set(schedulers.names())
True
>>> s = schedulers.create("alg2", classes=[["humanFell"], ["guideHuman"]], hysteresis=0.9)

Each algorithm is a module of this package with a class; a third-party algorithm
registers with :func:`register` (or the entry-point group ``tasker.schedulers``).
An unknown name is an error that lists the known ones.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from tasker.errors import UnknownName
from tasker.schedulers.base import Candidate, Decision, Scheduler, ScheduleView

__all__ = ["Candidate", "Decision", "Scheduler", "ScheduleView", "create", "names", "register"]

_BUILTIN = {
    "alg2": "tasker.schedulers.alg2:Alg2",
    "priority": "tasker.schedulers.priority:FixedPriority",
    "fifo": "tasker.schedulers.fifo:Fifo",
    "sjf": "tasker.schedulers.sjf:ShortestJobFirst",
    "srtf": "tasker.schedulers.srtf:ShortestRemainingTimeFirst",
    "edf": "tasker.schedulers.edf:EarliestDeadlineFirst",
    "simple": "tasker.schedulers.simple:LongestFirst",
    "simple2": "tasker.schedulers.simple2:ShortestFirst",
    "distance": "tasker.schedulers.distance:DistanceOverDuration",
    "lookahead": "tasker.schedulers.lookahead:LookAhead",
}
_registry: dict[str, str | Callable[..., Scheduler]] = dict(_BUILTIN)
_entry_points_loaded = False


def register(name: str, factory: str | Callable[..., Scheduler]) -> None:
    """Add a scheduler: a factory, or ``"module:Class"`` imported when first created."""
    _registry[name] = factory


def _load_entry_points() -> None:
    global _entry_points_loaded
    if _entry_points_loaded:
        return
    _entry_points_loaded = True
    from importlib.metadata import entry_points

    for ep in entry_points(group="tasker.schedulers"):
        _registry.setdefault(ep.name, ep.value)


def names() -> list[str]:
    _load_entry_points()
    return sorted(_registry)


def create(name: str, **options: Any) -> Scheduler:
    """Instantiate the scheduler ``name`` with its options; unknown names list the known ones."""
    _load_entry_points()
    try:
        factory = _registry[name]
    except KeyError:
        raise UnknownName("scheduler", name, list(_registry)) from None
    if isinstance(factory, str):
        module, _, attr = factory.partition(":")
        factory = getattr(importlib.import_module(module), attr)  # an ImportError here is raised, never hidden
    return factory(**options)
