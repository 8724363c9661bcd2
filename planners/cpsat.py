"""``lookahead-cpsat``: the look-ahead's sequencing problem solved by OR-Tools CP-SAT.

:class:`tasker.schedulers.lookahead.LookAhead` orders the whole queue with a branch and
bound of its own, because ``tasker/`` imports the standard library only.  This scheduler
is the same decision — the same :class:`~tasker.schedulers.lookahead.Problem` (durations
from the tasks' own ``reqSP`` answers, deadlines, hazard budgets), the same two searches
(continue ``exeDA``, or start with another task), the same ``hysteresis`` and the same
``decision`` record — with the search done by CP-SAT, so that the two can be compared on
queues where the branch and bound cannot finish (``benchmarks/bench_lookahead.py``).

The model: one integer completion time per job, a circuit over the jobs and a depot
(``add_circuit``: which job follows which), ``C_j = first_j`` when *j* leaves the depot and
``C_j = C_i + after[i][j]`` when it follows *i*; the objective is the look-ahead's, with
lateness and hazard terms as ``max(0, ·)`` variables.  Times are in centiseconds and
weights in hundredths (the model is integral); the order found is scored with the exact
:meth:`Problem.evaluate <tasker.schedulers.lookahead.Problem.evaluate>`, so records
compare with ``lookahead``'s.  The greedy order is given as a hint.  One search worker and
a limit in CP-SAT's *deterministic* time keep every decision, and so every trace,
reproducible.  A duration the tasks answer as infinite (unreachable) becomes a large
finite one, so that the model stays feasible and avoids it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from tasker.errors import ConfigError
from tasker.schedulers.lookahead import LookAhead, Problem, _greedy

TICKS_PER_S = 100  # centiseconds
WEIGHT_SCALE = 100  # weights (cps) in hundredths


class LookAheadCpSat(LookAhead):
    """:class:`LookAhead` with CP-SAT as its search; ``time_limit`` is the deterministic time
    (CP-SAT's work units, about seconds) each of a decision's searches may take."""

    name = "lookahead-cpsat"

    def __init__(self, time_limit: float = 0.2, node_budget: int = 2000, switch_penalty_s: float = 0.0,
                 lateness_weight: float = 1.0, hazard_weight: float = 1e4, budgets: Mapping[str, float] | None = None,
                 hysteresis: float = 1.0, incremental: bool = True) -> None:
        # the look-ahead's options, spelled out so that a misspelt one is named (tasker.schedulers.options)
        super().__init__(node_budget=node_budget, switch_penalty_s=switch_penalty_s, lateness_weight=lateness_weight,
                         hazard_weight=hazard_weight, budgets=budgets, hysteresis=hysteresis, incremental=incremental)
        if isinstance(time_limit, bool) or not isinstance(time_limit, int | float) \
                or not 0 < time_limit < math.inf:
            raise ConfigError(f"{self.name}: time_limit must be a finite number > 0, got {time_limit!r}")
        self.time_limit = float(time_limit)

    def solve(self, prob: Problem, budget: int, *, fixed_first: int | None = None,
              exclude_first: int | None = None,
              starts: Sequence[Sequence[int]] = ()) -> tuple[list[int], float, int, bool]:
        return solve_cpsat(prob, self.time_limit, fixed_first=fixed_first, exclude_first=exclude_first)


def solve_cpsat(p: Problem, time_limit: float, *, fixed_first: int | None = None,
                exclude_first: int | None = None) -> tuple[list[int], float, int, bool]:
    """Best order by CP-SAT: ``(order, objective, branches, proven optimal)``, as
    :func:`tasker.schedulers.lookahead.solve` returns them."""
    from ortools.sat.python import cp_model

    n = p.n
    allowed = [j for j in range(n) if (fixed_first is None or j == fixed_first) and j != exclude_first]
    if n == 0 or not allowed:
        return [], (0.0 if n == 0 else math.inf), 0, True
    if n == 1:
        return [0], p.evaluate([0]), 0, True
    finite = [x for x in [*p.first, *(v for row in p.after for v in row)] if math.isfinite(x)]
    big = 10 * (sum(finite) + 3600.0)  # an unreachable step: finite, and dearer than any real order

    def ticks(x: float) -> int:
        return round((x if math.isfinite(x) else big) * TICKS_PER_S)

    first = [ticks(x) for x in p.first]
    after = [[ticks(x) for x in row] for row in p.after]
    horizon = sum(max([first[j], *(after[i][j] for i in range(n) if i != j)]) for j in range(n))
    m = cp_model.CpModel()
    done = [m.new_int_var(0, horizon, f"C{j}") for j in range(n)]
    arcs: list[tuple[int, int, Any]] = []
    starts = {}
    for j in range(n):
        lit = m.new_bool_var(f"first{j}")
        starts[j] = lit
        arcs.append((0, j + 1, lit))
        arcs.append((j + 1, 0, m.new_bool_var(f"last{j}")))
        if j in allowed:
            m.add(done[j] == first[j]).only_enforce_if(lit)
        else:
            m.add(lit == 0)
    follows = {}
    for i in range(n):
        for j in range(n):
            if i != j:
                lit = m.new_bool_var(f"x{i}_{j}")
                follows[i, j] = lit
                arcs.append((i + 1, j + 1, lit))
                m.add(done[j] == done[i] + after[i][j]).only_enforce_if(lit)
    m.add_circuit(arcs)
    terms = []
    for j in range(n):
        w = round(p.weight[j] * WEIGHT_SCALE)
        terms.append(w * done[j])
        if math.isfinite(p.deadline[j]):
            due = ticks(p.deadline[j] - p.now)  # negative when the deadline has passed
            late = m.new_int_var(0, horizon + max(0, -due), f"late{j}")
            m.add_max_equality(late, [done[j] - due, 0])
            terms.append(round(p.lateness_weight * w) * late)
            if math.isfinite(p.budget[j]):
                over = m.new_int_var(0, horizon + max(0, -due), f"over{j}")
                m.add_max_equality(over, [done[j] - due - ticks(p.budget[j]), 0])
                terms.append(round(p.hazard_weight * WEIGHT_SCALE) * over)
    m.minimize(sum(terms))
    hint = _greedy(p, allowed)
    for a, b in zip(hint, hint[1:], strict=False):
        m.add_hint(follows[a, b], 1)
    m.add_hint(starts[hint[0]], 1)
    solver = cp_model.CpSolver()
    solver.parameters.num_workers = 1
    solver.parameters.random_seed = 0
    solver.parameters.max_deterministic_time = time_limit
    status = solver.solve(m)
    if status not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        order = hint  # no solution within the limit: the greedy order
    else:
        nxt = {i: j for (i, j), lit in follows.items() if solver.value(lit)}
        order = [next(j for j in range(n) if solver.value(starts[j]))]
        while order[-1] in nxt:
            order.append(nxt[order[-1]])
    return order, p.evaluate(order), int(solver.num_branches), status == cp_model.OPTIMAL
