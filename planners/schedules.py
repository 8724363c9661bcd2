"""Search schedules: which Fast Downward searches a planner call runs, in which order, for how long.

A schedule turns a SAS task (the translator's output) and a time budget into a
:class:`~planners.results.PlanResult` that says whether its plan is *proven* optimal and
which search produced it.  Four are registered, by the names ``Planner(name)`` and
``tasker plan --planner`` take:

``tasker-fd`` — **reproducible** (what task types plan with inside a run).  A* with LM-cut
    (optimal) within :data:`EXPANSION_BUDGET` expanded states; a task it does not finish
    within them gets LAMA-first's plan, marked not optimal.  The budget counts states, not
    seconds, so the answer is a function of the task alone: the same scenario gives the same
    trace on a quiet machine and a busy one (:mod:`planners.fd`, "A budget of expansions").
    The wall-clock ``timeout`` stays a safety net: only a task that runs out of it answers
    differently, and it ends as a time-out, as before.
``tasker-anytime`` — **anytime** (``tasker plan``'s default).  LAMA-first for a plan at once;
    then iterated LAMA (costs counted, weighted A* with falling weights) improves it for up
    to :data:`IMPROVE_SHARE` of the time left; then A* with LM-cut, bounded by the best cost
    found, for the rest: it finds the optimum or, exhausting every cheaper plan, proves the
    plan in hand optimal.  What it answers can depend on the machine's speed when the budget
    cuts a search short: that is why runs do not use it.
``tasker-opt`` — A* with LM-cut only: optimal or nothing (the engine's meaning before 0.5).
``tasker-first`` — LAMA-first only: the fastest plan, costs ignored.

With axioms (``:derived`` predicates, some ADL conditions) LM-cut refuses the task (exit
34); the optimal search is then A* with the blind heuristic, still optimal, far slower.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from planners.fd import (
    AXIOM_SEARCH,
    LAMA_FIRST,
    OPTIMAL_SEARCH,
    UNSUPPORTED_FEATURE,
    FDExit,
    FoundPlan,
    SearchRun,
    lama_iterated,
    optimal_below,
    search,
)
from planners.results import Attempt, Failure, PlanResult, PlanStatus, failure_of
from planners.translate import translate

EXPANSION_BUDGET = 10_000
"""States ``tasker-fd``'s optimal search may expand before LAMA-first answers instead.  The
bundled tasks' problems need at most a few dozen; LM-cut expands some 3,000–30,000 states a
second on IPC tasks (barman: 10,000 in about 1 s), so the budget costs a few seconds at most,
within a task's default ``timeout_s`` (10 s)."""

IMPROVE_SHARE = 0.5
"""Of the time left after the first plan, the share ``tasker-anytime`` gives iterated LAMA; A*
with LM-cut gets the rest (and whatever iterated LAMA leaves when it stops early)."""

CLI_PLANNER = "tasker-anytime"
"""``tasker plan``'s default: a plan at once, improved within the time limit."""

LAMA = "lama"
LAMA_FIRST_LABEL = "lama-first"


@dataclass
class _Call:
    """One planner call in progress: the SAS task, the clock, and every search run so far."""

    sas: str
    timeout: float | None
    t0: float = field(default_factory=time.perf_counter)
    attempts: list[Attempt] = field(default_factory=list)
    first_plan_s: float | None = None
    found_at: dict[int, float] = field(default_factory=dict)  # id(FoundPlan) -> seconds into the call

    def remaining(self) -> float | None:
        return None if self.timeout is None else self.timeout - (time.perf_counter() - self.t0)

    def run(self, label: str, config: str, *, share: float = 1.0, expansions: int | None = None) -> SearchRun:
        left = self.remaining()
        started = time.perf_counter() - self.t0
        out = search(self.sas, config, timeout=None if left is None else left * share, expansions=expansions)
        best = out.best
        self.attempts.append(Attempt(label, out.exit, best.cost if best else None, started, out.seconds))
        for plan in out.plans:
            self.found_at[id(plan)] = started + plan.at_s
        if out.plans and self.first_plan_s is None:
            self.first_plan_s = started + out.plans[0].at_s
        return out

    def optimal(self, bound: float | None = None, expansions: int | None = None) -> tuple[SearchRun, str]:
        """A* with LM-cut (the blind heuristic where LM-cut refuses the task), below ``bound``."""
        out = self.run(OPTIMAL_SEARCH, optimal_below("lmcut", bound), expansions=expansions)
        if out.exit is FDExit.ERROR and out.code == UNSUPPORTED_FEATURE:
            self.attempts[-1] = Attempt(OPTIMAL_SEARCH, FDExit.ERROR, None, self.attempts[-1].started_s,
                                        self.attempts[-1].seconds, "LM-cut does not support the task's axioms "
                                                                   "or conditional effects")
            return self.run(AXIOM_SEARCH, optimal_below("blind", bound), expansions=expansions), AXIOM_SEARCH
        return out, OPTIMAL_SEARCH

    def result(self, name: str, status: PlanStatus, *, best: FoundPlan | None = None, search: str = "",
               optimal: bool = False, message: str = "", failure: Failure | None = None) -> PlanResult:
        best_s = None if best is None else self.found_at.get(id(best))
        return PlanResult(status, best.steps if best else None, best.cost if best else None, name,
                          time.perf_counter() - self.t0, message=message, optimal=optimal, search=search,
                          failure=failure, attempts=tuple(self.attempts), first_plan_s=self.first_plan_s,
                          best_plan_s=best_s)

    def tried(self) -> str:
        """What was tried, for messages: no seconds (a result's message can reach a run's outputs)."""
        return "; ".join(a.describe() for a in self.attempts)


_STATUS = {FDExit.UNSOLVABLE: PlanStatus.UNSOLVABLE, FDExit.TIMEOUT: PlanStatus.TIMEOUT,
           FDExit.OVER_BUDGET: PlanStatus.TIMEOUT, FDExit.MEMOUT: PlanStatus.ERROR, FDExit.ERROR: PlanStatus.ERROR}


def _unsolved(call: _Call, name: str, out: SearchRun, advice: str) -> PlanResult:
    """A call that ends with ``out`` and no plan: the status, what was tried, and what to try."""
    status = _STATUS[out.exit]
    if status is PlanStatus.UNSOLVABLE:
        proof = "no plan exists" if out.code in (10, 11) else \
            "no plan found: the search ended incompletely (no proof that none exists)"
        return call.result(name, status, message=f"{proof} ({call.tried()})")
    failure = failure_of(out.exit, out.message)
    what = "time limit reached" if status is PlanStatus.TIMEOUT else (out.message or out.exit.value)
    return call.result(name, status, failure=failure,
                       message=f"{what}; tried: {call.tried()}" + (f"; {advice}" if advice else ""))


def reproducible(call: _Call, name: str) -> PlanResult:
    """``tasker-fd``: optimal within the expansion budget, else LAMA-first (module doc)."""
    expansions = EXPANSION_BUDGET
    out, label = call.optimal(expansions=expansions)
    if out.exit is FDExit.SOLVED and out.best is not None:
        return call.result(name, PlanStatus.SOLVED, best=out.best, search=label, optimal=True)
    if out.exit not in (FDExit.OVER_BUDGET, FDExit.MEMOUT):
        return _unsolved(call, name, out, "try tasker plan's default planner, tasker-anytime, or a longer timeout")
    first = call.run(LAMA_FIRST_LABEL, LAMA_FIRST)
    if first.exit is FDExit.SOLVED and first.best is not None:
        why = (f"{label} expanded more than {expansions} states" if out.exit is FDExit.OVER_BUDGET
               else f"{label} ran out of memory")
        return call.result(name, PlanStatus.SOLVED, best=first.best, search=LAMA_FIRST_LABEL,
                           optimal=first.best.cost == 0, message=f"{why}; LAMA-first's plan")
    return _unsolved(call, name, first, "try a longer timeout")


def anytime(call: _Call, name: str) -> PlanResult:
    """``tasker-anytime``: LAMA-first, improved by iterated LAMA, proven or improved by A* (module doc)."""
    first = call.run(LAMA_FIRST_LABEL, LAMA_FIRST)
    if first.exit is not FDExit.SOLVED or first.best is None:
        return _unsolved(call, name, first, "try a longer --timeout; --planner tasker-opt proves a small "
                                            "problem unsolvable")
    best, label = first.best, LAMA_FIRST_LABEL
    if best.cost == 0:
        return call.result(name, PlanStatus.SOLVED, best=best, search=label, optimal=True)
    improved = call.run(LAMA, lama_iterated(None), share=IMPROVE_SHARE)
    if improved.best is not None and improved.best.cost < best.cost:
        best, label = min(improved.plans, key=lambda p: p.cost), LAMA
    proof, opt_label = call.optimal(bound=best.cost)
    if proof.exit is FDExit.SOLVED and proof.best is not None:
        return call.result(name, PlanStatus.SOLVED, best=proof.best, search=opt_label, optimal=True)
    if proof.exit is FDExit.UNSOLVABLE:  # nothing cheaper than ``best`` exists
        return call.result(name, PlanStatus.SOLVED, best=best, search=label, optimal=True,
                           message=f"{opt_label} found no cheaper plan")
    why = "did not finish within the time limit" if proof.exit is FDExit.TIMEOUT else (proof.message or
                                                                                        proof.exit.value)
    return call.result(name, PlanStatus.SOLVED, best=best, search=label,
                       message=f"{opt_label} {why}; tried: {call.tried()}; a longer --timeout may improve or "
                               "prove it")


def optimal_only(call: _Call, name: str) -> PlanResult:
    """``tasker-opt``: A* with LM-cut, optimal or nothing."""
    out, label = call.optimal()
    if out.exit is FDExit.SOLVED and out.best is not None:
        return call.result(name, PlanStatus.SOLVED, best=out.best, search=label, optimal=True)
    return _unsolved(call, name, out, "an optimal search may need far longer: the default planner, "
                                      "tasker-anytime, finds a plan at once and improves it")


def first_only(call: _Call, name: str) -> PlanResult:
    """``tasker-first``: LAMA-first alone."""
    out = call.run(LAMA_FIRST_LABEL, LAMA_FIRST)
    if out.exit is FDExit.SOLVED and out.best is not None:
        return call.result(name, PlanStatus.SOLVED, best=out.best, search=LAMA_FIRST_LABEL,
                           optimal=out.best.cost == 0)
    return _unsolved(call, name, out, "try a longer --timeout")


@dataclass(frozen=True, slots=True)
class Schedule:
    """A registered schedule: its name, one line for ``--help`` and docs, and whether its answers
    depend on the task alone (``deterministic``) or also on the machine's speed."""

    name: str
    summary: str
    deterministic: bool
    run: Callable[[_Call, str], PlanResult]


SCHEDULES: dict[str, Schedule] = {s.name: s for s in (
    Schedule("tasker-fd", f"A* + LM-cut (optimal) within {EXPANSION_BUDGET} expanded states, else LAMA-first; "
                          "reproducible (what runs plan with)", True, reproducible),
    Schedule("tasker-anytime", "LAMA-first at once, improved by iterated LAMA, proven or improved by A* + LM-cut "
                               "within the time limit", False, anytime),
    Schedule("tasker-opt", "A* + LM-cut: an optimal plan or none", True, optimal_only),
    Schedule("tasker-first", "LAMA-first: a plan at once, action costs ignored", True, first_only),
)}
"""The schedules by name (the names :class:`~planners.planner.Planner` and ``--planner`` take)."""


def solve_text(name: str, domain: str, problem: str, timeout: float | None) -> PlanResult:
    """Translate ``domain`` + ``problem`` (PDDL text) and run schedule ``name`` on the SAS task.

    ``timeout`` bounds translation plus search; the translator cannot be interrupted, so an
    over-long translation is reported as a time-out after it ends."""
    schedule = SCHEDULES[name]
    call = _Call("", timeout)
    out = translate(domain, problem)
    if out.code != 0:
        failure = Failure.MEMORY if out.code == 20 else Failure.INPUT
        return call.result(name, PlanStatus.ERROR, message=out.message, failure=failure)
    left = call.remaining()
    if left is not None and left <= 0:
        return call.result(name, PlanStatus.TIMEOUT, message="time limit reached while translating (Fast Downward's "
                                                             "translator); try a longer --timeout")
    call.sas = out.sas
    return schedule.run(call, name)
