"""The PDDL features the Fast Downward path handles, as a unified-planning ``ProblemKind``.

One definition, used by the load-time checks (:mod:`planners.checks`) and by the
``tasker-fd`` engine (:mod:`planners.engine`).  It lives apart from the engine so that
checking a problem does not import UP's engine framework.
"""

from __future__ import annotations

from unified_planning.model import ProblemKind


def supported_kind() -> ProblemKind:
    """Classical STRIPS/ADL with typing and static or integer action costs."""
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
