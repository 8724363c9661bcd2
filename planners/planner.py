"""The :class:`Planner` facade: a search schedule or any UP one-shot engine by name, a typed result, an LRU cache.

``Planner().solve(problem)`` takes a unified-planning ``Problem`` or a :class:`PddlText`
(a domain and a problem as PDDL text, what task types build) and returns a
:class:`~planners.results.PlanResult`.  A name of :data:`~planners.schedules.SCHEDULES`
(``tasker-fd``, the default and reproducible one; ``tasker-anytime``, ``tasker-opt``,
``tasker-first``) runs Fast Downward in-process on the PDDL text, without building a UP
model at all.  Results are cached on the PDDL text (domain + problem), so a repeated
identical problem is answered from memory (its ``wall_time_s`` is that answer's, not the
original solve's); time-outs and errors are never cached.

With a schedule nothing of unified-planning is imported (the command line's path to Fast
Downward stays fast); another engine imports UP's factory when first used, and its
warnings and credits are kept off the terminal (they go to the result's message).  An
exception inside another engine is an ``ERROR`` result with failure ``ENGINE`` naming the
engine and its message, never an exception out of :meth:`Planner.solve`.
"""

from __future__ import annotations

import math
import threading
import time
import warnings
import weakref
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from planners.fd import OPTIMAL_SEARCH, run_fast_downward
from planners.registration import ENGINE_NAME, oneshot_planners, register_engine
from planners.results import Failure, PlanResult, PlanStatus, from_fd_outcome
from planners.schedules import SCHEDULES, solve_text
from tasker.errors import UnknownName

if TYPE_CHECKING:
    import unified_planning as up

DEFAULT_PLANNER = ENGINE_NAME
"""The engine a :class:`Planner` uses unless told otherwise."""


@dataclass(frozen=True, slots=True)
class PddlText:
    """A planning problem as PDDL text: what any PDDL planner reads unchanged."""

    domain: str
    problem: str


def plan_steps(plan: Any) -> tuple[tuple[str, ...], ...]:
    """A UP sequential plan as tuples of strings: ``("action", "arg", ...)``."""
    return tuple((a.action.name, *(str(p) for p in a.actual_parameters)) for a in plan.actions)


class Planner:
    """Solve planning problems with a named schedule or engine, cache the answers.

    ``name`` is a search schedule (:data:`~planners.schedules.SCHEDULES`: ``tasker-fd``,
    ``tasker-anytime``, ``tasker-opt``, ``tasker-first``) or any one-shot engine in UP's
    factory (``fast-downward-opt``, ``fast-downward``, ...): an unknown name raises
    :class:`~tasker.errors.UnknownName` listing the known ones.  ``timeout`` (seconds) is the
    default per call; ``cache_size`` bounds the LRU cache (0 disables it).  ``search``, a
    Fast Downward search string, replaces ``tasker-fd``'s schedule with that one search
    (its plans are not claimed optimal unless it is :data:`~planners.fd.OPTIMAL_SEARCH`).
    Thread-safe.
    """

    def __init__(self, name: str = DEFAULT_PLANNER, *, timeout: float | None = 30.0, cache_size: int = 512,
                 search: str | None = None) -> None:
        if name not in SCHEDULES:  # a schedule needs no factory: keep UP's engines unimported
            known = sorted({*oneshot_planners(), *SCHEDULES})
            if name not in known:
                raise UnknownName("planner", name, known)
        if search is not None and name != ENGINE_NAME:
            raise ValueError(f"search= replaces {ENGINE_NAME}'s schedule; planner {name!r} takes none")
        if timeout is not None and not (math.isfinite(timeout) and timeout > 0):
            raise ValueError(f"timeout must be a finite positive number of seconds, got {timeout}")
        if cache_size < 0:
            raise ValueError(f"cache_size must be >= 0, got {cache_size}")
        self.name = name
        self.timeout = timeout
        self.search = search
        self.cache_size = cache_size
        self._cache: OrderedDict[tuple[str, str, str], PlanResult] = OrderedDict()
        self._keys: dict[int, tuple[weakref.ref[Any], int, PddlText]] = {}
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    # -- public ----------------------------------------------------------------------

    def solve(self, problem: up.model.Problem | PddlText, timeout: float | None = None) -> PlanResult:
        """Solve ``problem``; never raises for an unsolvable or failing problem (see the status)."""
        asked = time.perf_counter()
        timeout = self.timeout if timeout is None else timeout
        text = problem if isinstance(problem, PddlText) else self._text_of(problem)
        key = (self.name, text.domain, text.problem)
        if self.cache_size:
            with self._lock:
                hit = self._cache.get(key)
                if hit is None:
                    self.misses += 1
                else:
                    self._cache.move_to_end(key)
                    self.hits += 1
            if hit is not None:  # this call's time: the original solve's was counted when it ran
                return replace(hit, cached=True, wall_time_s=time.perf_counter() - asked)
        start = time.perf_counter()
        if self.name in SCHEDULES:
            result = self._solve_fd(text, timeout, start)
        else:
            model = self._parse(text) if isinstance(problem, PddlText) else problem
            result = self._solve_up(model, timeout, start)
        if self.cache_size and result.status in (PlanStatus.SOLVED, PlanStatus.UNSOLVABLE):
            with self._lock:
                self._cache[key] = result
                while len(self._cache) > self.cache_size:
                    self._cache.popitem(last=False)
        return result

    def clear_cache(self) -> None:
        with self._lock:
            self._cache.clear()
            self._keys.clear()

    # -- private ---------------------------------------------------------------------

    def _text_of(self, problem: up.model.Problem) -> PddlText:
        """PDDL text of a UP problem; remembered per live object so a repeat costs one hash."""
        h = hash(problem)
        with self._lock:
            known = self._keys.get(id(problem))
        if known is not None and known[0]() is problem and known[1] == h:
            return known[2]
        from unified_planning.io import PDDLWriter

        writer = PDDLWriter(problem)
        text = PddlText(writer.get_domain(), writer.get_problem())
        with self._lock:
            if len(self._keys) > 4 * max(self.cache_size, 1):
                self._keys.clear()
            self._keys[id(problem)] = (weakref.ref(problem), h, text)
        return text

    @staticmethod
    def _parse(text: PddlText) -> up.model.Problem:
        from unified_planning.io import PDDLReader

        return PDDLReader().parse_problem_string(text.domain, text.problem)

    def _solve_fd(self, text: PddlText, timeout: float | None, start: float) -> PlanResult:
        if self.search is None:  # the facade times the call, as it does for every engine
            answer = solve_text(self.name, text.domain, text.problem, timeout)
            return replace(answer, wall_time_s=time.perf_counter() - start)
        out = run_fast_downward(text.domain, text.problem, search=self.search, timeout=timeout)
        return from_fd_outcome(out, self.name, time.perf_counter() - start, search=self.search,
                               optimal=self.search == OPTIMAL_SEARCH)

    def _solve_up(self, problem: up.model.Problem, timeout: float | None, start: float) -> PlanResult:
        from unified_planning.engines import PlanGenerationResultStatus as UPStatus
        from unified_planning.shortcuts import OneshotPlanner

        register_engine()  # also silences the credits banner
        with warnings.catch_warnings(record=True) as caught:
            # e.g. fast-downward-opt warns that it does not support the timeout; that is a message, not noise
            warnings.simplefilter("always")
            try:
                with OneshotPlanner(name=self.name) as engine:
                    engine.skip_checks = True  # problems are checked when loaded (planners.checks)
                    res = engine.solve(problem, timeout=timeout)
                    steps = plan_steps(res.plan) if res.plan is not None else None
                    cost = plan_cost(problem, res.plan) if res.plan is not None else None
            except Exception as exc:  # noqa: BLE001 - the engine's own failure (UP issue #290 for tamer, a panic)
                return self._engine_failed(exc, start)
        wall = time.perf_counter() - start
        notes = [str(w.message) for w in caught]
        status = PlanStatus.from_up(res.status)
        if status is not PlanStatus.SOLVED or steps is None or cost is None:
            msg = "; ".join([*(m.message for m in (res.log_messages or ())), *notes])[-300:]
            if status is PlanStatus.SOLVED:  # "solved" without a plan: the engine's fault
                status, msg = PlanStatus.ERROR, f"engine {self.name} said {res.status.name} but gave no plan"
            elif status is PlanStatus.TIMEOUT:  # what was tried, and what to try
                msg = (f"engine {self.name} found no plan within {timeout:g} s" if timeout else
                       f"engine {self.name} timed out") + (f" ({msg})" if msg else "") + \
                    "; try tasker-anytime (a plan at once, improved within the time) or a longer timeout"
            return PlanResult(status, None, None, self.name, wall, message=msg or res.status.name,
                              failure=Failure.ENGINE if status is PlanStatus.ERROR else None)
        return PlanResult(PlanStatus.SOLVED, steps, cost, self.name, wall, message="; ".join(notes)[-300:],
                          optimal=res.status is UPStatus.SOLVED_OPTIMALLY, search=self.name)

    def _engine_failed(self, exc: BaseException, start: float) -> PlanResult:
        """An exception inside engine ``self.name``: an ``ERROR`` naming the engine and its message."""
        text = " ".join(str(exc).split())[:300] or "(no message)"
        return PlanResult(PlanStatus.ERROR, None, None, self.name, time.perf_counter() - start,
                          message=f"engine {self.name} failed: {type(exc).__name__}: {text}", failure=Failure.ENGINE)


def plan_cost(problem: up.model.Problem, plan: up.plans.SequentialPlan) -> float:
    """The plan's metric value as UP's validator computes it (its length without a metric)."""
    from unified_planning.shortcuts import PlanValidator

    if not problem.quality_metrics:
        return float(len(plan.actions))
    with PlanValidator(name="sequential_plan_validator") as validator:
        res = validator.validate(problem, plan)
    values = list(res.metric_evaluations.values()) if res.metric_evaluations else []
    return float(values[0]) if values else float(len(plan.actions))
