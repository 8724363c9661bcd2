"""The look-ahead scheduler: its search is exact on small queues, anytime within a node budget on long ones."""

from __future__ import annotations

import itertools
import math
import random

import pytest

from tasker import schedulers
from tasker.errors import ConfigError
from tasker.messages import CompletionCost, CostParams, SPRequest
from tasker.schedulers.base import Candidate, ScheduleView
from tasker.schedulers.lookahead import Problem, solve


def random_problem(rng: random.Random, n: int, *, has_exe: bool = False) -> Problem:
    first = [rng.uniform(5, 100) for _ in range(n)]
    after = [[0.0 if i == j else rng.uniform(5, 120) for j in range(n)] for i in range(n)]
    weight = [rng.choice([0.0, 1.0, 2.0, 10.0]) for _ in range(n)]
    deadline = [rng.choice([math.inf, rng.uniform(20, 300)]) for _ in range(n)]
    budget = [rng.choice([math.inf, rng.uniform(0, 60)]) for _ in range(n)]
    return Problem(1000.0, first, after, weight, [1000.0 + d for d in deadline], budget, has_exe=has_exe,
                   lateness_weight=rng.choice([0.0, 1.0, 5.0]), hazard_weight=1e3)


def brute(p: Problem, first: int | None = None, not_first: int | None = None) -> float:
    return min(p.evaluate(o) for o in itertools.permutations(range(p.n))
               if (first is None or o[0] == first) and o[0] != not_first)


@pytest.mark.parametrize("seed", range(40))
def test_exact_search_finds_the_optimum_of_brute_force(seed: int) -> None:
    rng = random.Random(seed)
    p = random_problem(rng, rng.randint(1, 7))
    order, obj, nodes, exact = solve(p, node_budget=10**6)
    assert exact
    assert sorted(order) == list(range(p.n))
    assert obj == pytest.approx(p.evaluate(order))
    assert obj == pytest.approx(brute(p))


@pytest.mark.parametrize("seed", range(10))
def test_exact_search_with_the_first_job_fixed_or_forbidden(seed: int) -> None:
    rng = random.Random(100 + seed)
    p = random_problem(rng, rng.randint(2, 6), has_exe=True)
    keep, keep_obj, _, e1 = solve(p, node_budget=10**6, fixed_first=0)
    alt, alt_obj, _, e2 = solve(p, node_budget=10**6, exclude_first=0)
    assert e1 and e2 and keep[0] == 0 and alt[0] != 0
    assert keep_obj == pytest.approx(brute(p, first=0))
    assert alt_obj == pytest.approx(brute(p, not_first=0))


def test_pruning_expands_fewer_nodes_than_the_permutation_tree() -> None:
    p = random_problem(random.Random(7), 7)
    _, _, nodes, exact = solve(p, node_budget=10**6)
    tree = sum(math.perm(7, k) for k in range(1, 8))
    assert exact and nodes < tree


def test_a_small_budget_is_anytime_returns_a_full_order_and_says_so() -> None:
    p = random_problem(random.Random(3), 30)
    order, obj, nodes, exact = solve(p, node_budget=50)
    assert not exact
    assert sorted(order) == list(range(30))
    assert obj == pytest.approx(p.evaluate(order))


# -- the scheduler on a view -------------------------------------------------------------------------

def cand(agent: str, order: int, *, c_time: float, cps: float = 1.0, x: float = 0.0,
         deadline: float | None = None, task_type: str = "t") -> Candidate:
    params = CostParams(task_type, cost=cps * c_time, cps=cps, c_time=c_time, end_pose=(x, 0.0), deadline=deadline)
    return Candidate(agent, task_type, params, float(order), order)


def view(exe: Candidate | None, cands: list[Candidate]) -> ScheduleView:
    every = {c.id: c for c in [*cands, *([exe] if exe else [])]}

    def req_sp(agent: str, req: SPRequest) -> CompletionCost:  # 1 m/s travel from the pose to the task's x
        c = every[agent]
        assert isinstance(c.params, CostParams) and c.params.end_pose is not None
        extra = abs(req.args["pose"][0] - c.params.end_pose[0])
        return CompletionCost(c.params.cps * (c.params.c_time + extra), c.params.cps)

    return ScheduleView(0.0, exe, cands, req_sp)


def test_weighted_shortest_first_without_travel() -> None:
    s = schedulers.create("lookahead")
    d = s.schedule(view(None, [cand("d1", 0, c_time=50), cand("d2", 1, c_time=10), cand("d3", 2, c_time=30)]))
    assert d.irr_da == "d2"
    assert d.record is not None and d.record["order"] == ["d2", "d3", "d1"]
    assert d.record["rule"] == "exact" and d.record["nodes"] >= 3 and d.record["switch"] is True


def test_a_deadline_pulls_a_long_task_forward() -> None:
    s = schedulers.create("lookahead", lateness_weight=10.0)
    d = s.schedule(view(None, [cand("d1", 0, c_time=10), cand("d2", 1, c_time=40, deadline=45)]))
    assert d.irr_da == "d2"


def test_hazard_budget_preempts_and_switch_cost_keeps() -> None:
    exe = cand("d1", 0, c_time=100, x=0.0)
    urgent = cand("d2", 1, c_time=20, deadline=30, x=5.0, task_type="fall")
    s = schedulers.create("lookahead", budgets={"fall": 0.0}, switch_penalty_s=5.0)
    assert s.schedule(view(exe, [urgent])).irr_da == "d2"
    relaxed = cand("d2", 1, c_time=20, x=50.0)  # equal weight, far away: going there and back costs more
    d = schedulers.create("lookahead", switch_penalty_s=5.0).schedule(view(cand("d1", 0, c_time=10), [relaxed]))
    assert d.irr_da is None and d.record is not None and d.record["order"] == ["d1", "d2"]


def test_decisions_are_deterministic() -> None:
    rng = random.Random(5)
    cands = [cand(f"d{k}", k, c_time=rng.uniform(5, 90), cps=rng.choice([1.0, 2.0, 10.0]), x=rng.uniform(0, 10),
                  deadline=rng.uniform(10, 400)) for k in range(2, 14)]
    a = schedulers.create("lookahead", node_budget=300).schedule(view(cand("d1", 1, c_time=40), cands))
    b = schedulers.create("lookahead", node_budget=300).schedule(view(cand("d1", 1, c_time=40), cands))
    assert a == b and a.record is not None and a.record["rule"] == "anytime" and a.record["nodes"] <= 300 + 13


@pytest.mark.parametrize("options", [{"node_budget": 0}, {"node_budget": 2.5}, {"switch_penalty_s": -1},
                                     {"hysteresis": 0}, {"lateness_weight": math.inf}])
def test_bad_options_are_config_errors(options: dict[str, object]) -> None:
    with pytest.raises(ConfigError, match="lookahead"):
        schedulers.create("lookahead", **options)


# -- the TaBSA baselines (re-implemented from their description) ---------------------------------------

def test_simple_is_longest_first_with_a_hesitance_margin() -> None:
    exe = cand("d1", 0, c_time=40)
    assert schedulers.create("simple", hesitance=0.5).schedule(view(exe, [cand("d2", 1, c_time=50)])).irr_da is None
    assert schedulers.create("simple", hesitance=0.5).schedule(view(exe, [cand("d2", 1, c_time=70)])).irr_da == "d2"
    assert schedulers.create("simple").schedule(view(None, [cand("d2", 1, c_time=5),
                                                            cand("d3", 2, c_time=9)])).irr_da == "d3"


def test_simple2_is_shortest_first() -> None:
    s = schedulers.create("simple2")
    assert s.schedule(view(cand("d1", 0, c_time=40), [cand("d2", 1, c_time=10)])).irr_da == "d2"
    assert s.schedule(view(None, [cand("d2", 1, c_time=5), cand("d3", 2, c_time=9)])).irr_da == "d2"


def test_distance_prefers_little_travel_per_second_of_work_and_priority_first() -> None:
    s = schedulers.create("distance")
    s.schedule(view(cand("d1", 0, c_time=10, x=0.0), []))  # the robot will be at x = 0
    near, far = cand("d2", 1, c_time=10, x=1.0), cand("d3", 2, c_time=10, x=8.0)
    assert s.schedule(view(None, [far, near])).irr_da == "d2"
    hi = Candidate("d4", "t", CostParams("t", cost=1, cps=1, c_time=10, end_pose=(9.0, 0.0), priority=3), 3.0, 3)
    assert s.schedule(view(None, [near, hi])).irr_da == "d4"


@pytest.mark.parametrize("name", ["simple", "simple2"])
def test_a_negative_hesitance_is_a_config_error(name: str) -> None:
    with pytest.raises(ConfigError, match="hesitance"):
        schedulers.create(name, hesitance=-0.1)


@pytest.mark.parametrize("seed", range(30))
def test_a_move_dropped_early_changes_no_search(seed: int) -> None:
    """The local search drops a move once it is no earlier and no cheaper than the current order where their
    jobs meet again (:meth:`Problem.evaluate_unless`); every search then returns what evaluating each move whole
    returns — the same order, value, nodes and proof — budgets small and large, hazards left on or not."""
    rng = random.Random(seed)
    p = random_problem(rng, rng.randint(4, 14), has_exe=rng.random() < 0.5)
    if seed % 3 == 0:
        p = Problem(p.now, p.first, p.after, p.weight, p.deadline, p.budget, has_exe=p.has_exe,
                    lateness_weight=p.lateness_weight, hazard_weight=p.hazard_weight,
                    left_on=[[p.now + rng.uniform(0, 200)] if rng.random() < 0.3 else [] for _ in range(p.n)])
    budget = rng.choice([20, 200, 2000])
    kwargs = {"fixed_first": 0} if p.has_exe and seed % 2 else {}
    fast = solve(p, node_budget=budget, **kwargs)
    whole = Problem.evaluate_unless
    try:
        Problem.evaluate_unless = lambda self, order, m, state, stop, other: self.evaluate_from(  # type: ignore
            order, m, state)
        slow = solve(p, node_budget=budget, **kwargs)
    finally:
        Problem.evaluate_unless = whole  # type: ignore[method-assign]
    assert fast == slow


def test_evaluate_unless_is_evaluate_or_a_proof_that_the_order_is_no_better() -> None:
    rng = random.Random(7)
    dropped = 0
    for _ in range(300):
        p = random_problem(rng, rng.randint(4, 10))
        order = list(range(p.n))
        rng.shuffle(order)
        cand = list(order)
        i, k = rng.sample(range(p.n), 2)
        cand.insert(k, cand.pop(i))
        m, stop = min(i, k), max(i, k) + 2
        prefix = p.prefixes(order)
        v = p.evaluate_unless(cand, m, prefix[m], stop, prefix[stop] if stop <= p.n else prefix[-1])
        if v == math.inf and p.evaluate(cand) != math.inf:
            dropped += 1
            assert p.evaluate(cand) >= p.evaluate(order)  # dropped: never better than the current order
        else:
            assert v == p.evaluate(cand)  # bit for bit
    assert dropped > 0


def test_negative_weights_drop_no_move() -> None:
    p = Problem(0.0, [5, 5, 5, 5], [[0, 5, 5, 5]] * 4, [1.0, -1.0, 1.0, 1.0], [math.inf] * 4, [math.inf] * 4)
    assert not p.monotone
    prefix = p.prefixes([0, 1, 2, 3])
    assert p.evaluate_unless([1, 0, 2, 3], 0, prefix[0], 3, prefix[3]) == p.evaluate([1, 0, 2, 3])
