"""What a schedule algorithm (``pf_schedule``, eq. 35) sees and returns.

A scheduler reads a :class:`ScheduleView` (the report buffers ``B_report``, the
``reqSP`` buffers ``B_reqSP`` as a call, and the harmoniser's roles) and returns a
:class:`Decision`: the agent to put in ``irrDA``, or none, plus an optional record of
the comparison it made (written to the trace as a ``decision`` event).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

from tasker.errors import ConfigError
from tasker.messages import CostParams, ScheduleParams, SPRequest


@dataclass(frozen=True, slots=True)
class Candidate:
    """An agent as a scheduler sees it: identity, type, request order and its latest parameters."""

    id: str
    task_type: str
    params: ScheduleParams
    request_time: float
    order: int


@dataclass(frozen=True, slots=True)
class UnattendedHazard:
    """A hazard that holds now while its agent is out of ``cmd`` (a cooker left on by a
    suspended task): it overruns its budget unless the agent is back in ``cmd`` by
    ``since + budget_s``.  ``since`` is when the unattended stretch began: when the hazard
    went on or when its agent last left ``cmd``, whichever is later
    (:meth:`tasker.securing.HazardWatch.due` counts the same way)."""

    agent: str
    name: str
    budget_s: float
    since: float


@dataclass(frozen=True, slots=True)
class ScheduleView:
    """Read-only input of ``pf_schedule``.

    ``exe`` is the executing agent (``exeDA``) or None; ``candidates`` are the idle
    agents (``D_r``) whose report is initialised, in ``idleDA`` order.  ``req_sp``
    and ``fresh`` ask an agent now; either raises
    :class:`~tasker.errors.AgentEnded` if the agent's hook raised (the harmoniser
    then schedules again without it).

    ``lowest`` is set by a harmoniser that keeps its candidates indexed for an
    :attr:`Scheduler.indexed` scheduler (:mod:`tasker.schedulers.index`): the
    candidate with the lowest :meth:`Scheduler.select_key`, found without a scan.
    Such a scheduler asks for it through :meth:`best` and need not read
    ``candidates`` at all (the harmoniser then passes a sequence built only if read).

    ``suspension`` and ``hazards`` are what a whole-queue scheduler needs of the
    harmoniser beyond the reports (both optional; a unit test's view leaves them out):

    * ``suspension(by)``: seconds ``exe`` needs, from ``now``, to report ``wait`` if it is
      sent ``susp`` now with ``by`` (a candidate's id) as its replacement — what is left
      of its blocking stages and its own suspension plan, for the interruption the
      harmoniser would announce in that ``susp`` (``expected_s``); ``inf`` if it cannot
      be planned.  May raise :class:`~tasker.errors.AgentEnded` like ``req_sp``;
    * ``hazards``: the hazards that hold now and are unattended (:class:`UnattendedHazard`).

    ``generation`` (None: not kept) changes whenever ``candidates`` may have: an agent became or
    stopped being idle, or an idle one reported (a cost aging while its agent is parked,
    :mod:`tasker.parking`, is no report).  A scheduler may keep what it derived from the
    candidates while it is unchanged.
    """

    now: float
    exe: Candidate | None
    candidates: Sequence[Candidate]
    req_sp: Callable[[str, SPRequest], Any]
    fresh: Callable[[str], ScheduleParams | None] | None = None
    lowest: Candidate | None = None
    suspension: Callable[[str], float] | None = None
    hazards: Sequence[UnattendedHazard] = ()
    generation: int | None = None

    def best(self, key: Callable[[Candidate], Any]) -> Candidate | None:
        """The candidate with the lowest ``key`` (None if there is none).

        ``key`` must be the scheduler's :meth:`Scheduler.select_key`: when the
        harmoniser has found that candidate already (:attr:`lowest`), it is returned
        in O(1); otherwise the candidates are scanned, the first lowest winning.
        """
        if self.lowest is not None:
            return self.lowest
        return min(self.candidates, key=key, default=None)

    def params_now(self, c: Candidate) -> ScheduleParams:
        """``c``'s parameters computed by its agent at :attr:`now` (``compute_params``).

        Reports arrive at each agent's own rate, so two candidates' reports may be
        from different ticks; a scheduler that compares two agents asks both for
        parameters of this moment.  Without ``fresh`` (a unit test's view) or when
        the task type has none, the reported parameters are returned.
        """
        if self.fresh is None:
            return c.params
        params = self.fresh(c.id)
        return c.params if params is None else params


@dataclass(frozen=True, slots=True)
class Decision:
    """Output of ``pf_schedule``: the new ``irrDA`` (or None) and what was compared."""

    irr_da: str | None = None
    record: Mapping[str, Any] | None = None


NO_CHANGE = Decision()


class Scheduler:
    """Base of schedule algorithms.  Subclasses set :attr:`name` and implement :meth:`schedule`.

    ``preemptive`` schedulers may pick a candidate while an agent executes (IT);
    a non-preemptive one is only consulted when no agent executes.
    """

    name: ClassVar[str] = ""
    preemptive: ClassVar[bool] = True
    work_conserving: ClassVar[bool] = True
    """False for a scheduler that may leave the robot idle while candidates wait (a
    time-table one: a task waits for its slot)."""
    SWEEP: ClassVar[Mapping[str, tuple[Any, ...]]] = {}
    """Option values an experiment sweeps, as the algorithm's authors swept them (empty: none)."""
    indexed: ClassVar[bool] = False
    reads_harmoniser: ClassVar[bool] = False

    reads_cost: ClassVar[bool] = True
    """False for a scheduler whose :meth:`schedule` never reads a waiting candidate's ``cost``: the
    harmoniser then hands it the candidates as last reported, without aging the cost of those
    whose agent is parked (:mod:`tasker.parking`), which would cost a new candidate per tick."""
    key_cost: ClassVar[bool | None] = None
    """How :meth:`select_key` reads a candidate's ``cost``, for the harmoniser's index of the candidates
    whose cost ages while their agent is parked (:mod:`tasker.parking`): False, never; True, the key is
    ``(*key_prefix(c), cost, c.order)``; None (not said): such a candidate is keyed anew at every decision."""

    def key_prefix(self, c: Candidate) -> tuple[Any, ...]:
        """What :meth:`select_key` puts before the cost, when :attr:`key_cost` is True."""
        return tuple(self.select_key(c)[:-2])

    def outranks(self, a: Candidate, b: Candidate) -> bool:
        """Whether ``a``'s priority class is above ``b``'s, in this scheduler's own terms (hazard-aware
        waiting never preempts a task that outranks the one that would secure, unless the scenario
        allows it).  Default: the scheduler has no classes, so nobody outranks anybody."""
        return False
    """True for a scheduler that reads :attr:`ScheduleView.suspension` and :attr:`ScheduleView.hazards`:
    the harmoniser fills them only for such a one (they cost a suspension estimate per candidate)."""
    """True when :meth:`schedule` picks its candidate as the lowest :meth:`select_key`
    (through :meth:`ScheduleView.best`) and reads nothing else of the other candidates:
    the harmoniser then keeps the candidates in a heap updated on each report, and a
    decision costs O(log n) instead of a scan of every waiting agent
    (:mod:`tasker.schedulers.index`)."""

    def schedule(self, view: ScheduleView) -> Decision:
        raise NotImplementedError

    def queue_key(self, c: Candidate) -> tuple[Any, ...]:
        """Where ``c`` stands in this scheduler's queue: lower runs first.

        The harmoniser uses it to estimate how long a suspended task will wait (the
        ``expected_s`` of ``susp``): the tasks ranked ahead of it run before it
        resumes.  Default: request order.
        """
        return (c.order,)

    def select_key(self, c: Candidate) -> tuple[Any, ...]:
        """The key an :attr:`indexed` scheduler minimises over the candidates.

        A pure function of ``c`` (its type, reported parameters and request order)
        and of the scheduler's fixed configuration, never of the time or of other
        agents; unique per candidate (end it with ``c.order``) so that the lowest one
        does not depend on the order candidates are scanned in.  Keys made only of
        real numbers are indexed; any other key (or one that raises) makes the
        harmoniser scan, so errors surface in :meth:`schedule` as they would unindexed.
        """
        return self.queue_key(c)

    def preempt_when_better(self, view: ScheduleView, field: str, value: Callable[[Candidate], Any],
                            higher: bool = False) -> Decision:
        """The rule of the single-key preemptive baselines: the best candidate (lowest
        :meth:`select_key`) starts when nothing executes, and preempts the executing agent
        when its ``value`` is strictly better — lower, or with ``higher`` higher.  The
        decision records both values as ``{field}_dac`` and ``{field}_exeDA``."""
        best = view.best(self.select_key)
        if best is None:
            return NO_CHANGE
        if view.exe is None:
            return Decision(best.id)
        v_dac, v_exe = value(best), value(view.exe)
        switch = v_dac > v_exe if higher else v_dac < v_exe
        record = {"algorithm": self.name, "dac": best.id, "exeDA": view.exe.id,
                  f"{field}_dac": v_dac, f"{field}_exeDA": v_exe, "switch": switch}
        return Decision(best.id if switch else None, record)

    @staticmethod
    def cost_params(c: Candidate, algorithm: str) -> CostParams:
        if not isinstance(c.params, CostParams):
            raise ConfigError(
                f"scheduler {algorithm!r} needs CostParams from task type {c.task_type!r} "
                f"(agent {c.id}), got {type(c.params).__name__}"
            )
        return c.params


@dataclass(frozen=True, slots=True)
class Options:
    """Scheduler options read from configuration, checked for unknown keys."""

    values: Mapping[str, Any] = field(default_factory=dict)

    def take(self, allowed: set[str], algorithm: str) -> dict[str, Any]:
        unknown = sorted(set(self.values) - allowed)
        if unknown:
            raise ConfigError(f"scheduler {algorithm!r}: unknown option(s) {unknown}; allowed: {sorted(allowed)}")
        return dict(self.values)
