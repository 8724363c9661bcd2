"""Parked agents (tasker.inputs, tasker.parking) give the traces of agents stepped at every tick.

``SimulationLoop.parking = False`` keeps the plain computation (every agent stepped whenever it
asks) callable as the reference.  Every scheduler runs synthetic days and random programs of
requests, changes and terminations both ways: the traces must be equal byte for byte.  The
parts are checked on their own: the closed form of the cost, the declared inputs, the index's
groups of aging costs against a scan, the order the lot keeps, ``until``.
"""

from __future__ import annotations

import math
import random
from collections import Counter
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st_

from experiments.days import pipeline as days
from tasker import parking, schedulers
from tasker.agent import Rates
from tasker.inputs import Aging, EstimateInputs, Parking, aged, aging
from tasker.loop import SimulationLoop
from tasker.messages import CostParams, ScheduleParams
from tasker.schedulers.base import Candidate, ScheduleView
from tasker.schedulers.index import CandidateIndex
from tasker.store import TaskStore
from tasker.synthetic import SyntheticTask, TimedExecutor

from .helpers import BLOCK, st
from .test_incremental import change, program_loop, request, terminate


def parked_and_stepped(build: Any) -> tuple[str, str, Counter[str]]:
    """The trace of ``build()``'s loop with parking, then without; and how often the lot parked or
    estimated an agent anew (``park``, ``repark``)."""
    seen: Counter[str] = Counter()
    park, repark = parking.Lot.park, parking.Lot.repark

    def counted_park(self: parking.Lot, *args: Any) -> bool:
        done = park(self, *args)
        seen["park"] += done
        return done

    def counted_repark(self: parking.Lot, agent_id: str) -> bool:
        done = repark(self, agent_id)
        seen["repark"] += done
        return done

    out = []
    for on in (True, False):
        loop = build()
        loop.parking = on
        parking.Lot.park, parking.Lot.repark = counted_park, counted_repark  # type: ignore[method-assign,assignment]
        try:
            out.append(loop.run().dumps())
        finally:
            parking.Lot.park, parking.Lot.repark = park, repark  # type: ignore[method-assign]
    return out[0], out[1], seen


@pytest.mark.parametrize("scheduler", [n if n != "lookahead-cpsat" else pytest.param(n, marks=pytest.mark.slow)
                                       for n in schedulers.names()])
@pytest.mark.parametrize(("protocol", "seed"), [pytest.param("tabsa", 3, marks=pytest.mark.slow), ("tabsa-short", 5)])
def test_synthetic_days_same_trace_parked(protocol: str, seed: int, scheduler: str) -> None:
    parked, stepped, seen = parked_and_stepped(days.make(protocol, seed, scheduler=scheduler).build)
    assert parked == stepped
    assert seen["park"] >= 3  # waiting agents were parked: the comparison compared something


@pytest.mark.parametrize("scheduler", ["alg2", "edf", "tabsa-simple", "tabsa-scheduler", "atc", "simple2",
                                       pytest.param("lookahead", marks=pytest.mark.slow)])  # kept durations, loaded
def test_an_overloaded_day_same_trace_parked(scheduler: str) -> None:
    """TaBSA's day (one hour of it) piles work up: many agents wait, and are estimated anew as the robot moves."""
    import dataclasses

    proto = days.load("tabsa-original")
    proto = dataclasses.replace(proto, length_s=3600.0, tasks={k: dataclasses.replace(s, count=10)
                                                               for k, s in proto.tasks.items()})
    parked, stepped, seen = parked_and_stepped(days.make(proto, 2, scheduler=scheduler).build)
    assert parked == stepped
    assert seen["repark"] > 10  # inputs changed under parked agents


@pytest.mark.slow  # ~50 CPU s: every scheduler on 25 programs, twice
@settings(max_examples=25, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st_.lists(request, min_size=1, max_size=10), st_.lists(change, max_size=6), st_.lists(terminate, max_size=3))
def test_random_programs_same_trace_parked_with_every_scheduler(requests: list[Any], changes: list[Any],
                                                                terms: list[Any]) -> None:
    """Requests, new arguments (they wake a parked agent) and terminations at random, jittered stages."""
    for scheduler in schedulers.names():
        parked, stepped, _ = parked_and_stepped(lambda s=scheduler: program_loop(s, requests, changes, terms))
        assert parked == stepped, scheduler


def cancelling_loop(cancel_at: float) -> SimulationLoop:
    tasks = [SyntheticTask("long", [st("work", 30.0, BLOCK)], site=(1.0, 0.0)),
             SyntheticTask("short", [st("go", 2.0)], site=(0.0, 2.0))]
    loop = SimulationLoop(TaskStore(tasks), schedulers.create("fifo"), core=TimedExecutor(), rates=Rates(1.0, 1.0, 1.0))
    loop.request(0.0, "long")
    loop.request(0.5, "short", {"cancel_at": cancel_at})  # waits behind "long": ends itself while parked
    return loop


@pytest.mark.parametrize("cancel_at", [1.2, 7.0, 7.0005, 12.999, 13.0])
def test_a_parked_agent_ends_itself_when_its_until_comes(cancel_at: float) -> None:
    parked, stepped, seen = parked_and_stepped(lambda: cancelling_loop(cancel_at))
    assert parked == stepped
    assert '"reason":"no longer needed"' in parked
    assert seen["park"] >= (1 if cancel_at > 2 else 0)


# -- the closed form and the declared inputs ------------------------------------------------------------

def test_estimate_inputs_checks_its_fields() -> None:
    with pytest.raises(TypeError, match="hashable"):
        EstimateInputs(key=[1, 2])  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="until"):
        EstimateInputs(key=(1,), until=math.nan)
    with pytest.raises(TypeError, match="until"):
        EstimateInputs(key=(1,), until="later")  # type: ignore[arg-type]
    assert EstimateInputs(key=(1,)).until == math.inf


def test_aged_parameters_are_the_recomputed_ones_bit_for_bit() -> None:
    rng = random.Random(5)
    for _ in range(2000):
        w, r, c = rng.choice([1.0, 2.0, 10.0, 0.3, 1e-3]), rng.uniform(0, 9e4), rng.uniform(0, 5e3)
        t0 = r + rng.uniform(0, 3600)
        p0 = CostParams("x", cost=w * ((t0 - r) + c), cps=w, c_time=c, deadline=r + 100.0)
        form = aging(p0, r, t0)
        assert form is not None
        for t in (t0 + 5.0, t0 + 1234.567, t0 + rng.uniform(0, 1e4)):
            assert aged(p0, form, t) == CostParams("x", cost=w * ((t - r) + c), cps=w, c_time=c, deadline=r + 100.0)


def test_parameters_not_of_the_cost_model_are_not_aged() -> None:
    assert aging(ScheduleParams("x"), 0.0, 1.0) is None
    assert aging(CostParams("x", cost=5.0, cps=1.0, c_time=2.0), 0.0, 1.0) is None  # 1 * (1 + 2) != 5
    assert aging(CostParams("x", cost=math.inf, cps=1.0, c_time=2.0), 0.0, 1.0) is None
    inf = aging(CostParams("x", cost=math.inf, cps=1.0, c_time=math.inf), 0.0, 1.0)  # infeasible: never changes
    assert inf is not None and inf.steady
    assert Aging(0.0, 0.0, 3.0).steady and not Aging(2.0, 0.0, 3.0).steady


def test_synthetic_tasks_say_what_their_estimate_reads() -> None:
    plain = SyntheticTask("t", [st("go", 1.0)], site=(1.0, 1.0))
    custom = SyntheticTask("c", [st("go", 1.0)], cost_fn=lambda ctx, c: c)
    loop = SimulationLoop(TaskStore([plain, custom]), schedulers.create("fifo"), core=TimedExecutor())
    loop.core.pose = (2.0, 0.0)  # type: ignore[union-attr]
    loop.request(0.0, "t")  # runs first: a stage runs, its progress is time
    loop.request(0.0, "t", {"cancel_at": 50.0})
    loop.request(0.0, "c")
    loop.run(until=0.5)
    a, b, c = (loop.harmoniser.agents[x] for x in ("d1", "d2", "d3"))
    assert a.ctx.stage_started is not None and a.task.estimate_inputs(a.ctx) is None
    assert b.task.estimate_inputs(b.ctx) == EstimateInputs((2.0, 0.0), 50.0)
    assert c.task.estimate_inputs(c.ctx) is None  # its cost need not be the model's


def test_the_executor_counts_the_changes_of_its_pose() -> None:
    core = TimedExecutor()
    v = core.version
    core.pose = (1.0, 2.0)
    core.pose = (1.0, 2.0)  # no change
    assert core.version == v + 1
    core.begin("d1", st("go", 1.0, site=(3.0, 3.0)), 0.0)
    core.poll("d1", st("go", 1.0, site=(3.0, 3.0)), 1.0)
    assert core.pose == (3.0, 3.0) and core.version == v + 2


# -- the order the lot keeps ------------------------------------------------------------------------------

class _Agent:
    def __init__(self, name: str) -> None:
        self.id = name
        self.offer: Parking | None = Parking(EstimateInputs(("k",)), Aging(1.0, 0.0, 1.0),
                                             CostParams("x", cost=1.0, cps=1.0, c_time=1.0), 0.0)
        self.parked_with: Any = None

    def park(self, clock: Any) -> None:
        self.parked_with, self.offer = clock, None

    def unpark(self, at: float | None) -> None:
        self.unparked_at = at


def test_the_block_keeps_its_order_and_takes_the_early_at_its_front_and_the_late_at_its_back() -> None:
    """Wakes at grid tick 20 (period 10): pushed at 5 (early), at 10 (the block) or at 13 (late)."""
    import itertools

    lot = parking.Lot(10, 0.001, itertools.count())
    block = [lot.key(10, (0, (5, i)), 20) for i in range(2)]  # stepped in the block at 10: keep their places
    assert block == [(10, (5, 0)), (10, (5, 1))]
    early = lot.key(20, (5, (0, 0)), 30)  # at 20: came from a push before 10
    late = lot.key(20, (13, (0, 1)), 30)
    kept = lot.key(20, (10, (5, 0)), 30)
    assert early < kept < late
    assert lot.key(20, (13, (0, 1)), 25)[1][0] == 0  # not for the next grid tick: out of the block
    assert lot.key(23, (13, (0, 1)), 30)[1][0] == 0  # pushed off the grid: out of the block


def test_a_parked_agent_knows_whether_its_step_at_this_tick_has_come() -> None:
    import itertools

    lot = parking.Lot(10, 0.5, itertools.count(100))
    a = _Agent("a")
    assert lot.park(a, 10, (10, (5, 1)), 20)  # type: ignore[arg-type]
    m = lot.members["a"]
    lot.tick, lot.cur = 15, parking.AFTER
    assert lot.last(m) is None  # its first report tick (20) has not come
    lot.tick, lot.cur = 20, (10, (5, 0))  # stepping an agent before it in the block
    assert lot.last(m) is None
    lot.cur = (10, (5, 2))  # one after it
    assert lot.last(m) == 10.0
    lot.tick, lot.cur = 37, parking.BEFORE
    assert lot.last(m) == 15.0
    left = lot.leave("a")
    assert left is not None and left[1:] == (40, (30, (5, 1))) and a.unparked_at == 15.0


def test_until_is_the_first_grid_tick_at_or_after_it() -> None:
    import dataclasses
    import itertools

    lot = parking.Lot(5000, 0.001, itertools.count())
    assert [lot.grid_tick_at(t) for t in (0.0, 0.001, 5.0, 5.0001, 9.9999, 10.0)] == [0, 5000, 5000, 10000, 10000,
                                                                                      10000]
    a = _Agent("a")
    a.offer = Parking(EstimateInputs(("k",), until=4.5), Aging(1.0, 0.0, 1.0),
                      CostParams("x", cost=1.0, cps=1.0, c_time=1.0), 0.0)
    assert not lot.park(a, 4000, (4000, (0, 1)), 5000)  # type: ignore[arg-type]  # ic_term at its first tick...
    a.offer = dataclasses.replace(a.offer, inputs=EstimateInputs(("k",), until=11.0))
    assert lot.park(a, 4000, (4000, (0, 1)), 5000)  # type: ignore[arg-type]
    assert lot.due(10000) == [] and lot.due(15000) == ["a"]


# -- the index's groups of aging costs, against a scan -------------------------------------------------

class _Parked:
    """An agent the index reads: parked (aging from ``form``), settled, reporting at ``at``."""

    def __init__(self, form: Aging | None, at: float) -> None:
        self.parked = Parking(EstimateInputs(0), form, CostParams("x"), 0.0) if form is not None else None
        self.at = at

    def reported_at(self) -> float | None:
        return self.at if self.parked is not None else None

    def settled(self) -> bool:
        return self.parked is not None

    @property
    def report(self) -> Any:
        return None


aging_op = st_.one_of(
    st_.tuples(st_.just("park"), st_.integers(0, 7), st_.sampled_from(["a", "b"]), st_.sampled_from([1.0, 2.0, 10.0]),
               # near ties: 0.3 - 0.1 and 0.2 - 0.0 differ in the last bit, and so may the costs, either way
               st_.sampled_from([0.0, 0.1, 0.2, 100.0, 1e4 + 0.3]), st_.sampled_from([0.0, 0.2, 0.3, 3.3, 1e3])),
    st_.tuples(st_.just("report"), st_.integers(0, 7), st_.sampled_from(["a", "b"]), st_.floats(0, 1e4)),
    st_.tuples(st_.just("tick"), st_.sampled_from([5.0, 0.001, 777.7])),
    st_.tuples(st_.just("leave"), st_.integers(0, 7)),
    st_.tuples(st_.just("back"), st_.integers(0, 7)),
)


@settings(max_examples=400, derandomize=True, deadline=None)
@given(st_.lists(aging_op, max_size=60))
def test_aging_costs_are_ordered_as_a_scan_orders_them(ops: list[Any]) -> None:
    alg2 = schedulers.create("alg2", classes=[["a"], ["b"]])
    agents: dict[str, _Parked] = {}
    cands: dict[str, Candidate] = {}
    forms: dict[str, tuple[str, Aging | None, float]] = {}
    idle: dict[str, None] = {}
    now, used = 1e4, 0
    index = CandidateIndex(alg2, agents)

    def candidate(agent: str) -> Candidate:
        kind, form, cost = forms[agent]
        params = CostParams(kind, cost=form.cost(now) if form is not None else cost, cps=1.0, c_time=1.0)
        return Candidate(agent, kind, params, 0.0, int(agent[1:]))

    for op in ops:
        if op[0] == "park":
            _, i, kind, w, origin, offset = op
            a = f"d{i}"
            forms[a] = (kind, Aging(w, origin, offset), 0.0)
            agents[a] = _Parked(forms[a][1], now)
            idle[a] = None
            index.touch(a)
        elif op[0] == "report":
            _, i, kind, cost = op
            a = f"d{i}"
            forms[a] = (kind, None, cost)
            agents[a] = _Parked(None, now)
            idle[a] = None
            index.touch(a)
        elif op[0] == "tick":
            now += op[1]
            for p in agents.values():
                p.at = now
        elif op[0] == "leave":
            idle.pop(f"d{op[1]}", None)
        elif op[0] == "back" and f"d{op[1]}" in forms:
            idle[f"d{op[1]}"] = None
        cands = {a: candidate(a) for a in forms}
        expected = min((a for a in idle), key=lambda a: alg2.select_key(cands[a]), default=None)
        if index.ready(cands):  # else the harmoniser scans this once
            used += 1
            assert index.lowest(idle) == expected
    assert used >= len([op for op in ops if op[0] == "tick"])  # every decision after no report used the index


def test_every_indexed_scheduler_says_how_its_key_reads_the_cost() -> None:
    c = Candidate("d1", "a", CostParams("a", cost=3.0, cps=2.0, c_time=1.0, deadline=9.0, priority=1), 0.0, 1)
    dearer = Candidate("d1", "a", CostParams("a", cost=99.0, cps=2.0, c_time=1.0, deadline=9.0, priority=1), 0.0, 1)
    for name in schedulers.names():
        s = schedulers.create(name)
        if not s.indexed:
            continue
        assert s.key_cost is not None, name
        if s.key_cost:
            assert s.select_key(c) == (*s.key_prefix(c), 3.0, 1), name
        else:
            assert s.select_key(c) == s.select_key(dearer), name


@pytest.mark.parametrize("name", [n for n in schedulers.names() if not schedulers.create(n).reads_cost])
def test_a_scheduler_that_reads_no_waiting_cost_decides_the_same_whatever_it_is(name: str) -> None:
    rng = random.Random(7)
    for _ in range(40):
        def cand(i: int, cost: float) -> Candidate:
            kind = rng.choice(["fall", "transport"])
            r = random.Random(i)
            return Candidate(f"d{i}", kind, CostParams(kind, cost=cost, cps=1.0, c_time=r.uniform(1, 90),
                                                       end_pose=(r.uniform(0, 9), r.uniform(0, 9)),
                                                       deadline=r.uniform(50, 900), priority=r.choice([1, 2, 3])),
                             float(i), i)
        n = rng.randint(1, 6)
        exe = cand(0, 5.0) if rng.random() < 0.7 else None
        decisions = []
        for costs in ([float(i) for i in range(1, n + 1)], [1e6 - i for i in range(1, n + 1)]):
            s = schedulers.create(name)
            view = ScheduleView(now=10.0, exe=exe, candidates=[cand(i, costs[i - 1]) for i in range(1, n + 1)],
                                req_sp=lambda a, r: None)
            d = s.schedule(view)
            decisions.append((d.irr_da, dict(d.record or {})))
        assert decisions[0] == decisions[1], name
