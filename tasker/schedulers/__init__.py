"""Schedule algorithms (``pf_schedule``) in a name-keyed registry, loaded lazily.

>>> from tasker import schedulers
>>> {"alg2", "lookahead", "simple", "simple2", "distance"} <= set(schedulers.names())
True
>>> s = schedulers.create("alg2", classes=[["humanFell"], ["guideHuman"]], hysteresis=0.9)

Each algorithm is a module of this package with a class; a third-party algorithm
registers with :func:`register` (or the entry-point group ``tasker.schedulers``).
An unknown name is an error that lists the known ones.  Options are checked when the
scheduler is made: an unknown one, or a value of the wrong type or out of range, is a
:class:`~tasker.errors.ConfigError` naming the option and what it expects.
:func:`sweep` gives the option values an experiment sweeps for an algorithm (TaBSA's
grid for its agents' hesitance and ratio):

>>> schedulers.sweep("tabsa-simple")
{'hesitance': (0.0, 0.25, 0.5, 0.75, 1.0)}
"""

from __future__ import annotations

import importlib
import inspect
from collections.abc import Callable, Mapping
from typing import Any

from tasker.errors import ConfigError, UnknownName
from tasker.schedulers.base import Candidate, Decision, Scheduler, ScheduleView, UnattendedHazard
from tasker.support.reader import suggest

__all__ = ["Candidate", "Decision", "Scheduler", "ScheduleView", "UnattendedHazard", "create", "names", "options",
           "register", "sweep", "unknown_option"]

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
    "tabsa-simple": "tasker.schedulers.tabsa:TabsaSimple",
    "tabsa-simple2": "tasker.schedulers.tabsa:TabsaSimple2",
    "tabsa-distance": "tasker.schedulers.tabsa:TabsaDistance",
    "tabsa-scheduler": "tasker.schedulers.tabsa_slots:TabsaScheduler",
    "wspt": "tasker.schedulers.wspt:WeightedShortestFirst",
    "atc": "tasker.schedulers.atc:ApparentTardinessCost",
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


def _factory(name: str) -> Callable[..., Scheduler]:
    _load_entry_points()
    try:
        factory = _registry[name]
    except KeyError:
        raise UnknownName("scheduler", name, list(_registry)) from None
    if isinstance(factory, str):
        module, _, attr = factory.partition(":")
        factory = getattr(importlib.import_module(module), attr)  # an ImportError here is raised, never hidden
    return factory


def options(name: str) -> tuple[str, ...] | None:
    """The options scheduler ``name`` takes (its factory's keyword parameters), or ``None`` when
    its factory takes any keyword (``**kwargs``) or does not say."""
    try:
        sig = inspect.signature(_factory(name))
    except (TypeError, ValueError):  # a builtin or C factory without a signature
        return None
    params = sig.parameters.values()
    if any(p.kind is p.VAR_KEYWORD for p in params):
        return None
    return tuple(p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY))


def sweep(name: str) -> dict[str, tuple[Any, ...]]:
    """The option values scheduler ``name`` is swept over (its class's ``SWEEP``; empty if none),
    read without making one."""
    grid = getattr(_factory(name), "SWEEP", None)
    return {str(k): tuple(v) for k, v in grid.items()} if isinstance(grid, Mapping) else {}


def unknown_option(name: str, option: str) -> str | None:
    """Why ``option`` is not an option of scheduler ``name`` (with "did you mean"), or ``None``."""
    known = options(name)
    if known is None or option in known:
        return None
    listing = f"its options: {', '.join(known)}" if known else "it takes no options"
    return f"scheduler {name!r} has no option {option!r}{suggest(option, known)} ({listing})"


def create(name: str, **options: Any) -> Scheduler:
    """Instantiate the scheduler ``name`` with its options; unknown names list the known ones,
    an unknown option is a :class:`~tasker.errors.ConfigError` naming the valid ones."""
    factory = _factory(name)
    for option in options:
        why = unknown_option(name, option)
        if why:
            raise ConfigError(why)
    return factory(**options)
