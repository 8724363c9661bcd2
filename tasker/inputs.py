"""What a schedule-parameter estimate reads, and how its parameters age while that holds.

A waiting agent (``compSP``, ``wait``) reports its schedule parameters at ``repRate``
(eqs. 22, 27).  Most of that work is the estimate — ``cTime`` and ``endPose`` from a plan
or a template, from where the robot is — and between two reports nothing it reads has
usually changed: only the clock moved, and with it the ``cost`` (the harm the task will
have accumulated by the time it completes grows with the wait, ``docs/model.md``).

A task type says what its estimate reads with :meth:`tasker.task.TaskType.estimate_inputs`:
an :class:`EstimateInputs` whose ``key`` is everything ``compute_params`` and
``check_terminate`` read besides the clock and the agent's own context, and whose
``until`` is the first time the clock alone could change the answer of
``check_terminate`` (a cancel time).  While the key is unchanged and ``until`` has not
come, the loop does not step the agent (it is *parked*): its parameters at a later report
are :func:`aged`, the closed form of the cost, computed with the same operations as the
cost model itself, so they are the values a recomputation would give, bit for bit.

The cost model (:class:`~tasker.messages.CostParams`): ``cost = cps * ((now - request time)
+ cTime)``, the float operations in that order (``cps * (ctx.age + c_time)``), or a cost
that does not change (``inf`` for an infeasible task).  A task whose cost is anything else
declares no inputs, and its agent is stepped at every report as before.  Stdlib only.
"""

from __future__ import annotations

import math
from collections.abc import Hashable
from dataclasses import dataclass

from tasker.messages import CostParams, ScheduleParams


@dataclass(frozen=True, slots=True)
class EstimateInputs:
    """What an agent's estimate read besides the clock (:meth:`tasker.task.TaskType.estimate_inputs`).

    ``key``: equal keys mean equal estimates (``cTime``, ``endPose``, the reason of
    ``ic_term``) at any time; it may read the agent's context and whatever the core
    agent's and the world's ``version`` counters cover (the loop looks at the key again
    whenever one of them changes).  ``until``: the first time at which the clock alone
    could make ``check_terminate`` answer otherwise (``inf``: never).
    """

    key: Hashable
    until: float = math.inf

    def __post_init__(self) -> None:
        try:
            hash(self.key)
        except TypeError:
            raise TypeError(f"EstimateInputs.key must be hashable, got a {type(self.key).__name__}") from None
        if not isinstance(self.until, int | float) or self.until != self.until:
            raise TypeError(f"EstimateInputs.until must be a time (a number, inf for never), got {self.until!r}")


@dataclass(frozen=True, slots=True)
class Aging:
    """How a cost grows with the clock: ``cps * ((now - origin) + offset)``, the model's cost
    (``origin`` the request time, ``offset`` the ``cTime``).  :meth:`cost` uses exactly the
    float operations of ``cps * (ctx.age + c_time)``."""

    cps: float
    origin: float
    offset: float

    def cost(self, now: float) -> float:
        return self.cps * ((now - self.origin) + self.offset)

    @property
    def steady(self) -> bool:
        """True when the cost never changes (no growth, or an infinite ``cTime``)."""
        return self.cps == 0 or not math.isfinite(self.offset)


def aging(params: ScheduleParams, request_time: float, now: float) -> Aging | None:
    """How ``params``, computed at ``now`` for a task requested at ``request_time``, age; None
    when their cost does not follow the model's (then they cannot be aged)."""
    if type(params) is not CostParams:
        return None
    form = Aging(params.cps, request_time, params.c_time)
    if not (math.isfinite(form.cps) and form.cps >= 0 and form.offset >= 0):
        return None
    try:
        expected = form.cost(now)
    except (OverflowError, ArithmeticError):
        return None
    if expected != params.cost:
        return None
    return form


def aged(params: CostParams, form: Aging, now: float) -> CostParams:
    """``params`` as ``compute_params`` would give them at ``now`` with the same inputs."""
    if form.steady:
        return params
    return CostParams(params.task_type, cost=form.cost(now), cps=params.cps, c_time=params.c_time,
                      end_pose=params.end_pose, deadline=params.deadline, priority=params.priority)


@dataclass(frozen=True, slots=True)
class Parking:
    """A waiting agent's report and what its estimate read: while the inputs hold, its reports at
    later ticks are ``params`` aged by ``form`` (the loop does not step it)."""

    inputs: EstimateInputs
    form: Aging
    params: CostParams
    at: float

