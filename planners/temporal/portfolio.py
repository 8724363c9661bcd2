"""Solve a temporal problem with UP's engines in turn, and use only a plan UP's validator accepts.

:class:`TemporalPlanner` tries its engines in order (by default :data:`~planners.temporal.engines.DEFAULT_ORDER`,
those installed), each with an equal share of the time left.  An engine's plan is validated
with UP's ``up_time_triggered_validator`` (``sequential_plan_validator`` for a problem without
durative actions); an invalid plan is refused — named with its engine and the validator's
reason in the result's attempts — and the next engine is tried.  Anything an engine raises
(LPG's reader, Aries' panic, Tamer's type-hierarchy bug) is that engine's ``error`` attempt,
with its message: never an exception out of :meth:`TemporalPlanner.solve`.
"""

from __future__ import annotations

import contextlib
import gc
import math
import tempfile
import time
import warnings
from collections.abc import Callable, Sequence
from fractions import Fraction
from typing import IO, TYPE_CHECKING, Any

from planners.results import PlanStatus
from planners.temporal import engines
from planners.temporal.results import Attempt, Outcome, TemporalResult, TimedStep
from tasker.errors import EngineNotInstalled as EngineNotInstalled  # defined there; re-exported here

if TYPE_CHECKING:
    import unified_planning as up

MESSAGE_CHARS = 300
"""An attempt's message keeps the first this many characters of what the engine said."""
LINE_CHARS = 160
"""A line of an engine's message longer than this is a debug dump, left out."""
NO_GOAL = "(no goal)"
"""The ``engine`` of the empty plan of a problem that has no goal: no engine was asked."""


class TemporalPlanner:
    """Solve temporal problems with UP's engines, in order, within one time budget.

    ``engines`` names them (:data:`~planners.temporal.engines.ENGINES`); None means every engine
    of :data:`~planners.temporal.engines.DEFAULT_ORDER` that is installed.  ``timeout`` is the
    default budget (seconds) of a call, shared by the engines it tries.
    """

    def __init__(self, engines_: Sequence[str] | None = None, *, timeout: float | None = 60.0) -> None:
        if engines_ is None:
            names = [n for n in engines.DEFAULT_ORDER if engines.installed(n)]
            if not names:
                raise EngineNotInstalled("no temporal engine is installed: pip install "
                                         + " ".join(engines.spec(n).package for n in engines.DEFAULT_ORDER))
        else:
            names = list(engines_)
            for n in names:
                s = engines.spec(n)  # an unknown name lists the known ones
                if not engines.installed(n):
                    raise EngineNotInstalled(f"temporal engine {n!r} is not installed: pip install {s.package} "
                                             f"(licence: {s.licence})")
            if not names:
                raise ValueError("TemporalPlanner needs at least one engine")
        if timeout is not None and not (math.isfinite(timeout) and timeout > 0):
            raise ValueError(f"timeout must be a finite positive number of seconds, got {timeout}")
        self.engines = tuple(names)
        self.timeout = timeout

    @property
    def name(self) -> str:
        """``lpg,aries,kairos``: the engines, in the order they are tried."""
        return ",".join(self.engines)

    def solve(self, problem: up.model.Problem, timeout: float | None = None,
              accept: Callable[[tuple[TimedStep, ...]], str | None] | None = None) -> TemporalResult:
        """The first valid plan of the engines, in order, within ``timeout`` seconds (the default if None).

        ``accept``, if given, may refuse a valid plan (it returns why, or None to take it): the
        attempt is then ``refused`` with that reason, and the next engine is tried."""
        budget = self.timeout if timeout is None else timeout
        start = time.perf_counter()
        if not problem.goals and not getattr(problem, "timed_goals", None):
            return TemporalResult(PlanStatus.SOLVED, (), NO_GOAL, (), time.perf_counter() - start)
        attempts: list[Attempt] = []
        for k, name in enumerate(self.engines):
            left = None if budget is None else budget - (time.perf_counter() - start)
            if left is not None and left <= 0.05:
                attempts += [Attempt(n, Outcome.SKIPPED, "no time left") for n in self.engines[k:]]
                break
            share = None if left is None else left / (len(self.engines) - k)
            attempt, plan = attempt_engine(name, problem, share)
            why = accept(plan) if plan is not None and accept is not None else None
            if why is not None:
                attempt, plan = Attempt(name, Outcome.REFUSED, _tail(why), attempt.wall_time_s), None
            attempts.append(attempt)
            if plan is not None:
                attempts += [Attempt(n, Outcome.SKIPPED, f"{name}'s plan was used") for n in self.engines[k + 1:]]
                return TemporalResult(PlanStatus.SOLVED, plan, name, tuple(attempts), time.perf_counter() - start)
        return TemporalResult(_failed_status(attempts), None, "", tuple(attempts), time.perf_counter() - start)


def _failed_status(attempts: Sequence[Attempt]) -> PlanStatus:
    """No plan to use: an error if a valid plan was refused (the problem is solvable: the refusal is
    the news); unsolvable if an engine said so; a time-out if one ran out of time; else an error
    (every engine failed, or gave invalid plans)."""
    outcomes = {a.outcome for a in attempts}
    if Outcome.REFUSED in outcomes:
        return PlanStatus.ERROR
    if Outcome.UNSOLVABLE in outcomes:
        return PlanStatus.UNSOLVABLE
    if Outcome.TIMEOUT in outcomes or Outcome.SKIPPED in outcomes:
        return PlanStatus.TIMEOUT
    return PlanStatus.ERROR


def attempt_engine(name: str, problem: up.model.Problem,
                   timeout: float | None) -> tuple[Attempt, tuple[TimedStep, ...] | None]:
    """One engine on ``problem``: its attempt, and its plan when UP's validator accepts it.
    Nothing it does raises: an exception anywhere (the engine, its result, its plan's times)
    is an ``error`` attempt with the exception's message."""
    start = time.perf_counter()
    try:
        return _attempt(name, problem, timeout)
    except Exception as exc:  # noqa: BLE001 - e.g. a plan with a negative time: the engine's fault, said
        said = _tail(f"{type(exc).__name__}: {' '.join(str(exc).split())}")
        return Attempt(name, Outcome.ERROR, said, time.perf_counter() - start), None


def _attempt(name: str, problem: up.model.Problem,
             timeout: float | None) -> tuple[Attempt, tuple[TimedStep, ...] | None]:
    from unified_planning.engines import PlanGenerationResultStatus as UPStatus
    from unified_planning.shortcuts import OneshotPlanner

    start = time.perf_counter()
    spec = engines.spec(name)
    log: IO[str] | None = None
    try:
        with warnings.catch_warnings(record=True) as caught, contextlib.ExitStack() as stack:
            warnings.simplefilter("always")
            factory_name = engines.register(name)
            if name == "aries":  # its server's output: read back for a panic's message, then deleted
                log = stack.enter_context(tempfile.TemporaryFile("w+", prefix="tasker-aries-"))
            stack.enter_context(engines.settings(name))
            planner = stack.enter_context(OneshotPlanner(name=factory_name, params=dict(spec.params)))
            planner.skip_checks = True  # the engine decides what it handles: a refusal is its attempt
            res = planner.solve(problem, timeout=timeout, output_stream=log) if log is not None \
                else planner.solve(problem, timeout=timeout)
            gc.collect()  # a killed engine's pipes are closed here, their ResourceWarning caught above
            said = _said(res, caught, log)
    except Exception as exc:  # noqa: BLE001 - an engine's failure is its attempt's, whatever it is
        said = _tail(f"{type(exc).__name__}: {' '.join(str(exc).split())}" + _log_tail(log))
        return Attempt(name, Outcome.ERROR, said, time.perf_counter() - start), None
    wall = time.perf_counter() - start
    if res.plan is not None and res.status in (UPStatus.SOLVED_SATISFICING, UPStatus.SOLVED_OPTIMALLY,
                                               UPStatus.INTERMEDIATE, UPStatus.TIMEOUT):
        why = validate(problem, res.plan)
        if why is not None:
            return Attempt(name, Outcome.INVALID, _tail(f"UP's validator refused its plan: {why}"), wall), None
        return Attempt(name, Outcome.VALID, "", wall), timed_steps(res.plan)
    outcome = {UPStatus.UNSOLVABLE_PROVEN: Outcome.UNSOLVABLE, UPStatus.UNSOLVABLE_INCOMPLETELY: Outcome.UNSOLVABLE,
               UPStatus.TIMEOUT: Outcome.TIMEOUT, UPStatus.UNSUPPORTED_PROBLEM: Outcome.UNSUPPORTED}.get(
        res.status, Outcome.ERROR)
    if res.status is UPStatus.UNSOLVABLE_INCOMPLETELY:
        said = "found no plan (not a proof)" + (f": {said}" if said else "")
    elif res.status is UPStatus.MEMOUT:
        said = "out of memory" + (f": {said}" if said else "")
    elif not said and outcome is Outcome.ERROR:
        said = res.status.name.lower()
    return Attempt(name, outcome, _tail(said), wall), None


def _said(res: Any, caught: Sequence[warnings.WarningMessage], log: IO[str] | None) -> str:
    """What an engine said of a failure: its error log messages, its warnings, its server's output."""
    from unified_planning.engines import LogLevel

    msgs = [_summary(m.message) for m in (res.log_messages or ()) if m.level is LogLevel.ERROR and m.message.strip()]
    msgs += [_summary(str(w.message)) for w in caught if not _noise(w)]
    return "; ".join(m for m in msgs if m) + _log_tail(log)


def _noise(w: warnings.WarningMessage) -> bool:
    """Warnings that say nothing about the problem: unclosed pipes of a killed engine, and UP's
    "cannot establish whether ENGINE can solve this problem" (checks are the engine's, here)."""
    return issubclass(w.category, ResourceWarning) or "cannot establish whether" in str(w.message)


def _summary(text: str) -> str:
    """An engine's message without its debug dumps (Aries prints whole protobuf messages): the
    lines of at most :data:`LINE_CHARS` characters, joined."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    short = [ln for ln in lines if len(ln) <= LINE_CHARS]
    return " / ".join(short) if short else (lines[0][:LINE_CHARS] + "..." if lines else "")


def _log_tail(log: IO[str] | None) -> str:
    """A panic or an error in an engine server's output (Aries'), if any."""
    if log is None or log.closed:
        return ""
    try:
        log.flush()
        log.seek(0)
        text = log.read()
    except (OSError, ValueError):
        return ""
    lines = [ln for ln in text.splitlines() if "panic" in ln or "rror" in ln]
    return ("; " + _summary("\n".join(lines[-3:]))) if lines else ""


def _tail(text: str) -> str:
    """At most :data:`MESSAGE_CHARS` characters of a message, its beginning (where engines say what)."""
    text = text.strip("; ")
    return text if len(text) <= MESSAGE_CHARS else text[:MESSAGE_CHARS] + "..."


def validate(problem: up.model.Problem, plan: up.plans.Plan) -> str | None:
    """None if UP's validator accepts ``plan`` for ``problem``, else its reason."""
    import unified_planning as up
    from unified_planning.engines import ValidationResultStatus
    from unified_planning.shortcuts import PlanValidator

    name = "up_time_triggered_validator" if isinstance(plan, up.plans.TimeTriggeredPlan) \
        else "sequential_plan_validator"
    try:
        with warnings.catch_warnings(), PlanValidator(name=name) as validator:
            warnings.simplefilter("ignore")
            validator.skip_checks = True
            res = validator.validate(problem, plan)
    except Exception as exc:  # noqa: BLE001 - a validator that cannot check the plan does not accept it
        return f"the validator could not check it: {type(exc).__name__}: {' '.join(str(exc).split())}"
    if res.status is ValidationResultStatus.VALID:
        return None
    parts = [str(res.reason.name).lower().replace("_", " ") if res.reason is not None else "invalid"]
    if res.inapplicable_action is not None:
        parts.append(f"at {res.inapplicable_action}")
    parts += [" ".join(m.message.split()) for m in res.log_messages or () if m.message.strip()]
    return ", ".join(parts)


def timed_steps(plan: up.plans.Plan) -> tuple[TimedStep, ...]:
    """A UP plan as :class:`TimedStep` in start-time order (a sequential plan: one a second, no duration)."""
    import unified_planning as up

    if isinstance(plan, up.plans.TimeTriggeredPlan):
        raw = [(Fraction(start), ai, Fraction(dur) if dur is not None else Fraction(0))
               for start, ai, dur in plan.timed_actions]
    else:
        assert isinstance(plan, up.plans.SequentialPlan)
        raw = [(Fraction(k), ai, Fraction(0)) for k, ai in enumerate(plan.actions)]
    steps = [TimedStep(start, ai.action.name, tuple(str(p) for p in ai.actual_parameters), dur)
             for start, ai, dur in raw]
    return tuple(sorted(steps, key=lambda s: (s.start, s.end)))
