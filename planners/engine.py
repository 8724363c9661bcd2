"""``tasker-fd``: a unified-planning one-shot engine over :mod:`planners.fd`.

Registered with UP's factory under :data:`~planners.registration.ENGINE_NAME` (by
:func:`planners.registration.register_engine`), so any UP code can write::

    with OneshotPlanner(name="tasker-fd") as planner:
        result = planner.solve(problem, timeout=5)

It writes the problem with ``PDDLWriter``, runs Fast Downward's translator in-process
and the ``downward`` binary under a search schedule (:mod:`planners.schedules`; by
default ``tasker-fd``: A* + LM-cut, optimal under action costs like ``fast-downward-opt``,
within an expansion budget, else LAMA-first), and maps the plan back through the writer's
name table.  It is a drop-in for ``fast-downward-opt`` at a fraction of its start-up cost;
``SOLVED_OPTIMALLY`` means the plan is proven optimal.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import IO

import unified_planning as up
from unified_planning.engines import Engine, LogLevel, LogMessage, OptimalityGuarantee, PlanGenerationResult
from unified_planning.engines import PlanGenerationResultStatus as UPStatus
from unified_planning.engines.mixins import OneshotPlannerMixin
from unified_planning.io import PDDLWriter
from unified_planning.model import ProblemKind

from planners.fd import OPTIMAL_SEARCH, run_fast_downward
from planners.kind import supported_kind
from planners.registration import ENGINE_NAME
from planners.results import PlanStatus, from_fd_outcome
from planners.schedules import SCHEDULES, solve_text

_UP_STATUS = {
    PlanStatus.UNSOLVABLE: UPStatus.UNSOLVABLE_PROVEN,
    PlanStatus.TIMEOUT: UPStatus.TIMEOUT,
    PlanStatus.ERROR: UPStatus.INTERNAL_ERROR,
}


class TaskerFastDownward(Engine, OneshotPlannerMixin):
    """Fast Downward as a UP one-shot planner, without the driver's start-up cost.

    ``schedule`` names a search schedule (:data:`~planners.schedules.SCHEDULES`, default
    ``tasker-fd``); ``search``, a Fast Downward search string, replaces it with that one search
    (not claimed optimal unless it is ``astar(lmcut())``).  A plan proven optimal is reported
    ``SOLVED_OPTIMALLY`` (with a quality metric), any other ``SOLVED_SATISFICING``.  ``timeout``
    given to the constructor is the default for :meth:`solve` calls that pass none.  Any
    other parameter (``OneshotPlanner(name="tasker-fd", params={...})``) is refused, as
    ``TypeError`` naming it: a misspelt option must not be ignored.
    """

    def __init__(self, search: str | None = None, timeout: float | None = None,
                 schedule: str = ENGINE_NAME) -> None:
        if search is not None and (not isinstance(search, str) or not search.strip()):
            raise ValueError(f"tasker-fd: search must be a Fast Downward search string, got {search!r}")
        if schedule not in SCHEDULES:
            raise ValueError(f"tasker-fd: schedule must be one of {', '.join(SCHEDULES)}, got {schedule!r}")
        if timeout is not None and not timeout > 0:
            raise ValueError(f"tasker-fd: timeout must be a positive number of seconds, got {timeout!r}")
        Engine.__init__(self)
        OneshotPlannerMixin.__init__(self)
        self._search = search
        self._schedule = schedule
        self._timeout = timeout

    @property
    def name(self) -> str:
        return ENGINE_NAME

    @staticmethod
    def supported_kind() -> ProblemKind:
        return supported_kind()

    @staticmethod
    def supports(problem_kind: ProblemKind) -> bool:
        return problem_kind <= TaskerFastDownward.supported_kind()

    @staticmethod
    def satisfies(optimality_guarantee: OptimalityGuarantee) -> bool:
        # the default schedule is optimal within its expansion budget only (SOLVED_OPTIMALLY says when)
        return optimality_guarantee is OptimalityGuarantee.SATISFICING

    def _solve(
        self,
        problem: up.model.AbstractProblem,
        heuristic: Callable[[up.model.state.State], float | None] | None = None,
        timeout: float | None = None,
        output_stream: IO[str] | None = None,
    ) -> PlanGenerationResult:
        assert isinstance(problem, up.model.Problem)
        start = time.perf_counter()
        writer = PDDLWriter(problem)
        budget = timeout if timeout is not None else self._timeout
        if self._search is None:
            result = solve_text(self._schedule, writer.get_domain(), writer.get_problem(), budget)
        else:
            outcome = run_fast_downward(writer.get_domain(), writer.get_problem(), search=self._search, timeout=budget)
            result = from_fd_outcome(outcome, self.name, time.perf_counter() - start, search=self._search,
                                     optimal=self._search == OPTIMAL_SEARCH)
        metrics = {"engine_internal_time": str(result.wall_time_s), "search": result.search,
                   "optimal": str(result.optimal)}
        if result.status is not PlanStatus.SOLVED:
            if output_stream is not None and result.message:
                output_stream.write(result.message + "\n")
            logs = [LogMessage(LogLevel.ERROR if result.status is PlanStatus.ERROR else LogLevel.INFO, result.message)]
            return PlanGenerationResult(_UP_STATUS[result.status], None, self.name, metrics, logs)
        assert result.plan is not None and result.cost is not None
        em = problem.environment.expression_manager
        actions = [
            up.plans.ActionInstance(
                writer.get_item_named(step[0]), [em.ObjectExp(writer.get_item_named(a)) for a in step[1:]]
            )
            for step in result.plan
        ]
        metrics["cost"] = str(result.cost)
        optimal = result.optimal and bool(problem.quality_metrics)
        status = UPStatus.SOLVED_OPTIMALLY if optimal else UPStatus.SOLVED_SATISFICING
        note = f"{len(result.plan)} steps, cost {result.cost:g}, search {result.search}" + (
            f"; {result.message}" if result.message else "")
        logs = [LogMessage(LogLevel.INFO, note)]
        return PlanGenerationResult(status, up.plans.SequentialPlan(actions), self.name, metrics, logs)

