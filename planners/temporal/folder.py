"""Task folders whose ``domain.pddl`` is temporal: what :mod:`planners.loader` calls instead.

The loader calls :func:`load_domain`, :func:`domain_model`, :func:`load_problem_text` and
:func:`planner_for` for every folder; each hands a classical domain to the classical path
unchanged, and does the temporal work for a temporal one:

* the domain is checked by UP's reader (PlanSys2's empty blocks read, :mod:`~planners.temporal.reading`);
* its :class:`TemporalDomainModel` reads the schema from UP's model (:mod:`~planners.temporal.schema`);
* its task type plans with a :class:`FolderPlanner`: the temporal engines in turn
  (:class:`~planners.temporal.portfolio.TemporalPlanner`), every plan validated, and a plan in which
  the one robot would do two things at once refused (the next engine is asked), with the
  domain file, the two actions and their times.  The plan's steps become stages in start-time
  order; a stage lasts what ``task.toml`` says (``travel``: the motion model; ``duration``) or
  else the domain's fixed ``:duration`` — :func:`check_durations` refuses at load an action
  with neither.  The stages of a plan that refuses overlap run one after the other, so the
  plan's makespan re-timed by the robot's skills is the sum of its stages' durations: ``cTime``
  (:mod:`planners.estimates`) is exactly that.
"""

from __future__ import annotations

import dataclasses
import threading
import time
from collections import OrderedDict
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING

from planners import checks
from planners.checks import CheckedDomain, DefinitionError, PddlError
from planners.problem import DomainModel
from planners.results import Failure, PlanResult, PlanStatus
from planners.schema import DomainSchema
from planners.temporal.reading import is_temporal, parse, tolerant
from planners.temporal.results import TimedStep

if TYPE_CHECKING:
    import unified_planning as up

    from planners.planner import PddlText
    from planners.taskspec import TaskSpec

OVERLAP_S = Fraction(1, 10**6)
"""Two steps overlapping by less than this (engines separate steps by an epsilon) do not."""
CACHED = 256
"""How many answers a :class:`FolderPlanner` keeps (by domain and problem text)."""


def load_domain(path: str | Path) -> CheckedDomain:
    """:func:`planners.checks.load_domain` for a classical domain; for a temporal one, the
    checks UP's reader makes (errors with file, line and column), and its text as read."""
    text = checks._read(path)  # noqa: SLF001 - the one reader of PDDL files (errors name the line)
    if not is_temporal(text):
        return checks.load_domain(path)
    checks.check_depth(text, path)
    checks.check_types(text, path)
    checks.check_constructs(text, path)
    parse(text, None, path)
    return CheckedDomain(Path(path), tolerant(text))


def domain_model(domain: CheckedDomain) -> DomainModel:
    """The domain's model: a :class:`TemporalDomainModel` for a temporal domain."""
    if is_temporal(domain.text):
        return TemporalDomainModel(CheckedDomain(domain.path, tolerant(domain.text)))
    return DomainModel(domain)


def load_problem_text(domain: CheckedDomain, problem_text: str, problem_file: str | Path) -> up.model.Problem:
    """:func:`planners.checks.load_problem_text`, or UP's reading of a temporal problem."""
    if is_temporal(domain.text):
        return parse(domain.text, problem_text, domain.path, problem_file)
    return checks.load_problem_text(domain, problem_text, problem_file)


class TemporalDomainModel(DomainModel):
    """A :class:`~planners.problem.DomainModel` of a temporal domain, its schema read from UP's model."""

    @staticmethod
    def _schema(domain: CheckedDomain) -> DomainSchema:
        from planners.temporal.schema import schema_of

        return schema_of(parse(domain.text, None, domain.path))


def check_durations(spec: TaskSpec, dm: DomainModel) -> None:
    """Every action's stage has a duration: ``travel`` or ``duration`` in ``task.toml``, or a fixed
    ``:duration`` in the domain (an expression such as ``(travel-time ?a ?b)`` needs ``travel``)."""
    for name, a in spec.actions.items():
        if a.travel is None and a.duration is None and name in dm.actions and dm.actions[name].constant_cost is None:
            raise spec.error(f"actions.{name}", f"the :duration of {name} in {spec.domain_file.name} is not a fixed "
                                                "number, so its stage has no duration: give travel = [\"?from\", "
                                                "\"?to\"] (the motion model times it) or duration = SECONDS here")


def planner_for(spec: TaskSpec, dm: DomainModel) -> FolderPlanner | None:
    """The planner of a temporal folder's task type (its durations checked), None for a classical one."""
    if not isinstance(dm, TemporalDomainModel):
        return None
    check_durations(spec, dm)
    return FolderPlanner(spec.domain_file, timeout=spec.timeout_s)


def overlap(plan: tuple[TimedStep, ...], domain_file: str | Path) -> str | None:
    """Why the one robot cannot run ``plan`` (two steps at once: file, actions, times), or None."""
    latest: TimedStep | None = None
    for step in plan:
        if latest is not None and step.start < latest.end - OVERLAP_S and step.duration > 0:
            return (f"{domain_file}: the plan needs the one robot to do two things at once: ({' '.join(latest.step)}) "
                    f"from {float(latest.start):g} s to {float(latest.end):g} s and ({' '.join(step.step)}) from "
                    f"{float(step.start):g} s to {float(step.end):g} s (a robot runs one skill at a time)")
        if step.duration > 0 and (latest is None or step.end > latest.end):
            latest = step
    return None


class FolderPlanner:
    """What a temporal task folder plans with: the :class:`~planners.planner.Planner` interface
    (``name``, ``solve(PddlText, timeout) -> PlanResult``) over the temporal engines.

    A solved result's ``plan`` is the steps in start-time order and its ``cost`` the makespan;
    a failure's ``message`` says what each engine did.  Answers are kept by text (an LRU of
    :data:`CACHED`); errors and time-outs are not.  Thread-safe.
    """

    def __init__(self, domain_file: str | Path, engines: tuple[str, ...] | None = None,
                 timeout: float | None = 10.0) -> None:
        from planners.temporal.portfolio import TemporalPlanner

        self.domain_file = Path(domain_file)
        self._planner = TemporalPlanner(engines, timeout=timeout)
        self.timeout = timeout
        self._cache: OrderedDict[tuple[str, str], PlanResult] = OrderedDict()
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    @property
    def name(self) -> str:
        return self._planner.name

    def solve(self, text: PddlText, timeout: float | None = None) -> PlanResult:
        key = (text.domain, text.problem)
        with self._lock:
            known = self._cache.get(key)
            if known is not None:
                self._cache.move_to_end(key)
                self.hits += 1
        if known is not None:
            return dataclasses.replace(known, wall_time_s=0.0, cached=True)
        start = time.perf_counter()
        try:
            problem = parse(text.domain, text.problem, self.domain_file, f"{self.domain_file.parent}/<problem>")
        except PddlError as exc:
            return PlanResult(PlanStatus.ERROR, None, None, self.name, time.perf_counter() - start, message=str(exc),
                              failure=Failure.INPUT)
        result = self._planner.solve(problem, self.timeout if timeout is None else timeout,
                                     accept=lambda plan: overlap(plan, self.domain_file)).to_plan_result()
        if result.status in (PlanStatus.SOLVED, PlanStatus.UNSOLVABLE):
            with self._lock:
                self.misses += 1
                self._cache[key] = result
                while len(self._cache) > CACHED:
                    self._cache.popitem(last=False)
        return result


__all__ = ["DefinitionError", "FolderPlanner", "TemporalDomainModel", "check_durations", "domain_model",
           "load_domain", "load_problem_text", "overlap", "planner_for"]
