"""The temporal engines tasker uses, through unified-planning's factory: a name-keyed registry.

Each :class:`EngineSpec` says which UP engine a name is, the PyPI package that brings it, its
licence, and the settings that make it work as installed and give the same plan for the same
problem (tasker's runs are byte-reproducible):

* ``lpg`` — LPG-td (``up-lpg``): :mod:`planners.temporal.lpg`'s subclass, with a fixed seed;
* ``aries`` — Aries (``up-aries``, MIT): with ``ARIES_PLANNING_PREPRO_STATE_VARS=false`` (by
  default it panics on PlanSys2's simple example), ``ARIES_UP_ASSUME_REALS_ARE_INTS=true``
  (PDDL's numbers are reals to UP; Aries refuses real-valued fluents) and one search strategy,
  ``ARIES_STRATEGIES=act-bool`` (its default portfolio races four threads, and which finishes
  first decides the plan: the same problem gave makespans 30.4 and 40.8).  Its server's output
  goes to a temporary file read back for an error's message and deleted (by default it leaves
  ``/tmp/aries-PORT.*`` behind);
* ``kairos`` — Kairos (``up-kairos``, Apache-2.0, PlanSys2's planner), one thread, seed 0, first plan;
* ``tamer`` — TAMER (``up-tamer``; pytamer's licence reads "Free For Educational Use", so it is
  never a dependency: it is used when installed and named).

:data:`DEFAULT_ORDER` is the order :class:`~planners.temporal.portfolio.TemporalPlanner` tries
them in, chosen by measurement (``docs/planners.md``, "Temporal domains").
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import threading
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from tasker.errors import UnknownName


@dataclass(frozen=True, slots=True)
class EngineSpec:
    """One temporal engine: tasker's name for it, how UP's factory finds it, what it needs."""

    name: str
    package: str
    """The PyPI distribution that brings it (``pip install PACKAGE``)."""
    module: str
    """The module whose import tells whether it is installed."""
    licence: str
    factory_name: str
    """Its name in UP's factory (added there by :func:`register` when UP does not list it)."""
    factory_class: tuple[str, str] | None = None
    """``(module, class)`` for ``factory.add_engine``; None when UP's factory lists it already."""
    params: Mapping[str, object] = field(default_factory=lambda: MappingProxyType({}))
    """Options for the engine's constructor (``OneshotPlanner(name, params=...)``)."""
    env: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    """Environment variables set while it solves (read by the engine's own process)."""
    ignores_timeout: bool = False

    def __post_init__(self) -> None:
        if not self.name or not self.factory_name:
            raise ValueError("an EngineSpec needs a name and a factory name")


ENGINES: Mapping[str, EngineSpec] = MappingProxyType({s.name: s for s in (
    EngineSpec("lpg", "up-lpg", "up_lpg", "up-lpg: Apache-2.0; the LPG-td binary it ships: LPG's own terms",
               "tasker-lpg", ("planners.temporal.lpg", "TaskerLPG")),
    EngineSpec("aries", "up-aries", "up_aries", "MIT", "aries", None,
               env=MappingProxyType({"ARIES_PLANNING_PREPRO_STATE_VARS": "false",
                                     "ARIES_UP_ASSUME_REALS_ARE_INTS": "true",
                                     "ARIES_STRATEGIES": "act-bool"})),
    EngineSpec("kairos", "up-kairos", "up_kairos", "Apache-2.0", "kairos", ("up_kairos", "KairosEngine"),
               params=MappingProxyType({"threads": 1, "seed": 0, "anytime": False})),
    EngineSpec("tamer", "up-tamer", "up_tamer", "pytamer: \"Free For Educational Use\"", "tamer", None,
               ignores_timeout=True),
)})
"""Every temporal engine tasker knows, by name."""

DEFAULT_ORDER: tuple[str, ...] = ("kairos", "lpg", "aries")
"""The engines tried, in order, when none is named (``tamer`` only when named: its licence)."""

_env_lock = threading.Lock()


def spec(name: str) -> EngineSpec:
    """The engine called ``name``; an unknown name lists the known ones."""
    if name not in ENGINES:
        raise UnknownName("temporal engine", name, list(ENGINES))
    return ENGINES[name]


def installed(name: str) -> bool:
    """Whether the engine's package is importable here."""
    s = spec(name)
    if s.name == "lpg":
        from planners.temporal import lpg

        return lpg.importable()
    return importlib.util.find_spec(s.module) is not None


def register(name: str) -> str:
    """Make the engine known to UP's factory (idempotent); return its factory name."""
    from unified_planning.environment import get_environment

    s = spec(name)
    env = get_environment()
    env.credits_stream = None
    if s.factory_class is not None and s.factory_name not in env.factory.engines:
        env.factory.add_engine(s.factory_name, *s.factory_class)
    return s.factory_name


@contextlib.contextmanager
def settings(name: str) -> Iterator[None]:
    """The engine's environment variables, set for the length of a solve and restored after
    (under a lock: the environment is the process's)."""
    s = spec(name)
    if not s.env:
        yield
        return
    with _env_lock:
        old = {k: os.environ.get(k) for k in s.env}
        os.environ.update(s.env)
        try:
            yield
        finally:
            for k, v in old.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
