"""A look-ahead scheduler: orders the whole queue, not a pair.

Each decision solves a single-machine sequencing problem over the executing task
(``exeDA``) and every candidate, and starts the first task of the best order:

* **durations are sequence-dependent**: task *j* started after task *i* lasts
  ``d(i, j) = cTime_j + (cc_j(endPose_i) - cost_j) / cps_j`` — the task's own
  ``reqSP`` answer for a start at *i*'s end pose, turned back into seconds (``cc`` and
  ``cost`` differ only by the cps-weighted extra time).  For the executing task asked
  from another pose, that answer is what resuming it costs (travel back, the resume
  stages, planning): the switch cost comes from the task's own plans and motion;
* **preempting** ``exeDA`` puts its suspension before the first task — the seconds the
  executing task's own suspension plan takes (what is left of its blocking stages, then
  its ``exeSusp``), from ``ScheduleView.suspension`` when the harmoniser gives it, else
  the constant ``switch_penalty_s`` — and makes ``exeDA`` a later job resumed from its
  predecessor's end pose (travel back and resume stages: its ``reqSP`` answer, above);
* the **objective** of an order with start times ``S_j`` and completion times ``C_j`` is

      sum_j  cps_j * (C_j - now)                                (cost: harm grows with delay)
           + lateness_weight * cps_j * max(0, C_j - deadline_j)  (deadlines)
           + hazard_weight * max(0, C_j - deadline_j - budget_j) (hazard budgets, per task type:
                                                                  a fall's death time)
           + hazard_weight * sum_h max(0, S_j - since_h - budget_h) (hazards left on: a cooker
                                      left on by suspended task j, from ``ScheduleView.hazards``)

* the **search** starts from a greedy order improved by insertion moves, then runs a
  depth-first branch and bound over orders, children tried best first, pruned by the
  lower bound ``C_j >= t + min_i d(i, j)`` for every job not yet placed.  It is exact
  when it ends within ``node_budget`` (moves evaluated + nodes expanded), and anytime
  otherwise: then a second pass improves Smith's order (shortest duration per cost rate
  first) by insertion moves, with as much budget again, and the better order wins — on
  long queues the greedy start is far from the best order and the branch and bound runs
  out long before it gets near one.  The budget counts work, never wall time, so traces
  are reproducible.

Between decisions (``incremental``): when the problem differs from the last one only in the
clock, ``exeDA``'s progress, the switch penalties and (while ``exeDA`` executes) the waiting
jobs' durations as the first (:meth:`LookAhead.signature`), the last orders are priced again
instead of searched (rule ``incremental``): the order that continues ``exeDA`` keeps every
completion where it was, and the switching orders are the last one and each waiting job moved
to its front, with the penalties and first durations of now.  Otherwise the last orders,
adapted (:func:`adapt`), join the search as incumbents.  A waiting job's duration after
another waiting job is kept while ``ScheduleView.generation`` holds, when the task answers in
seconds (``CompletionCost.c_time``).

A rolling horizon (``horizon`` h > 0; 0, the default, orders the whole queue): a decision orders the
executing task and at most h waiting jobs (:meth:`LookAhead.window`: the half whose lateness would start
first, then Smith's order); the others wait beyond it, out of the problem, and the record says how many
(``beyond``).

The executing task keeps the robot unless the best order that starts with another
task beats the best order that continues it by the factor ``hysteresis``.
Every decision leaves a ``decision`` record: ``rule`` (``exact``, ``anytime`` or ``incremental``),
``order``, ``objective``, ``objective_continue``, ``nodes``; ``suspend_s`` (each
candidate's plan-based switch penalty) when the view gives suspension estimates, and
``left_on`` (agent, hazard, due) when hazards are left on; ``beyond`` when a horizon left jobs out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from tasker.errors import ConfigError
from tasker.messages import SP_COMPLETION, CompletionCost, CostParams, SPRequest
from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView


class Problem:
    """The sequencing instance of one decision.  Job 0 is ``exeDA`` when ``has_exe``.

    ``first[j]`` is job *j*'s duration when it goes first, ``after[i][j]`` when it follows
    job *i*; ``weight``, ``deadline``, ``budget`` per job; ``now`` the clock.  ``left_on[j]``
    (optional): for each hazard job *j* left unattended, the time by which *j* must be
    running again (``since + budget``); every second it starts later costs ``hazard_weight``.
    """

    def __init__(self, now: float, first: Sequence[float], after: Sequence[Sequence[float]],
                 weight: Sequence[float], deadline: Sequence[float], budget: Sequence[float], *,
                 has_exe: bool = False, lateness_weight: float = 1.0, hazard_weight: float = 1e4,
                 left_on: Sequence[Sequence[float]] | None = None) -> None:
        n = len(first)
        self.n, self.now, self.has_exe = n, now, has_exe
        self.first, self.after = list(first), [list(r) for r in after]
        self.weight, self.deadline, self.budget = list(weight), list(deadline), list(budget)
        self.lateness_weight, self.hazard_weight = lateness_weight, hazard_weight
        self.left_on = [tuple(x) for x in left_on] if left_on is not None else [()] * n
        self.hazards_left_on = any(self.left_on)  # without any, the search skips the term (its hot loop)
        # every term grows with the time it is taken at: an order no earlier and no cheaper than another at some
        # position, with the same jobs after it in the same order, is no better (used to drop moves early)
        self.monotone = all(w >= 0 for w in self.weight) and lateness_weight >= 0 and hazard_weight >= 0
        self.dmin = [min([self.first[j], *(self.after[i][j] for i in range(n) if i != j)]) for j in range(n)]

    def cost(self, j: int, c: float) -> float:
        """Objective term of job ``j`` completing at absolute time ``c``."""
        w = self.weight[j]
        late = c - self.deadline[j]
        out = w * (c - self.now)
        if late > 0:
            out += self.lateness_weight * w * late
            if late > self.budget[j]:
                out += self.hazard_weight * (late - self.budget[j])
        return out

    def wait_cost(self, j: int, s: float) -> float:
        """Objective term of job ``j`` starting at ``s``: its hazards' overruns (0 without hazards)."""
        due = self.left_on[j]
        return self.hazard_weight * sum(s - d for d in due if s > d) if due else 0.0

    def evaluate(self, order: Sequence[int]) -> float:
        return self.evaluate_from(order, 0, (self.now, 0.0, -1))

    def prefixes(self, order: Sequence[int]) -> list[tuple[float, float, int]]:
        """``(t, total, prev)`` of :meth:`evaluate` before each position of ``order`` (and after the last)."""
        t, total, prev = self.now, 0.0, -1
        out = [(t, total, prev)]
        for j in order:
            if self.hazards_left_on:
                total += self.wait_cost(j, t)
            t += self.first[j] if prev < 0 else self.after[prev][j]
            total += self.cost(j, t)
            prev = j
            out.append((t, total, prev))
        return out

    def evaluate_from(self, order: Sequence[int], m: int, state: tuple[float, float, int]) -> float:
        """:meth:`evaluate` of ``order`` from position ``m``, ``state`` being its ``(t, total, prev)`` there:
        the same operations in the same order, so the same float as evaluating it whole."""
        return self._run(order, m, len(order), state)[1]

    def evaluate_unless(self, order: Sequence[int], m: int, state: tuple[float, float, int], stop: int,
                        other: tuple[float, float, int]) -> float:
        """:meth:`evaluate_from`, or ``inf`` when the order cannot be better than another order whose state
        before position ``stop`` is ``other`` and whose jobs from ``stop - 1`` on are this one's: there this
        order is no earlier and no cheaper, and every later term can only grow with the time (:attr:`monotone`;
        IEEE sums and products by weights >= 0 keep that order).  The value when not ``inf`` is
        :meth:`evaluate_from`'s."""
        n = len(order)
        if not self.monotone or not m < stop < n:
            return self._run(order, m, n, state)[1]
        state = self._run(order, m, stop, state)
        if state[0] >= other[0] and state[1] >= other[1]:
            return math.inf
        return self._run(order, stop, n, state)[1]

    def _run(self, order: Sequence[int], m: int, end: int,
             state: tuple[float, float, int]) -> tuple[float, float, int]:
        """The state ``(t, total, prev)`` before position ``end`` of ``order``, from ``state`` before ``m``."""
        t, total, prev = state
        first, after, now, hazards = self.first, self.after, self.now, self.hazards_left_on
        weight, deadline, budget = self.weight, self.deadline, self.budget
        lw, hw = self.lateness_weight, self.hazard_weight
        for k in range(m, end):
            j = order[k]
            if hazards:
                total += self.wait_cost(j, t)
            t += first[j] if prev < 0 else after[prev][j]
            w = weight[j]  # Problem.cost, inlined
            late = t - deadline[j]
            out = w * (t - now)
            if late > 0:
                out += lw * w * late
                if late > budget[j]:
                    out += hw * (late - budget[j])
            total += out
            prev = j
        return t, total, prev


def _greedy(p: Problem, allowed_first: list[int]) -> list[int]:
    """Each step, the job whose completion now costs least above its earliest possible one."""
    order: list[int] = []
    left = set(range(p.n))
    t, prev = p.now, -1
    while left:
        pool = allowed_first if prev < 0 else sorted(left)
        best = min(pool, key=lambda j: (p.cost(j, t + (p.first[j] if prev < 0 else p.after[prev][j]))
                                        - p.cost(j, t + p.dmin[j]), j))
        t += p.first[best] if prev < 0 else p.after[prev][best]
        order.append(best)
        left.discard(best)
        prev = best
    return order


def _improve(p: Problem, order: list[int], allowed_first: set[int], budget: int) -> tuple[list[int], float, int]:
    """Insertion local search (move one job elsewhere; first improvement) within ``budget`` evaluations."""
    best = p.evaluate(order)
    used = 0
    improved = True
    while improved:
        improved = False
        prefix = p.prefixes(order)  # a move changes the order from min(i, k) on: evaluated from there
        for i in range(p.n):
            for k in range(p.n):
                if i == k:
                    continue
                cand = order[:i] + order[i + 1:]
                cand.insert(k, order[i])
                if cand[0] not in allowed_first:
                    continue
                if used >= budget:
                    return order, best, used
                used += 1
                m, stop = min(i, k), max(i, k) + 2  # from stop on, cand's jobs (and the one before) are order's
                v = p.evaluate_unless(cand, m, prefix[m], stop, prefix[min(stop, p.n)])  # stop >= n: evaluated whole
                if v < best - 1e-9 * max(1.0, abs(best)):
                    order, best, improved = cand, v, True
                    break
            if improved:
                break
    return order, best, used


def solve(p: Problem, *, node_budget: int, fixed_first: int | None = None,
          exclude_first: int | None = None,
          starts: Sequence[Sequence[int]] = ()) -> tuple[list[int], float, int, bool]:
    """Best order: ``(order, objective, nodes expanded, exact)``.

    A greedy order, improved by insertion moves with up to half the budget, is the
    incumbent of a depth-first branch and bound that uses the rest; ``exact`` is true
    when that search ended on its own.  When it did not, :func:`_smith`'s order improved
    by insertion moves (up to ``node_budget`` more) replaces the result if it is better.
    Every evaluated move and every expanded node counts against ``node_budget``.  ``fixed_first`` forces the first job;
    ``exclude_first`` forbids one as first.  ``starts`` are other orders of all the jobs (the last decision's,
    :func:`adapt`): the best of them becomes the incumbent if it beats the improved greedy order (each costs ``n``).
    """
    n = p.n
    allowed = [j for j in range(n) if (fixed_first is None or j == fixed_first) and j != exclude_first]
    if n == 0 or not allowed:
        return [], (0.0 if n == 0 else math.inf), 0, True
    best_order, best, nodes = _improve(p, _greedy(p, allowed), set(allowed), node_budget // 2)
    nodes += n
    for start in starts:  # the last decision's orders: a warm incumbent, so the bound prunes from the start
        if len(start) == n and start[0] in allowed:
            nodes += n
            value = p.evaluate(start)
            if value < best - 1e-9 * max(1.0, abs(best)):
                best_order, best = list(start), value
    exhausted = False
    order: list[int] = []
    placed = [False] * n

    def bound(t: float, acc: float) -> float:
        if p.hazards_left_on:
            return acc + sum(p.cost(j, t + p.dmin[j]) + p.wait_cost(j, t) for j in range(n) if not placed[j])
        return acc + sum(p.cost(j, t + p.dmin[j]) for j in range(n) if not placed[j])

    def dfs(prev: int, t: float, acc: float) -> None:
        nonlocal best, best_order, nodes, exhausted
        if len(order) == n:
            if acc < best:
                best, best_order = acc, list(order)
            return
        children = []
        for j in (allowed if prev < 0 else range(n)):
            if placed[j]:
                continue
            c = t + (p.first[j] if prev < 0 else p.after[prev][j])
            children.append((p.cost(j, c) - p.cost(j, t + p.dmin[j]), c, j))
        children.sort()
        for _, c, j in children:
            if nodes >= node_budget:
                exhausted = True
                return
            nodes += 1
            acc_j = acc + p.cost(j, c) + (p.wait_cost(j, t) if p.hazards_left_on else 0.0)
            placed[j] = True
            order.append(j)
            if bound(c, acc_j) < best:
                dfs(j, c, acc_j)
            order.pop()
            placed[j] = False
            if exhausted:
                return

    dfs(-1, p.now, 0.0)
    if exhausted:  # not proven optimal: a second pass from Smith's order, with as much budget again
        order2, value2, used = _improve(p, _smith(p, allowed), set(allowed), node_budget)
        nodes += used
        if value2 < best - 1e-9 * max(1.0, abs(best)):
            best_order, best = order2, value2
    return best_order, best, nodes, not exhausted


def _smith(p: Problem, allowed_first: list[int]) -> list[int]:
    """Smith's rule: shortest (fastest possible) duration per unit of cost rate first — the
    optimal order of ``sum cps_j C_j`` without travel or deadlines, and a strong start with
    them (``benchmarks/bench_lookahead.py``, part 3).  The first job is one allowed first."""
    def key(j: int) -> tuple[float, int]:
        return (p.dmin[j] / p.weight[j] if p.weight[j] > 0 else math.inf, j)

    first = min(allowed_first, key=key)
    return [first, *sorted((j for j in range(p.n) if j != first), key=key)]


def _hashable(value: Any) -> bool:
    try:
        hash(value)
    except TypeError:
        return False
    return True


def adapt(p: Problem, ids: Sequence[str], last: Sequence[str], *, fixed_first: int | None = None,
          exclude_first: int | None = None) -> list[int]:
    """The order ``last`` (agent ids of an earlier decision) over this problem's jobs ``ids``: the jobs it has,
    in its order, then the new ones in Smith's order; ``fixed_first`` moved to the front, ``exclude_first``
    moved to second place.  Empty when no such order exists."""
    at = {x: k for k, x in enumerate(ids)}
    order = [at[x] for x in last if x in at]
    kept = set(order)
    order += sorted((j for j in range(p.n) if j not in kept),
                    key=lambda j: (p.dmin[j] / p.weight[j] if p.weight[j] > 0 else math.inf, j))
    if fixed_first is not None:
        order.remove(fixed_first)
        order.insert(0, fixed_first)
    if exclude_first is not None and order and order[0] == exclude_first:
        if len(order) < 2:
            return []
        order[0], order[1] = order[1], order[0]
    return order


class LookAhead(Scheduler):
    """Whole-queue sequencing by branch and bound within a node budget; see the module docstring."""

    name = "lookahead"
    preemptive = True
    reads_harmoniser = True

    def __init__(self, node_budget: int = 2000, switch_penalty_s: float = 0.0, lateness_weight: float = 1.0,
                 hazard_weight: float = 1e4, budgets: Mapping[str, float] | None = None,
                 hysteresis: float = 1.0, incremental: bool = True, horizon: int = 0) -> None:
        if isinstance(node_budget, bool) or not isinstance(node_budget, int) or node_budget < 1:
            raise ConfigError(f"lookahead: node_budget must be an integer >= 1, got {node_budget!r}")
        for key, value in (("switch_penalty_s", switch_penalty_s), ("lateness_weight", lateness_weight),
                           ("hazard_weight", hazard_weight)):
            if isinstance(value, bool) or not isinstance(value, int | float) or not value >= 0 or value == math.inf:
                raise ConfigError(f"lookahead: {key} must be a finite number >= 0, got {value!r}")
        if not isinstance(hysteresis, int | float) or not 0 < hysteresis <= 1:
            raise ConfigError(f"lookahead: hysteresis must be in (0, 1], got {hysteresis!r}")
        self.node_budget = node_budget
        self.switch_penalty_s = float(switch_penalty_s)
        self.lateness_weight = float(lateness_weight)
        self.hazard_weight = float(hazard_weight)
        if budgets is not None and not isinstance(budgets, Mapping):
            raise ConfigError(f"lookahead: budgets must be a table of task type = seconds, got {budgets!r}")
        for key, value in (budgets or {}).items():
            if isinstance(value, bool) or not isinstance(value, int | float) or not 0 <= value < math.inf:
                raise ConfigError(f"lookahead: budgets[{key!r}] must be a finite number of seconds >= 0, "
                                  f"got {value!r}")
        self.budgets = {str(k): float(v) for k, v in (budgets or {}).items()}
        self.hysteresis = float(hysteresis)
        if not isinstance(incremental, bool):
            raise ConfigError(f"lookahead: incremental must be true or false, got {incremental!r}")
        self.incremental = incremental
        if isinstance(horizon, bool) or not isinstance(horizon, int) or horizon < 0:
            raise ConfigError(f"lookahead: horizon must be an integer >= 0 (0: the whole queue), got {horizon!r}")
        self.horizon = horizon
        self._penalty: dict[str, float] = {}  # the last problem's switch penalty per candidate
        # what one decision leaves the next (incremental search, module docstring):
        self._generation: int | None = None  # ScheduleView.generation the kept durations belong to
        self._durations: dict[tuple[str, str, Any], float] = {}  # (job, after, pose) -> seconds, idle jobs only
        self._last: tuple[Any, list[str], list[str]] | None = None  # (signature, chosen order, other order)

    def _duration(self, view: ScheduleView, c: Candidate, p: CostParams, pose: Any, after: str,
                  keep: bool = False) -> float:
        """Seconds ``c`` takes if started at ``pose`` once ``after`` is complete: its reqSP
        answer's ``c_time``, or the answer back in seconds when the task gives none.  ``keep``:
        ``c`` is idle and the answer may be kept while :attr:`ScheduleView.generation` holds (an
        answer in seconds is; one recovered from two costs depends on when it was asked).
        :meth:`problem` reads the kept answers."""
        if pose is None or p.cps == 0:
            return p.c_time
        answer = view.req_sp(c.id, SPRequest(SP_COMPLETION, {"pose": pose, "after": after}))
        if not isinstance(answer, CompletionCost):
            raise ConfigError(f"lookahead: task type {c.task_type!r} answered reqSP {SP_COMPLETION!r} with "
                              f"{type(answer).__name__}, expected CompletionCost")
        if answer.c_time is not None:
            if isinstance(answer.c_time, bool) or not isinstance(answer.c_time, int | float):
                raise ConfigError(f"lookahead: task type {c.task_type!r} answered reqSP {SP_COMPLETION!r} with "
                                  f"c_time {answer.c_time!r}, expected seconds (a number) or None")
            d = float(answer.c_time)
            d = max(0.0, d) if math.isfinite(d) else math.inf
            if keep:
                self._durations[c.id, after, pose] = d
            return d
        extra = (answer.cc - p.cost) / p.cps
        return max(0.0, p.c_time + extra) if math.isfinite(extra) else math.inf

    def switch_penalty(self, view: ScheduleView, c: Candidate) -> float:
        """Seconds before ``c`` can start if it preempts ``exeDA`` now: the executing task's own
        suspension estimate when the view has one (``ScheduleView.suspension``), else
        ``switch_penalty_s``.  Travel and the resumption are in ``exeDA``'s ``reqSP`` answers."""
        if view.suspension is None:
            return self.switch_penalty_s
        s = float(view.suspension(c.id))
        if s != s or s < 0:
            raise ConfigError(f"lookahead: the suspension estimate of {view.exe.id if view.exe else None} "
                              f"for {c.id} is {s!r}, expected seconds >= 0")
        return s

    def problem(self, view: ScheduleView) -> tuple[Problem, list[Candidate]]:
        jobs = ([view.exe] if view.exe is not None else []) + list(view.candidates)
        params = [self.cost_params(c, self.name) for c in jobs]
        has_exe = view.exe is not None
        self._penalty = {c.id: self.switch_penalty(view, c) for c in jobs[1:]} if has_exe else {}
        first = [p.c_time + (self._penalty[jobs[k].id] if has_exe and k > 0 else 0.0) for k, p in enumerate(params)]
        if view.generation is None or view.generation != self._generation:  # an idle agent's estimate may differ
            self._durations.clear()
            self._generation = view.generation
        # an entry between two idle jobs holds with the generation (kept by pose: poses that are values)
        idle = view.generation is not None and all(_hashable(p.end_pose) for p in params)
        kept, n = self._durations, len(jobs)
        after = [[0.0 if i == j else d
                  if idle and (d := kept.get((jobs[j].id, jobs[i].id, params[i].end_pose))) is not None
                  else self._duration(view, jobs[j], params[j], params[i].end_pose, jobs[i].id,
                                      keep=idle and (not has_exe or (i > 0 and j > 0)))
                  for j in range(n)] for i in range(n)]
        deadline = [math.inf if p.deadline is None else p.deadline for p in params]
        budget = [self.budgets.get(c.task_type, math.inf) for c in jobs]
        at = {c.id: k for k, c in enumerate(jobs)}
        left_on: list[list[float]] = [[] for _ in jobs]
        for hz in view.hazards:  # a hazard left on: its agent must be back in cmd by since + budget
            k = at.get(hz.agent)
            if k is not None and math.isfinite(hz.since + hz.budget_s):
                left_on[k].append(hz.since + hz.budget_s)
        return Problem(view.now, first, after, [p.cps for p in params], deadline, budget, has_exe=has_exe,
                       lateness_weight=self.lateness_weight, hazard_weight=self.hazard_weight,
                       left_on=left_on), jobs

    def solve(self, prob: Problem, budget: int, *, fixed_first: int | None = None,
              exclude_first: int | None = None,
              starts: Sequence[Sequence[int]] = ()) -> tuple[list[int], float, int, bool]:
        """The search one decision runs (:func:`solve`); a subclass may put another solver
        behind the same problem, budget split and record (``planners.cpsat``)."""
        return solve(prob, node_budget=budget, fixed_first=fixed_first, exclude_first=exclude_first, starts=starts)

    @staticmethod
    def signature(prob: Problem, jobs: Sequence[Candidate]) -> tuple[Any, ...]:
        """What the value of an order depends on beyond what an incremental decision prices anew: the jobs,
        the durations after each job (but a resumed ``exeDA``'s), weights, deadlines, budgets and hazards —
        and, when nothing executes, each job's duration as the first.  While ``exeDA`` executes, a waiting
        job's duration as the first (from the robot's pose, with the switch penalty) matters to the switching
        orders only, and an incremental decision prices those with the durations of now."""
        k = 1 if prob.has_exe else 0
        own = () if prob.has_exe else tuple(prob.first)
        return (prob.has_exe, tuple(c.id for c in jobs), own,
                tuple(prob.weight), tuple(prob.deadline), tuple(prob.budget), tuple(prob.left_on),
                tuple(tuple(row[k:]) for row in prob.after))

    def window(self, view: ScheduleView) -> tuple[ScheduleView, int]:
        """The view a decision orders and how many waiting jobs it leaves beyond it.  With ``horizon`` h > 0 and
        more than h candidates, the view keeps h of them (a rolling horizon): the half (rounded up) whose
        lateness would start first — the earliest of deadline plus hazard budget and of a hazard left on's due
        — then the rest in Smith's order on their own durations (``cTime / cps``), each rule taken in request
        order on ties.  The others wait beyond the horizon, out of this decision's problem."""
        if not self.horizon or len(view.candidates) <= self.horizon:
            return view, 0
        cands = list(view.candidates)
        params = {c.id: self.cost_params(c, self.name) for c in cands}
        due: dict[str, float] = {}
        for hz in view.hazards:
            if math.isfinite(hz.since + hz.budget_s):
                due[hz.agent] = min(due.get(hz.agent, math.inf), hz.since + hz.budget_s)

        def urgent(c: Candidate) -> tuple[float, int, str]:
            p = params[c.id]
            late = math.inf if p.deadline is None else p.deadline + self.budgets.get(c.task_type, 0.0)
            return (min(late, due.get(c.id, math.inf)), c.order, c.id)

        def smith(c: Candidate) -> tuple[float, int, str]:
            p = params[c.id]
            return (p.c_time / p.cps if p.cps > 0 else math.inf, c.order, c.id)

        first = [c for c in sorted(cands, key=urgent)[:(self.horizon + 1) // 2] if math.isfinite(urgent(c)[0])]
        taken = {c.id for c in first}
        rest = [c for c in sorted(cands, key=smith) if c.id not in taken][:self.horizon - len(first)]
        keep = {c.id for c in first + rest}
        return replace(view, candidates=[c for c in cands if c.id in keep]), len(cands) - len(keep)

    def schedule(self, view: ScheduleView) -> Decision:
        if not view.candidates:
            return NO_CHANGE
        view, beyond = self.window(view)
        prob, jobs = self.problem(view)
        ids = [c.id for c in jobs]
        sig = self.signature(prob, jobs) if self.incremental else None
        last = self._last
        at = {x: k for k, x in enumerate(ids)}
        if last is not None and last[0] == sig:  # only the clock and exeDA's progress moved: the last orders, again
            rule = "incremental"
            chosen, other = [at[x] for x in last[1]], [at[x] for x in last[2]]
            nodes, exact = 2 * prob.n, False
            if view.exe is None:
                order, obj, keep_obj, alt_order = chosen, prob.evaluate(chosen), math.inf, other
            else:  # continuing exeDA: every order shifts alike; switching: re-priced with the penalties of now
                keep, alt = (chosen, other) if chosen[0] == 0 else (other, chosen)
                keep_obj, alt_obj = prob.evaluate(keep), math.inf
                for cand in ([alt] + [[j, *(x for x in alt if x != j)] for j in range(1, prob.n) if j != alt[0]]
                             if alt else []):
                    value = prob.evaluate(cand)
                    nodes += 1
                    if value < alt_obj:
                        alt, alt_obj = cand, value
                switch = alt_obj < self.hysteresis * keep_obj
                order, obj = (alt, alt_obj) if switch else (keep, keep_obj)
                alt_order = keep if switch else alt
        else:
            hints = [list(o) for o in last[1:]] if (self.incremental and last is not None) else []
            if view.exe is None:
                starts = [o for h in hints if (o := adapt(prob, ids, h))]
                order, obj, nodes, exact = self.solve(prob, self.node_budget, starts=starts)
                keep_obj, alt_order = math.inf, []
            else:  # two searches share the budget: continue exeDA, or start with someone else
                half = max(1, self.node_budget // 2)
                starts = [o for h in hints if (o := adapt(prob, ids, h, fixed_first=0))]
                keep, keep_obj, n1, e1 = self.solve(prob, half, fixed_first=0, starts=starts)
                starts = [o for h in hints if (o := adapt(prob, ids, h, exclude_first=0))]
                alt, alt_obj, n2, e2 = self.solve(prob, self.node_budget - n1, exclude_first=0, starts=starts)
                nodes, exact = n1 + n2, e1 and e2
                switch = alt_obj < self.hysteresis * keep_obj
                order, obj = (alt, alt_obj) if switch else (keep, keep_obj)
                alt_order = keep if switch else alt
            rule = "exact" if exact else "anytime"
        if self.incremental:
            self._last = (sig, [ids[k] for k in order], [ids[k] for k in alt_order])
        first = jobs[order[0]].id
        switch = view.exe is None or first != view.exe.id
        record: dict[str, Any] = {
            "algorithm": self.name, "rule": rule,
            "dac": first if switch else None, "exeDA": view.exe.id if view.exe is not None else None,
            "order": [jobs[k].id for k in order], "objective": obj, "objective_continue": keep_obj,
            "nodes": nodes, "switch": switch,
        }
        if view.exe is not None and view.suspension is not None:  # the plan-based switch penalty
            record["suspend_s"] = {c.id: self._penalty[c.id] for c in view.candidates}
        if beyond:
            record["beyond"] = beyond
        if prob.hazards_left_on:
            record["left_on"] = [{"agent": hz.agent, "hazard": hz.name, "due": hz.since + hz.budget_s}
                                 for hz in view.hazards if hz.agent in {c.id for c in jobs}]
        return Decision(first if switch else None, record)
