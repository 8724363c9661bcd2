"""Property: random interleavings never break the harmoniser's invariants.

Requests, terminations, parameter changes, mode switches and stage completions or
failures are interleaved at random; after every step we check that at most one agent
is in ``cmd``, every live task holds exactly one role, no task ends twice, and that
in the end every task ends exactly once (a suspended task resumes when it is the
only one left).
"""

from __future__ import annotations

from collections import Counter

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st_

from tasker.agent import DynamicAgent
from tasker.messages import FsmState
from tasker.requester import Requester
from tasker.synthetic import ManualExecutor, SyntheticTask

from .helpers import BLOCK, make_loop, st

TASKS = [
    SyntheticTask("hi", [st("go", 1), st("check", 1, BLOCK)], weight=5.0,
                  suspension={"go": [st("mark", 1, BLOCK)]}),
    SyntheticTask("lo", [st("go", 1), st("hold", 1, BLOCK), st("move", 1), st("bye", 1, BLOCK)],
                  suspension={"move": [st("put_down", 1, BLOCK), st("close_door", 1)]},
                  resume_prefix=[st("apologise", 1, BLOCK)]),
]

ops = st_.one_of(
    st_.tuples(st_.just("request"), st_.sampled_from(["hi", "lo"]), st_.floats(0.1, 10)),
    st_.tuples(st_.just("terminate"), st_.integers(0, 9)),
    st_.tuples(st_.just("change"), st_.integers(0, 9), st_.floats(0.1, 10)),
    st_.tuples(st_.just("finish")),
    st_.tuples(st_.just("finish")),
    st_.tuples(st_.just("fail")),
    st_.tuples(st_.just("mode"), st_.sampled_from(["IT", "CT"])),
    st_.tuples(st_.just("advance"), st_.sampled_from([0.001, 0.1, 0.5, 3.0])),
)


def check(loop, created: dict[str, DynamicAgent], ends: Counter[str]) -> None:  # type: ignore[no-untyped-def]
    h = loop.harmoniser
    in_cmd = [a.id for a in created.values() if a.state.in_cmd]
    assert len(in_cmd) <= 1, f"two agents in cmd: {in_cmd}"
    assert set(in_cmd) == set(h.in_cmd)
    for agent_id, agent in created.items():
        roles = (h.exe_da == agent_id) + (h.irr_da == agent_id) + (agent_id in h.idle_da)
        if agent.state is FsmState.END:
            assert roles == 0 and agent_id not in h.agents, f"{agent_id} ended but still holds a role"
        else:
            assert roles == 1, f"{agent_id} holds {roles} roles"
    assert all(n == 1 for n in ends.values()), f"a task ended twice: {ends}"


@settings(max_examples=2500, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st_.lists(ops, min_size=1, max_size=25), st_.sampled_from(["alg2", "priority", "fifo", "srtf", "edf"]))
def test_random_interleavings_keep_the_invariants(program, scheduler) -> None:  # type: ignore[no-untyped-def]
    core = ManualExecutor()
    options = {"classes": [["hi"], ["lo"]]} if scheduler == "alg2" else {}
    loop = make_loop(TASKS, scheduler=scheduler, core=core, **options)
    h = loop.harmoniser
    req = Requester(loop.store, h)
    ids: list[str] = []
    created: dict[str, DynamicAgent] = {}
    ends: Counter[str] = Counter()
    loop.trace.subscribe(lambda e: ends.update([e["agent"]]) if e["event"] == "end" else None)
    make = h._factory
    h._factory = lambda *a: created.setdefault(a[0], make(*a))  # record every agent pf_initDA creates

    def advance(dt: float) -> None:
        loop.run(until=loop.now + dt)
        check(loop, created, ends)

    for op in program:
        kind = op[0]
        if kind == "request":
            ids.append(req.request(op[1], {"weight": op[2]}))
        elif kind == "terminate" and op[1] < len(ids):
            req.terminate(ids[op[1]], "cancelled")
        elif kind == "change" and op[1] < len(ids) and ids[op[1]] in h.agents:
            req.change(ids[op[1]], {"weight": op[2]})
        elif kind == "finish":
            core.finish()
        elif kind == "fail":
            core.finish(reason="skill crashed")
        elif kind == "mode":
            h.set_mode(op[1])
        advance(op[1] if kind == "advance" else 0.01)

    # drain: keep finishing stages; every task must end, exactly once
    for _ in range(400):
        if not h.busy:
            break
        live = [a for a in created.values() if a.state is not FsmState.END]
        if len(live) == 1 and h.exe_da is None and h.irr_da is None:
            advance(0.01)
            assert h.exe_da == live[0].id or live[0].state is FsmState.END, "a lone suspended task was not resumed"
        core.finish()
        advance(0.2)
    assert not h.busy, f"tasks never ended: {sorted(h.agents)}"
    assert sorted(ends) == sorted(created) == sorted(ids)
    assert all(n == 1 for n in ends.values())
