"""``lookahead-cpsat``: the look-ahead's problem solved by OR-Tools CP-SAT (planners.cpsat)."""

from __future__ import annotations

import math
import random

import pytest

from planners.cpsat import LookAheadCpSat, solve_cpsat
from tasker import schedulers
from tasker.errors import ConfigError
from tasker.schedulers.lookahead import Problem, solve


def random_problem(n: int, seed: int, *, has_exe: bool = True) -> Problem:
    """Jobs at random points of a 10 x 8 m flat, sequence-dependent by travel at 0.5 m/s;
    some deadlines already passed, some hazard budgets."""
    rng = random.Random(seed)
    sites = [(rng.uniform(0, 10), rng.uniform(0, 8)) for _ in range(n)]
    work = [rng.uniform(20, 200) for _ in range(n)]
    first = [work[j] + math.dist((5.0, 4.0), sites[j]) / 0.5 for j in range(n)]
    after = [[0.0 if i == j else work[j] + math.dist(sites[i], sites[j]) / 0.5 for j in range(n)] for i in range(n)]
    weight = [rng.choice((0.5, 1.0, 10.0)) for _ in range(n)]
    deadline = [rng.choice((math.inf, rng.uniform(900.0, 1800.0))) for _ in range(n)]
    budget = [rng.choice((math.inf, 300.0)) for _ in range(n)]
    return Problem(1000.0, first, after, weight, deadline, budget, has_exe=has_exe)


@pytest.mark.parametrize("seed", range(8))
def test_cpsat_finds_the_branch_and_bound_optimum(seed: int) -> None:
    p = random_problem(6, seed)
    _, best, _, exact = solve(p, node_budget=10**7)
    assert exact
    order, value, _, optimal = solve_cpsat(p, 5.0)
    assert sorted(order) == list(range(p.n))
    assert value == pytest.approx(p.evaluate(order))
    assert optimal
    # proven optimal for its integer model (times in centiseconds): the same optimum, up to rounding
    assert value <= best * (1 + 1e-4)


def test_first_job_constraints_hold() -> None:
    p = random_problem(5, 3)
    assert solve_cpsat(p, 1.0, fixed_first=2)[0][0] == 2
    assert solve_cpsat(p, 1.0, exclude_first=0)[0][0] != 0
    assert solve_cpsat(p, 1.0, fixed_first=1, exclude_first=1) == ([], math.inf, 0, True)


def test_the_same_problem_gives_the_same_order() -> None:
    p = random_problem(14, 5)  # too long to prove optimal in the limit: anytime, yet reproducible
    assert solve_cpsat(p, 0.05)[:2] == solve_cpsat(p, 0.05)[:2]


def test_an_unreachable_job_goes_last_and_scores_infinite() -> None:
    p = random_problem(4, 1)
    p.first[3] = math.inf
    for row in p.after:
        row[3] = math.inf
    order, value, _, _ = solve_cpsat(p, 1.0)
    assert order[-1] == 3 and value == math.inf


def test_registered_with_the_look_ahead_s_options() -> None:
    s = schedulers.create("lookahead-cpsat", time_limit=0.1, switch_penalty_s=5.0, budgets={"fall": 900.0})
    assert isinstance(s, LookAheadCpSat) and s.switch_penalty_s == 5.0
    assert schedulers.unknown_option("lookahead-cpsat", "tme_limit") is not None
    assert schedulers.unknown_option("lookahead-cpsat", "node_budget") is None
    for bad in (0, -1.0, math.inf, True, "1"):
        with pytest.raises(ConfigError, match="time_limit"):
            LookAheadCpSat(time_limit=bad)  # type: ignore[arg-type]


def test_a_synthetic_day_runs_and_repeats() -> None:
    from experiments.days import pipeline as days

    def trace() -> str:
        run = days.make("tabsa-short", 2, scheduler="lookahead-cpsat").run()
        return "\n".join(map(repr, run.events))

    first = trace()
    assert '"lookahead-cpsat"' in first or "'lookahead-cpsat'" in first
    assert trace() == first
