"""Check plans and replay them with unified-planning: never a hand-written validator.

* :func:`validate_plan` — UP's ``sequential_plan_validator`` on a plan given as steps;
* :func:`state_after` — UP's ``SequentialSimulator``: the true facts after a plan prefix.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import unified_planning as up
from unified_planning.engines import ValidationResultStatus
from unified_planning.shortcuts import PlanValidator, SequentialSimulator

from planners.checks import PddlError

Fact = tuple[str, ...]


@dataclass(frozen=True, slots=True)
class Validation:
    """UP's verdict on a plan: valid or not, why not, and the metric value."""

    valid: bool
    reason: str = ""
    cost: float | None = None


def to_up_plan(problem: up.model.Problem, steps: Sequence[Sequence[str]]) -> up.plans.SequentialPlan:
    """A plan given as ``(action, arg, ...)`` steps, as UP action instances of ``problem``."""
    em = problem.environment.expression_manager
    actions = []
    for step in steps:
        if not problem.has_action(step[0]):
            raise PddlError("<plan>", f"unknown action {step[0]!r}")
        actions.append(up.plans.ActionInstance(problem.action(step[0]),
                                               [em.ObjectExp(problem.object(a)) for a in step[1:]]))
    return up.plans.SequentialPlan(actions)


def validate_plan(problem: up.model.Problem, steps: Sequence[Sequence[str]]) -> Validation:
    """Does the plan apply from the initial state and reach the goal?  UP decides."""
    plan = to_up_plan(problem, steps)
    with warnings.catch_warnings(), PlanValidator(name="sequential_plan_validator") as validator:
        warnings.simplefilter("ignore")
        validator.skip_checks = True  # parsed PDDL numbers are Real; the problem was checked on load
        res = validator.validate(problem, plan)
    values = list(res.metric_evaluations.values()) if res.metric_evaluations else []
    reason = "" if res.status is ValidationResultStatus.VALID else str(res.reason or "") + \
        (f": {res.inapplicable_action}" if res.inapplicable_action is not None else "")
    return Validation(res.status is ValidationResultStatus.VALID, reason, float(values[0]) if values else None)


def state_after(problem: up.model.Problem, steps: Sequence[Sequence[str]], k: int | None = None) -> frozenset[Fact]:
    """True Boolean ground facts after the first ``k`` steps (all if None), by UP's simulator."""
    plan = to_up_plan(problem, steps[:k] if k is not None else steps)
    with warnings.catch_warnings(), SequentialSimulator(problem=problem) as sim:
        warnings.simplefilter("ignore")
        state = sim.get_initial_state()
        for n, ai in enumerate(plan.actions, 1):
            nxt = sim.apply(state, ai)
            if nxt is None:
                raise PddlError("<plan>", f"step {n} ({ai}) is not applicable")
            state = nxt
        facts = set()
        for fluent_exp in problem.initial_values:
            if fluent_exp.type.is_bool_type() and state.get_value(fluent_exp).is_true():
                facts.add((fluent_exp.fluent().name, *(str(a) for a in fluent_exp.args)))
    return frozenset(facts)
