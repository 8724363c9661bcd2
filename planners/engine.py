"""``tasker-fd``: a unified-planning one-shot engine over :mod:`planners.fd`.

Registered with UP's factory under :data:`~planners.registration.ENGINE_NAME` (by
:func:`planners.registration.register_engine`), so any UP code can write::

    with OneshotPlanner(name="tasker-fd") as planner:
        result = planner.solve(problem, timeout=5)

It writes the problem with ``PDDLWriter``, runs Fast Downward's translator in-process
and the ``downward`` binary (A* + LM-cut by default: optimal under action costs, like
``fast-downward-opt``), and maps the plan back through the writer's name table.  It is
a drop-in for ``fast-downward-opt`` at a fraction of its start-up cost.
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

_UP_STATUS = {
    PlanStatus.UNSOLVABLE: UPStatus.UNSOLVABLE_PROVEN,
    PlanStatus.TIMEOUT: UPStatus.TIMEOUT,
    PlanStatus.ERROR: UPStatus.INTERNAL_ERROR,
}


class TaskerFastDownward(Engine, OneshotPlannerMixin):
    """Optimal Fast Downward as a UP one-shot planner, without the driver's start-up cost.

    ``search`` is a Fast Downward search string (default ``astar(lmcut())``); with a
    non-optimal search the engine reports ``SOLVED_SATISFICING``.  ``timeout`` given
    to the constructor is the default for :meth:`solve` calls that pass none.  Any
    other parameter (``OneshotPlanner(name="tasker-fd", params={...})``) is refused, as
    ``TypeError`` naming it: a misspelt option must not be ignored.
    """

    def __init__(self, search: str = OPTIMAL_SEARCH, timeout: float | None = None) -> None:
        if not isinstance(search, str) or not search.strip():
            raise ValueError(f"tasker-fd: search must be a Fast Downward search string, got {search!r}")
        if timeout is not None and not timeout > 0:
            raise ValueError(f"tasker-fd: timeout must be a positive number of seconds, got {timeout!r}")
        Engine.__init__(self)
        OneshotPlannerMixin.__init__(self)
        self._search = search
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
        return True  # the default search is optimal; a user-supplied search is the user's choice

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
        outcome = run_fast_downward(
            writer.get_domain(), writer.get_problem(), search=self._search,
            timeout=timeout if timeout is not None else self._timeout,
        )
        result = from_fd_outcome(outcome, self.name, time.perf_counter() - start)
        metrics = {
            "engine_internal_time": str(outcome.translate_s + outcome.search_s),
            "translate_time": str(outcome.translate_s),
            "search_time": str(outcome.search_s),
        }
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
        optimal = self._search == OPTIMAL_SEARCH and bool(problem.quality_metrics)
        status = UPStatus.SOLVED_OPTIMALLY if optimal else UPStatus.SOLVED_SATISFICING
        logs = [LogMessage(LogLevel.INFO, f"{len(result.plan)} steps, cost {result.cost:g}, search {self._search}")]
        return PlanGenerationResult(status, up.plans.SequentialPlan(actions), self.name, metrics, logs)

