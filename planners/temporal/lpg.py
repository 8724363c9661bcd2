"""LPG-td as shipped by ``up-lpg`` 0.1.3, made to work as installed from PyPI.

Three things keep ``up_lpg.LPGEngine`` from working as is; each is fixed here, in a subclass,
without touching the installed package:

* it imports ``pkg_resources`` at module level, which setuptools >= 81 no longer ships.  It uses
  it only to find its ``lpg`` binary, which :meth:`TaskerLPG._get_cmd` finds with
  :mod:`importlib.resources`; for the import itself :func:`importable` puts a stand-in module
  (no attributes) into ``sys.modules`` while ``up_lpg`` is imported, and takes it away after;
* its plan reader refuses LPG-td's own plan lines, which end ``[5.0000])`` (a stray ``)``):
  :meth:`TaskerLPG._plan_from_file` reads them, and names a line it does not understand;
* LPG draws a random seed per run: :class:`TaskerLPG` passes ``-seed`` (default 1), so the same
  problem gets the same plan (tasker's runs are byte-reproducible).
"""

from __future__ import annotations

import contextlib
import importlib
import re
import sys
import types
from collections.abc import Callable, Iterator
from fractions import Fraction
from typing import Any

_LINE = re.compile(r"^\s*(\d+(?:\.\d*)?)\s*:\s*\(\s*([^()]+?)\s*\)\s*(?:\[\s*(\d+(?:\.\d*)?)\s*\])?\s*\)?\s*(;.*)?$")
DEFAULT_SEED = 1
_ABSENT = object()


@contextlib.contextmanager
def _pkg_resources_stand_in() -> Iterator[None]:
    """A ``pkg_resources`` module for the length of an import, if the real one is missing."""
    try:
        importlib.import_module("pkg_resources")
        yield
        return
    except ImportError:
        pass
    before = sys.modules.get("pkg_resources", _ABSENT)  # None: an import refused on purpose; keep that
    sys.modules["pkg_resources"] = types.ModuleType("pkg_resources", "stand-in for up_lpg's import (planners.temporal)")
    try:
        yield
    finally:
        if before is _ABSENT:
            sys.modules.pop("pkg_resources", None)
        else:
            sys.modules["pkg_resources"] = before  # type: ignore[assignment]


def importable() -> bool:
    """Whether up-lpg is installed (importing it with the stand-in when needed)."""
    try:
        _engine_base()
    except ImportError:
        return False
    return True


def _engine_base() -> type:
    with _pkg_resources_stand_in():
        from up_lpg.lpg_planner import LPGEngine
    return LPGEngine


def _make_class() -> type:
    import unified_planning as up

    base = _engine_base()

    class TaskerLPG(base):  # type: ignore[misc, valid-type]
        """``up_lpg``'s LPG engine with its binary found, its plan lines read, and a fixed seed."""

        def __init__(self, seed: int = DEFAULT_SEED, **kwargs: Any) -> None:
            super().__init__(**kwargs)
            self.parameter += ["-seed", str(int(seed))]

        @property
        def name(self) -> str:
            return "lpg"

        def _get_cmd(self, domain_filename: str, problem_filename: str, plan_filename: str) -> list[str]:
            import importlib.resources

            exe = str(importlib.resources.files("up_lpg") / "lpg")
            return [exe, "-o", domain_filename, "-f", problem_filename, "-n", "1", "-out", plan_filename,
                    *self.parameter]

        def _plan_from_file(self, problem: up.model.Problem, plan_filename: str,
                            get_item_named: Callable[[str], Any]) -> up.plans.Plan:
            return read_plan(problem, open(plan_filename, encoding="utf-8").read(), get_item_named)

    return TaskerLPG


def read_plan(problem: Any, text: str, get_item_named: Callable[[str], Any]) -> Any:
    """LPG-td's plan text as a UP plan (time-triggered for a temporal problem); None for its
    ``no solution`` (the engine then reports the problem unsolved, as up_lpg does)."""
    import unified_planning as up
    from unified_planning.exceptions import UPException

    temporal = problem.kind.has_continuous_time()
    em = problem.environment.expression_manager
    timed: list[tuple[Fraction, Any, Fraction | None]] = []
    steps = []
    for n, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.lstrip().startswith(";"):
            continue
        if line.strip().lower() == "no solution":
            return None
        m = _LINE.match(line)
        if m is None:
            raise UPException(f"LPG's plan, line {n}: not a plan step: {line.strip()!r}")
        name, *args = m.group(2).lower().split()
        action = get_item_named(name)
        ai = up.plans.ActionInstance(action, tuple(em.ObjectExp(get_item_named(a)) for a in args))
        if temporal:
            durative = isinstance(action, up.model.DurativeAction)
            duration = Fraction(m.group(3)) if durative and m.group(3) else None
            timed.append((Fraction(m.group(1)), ai, duration))
        else:
            steps.append(ai)
    return up.plans.TimeTriggeredPlan(timed) if temporal else up.plans.SequentialPlan(steps)


_CLASS: type | None = None


def engine_class() -> type:
    """The :class:`TaskerLPG` class (built on first use: it subclasses an optional dependency)."""
    global _CLASS
    if _CLASS is None:
        _CLASS = _make_class()
    return _CLASS


def __getattr__(name: str) -> Any:  # UP's factory imports the class by name: planners.temporal.lpg.TaskerLPG
    if name == "TaskerLPG":
        return engine_class()
    raise AttributeError(name)
