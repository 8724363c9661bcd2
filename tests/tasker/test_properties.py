"""Property: random interleavings never break the model's rules.

Requests, terminations, parameter changes, mode switches and stage completions or
failures are interleaved at random.  After every step: at most one agent is in
``cmd``, every live task holds exactly one role, no task ends twice.  At the end
every task has ended exactly once (a suspended task resumes when it is the only one
left), and the trace obeys the rules of the model (:func:`check_trace`):

* **terminations are not dropped**: a task sent ``term`` ends with cause ``term``
  (or ``failed``), or -- already past its last suspendable point -- ``finished``
  without being started again;
* **blocking stages are never interrupted**: no blocking stage is ``stopped``;
* **the end's cause is true**: a task whose stage failed ends ``failed``; a task
  that ends ``finished`` completed every stage of its last ``exeTsk``; no ``error``
  (synthetic tasks never raise);
* **the mode is obeyed**: no ``susp`` is sent while harmonisation is CT;
* **exeSusp is never skipped**: a task that reaches ``wait`` or ends after a
  suspension ran every stage its ``genSusp`` planned, in order.

Mutation run (each rule's mutant must be caught; apply one, run
``python -m pytest tests/tasker/test_properties.py -q -x``, revert with
``git checkout tasker/``).  Results of the run at the commit that moved the agent's
commands into the FSM table (latched conditions, :mod:`tasker.conditions`):

=========================  ================================================  ========
rule                       mutant                                            result
=========================  ================================================  ========
terminations not dropped   ``conditions.Latched.receive``: ignore ``term``   caught
blocking stages            ``agent._suspendable``: drop                      caught
                           ``and not stage.blocking`` (guard ``suspendable``)
true causes                ``agent._end``: ``cause="finished"`` always        caught
mode obeyed                ``harmoniser.step``: ``self.mode is Mode.IT`` ->   caught
                           ``True``
exeSusp not skipped        ``agent._gen_susp``: ``runner.index = len(stages)``  caught
                           before ``_enter_stage``
=========================  ================================================  ========
"""

from __future__ import annotations

from collections import Counter, defaultdict
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st_

from tasker.events import TaskEnded
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


def check(loop: Any, ends: Counter[str]) -> None:
    h = loop.harmoniser
    agents = {a.id: a for a in loop.all_agents}
    in_cmd = [a.id for a in agents.values() if a.state.in_cmd]
    assert len(in_cmd) <= 1, f"two agents in cmd: {in_cmd}"
    assert set(in_cmd) == set(h.in_cmd)
    for agent_id, agent in agents.items():
        roles = (h.exe_da == agent_id) + (h.irr_da == agent_id) + (agent_id in h.idle_da)
        if agent.state is FsmState.END:
            assert roles == 0 and agent_id not in h.agents, f"{agent_id} ended but still holds a role"
        else:
            assert roles == 1, f"{agent_id} holds {roles} roles"
    assert all(n == 1 for n in ends.values()), f"a task ended twice: {ends}"


def check_trace(events: list[dict[str, Any]]) -> None:
    """The rules of the module docstring, read from the trace alone."""
    mode = "IT"
    per: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for e in events:
        if e["event"] == "mode":
            mode = e["mode"]
        elif e["event"] == "command" and e["flag"] == "susp":
            assert mode == "IT", f"t={e['t']}: susp sent to {e['agent']} in CT mode"
        elif e["event"] == "stage":
            assert not (e["kind"] == "blocking" and e["status"] == "stopped"), f"blocking stage interrupted: {e}"
        elif e["event"] == "end":
            assert e["cause"] != "error", f"an agent raised: {e}"
        if "agent" in e:
            per[e["agent"]].append(e)
    for agent, evs in per.items():
        end = next(e for e in evs if e["event"] == "end")
        cause = end["cause"]
        if any(e["event"] == "stage" and e["status"] == "failed" for e in evs):
            assert cause == "failed", f"{agent}: a stage failed but it ended {cause!r}"
        if cause == "finished":
            k = max((i for i, e in enumerate(evs) if e["event"] == "plan" and e["purpose"] == "upTsk"), default=None)
            planned = [s["action"] for s in evs[k]["stages"]] if k is not None else []
            done = [e["action"] for e in evs[k or 0:] if e["event"] == "stage" and e["fsm"] == "exeTsk"
                    and e["status"] == "done"]
            assert done == planned, f"{agent} ended 'finished' after {done} of {planned}"
        term = next((e["t"] for e in evs if e["event"] == "command" and e["flag"] == "term"), None)
        if term is not None:
            restarted = any(e["event"] == "transition" and e["to"] == "upTsk" and e["t"] >= term for e in evs)
            assert cause in ("term", "failed") or (cause == "finished" and not restarted), \
                f"{agent}: term at t={term} was dropped (ended {cause!r}, restarted={restarted})"
        for i, e in enumerate(evs):
            if e["event"] == "plan" and e["purpose"] == "genSusp":
                after = evs[i + 1:]
                stop = next((j for j, x in enumerate(after) if x["event"] == "transition"
                             and x["to"] in ("wait", "end")), len(after))
                ran = [x["action"] for x in after[:stop] if x["event"] == "stage" and x["fsm"] == "exeSusp"
                       and x["status"] == "done"]
                failed = any(x["event"] == "stage" and x["status"] == "failed" for x in after[:stop])
                if stop < len(after) and not failed:
                    assert ran == [s["action"] for s in e["stages"]], f"{agent}: exeSusp ran {ran} of {e['stages']}"


@pytest.mark.slow
@settings(max_examples=2500, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st_.lists(ops, min_size=1, max_size=25), st_.sampled_from(["alg2", "priority", "fifo", "srtf", "edf"]))
def test_random_interleavings_keep_the_invariants(program: list[tuple[Any, ...]], scheduler: str) -> None:
    core = ManualExecutor()
    options = {"classes": [["hi"], ["lo"]]} if scheduler == "alg2" else {}
    loop = make_loop(TASKS, scheduler=scheduler, core=core, **options)
    h = loop.harmoniser
    req = Requester(loop.store, h)
    ids: list[str] = []
    ends: Counter[str] = Counter()
    loop.trace.subscribe(lambda e: ends.update([e.agent]) if isinstance(e, TaskEnded) else None)

    def advance(dt: float) -> None:
        loop.run(until=loop.now + dt)
        check(loop, ends)

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
        live = [a for a in loop.all_agents if a.state is not FsmState.END]
        if len(live) == 1 and h.exe_da is None and h.irr_da is None:
            advance(0.01)
            assert h.exe_da == live[0].id or live[0].state is FsmState.END, "a lone suspended task was not resumed"
        core.finish()
        advance(0.2)
    assert not h.busy, f"tasks never ended: {sorted(h.agents)}"
    assert sorted(ends) == sorted(a.id for a in loop.all_agents) == sorted(ids)
    assert all(n == 1 for n in ends.values())
    check_trace(loop.trace.events)
