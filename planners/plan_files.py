"""A classical PDDL domain and problem from files, checked, planned and validated: ``tasker plan``'s pipeline.

Which reader reads the task decides what can be said of the plan:

* **unified-planning's reader** (:func:`planners.checks.load_problem`) checks the task first,
  with file, line and column in its errors; a check that passed is remembered
  (:mod:`planners.cache`, kind ``pddl-problem``), so a later call skips it;
* where it refuses **legal PDDL it cannot read** (``PddlError.reader_only``: ``(either ...)``
  types, ``:derived`` predicates, a predicate that names one parameter twice as logistics00's,
  a name glued to a variable as zenotravel's ``(aircraft?a)``, action costs without
  ``(= (total-cost) 0)`` in the problem as tetris'), a search schedule
  (``tasker-fd``, ``tasker-anytime``, ...) plans from **Fast Downward's own translator**, which
  reads them.  The answer says so (:attr:`Reader.FAST_DOWNWARD`, with UP's refusal).  When
  the translator refuses it too, the refusal is UP's (it names the line), with the
  translator's reason added.  Any other refusal is an error in the PDDL and stays one: the
  translator is more lenient in places it should not be (an undeclared type is an empty
  one to it, and the task silently unsolvable).  Another UP engine
  (``--planner fast-downward-opt``) needs UP's model: UP's refusal is final there.

Every plan is then **validated** by UP's ``sequential_plan_validator`` when UP's reader can
read the task; a plan that passed is remembered (kind ``plan-valid``, keyed by the domain,
problem and plan), so repeating an answer does not import UP's engines again.  When UP cannot
read the task, nothing here can validate the plan: the answer says so (``validated`` is
``None`` and ``validation`` gives the reason), never that it is valid.  A plan the validator
rejects is the engine's failure (``ERROR``, :attr:`~planners.results.Failure.ENGINE`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum
from pathlib import Path

from planners import cache
from planners.checks import PddlError
from planners.planner import PddlText, Planner
from planners.results import Failure, PlanResult, PlanStatus
from planners.schedules import SCHEDULES


class Reader(StrEnum):
    """Which PDDL reader read the task that was planned."""

    UNIFIED_PLANNING = "unified-planning"
    FAST_DOWNWARD = "fast-downward-translator"


@dataclass(frozen=True, slots=True)
class FilesAnswer:
    """A planner's answer on a domain and a problem file, with what read the task and what checked the plan.

    ``refused`` is unified-planning's refusal when ``reader`` is Fast Downward's translator;
    ``validated`` is ``True`` (UP's validator accepted the plan), ``None`` (not validated:
    ``validation`` says why) — a rejected plan is an ``ERROR`` result, not an answer with
    ``False``.
    """

    result: PlanResult
    reader: Reader
    refused: str = ""
    validated: bool | None = None
    validation: str = ""

    def __post_init__(self) -> None:
        if (self.reader is Reader.FAST_DOWNWARD) != bool(self.refused):
            raise ValueError("a FilesAnswer names unified-planning's refusal exactly when the translator read the task")
        if self.validated is True and self.reader is Reader.FAST_DOWNWARD:
            raise ValueError("UP's validator cannot have validated a task UP's reader refused")
        if self.validated is not None and not self.result.solved:
            raise ValueError("only a plan can be validated")
        if self.validated is False:
            raise ValueError("a plan UP's validator rejects is an ERROR result, not a FilesAnswer with validated=False")

    def to_json(self) -> dict[str, object]:
        """``tasker plan --json``: the result's fields, then the reader and the validation."""
        return {**self.result.to_json(), "reader": self.reader.value, "reader_refusal": self.refused or None,
                "validated": self.validated, "validation": self.validation}


def plan_files(domain: Path, problem: Path, domain_text: str, problem_text: str, planner: Planner) -> FilesAnswer:
    """Check, plan and validate (module doc).  Raises :class:`PddlError` when no reader reads the task."""
    key = cache.content_key("pddl-problem", [domain_text, problem_text])
    model = None
    refused: PddlError | None = None
    if planner.name not in SCHEDULES or not cache.passed("pddl-problem", key):
        from planners.checks import load_problem

        try:
            _, _, model = load_problem(domain, problem)
        except PddlError as exc:
            if not exc.reader_only:
                raise
            if planner.name not in SCHEDULES:
                raise PddlError(exc.file, f"{exc.reason} (planner {planner.name} needs unified-planning's reader; "
                                          "the default planner reads more of PDDL with Fast Downward's translator)",
                                exc.line, exc.col) from None
            refused = exc
        else:
            cache.record("pddl-problem", key, {"domain": str(domain), "problem": str(problem)})
    result = planner.solve(PddlText(domain_text, problem_text) if planner.name in SCHEDULES else model)
    if result.failure is Failure.INPUT and planner.name in SCHEDULES and refused is None:
        # FD's own PDDL reader is stricter than UP's in places (e.g. an empty ``(:goal ())``): let UP write it
        if model is None:
            from planners.checks import load_problem

            _, _, model = load_problem(domain, problem)
        result = planner.solve(model)
    if refused is not None:
        if result.failure is Failure.INPUT:  # neither reader reads it: UP's refusal names the line
            raise PddlError(refused.file, f"{refused.reason} (Fast Downward's translator refuses it too: "
                                          f"{result.message})", refused.line, refused.col)
        why = f"unified-planning's reader refuses the task: {refused}"
        note = f"not validated: {why}; UP's validator needs it" if result.solved else ""
        return FilesAnswer(result, Reader.FAST_DOWNWARD, str(refused), None, note)
    if not result.solved:
        return FilesAnswer(result, Reader.UNIFIED_PLANNING)
    return _validated(domain, problem, domain_text, problem_text, result, model)


def _validated(domain: Path, problem: Path, domain_text: str, problem_text: str, result: PlanResult,
               model: object | None) -> FilesAnswer:
    """UP's validator on the plan (remembered when it passed); a rejected plan becomes an engine ``ERROR``."""
    assert result.plan is not None
    plan_text = "\n".join(" ".join(step) for step in result.plan)
    key = cache.content_key("plan-valid", [domain_text, problem_text, plan_text])
    if cache.passed("plan-valid", key):
        return FilesAnswer(result, Reader.UNIFIED_PLANNING, validated=True,
                           validation="valid (UP's sequential_plan_validator; remembered)")
    from planners.checks import load_problem
    from planners.validate import validate_plan

    if model is None:
        _, _, model = load_problem(domain, problem)
    try:
        verdict = validate_plan(model, result.plan)
    except PddlError as exc:  # a step UP's model has no name for: the plan is not one of this task
        verdict, reason = None, exc.reason
    except Exception as exc:  # noqa: BLE001 - the validator's own failure says nothing of the plan
        why = " ".join(f"{type(exc).__name__}: {exc}".split())[:300]
        return FilesAnswer(result, Reader.UNIFIED_PLANNING, validation=f"not validated: UP's validator failed: {why}")
    if verdict is not None and verdict.valid:
        cache.record("plan-valid", key, {"domain": str(domain), "problem": str(problem)})
        return FilesAnswer(result, Reader.UNIFIED_PLANNING, validated=True,
                           validation="valid (UP's sequential_plan_validator)")
    reason = verdict.reason if verdict is not None else reason
    bad = replace(result, status=PlanStatus.ERROR, plan=None, cost=None, optimal=False, failure=Failure.ENGINE,
                  message=f"planner {result.planner} returned a plan that UP's sequential_plan_validator rejects: "
                          f"{reason}")
    return FilesAnswer(bad, Reader.UNIFIED_PLANNING)
