"""``tasker-fd``: a unified-planning one-shot engine over :mod:`planners.fd`.

Registered with UP's factory under :data:`ENGINE_NAME`, so any UP code can write::

    with OneshotPlanner(name="tasker-fd") as planner:
        result = planner.solve(problem, timeout=5)

It writes the problem with ``PDDLWriter``, runs Fast Downward's translator in-process
and the ``downward`` binary (A* + LM-cut by default: optimal under action costs, like
``fast-downward-opt``), and maps the plan back through the writer's name table.  It is
a drop-in for ``fast-downward-opt`` at a fraction of its start-up cost.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import IO, Any

import unified_planning as up
from unified_planning.engines import Engine, OptimalityGuarantee, PlanGenerationResult
from unified_planning.engines import PlanGenerationResultStatus as UPStatus
from unified_planning.engines.mixins import OneshotPlannerMixin
from unified_planning.environment import get_environment
from unified_planning.io import PDDLWriter
from unified_planning.model import ProblemKind

from planners.fd import OPTIMAL_SEARCH, FDExit, run_fast_downward

ENGINE_NAME = "tasker-fd"
"""The name under which :class:`TaskerFastDownward` is registered in UP's factory."""

_UP_STATUS = {
    FDExit.UNSOLVABLE: UPStatus.UNSOLVABLE_PROVEN,
    FDExit.TIMEOUT: UPStatus.TIMEOUT,
    FDExit.MEMOUT: UPStatus.MEMOUT,
    FDExit.ERROR: UPStatus.INTERNAL_ERROR,
}


class TaskerFastDownward(Engine, OneshotPlannerMixin):
    """Optimal Fast Downward as a UP one-shot planner, without the driver's start-up cost.

    ``search`` is a Fast Downward search string (default ``astar(lmcut())``); with a
    non-optimal search the engine reports ``SOLVED_SATISFICING``.  ``timeout`` given
    to the constructor is the default for :meth:`solve` calls that pass none.
    """

    def __init__(self, search: str = OPTIMAL_SEARCH, timeout: float | None = None, **kwargs: Any) -> None:
        Engine.__init__(self)
        OneshotPlannerMixin.__init__(self)
        self._search = search
        self._timeout = timeout

    @property
    def name(self) -> str:
        return ENGINE_NAME

    @staticmethod
    def supported_kind() -> ProblemKind:
        kind = ProblemKind(version=2)
        kind.set_problem_class("ACTION_BASED")
        kind.set_typing("FLAT_TYPING")
        kind.set_typing("HIERARCHICAL_TYPING")
        for c in ("NEGATIVE_CONDITIONS", "DISJUNCTIVE_CONDITIONS", "EXISTENTIAL_CONDITIONS",
                  "UNIVERSAL_CONDITIONS", "EQUALITIES"):
            kind.set_conditions_kind(c)
        for e in ("CONDITIONAL_EFFECTS", "STATIC_FLUENTS_IN_BOOLEAN_ASSIGNMENTS",
                  "FLUENTS_IN_BOOLEAN_ASSIGNMENTS", "FORALL_EFFECTS"):
            kind.set_effects_kind(e)
        kind.set_quality_metrics("ACTIONS_COST")
        kind.set_quality_metrics("PLAN_LENGTH")
        kind.set_actions_cost_kind("STATIC_FLUENTS_IN_ACTIONS_COST")
        kind.set_actions_cost_kind("INT_NUMBERS_IN_ACTIONS_COST")
        return kind

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
        writer = PDDLWriter(problem)
        outcome = run_fast_downward(
            writer.get_domain(), writer.get_problem(), search=self._search,
            timeout=timeout if timeout is not None else self._timeout,
        )
        metrics = {
            "engine_internal_time": str(outcome.translate_s + outcome.search_s),
            "translate_time": str(outcome.translate_s),
            "search_time": str(outcome.search_s),
        }
        if outcome.exit is not FDExit.SOLVED:
            if output_stream is not None and outcome.message:
                output_stream.write(outcome.message + "\n")
            return PlanGenerationResult(_UP_STATUS[outcome.exit], None, self.name, metrics)
        assert outcome.plan is not None
        em = problem.environment.expression_manager
        actions = [
            up.plans.ActionInstance(
                writer.get_item_named(step[0]), [em.ObjectExp(writer.get_item_named(a)) for a in step[1:]]
            )
            for step in outcome.plan
        ]
        if outcome.cost is not None:
            metrics["cost"] = str(outcome.cost)
        optimal = self._search == OPTIMAL_SEARCH and bool(problem.quality_metrics)
        status = UPStatus.SOLVED_OPTIMALLY if optimal else UPStatus.SOLVED_SATISFICING
        return PlanGenerationResult(status, up.plans.SequentialPlan(actions), self.name, metrics)


def register_engine(name: str = ENGINE_NAME) -> None:
    """Add the engine to UP's factory (idempotent), through UP's documented ``add_engine``."""
    factory = get_environment().factory
    if name not in factory.engines:
        factory.add_engine(name, __name__, TaskerFastDownward.__name__)
