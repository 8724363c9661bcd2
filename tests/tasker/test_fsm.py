"""The FSM table holds every behaviour of the agent: its rows, its latched conditions, its checks.

The agent's commands are latched conditions of :data:`tasker.fsm.LATCHES` that the rows of
:data:`tasker.fsm.TRANSITIONS` read as guards; these tests pin what each latch does in each
state, that the table's checks catch a malformed table, that the diagrams show the
latches, and that an agent driven command by command does what the table says.
"""

from __future__ import annotations

import random
from dataclasses import replace

import pytest

from tasker import agent as agent_module
from tasker import fsm
from tasker.agent import DynamicAgent, Rates
from tasker.conditions import Latched, Term
from tasker.errors import FSMError
from tasker.messages import Command, Flag, FsmState
from tasker.synthetic import ManualExecutor, SyntheticTask
from tasker.task import TaskContext
from tasker.trace import Trace

from .helpers import BLOCK, st

S = FsmState
T = fsm.Transition


# -- the table ------------------------------------------------------------------------------


def test_the_shipped_table_is_sound() -> None:
    assert fsm.check_table(fsm.TRANSITIONS, fsm.LATCHES, fsm.GUARD_MEANING, fsm.LATCH_DATA) == []


def _problems(rows: tuple[fsm.Transition, ...], latches: tuple[fsm.Latch, ...] = fsm.LATCHES) -> str:
    return "; ".join(fsm.check_table(rows, latches, fsm.GUARD_MEANING, fsm.LATCH_DATA))


def test_the_table_check_catches_each_kind_of_fault() -> None:
    rows = fsm.TRANSITIONS
    no_error = tuple(t for t in rows if not (t.source is S.WAIT and t.event == "error"))
    assert "wait has no error row to end" in _problems(no_error)
    no_start = tuple(t for t in rows if t.target is not S.UP_TSK)
    assert "upTsk cannot be reached from initComm" in _problems(no_start)
    assert "end has a row" in _problems(rows + (T(S.END, "start", S.UP_TSK, ("ic_start",)),))
    assert "guard 'ready' has no meaning" in _problems(rows + (T(S.UP_TSK, "planned", S.END, ("ready",)),))
    assert "a command row must read a latched condition" in _problems(
        rows + (T(S.UP_TSK, "go", S.EXE_TSK, ("has_stages",), auto=True),))
    assert "ic_start is never held in exeTsk" in _problems(
        rows + (T(S.EXE_TSK, "start", S.UP_TSK, ("ic_start",), auto=True),))
    assert "ic_start is never held in exeSusp" in _problems(  # data of a latch counts as the latch
        rows + (T(S.EXE_SUSP, "secure", S.GEN_SUSP, ("secure",)),))
    unread = (fsm.Latch("ic_susp", "susp", frozenset({S.UP_TSK})),)
    assert "latch ic_susp: no command row reads it where it is held" in _problems(rows, unread)
    shadowed = tuple(replace(t, guards=()) if t.source is S.WAIT and t.event == "term" else t for t in rows)
    assert "wait --secure--> genSusp is shadowed by wait --term--> end" in _problems(shadowed)


def test_a_transitions_guards_must_be_a_tuple_of_names() -> None:
    with pytest.raises(FSMError, match="guards must be a tuple of names"):
        T(S.WAIT, "start", S.UP_TSK, "ic_start")  # type: ignore[arg-type]
    with pytest.raises(FSMError, match="guards must be a tuple of names"):
        T(S.WAIT, "start", S.UP_TSK, ("",))


def test_the_agent_evaluates_every_guard_and_command_of_the_table() -> None:
    assert set(agent_module._GUARDS) == set(fsm.GUARDS) == set(fsm.GUARD_MEANING)
    commands = {t.event for t in fsm.TRANSITIONS if t.auto}
    assert commands == {"term", "start", "secure", "suspend"}
    assert set(agent_module._COMMANDS) == commands - {"suspend"}  # suspend leaves exeTsk through the stage runner


def held(**latched: bool) -> object:
    return lambda g: latched.get(g, False)


@pytest.mark.parametrize(("state", "latched", "event", "target"), [
    (S.COMP_SP, {"ic_start": True, "ic_term": True}, "term", S.END),  # a term before a start
    (S.COMP_SP, {"ic_start": True, "secure": True}, "start", S.UP_TSK),  # compSP never secures
    (S.WAIT, {"ic_start": True, "secure": True}, "secure", S.GEN_SUSP),
    (S.WAIT, {"ic_start": True, "secure": True, "ic_term": True}, "term", S.END),
    (S.WAIT, {"ic_start": True}, "start", S.UP_TSK),
    (S.EXE_TSK, {"ic_susp": True, "suspendable": True}, "suspend", S.GEN_SUSP),
    (S.EXE_TSK, {"ic_term": True, "suspendable": True}, "suspend", S.GEN_SUSP),
    (S.EXE_TSK, {"ic_susp": True, "ic_term": True}, None, None),  # a blocking stage runs to its goal (eq. 25)
    (S.UP_TSK, {"ic_susp": True, "ic_term": True, "suspendable": True}, None, None),  # held for exeTsk
    (S.EXE_SUSP, {"ic_susp": True, "ic_start": True, "ic_term": True, "suspendable": True}, None, None),
    (S.WAIT, {"ic_susp": True}, None, None),
])
def test_the_command_rows_taken_in_each_state(state: S, latched: dict[str, bool], event: str | None,
                                               target: S | None) -> None:
    t = fsm.enabled(state, held(**latched))  # type: ignore[arg-type]
    assert (t.event, t.target) == (event, target) if t is not None else event is None


def test_what_each_state_holds() -> None:
    assert fsm.held_in(S.COMP_SP) == fsm.held_in(S.WAIT) == ("ic_start", "ic_term")
    assert fsm.held_in(S.UP_TSK) == fsm.held_in(S.EXE_TSK) == ("ic_susp", "ic_term")
    assert fsm.held_in(S.GEN_SUSP) == fsm.held_in(S.EXE_SUSP) == ("ic_term",)
    assert fsm.held_in(S.END) == ()


def test_the_diagrams_show_the_latches_and_the_guards() -> None:
    mermaid, dot = fsm.to_mermaid(), fsm.to_dot()
    assert "        upTsk : holds ic_susp, ic_term" in mermaid
    assert "    wait : holds ic_start, ic_term" in mermaid
    assert "exeTsk --> genSusp : suspend [ic_susp, suspendable]" in mermaid
    assert "exeTsk --> genSusp : suspend [ic_term, suspendable]" in mermaid
    assert "wait --> genSusp : secure [ic_start, secure]" in mermaid
    assert '"genSusp" [label="genSusp\\nholds ic_term"];' in dot
    assert '"end" [shape=doublecircle];' in dot


# -- the latches --------------------------------------------------------------------------------


def test_a_command_is_latched_only_where_it_is_held() -> None:
    c = Latched()
    c.receive("start", {"secure": True}, S.EXE_TSK)  # void in cmd
    c.receive("susp", {}, S.WAIT)  # void outside upTsk and exeTsk
    assert not (c.holds("ic_start") or c.holds("secure") or c.holds("ic_susp"))
    c.receive("susp", {}, S.UP_TSK)
    c.receive("start", {"secure": True}, S.WAIT)
    assert c.holds("ic_susp") and c.holds("ic_start") and c.holds("secure")
    c.enter(S.EXE_TSK)  # ic_susp is held on into exeTsk; ic_start is dropped
    assert c.holds("ic_susp") and not c.holds("ic_start") and not c.holds("secure")
    c.enter(S.GEN_SUSP)  # taken: the suspension honours it
    assert not c.holds("ic_susp")
    with pytest.raises(FSMError, match="not a latched condition"):
        c.holds("suspendable")


def test_which_term_wins() -> None:
    c = Latched()
    c.terminate("no longer needed", "self")
    c.receive("term", {"reason": "cancelled"}, S.EXE_TSK)  # the harmoniser's term overrides the task's own
    assert c.term == Term("cancelled", "term")
    c.receive("term", {"reason": "again"}, S.EXE_TSK)  # the first term stays
    c.terminate("stage drive failed", "failed")  # a failure overrides a term
    c.receive("term", {}, S.GEN_SUSP)
    c.terminate("no longer needed", "self")
    assert c.term == Term("stage drive failed", "failed")
    c.enter(S.EXE_SUSP)
    assert c.holds("ic_term")


def test_a_terms_cause_is_one_of_the_tables() -> None:
    with pytest.raises(FSMError, match="ic_term cause must be one of"):
        Term("why", "user")


# -- an agent driven command by command ------------------------------------------------------


class Driven:
    """One agent, a manual core agent and a trace; commands delivered and steps made by hand."""

    def __init__(self, task: SyntheticTask) -> None:
        self.core = ManualExecutor()
        self.trace = Trace()
        ctx = TaskContext("d1", task.name, task.validate_args({}), 0.0, random.Random(0))
        self.agent = DynamicAgent("d1", task, ctx, trace=self.trace, rates=Rates(1.0, 10.0, 1.0), core=self.core)
        self.seq = 0
        self.t = 0.0

    def step(self, dt: float = 0.1) -> None:
        self.t = round(self.t + dt, 6)
        self.agent.step(self.t)

    def send(self, flag: Flag, **data: object) -> None:
        self.seq += 1
        self.agent.deliver(Command(flag, self.seq, data))
        self.step(0.0)

    def path(self) -> list[tuple[str, str, str]]:
        return [(e["from"], e["trigger"], e["to"]) for e in self.trace.of("transition")]


TASK = SyntheticTask("job", [st("reach", 5), st("lift", 5, BLOCK), st("carry", 5)],
                     suspension={"reach": [st("back_off", 1)], "carry": [st("put_down", 1, BLOCK)]})


def test_a_start_to_an_executing_agent_is_void() -> None:
    d = Driven(TASK)
    d.step()
    d.send(Flag.START)
    assert d.agent.state is S.EXE_TSK
    d.send(Flag.START)  # nothing to start: the agent commands the robot already
    d.send(Flag.SUSP)
    assert d.path()[-2:] == [("exeTsk", "suspend", "genSusp"), ("genSusp", "planned", "exeSusp")]
    d.core.finish()  # back_off
    d.step()
    assert d.agent.state is S.WAIT  # the stale start did not restart it once it waits
    assert d.path()[-1] == ("exeSusp", "finished", "wait")


def test_a_susp_is_held_through_a_blocking_stage_and_void_once_waiting() -> None:
    d = Driven(TASK)
    d.step()
    d.send(Flag.START)
    d.core.finish()  # reach done: lift (blocking) begins
    d.step()
    d.send(Flag.SUSP)
    assert d.agent.state is S.EXE_TSK  # eq. 25: lift runs to its goal
    d.core.finish()  # lift done: carry is suspendable, the held susp ends it before it begins (eq. 26)
    d.step()
    assert d.path()[-2:] == [("exeTsk", "suspend", "genSusp"), ("genSusp", "planned", "exeSusp")]
    assert [e["action"] for e in d.trace.of("stage", status="begin")] == ["reach", "lift", "put_down"]
    d.send(Flag.SUSP)  # during exeSusp: void, it is not held into wait
    d.core.finish()
    d.step()
    assert d.agent.state is S.WAIT
    d.send(Flag.START)
    assert d.agent.state is S.EXE_TSK and d.agent.progress == (S.EXE_TSK, 0)


def test_a_term_in_cmd_ends_through_the_safe_suspension() -> None:
    d = Driven(TASK)
    d.step()
    d.send(Flag.START)
    d.core.finish()
    d.step()  # lift (blocking) runs
    d.send(Flag.TERM, reason="cancelled")
    assert d.agent.state is S.EXE_TSK
    d.core.finish()
    d.step()
    d.core.finish()  # put_down
    d.step()
    assert d.path()[-3:] == [("exeTsk", "suspend", "genSusp"), ("genSusp", "planned", "exeSusp"),
                             ("exeSusp", "finished", "end")]
    assert d.agent.end_reason == "cancelled" and d.trace.of("end")[0]["cause"] == "term"


def test_a_secure_start_is_taken_only_by_a_waiting_agent() -> None:
    d = Driven(TASK)
    d.step()
    d.send(Flag.START, secure=True)  # in compSP the table has no secure row: an ordinary start
    assert d.path()[1:3] == [("compSP", "start", "upTsk"), ("upTsk", "planned", "exeTsk")]
    d.send(Flag.SUSP)
    d.core.finish()
    d.step()
    assert d.agent.state is S.WAIT
    d.send(Flag.START, secure=True)
    assert ("wait", "secure", "genSusp") in d.path()
