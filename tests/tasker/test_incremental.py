"""The harmoniser's candidate index decides exactly as the scan it replaces.

``TaskHarmoniser.incremental = False`` keeps the plain computation (every waiting
agent scanned at each decision) callable as the reference.  Every scheduler in the
registry runs the bundled synthetic scenario, synthetic days of the shipped
protocols, and random programs of requests, changes and terminations both ways: the
traces must be equal byte for byte.  The index alone is checked against a scan under
random report updates, and the tick is shown not to read the candidates at all.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st_

from experiments.days import pipeline as days
from experiments.inputs import synthetic
from tasker import schedulers
from tasker.agent import Rates
from tasker.errors import ConfigError
from tasker.harmoniser import TaskHarmoniser
from tasker.loop import SimulationLoop
from tasker.messages import CostParams, ScheduleParams
from tasker.schedulers.base import Candidate, ScheduleView
from tasker.schedulers.index import CandidateIndex
from tasker.schedulers.index import IdleCandidates as _IdleCandidates
from tasker.store import TaskStore
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.task import TaskContext

from .helpers import BLOCK, st

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml"
INDEXED = sorted(n for n in schedulers.names() if schedulers.create(n).indexed)


def both_ways(build: Any, scan_below: int = 0) -> tuple[str, str, TaskHarmoniser]:
    """The trace of ``build()``'s loop with the index, then with the scan; and the indexed harmoniser.

    ``scan_below = 0``: the index serves every decision, however short the queue."""
    out = []
    harm = None
    for incremental in (True, False):
        loop = build()
        loop.harmoniser.incremental = incremental
        loop.harmoniser.scan_below = scan_below
        out.append(loop.run().dumps())
        harm = harm or loop.harmoniser
    assert harm is not None
    return out[0], out[1], harm


def test_the_index_serves_the_key_picking_schedulers() -> None:
    assert {"alg2", "priority", "fifo", "sjf", "srtf", "edf", "simple", "simple2"} <= set(INDEXED)
    assert not schedulers.create("lookahead").indexed and not schedulers.create("distance").indexed


@pytest.mark.parametrize("scheduler", [n if n != "lookahead-cpsat" else pytest.param(n, marks=pytest.mark.slow)
                                       for n in schedulers.names()])
def test_bundled_synthetic_scenario_same_trace(scheduler: str) -> None:
    scenario = synthetic.load(DEMO)
    indexed, scanned, harm = both_ways(lambda: synthetic.build(scenario, seed=1, scheduler=scheduler))
    assert indexed == scanned
    assert (harm._index is not None) == harm.scheduler.indexed  # the index really ran where it could
    assert harm._index is None or len(harm._index) == 0  # every task ended: none left in the heap


@pytest.mark.slow
@pytest.mark.parametrize("scheduler", schedulers.names())
@pytest.mark.parametrize(("protocol", "seed"), [("tabsa", 1), ("tabsa", 7), ("tabsa-short", 2), ("tabsa-short", 5)])
def test_synthetic_days_same_trace(protocol: str, seed: int, scheduler: str) -> None:
    day = days.make(protocol, seed, scheduler=scheduler)
    indexed, scanned, _ = both_ways(day.build)
    assert indexed == scanned
    assert '"event":"decision"' in indexed.replace(" ", "")  # the day made decisions to compare


def test_an_indexed_tick_never_builds_the_candidate_list(monkeypatch: pytest.MonkeyPatch) -> None:
    """The O(n) list is what the index avoids: with alg2 no decision of a day reads it."""
    def boom(self: _IdleCandidates) -> list[Candidate]:
        raise AssertionError("an indexed scheduler read every candidate")

    served = []
    lowest = CandidateIndex.lowest

    def counted(self: CandidateIndex, idle: Any) -> str | None:
        served.append(idle)
        return lowest(self, idle)

    monkeypatch.setattr(_IdleCandidates, "_list", boom)
    monkeypatch.setattr(CandidateIndex, "lowest", counted)
    loop = days.make("tabsa", 3, scheduler="alg2").build()
    loop.harmoniser.scan_below = 0
    events = loop.run().events
    assert not [e for e in events if e["event"] == "decision" and e.get("rule") == "error"]
    assert len(served) >= 10  # the heap served decisions (the others followed reports: scanned, ``ready``)


# -- random programs through the whole loop ------------------------------------------------------


class Opaque(SyntheticTask):
    """Reports parameters without costs: cost-keyed schedulers raise on it, so the index must step aside."""

    def compute_params(self, ctx: TaskContext) -> ScheduleParams:  # type: ignore[override]
        return ScheduleParams(self.name)


TASKS = [
    SyntheticTask("hi", [st("go", 4), st("check", 3, BLOCK)], weight=3.0, site=(2.0, 0.0)),
    SyntheticTask("lo", [st("go", 5), st("hold", 2, BLOCK), st("move", 6)], site=(0.0, 3.0),
                  suspension={"move": [st("put_down", 1, BLOCK)]}, resume_prefix=[st("apologise", 1, BLOCK)]),
    SyntheticTask("never", [st("go", 5)], cost_fn=lambda ctx, c_time: math.inf),  # infeasible: cost inf
    Opaque("opaque", [st("go", 3)]),
]
OPTIONS: dict[str, dict[str, Any]] = {"alg2": {"classes": [["hi"], ["lo", "opaque"]], "hysteresis": 0.9}}

request = st_.tuples(
    st_.floats(0, 40).map(lambda t: round(t, 1)),
    st_.sampled_from(["hi", "lo", "lo", "hi", "never", "opaque"]),
    st_.sampled_from([0.0, 1.0, 1.0, 2.0]),  # equal weights make equal costs: ties the order must break
    st_.sampled_from([None, 0, 1, 1, 2]),
    st_.sampled_from([None, 20.0, 20.0, 60.0]),
)
change = st_.tuples(st_.floats(0, 60).map(lambda t: round(t, 1)), st_.integers(0, 11),
                    st_.sampled_from([0.0, 1.0, 5.0]), st_.sampled_from([None, 0, 3]))
terminate = st_.tuples(st_.floats(0, 60).map(lambda t: round(t, 1)), st_.integers(0, 11))


def program_loop(scheduler: str, requests: list[Any], changes: list[Any], terms: list[Any]) -> SimulationLoop:
    loop = SimulationLoop(TaskStore(TASKS), schedulers.create(scheduler, **OPTIONS.get(scheduler, {})),
                          core=TimedExecutor(seed=3, jitter=0.2), rates=Rates(1.0, 10.0, 1.0), seed=3,
                          horizon=400.0)  # an opaque task under a cost scheduler never starts: stop
    for t, kind, weight, prio, deadline in requests:
        args: dict[str, Any] = {"weight": weight}
        if prio is not None:
            args["priority"] = prio
        if deadline is not None:
            args["deadline"] = deadline
        loop.request(t, kind, args)
    h = loop.harmoniser

    def change_at(agent: str, args: dict[str, Any]) -> None:
        da = h.agents.get(agent)
        if da is not None and not da.ended:
            merged = loop.store.validate(da.ctx.task_type, {**da.ctx.args, **args})
            da.update_args(merged, requester="test", now=h.now)

    for t, i, weight, prio in changes:
        loop.at(t, lambda a=f"d{i + 1}", w=weight, p=prio: change_at(a, {"weight": w, "priority": p}))
    for t, i in terms:
        loop.at(t, lambda a=f"d{i + 1}": h.terminate(a, "cancelled") if a in h.agents else None)
    return loop


@pytest.mark.slow
@settings(max_examples=30, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st_.lists(request, min_size=1, max_size=10), st_.lists(change, max_size=6), st_.lists(terminate, max_size=3))
def test_random_programs_same_trace_with_every_scheduler(requests: list[Any], changes: list[Any],
                                                         terms: list[Any]) -> None:
    for k, scheduler in enumerate(schedulers.names()):
        # scan_below 2: the queue crosses it both ways, so the heap is left and taken up again
        indexed, scanned, _ = both_ways(lambda s=scheduler: program_loop(s, requests, changes, terms),
                                        scan_below=k % 3)
        assert indexed == scanned, scheduler


def test_a_candidate_without_costs_gives_the_same_error_both_ways() -> None:
    """The opaque task's key cannot be indexed: the scan runs and raises where it always did."""
    reqs = [(0.0, "hi", 1.0, None, None), (1.0, "opaque", 1.0, None, None), (2.0, "lo", 1.0, None, None)]
    indexed, scanned, _ = both_ways(lambda: program_loop("alg2", reqs, [], []))
    assert indexed == scanned
    assert "needs CostParams from task type 'opaque'" in indexed


# -- the index alone, against a scan -------------------------------------------------------------

agent_no = st_.integers(0, 4)
key_op = st_.one_of(
    st_.tuples(st_.just("report"), agent_no, st_.sampled_from(["a", "b", "c"]),
               st_.sampled_from([0.0, 1.0, 1.0, 1.0, 2.5, math.inf, -math.inf]), st_.booleans()),
    st_.tuples(st_.just("opaque"), agent_no),
    st_.tuples(st_.just("decide")),  # the harmoniser refreshes the heap only when it decides
    st_.tuples(st_.just("decide")),
    st_.tuples(st_.just("end"), agent_no),
    st_.tuples(st_.just("leave"), agent_no),  # starts executing, or becomes irrDA
    st_.tuples(st_.just("back"), agent_no),  # waits again (at the end of idleDA)
)


@pytest.mark.slow
@settings(max_examples=600, derandomize=True, deadline=None)
@given(st_.lists(key_op, max_size=60), st_.sampled_from(INDEXED))
@example([("report", 0, "a", 1.0, True), ("report", 1, "a", 1.0, False), ("decide",), ("leave", 0), ("back", 0)],
         "alg2")  # a tie: the order decides
def test_the_index_finds_what_a_scan_finds(ops: list[Any], name: str) -> None:
    scheduler = schedulers.create(name, **({"classes": [["a"], ["b"]]} if name == "alg2" else {}))
    index = CandidateIndex(scheduler)
    cands: dict[str, Candidate] = {}
    idle: dict[str, None] = {}

    def decide(last: bool = False) -> None:
        """As the harmoniser: the heap if it is ready (the last decision forces it), else the scan."""
        scan = [c for a in idle if (c := cands.get(a)) is not None]
        if last:
            index.refresh(cands)
        elif not index.ready(cands):
            return
        if index.needs_scan(idle):
            with pytest.raises(ConfigError):
                min(scan, key=scheduler.select_key)
            return
        expected = min(scan, key=scheduler.select_key, default=None)
        assert index.lowest(idle) == (expected.id if expected is not None else None)

    for op in ops:
        if op[0] == "decide":
            decide()
            continue
        agent = f"d{op[1]}"
        if op[0] == "report":
            cost = op[3]
            params = CostParams(op[2], cost=cost, cps=1.0, c_time=abs(cost) if math.isfinite(cost) else 1.0,
                                deadline=cost, priority=int(cost) if math.isfinite(cost) else None)
            cands[agent] = Candidate(agent, op[2], params, 0.0, op[1])
            if op[4]:
                index.update(cands[agent])  # re-keyed at once
            else:
                index.touch(agent)  # re-keyed at the next refresh, as a report does
            idle.setdefault(agent, None)
        elif op[0] == "opaque":
            cands[agent] = Candidate(agent, "a", ScheduleParams("a"), 0.0, op[1])
            index.touch(agent)
            idle.setdefault(agent, None)
        elif op[0] == "end":
            cands.pop(agent, None)
            idle.pop(agent, None)
            index.discard(agent)
        elif op[0] == "leave":
            idle.pop(agent, None)
        elif agent in cands:
            idle[agent] = None
    decide(last=True)
    assert len(index._heap) <= 2 * len(index) + 65  # stale entries are compacted away


@pytest.mark.parametrize("name", INDEXED)
def test_select_keys_are_unique(name: str) -> None:
    """The contract that makes the heap's lowest the scan's first lowest: equal parameters, distinct keys."""
    scheduler = schedulers.create(name)
    params = CostParams("t", cost=1.0, cps=1.0, c_time=5.0, deadline=9.0, priority=1)
    early, late = (scheduler.select_key(Candidate(f"d{k}", "t", params, 0.0, k)) for k in (3, 4))
    assert early < late


def test_schedule_view_best_scans_unless_the_harmoniser_found_it() -> None:
    a = Candidate("d1", "t", CostParams("t", cost=2.0), 0.0, 0)
    b = Candidate("d2", "t", CostParams("t", cost=1.0), 0.0, 1)
    alg2 = schedulers.create("alg2")
    view = ScheduleView(0.0, None, [a, b], lambda *_: None)
    assert view.best(alg2.select_key) is b
    assert ScheduleView(0.0, None, [], lambda *_: None).best(alg2.select_key) is None
    assert ScheduleView(0.0, None, [a, b], lambda *_: None, lowest=a).best(alg2.select_key) is a


def test_an_unindexed_scheduler_has_no_index() -> None:
    with pytest.raises(TypeError, match="not indexed"):
        CandidateIndex(schedulers.create("lookahead"))


def test_a_new_scheduler_gets_a_new_index() -> None:
    """Swapping ``harmoniser.scheduler`` mid-run re-keys every candidate for the new one."""
    reqs = [(0.0, "lo", 1.0, 2, None), (1.0, "hi", 2.0, 0, None), (1.0, "lo", 0.0, 1, None)]

    def swapped() -> SimulationLoop:
        loop = program_loop("alg2", reqs, [], [])
        loop.at(3.0, lambda: setattr(loop.harmoniser, "scheduler", schedulers.create("priority")))
        return loop

    indexed, scanned, harm = both_ways(swapped)
    assert indexed == scanned
    assert harm._index is not None and harm._index.scheduler is harm.scheduler
