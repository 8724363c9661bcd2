"""Alg. 1 and the dynamic agent's FSM, driven through the simulation loop."""

from __future__ import annotations

from typing import Any

import pytest

from tasker.errors import BadRequest, InvariantViolation, PlanningFailed, UnknownName
from tasker.messages import FsmState, Report
from tasker.stage import Purpose, StagePlan
from tasker.synthetic import ManualExecutor, SyntheticTask
from tasker.task import TaskContext

from .helpers import BLOCK, first, guide, make_loop, st

FELL = dict(classes=[["fell"], ["guide"]])


def transitions(trace, agent):  # type: ignore[no-untyped-def]
    return [(e["from"], e["to"]) for e in trace.of("transition", agent=agent)]


def test_new_request_joins_idle_and_is_started() -> None:
    loop = make_loop([guide()])
    loop.request(0.0, "guide")
    tr = loop.run()
    assert first(tr.events, event="roles")["idleDA"] == ["d1"]
    assert transitions(tr, "d1")[:4] == [("initComm", "compSP"), ("compSP", "upTsk"), ("upTsk", "exeTsk"),
                                         ("exeTsk", "end")]
    assert tr.of("end", agent="d1")[0]["reason"] == "finished"
    assert tr.of("end")[0]["t"] == pytest.approx(19.0, abs=0.2)  # 5 + 2 + 10 + 2 s of stages


def test_preemption_suspends_then_starts_then_resumes() -> None:
    loop = make_loop([guide("guide"), SyntheticTask("fell", [st("approach", 3), st("check", 2)])], **FELL)
    loop.request(0.0, "guide")
    loop.request(2.0, "fell")
    tr = loop.run()
    cmds = [(e["agent"], e["flag"]) for e in tr.of("command")]
    assert cmds == [("d1", "start"), ("d1", "susp"), ("d2", "start"), ("d1", "start")]
    assert ("exeTsk", "genSusp") in transitions(tr, "d1") and ("exeSusp", "wait") in transitions(tr, "d1")
    start_d2 = first(tr.events, event="command", agent="d2", flag="start")["t"]
    wait_d1 = first(tr.events, event="transition", agent="d1", to="wait")["t"]
    assert start_d2 >= wait_d1  # start only once exeDA reported wait
    assert [e["reason"] for e in tr.of("end")] == ["finished", "finished"]


def test_blocking_stage_delays_the_switch_to_the_next_suspendable_stage() -> None:
    t = SyntheticTask("guide", [st("approach", 5), st("greet", 4, BLOCK), st("hand_over", 4, BLOCK), st("guide", 10)])
    loop = make_loop([t, SyntheticTask("fell", [st("check", 2)])], **FELL)
    loop.request(0.0, "guide")
    loop.request(6.0, "fell")  # during the blocking "greet" (5..9), then blocking "hand_over" (9..13)
    tr = loop.run()
    susp = first(tr.events, event="command", agent="d1", flag="susp")["t"]
    gen = first(tr.events, event="transition", agent="d1", to="genSusp")["t"]
    assert susp == pytest.approx(6.0, abs=0.01)
    assert gen == pytest.approx(13.0, abs=0.2)  # after both blocking stages, at the suspendable "guide"
    done = [e["action"] for e in tr.of("stage", agent="d1", status="done") if e["t"] <= gen]
    assert done == ["approach", "greet", "hand_over"]
    assert not tr.of("stage", agent="d1", action="greet", status="stopped")


def test_suspendable_stage_is_stopped_at_once() -> None:
    loop = make_loop([guide(), SyntheticTask("fell", [st("check", 2)])], **FELL)
    loop.request(0.0, "guide")
    loop.request(2.5, "fell")
    tr = loop.run()
    stopped = first(tr.events, event="stage", agent="d1", status="stopped")
    assert stopped["action"] == "approach" and stopped["t"] == pytest.approx(2.5, abs=0.01)


def test_agent_ending_itself_before_it_starts_is_removed() -> None:
    tasks = [guide("guide"), SyntheticTask("fell", [st("approach", 5), st("check", 5)])]
    loop = make_loop(tasks, **FELL)
    loop.request(0.0, "fell")  # d1 executes
    loop.request(1.0, "fell", {"cancel_at": 5.0})  # d3: never started while d1 runs ...
    loop.request(0.5, "guide")
    tr = loop.run()
    # ... so it ends itself from compSP; and the harmoniser removes it (Alg. 1, lines 15-16)
    assert ("compSP", "end") in transitions(tr, "d3")
    assert tr.of("end", agent="d3")[0]["reason"] == "no longer needed"
    last_roles = tr.of("roles")[-1]
    assert "d3" not in last_roles["idleDA"] and last_roles["exeDA"] != "d3"
    assert "d3" not in loop.harmoniser.agents


def test_agent_in_wait_ends_itself_and_the_rest_go_on() -> None:
    tasks = [guide("guide"), SyntheticTask("fell", [st("approach", 5), st("check", 5)])]
    loop = make_loop(tasks, **FELL)
    loop.request(0.0, "guide", {"cancel_at": 8.0})
    loop.request(2.0, "fell")  # preempts d1, which waits ...
    tr = loop.run()
    assert ("wait", "end") in transitions(tr, "d1")  # ... and ends itself from wait at t = 8
    assert tr.of("end", agent="d1")[0]["t"] == pytest.approx(8.0, abs=1.01)
    assert tr.of("end", agent="d2")[0]["reason"] == "finished"
    assert not any(e["agent"] == "d1" for e in tr.of("command") if e["t"] > 8.0)
    assert all("d1" not in r["idleDA"] for r in tr.of("roles") if r["t"] > 9.1)


def test_ct_mode_never_preempts() -> None:
    loop = make_loop([guide("guide"), SyntheticTask("fell", [st("check", 2)])], mode="CT", **FELL)
    loop.request(0.0, "guide")
    loop.request(2.0, "fell")
    tr = loop.run()
    assert [e["flag"] for e in tr.of("command")] == ["start", "start"]
    assert first(tr.events, event="command", agent="d2")["t"] >= tr.of("end", agent="d1")[0]["t"]


def test_switching_ct_to_it_online() -> None:
    loop = make_loop([guide("guide"), SyntheticTask("fell", [st("check", 2)])], mode="CT", **FELL)
    loop.request(0.0, "guide")
    loop.request(2.0, "fell")
    loop.at(7.0, lambda: loop.harmoniser.set_mode("IT"))
    tr = loop.run()
    susp = first(tr.events, event="command", flag="susp")
    assert susp["agent"] == "d1" and susp["t"] == pytest.approx(7.0, abs=0.01)
    assert first(tr.events, event="mode")["mode"] == "IT"


def test_requester_terminates_an_executing_task_after_a_safe_suspension() -> None:
    t = SyntheticTask("carry", [st("pick", 2, BLOCK), st("walk", 10)], suspension={"walk": [st("put_down", 3, BLOCK)]})
    loop = make_loop([t])
    loop.request(0.0, "carry")
    loop.terminate(4.0, "d1", "user changed their mind")
    tr = loop.run()
    assert transitions(tr, "d1")[-3:] == [("exeTsk", "genSusp"), ("genSusp", "exeSusp"), ("exeSusp", "end")]
    assert [e["action"] for e in tr.of("stage", agent="d1", status="done")] == ["pick", "put_down"]
    assert tr.of("end", agent="d1")[0]["reason"] == "user changed their mind"


def test_unsolvable_task_ends_with_its_reason_and_others_go_on() -> None:
    class Unsolvable(SyntheticTask):
        def update_task(self, ctx: TaskContext) -> StagePlan:
            raise PlanningFailed("unsolvable", "no plan reaches (at john kitchen)")

    loop = make_loop([Unsolvable("bad", [st("x", 1)]), guide()])
    loop.request(0.0, "bad")
    loop.request(0.0, "guide")
    tr = loop.run()
    bad = tr.of("end", agent="d1")[0]
    assert bad["reason"] == "upTsk unsolvable: no plan reaches (at john kitchen)" and bad["cause"] == "failed"
    assert tr.of("end", agent="d2")[0]["reason"] == "finished"


def test_failing_stage_ends_the_task_and_others_go_on() -> None:
    loop = make_loop([SyntheticTask("flaky", [st("grab", 1, fail="object gone")]), guide()])
    loop.request(0.0, "flaky")
    loop.request(0.0, "guide")
    tr = loop.run()
    assert tr.of("end", agent="d1")[0]["reason"] == "stage grab failed: object gone"
    assert tr.of("end", agent="d2")[0]["reason"] == "finished"


def test_resumed_task_does_not_redo_completed_stages_and_uses_alg3_prefix() -> None:
    g = SyntheticTask("guide", [st("approach", 5), st("greet", 2, BLOCK), st("guide", 10)],
                      resume_prefix=[st("greet_and_apologise", 2, BLOCK)])
    loop = make_loop([g, SyntheticTask("fell", [st("check", 2)])], **FELL)
    loop.request(0.0, "guide")
    loop.request(9.0, "fell")  # during "guide"
    tr = loop.run()
    plans = tr.of("plan", agent="d1", purpose="upTsk")
    assert [s["action"] for s in plans[0]["stages"]] == ["approach", "greet", "guide"]
    assert [s["action"] for s in plans[1]["stages"]] == ["greet_and_apologise", "guide"]


def test_bad_requests_change_nothing() -> None:
    loop = make_loop([guide()])
    with pytest.raises(UnknownName, match="known: guide"):
        loop.request(0.0, "gide")
    with pytest.raises(BadRequest, match="argument 'weight': expected a number"):
        loop.request(0.0, "guide", {"weight": "heavy"})
    with pytest.raises(BadRequest, match="unknown argument"):
        loop.request(0.0, "guide", {"person": "john"})
    assert loop.run().of("request") == []


def test_requester_changes_a_parameter_and_the_schedule_follows() -> None:
    from tasker.requester import Requester

    loop = make_loop([guide("a"), guide("b")], scheduler="priority")
    loop.request(0.0, "a")
    loop.request(1.0, "b")
    req = Requester(loop.store, loop.harmoniser, "nurse")
    loop.at(3.0, lambda: req.change("d2", {"priority": 5}))
    tr = loop.run()
    assert first(tr.events, event="change")["args"] == {"priority": 5}
    assert first(tr.events, event="command", flag="susp")["t"] == pytest.approx(3.0, abs=0.01)


def test_two_agents_in_cmd_is_an_invariant_violation() -> None:
    loop = make_loop([guide()])
    loop.request(0.0, "guide")
    loop.request(0.0, "guide")
    loop.run(until=0.5)
    h = loop.harmoniser
    a, b = (h.agents[x] for x in ("d1", "d2"))
    assert h.in_cmd == {"d1"}
    b.report = Report(FsmState.EXE_TSK)
    with pytest.raises(InvariantViolation, match="in cmd at once"):
        h._on_report(b)
    assert a.state.in_cmd


def test_a_stale_wait_report_is_not_taken_for_a_suspension() -> None:
    loop = make_loop([guide("a"), guide("b")], scheduler="priority", priorities={"b": 1})
    loop.request(0.0, "a")
    loop.run(until=1.0)
    h = loop.harmoniser
    h._susp_seq["d1"] = 99  # a susp the agent has not acknowledged yet
    h.agents["d1"].report = Report(FsmState.WAIT, ack=1)
    h.irr_da = "dX"
    h._pf_switch_da(1.0)
    assert h.exe_da == "d1"  # still the executing agent: no second start


def test_manual_executor_drives_stages() -> None:
    core = ManualExecutor()
    loop = make_loop([guide()], core=core)
    loop.request(0.0, "guide")
    loop.run(until=100.0)
    assert loop.harmoniser.agents["d1"].state is FsmState.EXE_TSK  # nothing finishes by itself
    for _ in range(4):
        core.finish()
        loop.run(until=loop.now + 1.0)
    assert loop.trace.of("end", agent="d1")[0]["reason"] == "finished"


def test_plan_purpose_is_checked() -> None:
    class Wrong(SyntheticTask):
        def update_task(self, ctx: TaskContext) -> StagePlan:
            return StagePlan((), Purpose.GEN_SUSP)

    loop = make_loop([Wrong("w", [st("x", 1)])])
    loop.request(0.0, "w")
    end = loop.run().of("end", agent="d1")[0]  # a task type's mistake ends that task, not the run
    assert end["cause"] == "error" and "returned a genSusp plan in upTsk" in end["reason"]


def test_replacement_ending_while_exe_suspends_does_not_strand_it() -> None:
    """Regression (found by the property test): irrDA ends while exeDA runs its exeSusp."""
    t = SyntheticTask("lo", [st("go", 5)], suspension={"go": [st("put_down", 3, BLOCK)]})
    loop = make_loop([t, SyntheticTask("hi", [st("check", 2)])], classes=[["hi"], ["lo"]])
    loop.request(0.0, "lo")
    loop.request(1.0, "hi")  # d2 preempts d1, which puts down what it holds (1..4) ...
    loop.terminate(2.0, "d2", "not needed after all")  # ... while d2 is cancelled
    tr = loop.run()
    assert ("exeSusp", "wait") in transitions(tr, "d1") and ("wait", "upTsk") in transitions(tr, "d1")
    assert tr.of("end", agent="d1")[0]["reason"] == "finished"


def test_expected_interruption_counts_the_queue_ahead_of_the_suspended_task() -> None:
    """susp's expected_s = the replacement's cTime + cTime of waiting tasks ranked ahead of the suspended one."""
    tasks = [guide("guide"), SyntheticTask("short", [st("s", 5)]), SyntheticTask("fell", [st("check", 2)])]
    loop = make_loop(tasks, classes=[["fell"], ["guide", "short"]], hysteresis=0.5)
    loop.request(0.0, "guide")  # d1: 19 s of stages
    loop.request(1.0, "short")  # d2: cheaper than d1 (ranked ahead), but not enough to switch with h = 0.5
    loop.request(3.0, "fell")  # d3: a higher class preempts d1
    tr = loop.run()
    start = first(tr.events, event="command", agent="d1", flag="start")
    assert start["predicted_s"] == pytest.approx(19.0)
    assert not [e for e in tr.of("decision") if e.get("dac") == "d2" and e["switch"] and e["t"] < 3.0]
    susp = first(tr.events, event="command", agent="d1", flag="susp")
    assert susp["by"] == "d3" and susp["expected_s"] == pytest.approx(2.0 + 5.0)
    assert first(tr.events, event="command", agent="d3", flag="start")["predicted_s"] == pytest.approx(2.0)


@pytest.mark.parametrize(("scheduler", "other", "ahead"), [("simple", 30.0, 30.0), ("simple2", 5.0, 5.0),
                                                          ("simple", 5.0, 0.0), ("simple2", 30.0, 0.0)])
def test_the_expected_interruption_follows_the_schedulers_own_ranking(scheduler: str, other: float,
                                                                      ahead: float) -> None:
    """simple ranks longest first, simple2 shortest first: a task requested after the executing
    one but ranked ahead of it by the scheduler runs before it resumes (request order is not
    their queue)."""
    tasks = [guide("guide"), SyntheticTask("other", [st("s", other)]), SyntheticTask("fell", [st("check", 2)])]
    loop = make_loop(tasks, scheduler=scheduler, hesitance=10.0)  # hesitance: d2 never preempts d1
    loop.request(0.0, "guide")  # d1: 19 s of stages
    loop.request(1.0, "other")  # d2: waits, ranked ahead of d1 or behind it
    loop.request(3.0, "fell", {"priority": 3})  # d3: a higher priority preempts d1
    tr = loop.run()
    susp = first(tr.events, event="command", agent="d1", flag="susp")
    assert susp["by"] == "d3" and susp["expected_s"] == pytest.approx(2.0 + ahead)


def test_a_choice_with_no_executing_agent_leaves_a_decision() -> None:
    loop = make_loop([guide("a"), guide("b")], scheduler="fifo")
    loop.request(0.0, "a")
    loop.request(0.0, "b")
    tr = loop.run()
    starts = tr.of("command", flag="start")
    decisions = [e for e in tr.of("decision") if e["switch"]]
    assert [(d["dac"], d["exeDA"], d["rule"]) for d in decisions] == [("d1", None, "no exeDA"),
                                                                      ("d2", None, "no exeDA")]
    assert [d["t"] for d in decisions] == [s["t"] for s in starts]


def test_a_start_predicts_from_the_moment_of_the_start() -> None:
    """predicted_s is the cTime computed at the start, not at the last report: the task it
    replaces has suspended in between (in compound, put down the vase cook's plan needs gone)."""
    from dataclasses import replace

    class Clock(SyntheticTask):  # a cTime that says when it was computed
        def compute_params(self, ctx: TaskContext):  # type: ignore[no-untyped-def]
            return replace(super().compute_params(ctx), c_time=ctx.now)

    loop = make_loop([guide("guide"), Clock("fell", [st("approach", 3), st("check", 2)])], **FELL)
    loop.request(0.0, "guide")
    loop.request(2.0, "fell")
    tr = loop.run()
    start = first(tr.events, event="command", agent="d2", flag="start")
    assert start["predicted_s"] == pytest.approx(start["t"])


def test_handover_tells_a_waiting_task_what_the_one_before_it_leaves() -> None:
    """TaskContext.handover: with no argument, the executing task's suspension effects (a
    start now replaces it); with an agent's id, that agent's completion effects; nothing
    about the executing task itself, nor from a task that is not running exeTsk."""
    from tasker.task import Effects

    class Holder(SyntheticTask):
        def leaves(self, ctx: TaskContext, how):  # type: ignore[no-untyped-def]
            return Effects(add=(("put_down", how),), delete=(("holding", "vase"),))

    seen: list = []

    class Asker(SyntheticTask):
        def compute_params(self, ctx: TaskContext):  # type: ignore[no-untyped-def]
            seen.append((ctx.now, ctx.handover(None), ctx.handover("d1")))
            return super().compute_params(ctx)

    loop = make_loop([Holder("hold", [st("carry", 10)]), Asker("ask", [st("x", 1)])], hysteresis=0.5)
    loop.request(0.0, "hold")
    loop.request(2.0, "ask")
    loop.run()
    while_held = [s for s in seen if 2.0 <= s[0] < 10.0]
    assert while_held
    for _, now, done in while_held:
        assert now == Effects(add=(("put_down", "suspend"),), delete=(("holding", "vase"),))
        assert done == Effects(add=(("put_down", "complete"),), delete=(("holding", "vase"),))
    assert loop.harmoniser.handover("d2") is None  # d1 has ended: nothing to assume
    from tasker.stage import Stage

    net = Effects.of([Stage("pick", data={"add": [["holding", "vase"]], "delete": [["hand_empty"]]}),
                      Stage("put", data={"add": [["hand_empty"]], "delete": [["holding", "vase"]]})])
    assert net == Effects(add=(("hand_empty",),), delete=(("holding", "vase"),))
    assert not Effects.of([])


def test_a_leaves_hook_that_raises_assumes_nothing() -> None:
    """A task type's broken ``leaves`` must not take down the estimate of another task (or
    the run): the handover assumes nothing, and both tasks finish."""
    class Broken(SyntheticTask):
        def leaves(self, ctx: TaskContext, how):  # type: ignore[no-untyped-def]
            raise RuntimeError("a bug in a user's task type")

    seen: list = []

    class Asker(SyntheticTask):
        def compute_params(self, ctx: TaskContext):  # type: ignore[no-untyped-def]
            seen.append((ctx.handover(None), ctx.handover("d1")))
            return super().compute_params(ctx)

    loop = make_loop([Broken("broken", [st("carry", 10)]), Asker("ask", [st("x", 1)])], hysteresis=0.5)
    loop.request(0.0, "broken")
    loop.request(2.0, "ask")
    tr = loop.run()
    assert seen and all(s == (None, None) for s in seen)
    assert [e["reason"] for e in tr.of("end")] == ["finished", "finished"]


def test_the_queue_ahead_is_summed_once_a_moment_whoever_the_replacement() -> None:
    """The look-ahead asks the executing task's suspension for every candidate at each decision; the queue
    ahead of it (in each ``expected_s``) is read once for all of them, and the susp sent carries the same sum."""
    tasks = [guide("guide"), *(SyntheticTask(f"w{k}", [st("s", 5.0 + k)]) for k in range(4)),
             SyntheticTask("fell", [st("check", 2)])]
    loop = make_loop(tasks, scheduler="lookahead")
    loop.request(0.0, "guide")
    for k in range(4):
        loop.request(0.5, f"w{k}")
    loop.request(3.0, "fell", {"priority": 3})
    scheduler, calls = loop.harmoniser.scheduler, [0]
    key = scheduler.queue_key

    def counted(c: Any) -> Any:
        calls[0] += 1
        return key(c)

    scheduler.queue_key = counted  # type: ignore[method-assign]
    moments: set[float] = set()
    ask = loop.harmoniser._suspension_of

    def asked(by: str) -> float:
        moments.add(loop.harmoniser.now)
        return ask(by)

    loop.harmoniser._suspension_of = asked  # type: ignore[method-assign]
    tr = loop.run()
    assert moments and calls[0] <= len(moments) * (len(tasks) + 1)  # not once per candidate and moment
    assert all(s["expected_s"] >= 0 for s in tr.of("command", flag="susp") if "expected_s" in s)


@pytest.mark.parametrize("reads", [False, True])
def test_a_suspension_that_does_not_read_the_interruption_is_estimated_once_a_moment(reads: bool) -> None:
    """The look-ahead asks the executing task's suspension for every candidate: a suspension that never reads how
    long the interruption lasts is planned once a moment for all of them; one that reads it, once per candidate
    (each candidate announces another interruption), and the decisions record the estimates that differ."""
    calls: list[float] = []

    class Guide(SyntheticTask):
        def generate_suspension(self, ctx: TaskContext):  # type: ignore[no-untyped-def]
            calls.append(ctx.memory.interruption_s if reads else 0.0)
            plan = super().generate_suspension(ctx)
            return plan if not reads or plan.stages else StagePlan(
                (st("park", 1.0 + (ctx.memory.interruption_s or 0.0) / 100),), Purpose.GEN_SUSP, strategy="static")

    tasks = [Guide("guide", [st("approach", 30), st("guide", 60)]),
             *(Guide(f"w{k}", [st("s", 5.0 + 7 * k)]) for k in range(4))]
    loop = make_loop(tasks, scheduler="lookahead", hysteresis=0.5)
    loop.request(0.0, "guide")
    for k in range(4):
        loop.request(0.5, f"w{k}")
    moments: set[float] = set()
    ask = loop.harmoniser._suspension_of

    def asked(by: str) -> float:
        if loop.harmoniser.exe_da is not None:
            moments.add(loop.harmoniser.now)
        return ask(by)

    loop.harmoniser._suspension_of = asked  # type: ignore[method-assign]
    tr = loop.run()
    suspend = [d["suspend_s"] for d in tr.of("decision") if "suspend_s" in d and len(d["suspend_s"]) > 1]
    assert moments and suspend
    if reads:
        assert len(calls) > len(moments) and any(len(set(s.values())) > 1 for s in suspend)
    else:
        assert len(calls) <= 2 * len(moments) and all(len(set(s.values())) == 1 for s in suspend)
