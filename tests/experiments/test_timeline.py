"""The timeline's reading of a trace, one event type at a time (:mod:`experiments.trace.timeline`).

Each handler gets a small hand-written trace whose expected intervals are worked out here, not
read back from the code under test."""

from __future__ import annotations

from experiments.trace import timeline as tlm
from experiments.trace.timeline import Timeline
from tasker import events as ev


def _req(t: float, agent: str = "d1", task: str = "cook") -> ev.TaskRequested:
    return ev.TaskRequested(t, agent, task, {}, "scenario")


def _tr(t: float, src: str, trigger: str, dst: str, agent: str = "d1") -> ev.Transition:
    return ev.Transition(t, agent, trigger, src, dst)


def test_every_event_type_has_a_handler() -> None:
    assert set(tlm._HANDLERS) == set(ev.TYPES)


def test_states_are_spans_from_the_request_and_the_last_is_closed_at_the_end() -> None:
    tl = Timeline([_req(1.0), _tr(2.0, "initComm", "initialised", "compSP"),
                   _tr(5.0, "compSP", "start", "upTsk"), ev.ModeChanged(9.0, "CT")])
    spans = [(s.state, s.start, s.end, s.closed, s.entered_by, s.left_by) for s in tl.agents["d1"].states]
    assert spans == [("initComm", 1.0, 2.0, True, "request", "initialised"),
                     ("compSP", 2.0, 5.0, True, "initialised", "start"),
                     ("upTsk", 5.0, 9.0, False, "start", None)]
    assert [m.mode for m in tl.modes] == ["CT"]


def test_a_stage_runs_from_begin_to_its_closing_event_and_an_open_one_stays_running() -> None:
    def st(t: float, index: int, status: str, reason: str | None = None) -> ev.StageChanged:
        return ev.StageChanged(t, "d1", "exeTsk", index, "navigate", ["robot", "a", "b"], "suspendable", status, reason)

    tl = Timeline([_req(0.0), st(1.0, 0, "begin"), st(4.5, 0, "failed", "blocked"), st(5.0, 1, "begin")])
    runs = [(r.index, r.begin, r.end, r.status, r.reason) for r in tl.agents["d1"].stages]
    assert runs == [(0, 1.0, 4.5, "failed", "blocked"), (1, 5.0, None, "running", None)]


def test_a_suspension_episode_holds_its_plan_its_stages_and_how_it_ended() -> None:
    plan = ev.PlanMade(3.0, "d1", "genSusp", "static", [{"action": "put_down", "args": [], "kind": "blocking"}])
    events = [_req(0.0), _tr(3.0, "exeTsk", "suspend", "genSusp"), plan, _tr(3.5, "genSusp", "planned", "exeSusp"),
              ev.StageChanged(3.5, "d1", "exeSusp", 0, "put_down", [], "blocking", "begin"),
              ev.StageChanged(7.0, "d1", "exeSusp", 0, "put_down", [], "blocking", "done"),
              _tr(7.0, "exeSusp", "finished", "wait")]
    (s,) = Timeline(events).agents["d1"].suspensions
    assert (s.start, s.ready, s.end, s.trigger, s.outcome, s.duration) == (3.0, 3.5, 7.0, "suspend", "wait", 4.0)
    assert s.plan == plan and [r.status for r in s.stages] == ["done"]


def test_an_interruption_runs_from_susp_to_the_next_start_and_says_what_became_of_it() -> None:
    events = [_req(0.0), ev.CommandSent(2.0, "d1", "susp", by="d2", expected_s=30.0),
              _tr(2.0, "exeTsk", "suspend", "genSusp"), _tr(3.0, "genSusp", "planned", "exeSusp"),
              _tr(6.0, "exeSusp", "finished", "wait"), ev.CommandSent(40.0, "d1", "start"),
              ev.CommandSent(50.0, "d1", "susp", by="d3"), ev.TaskEnded(55.0, "d1", "cook", "term", "term")]
    a = Timeline(events).agents["d1"]
    got = [(i.susp_t, i.by, i.expected_s, i.wait_t, i.resume_t, i.outcome) for i in a.interruptions]
    assert got == [(2.0, "d2", 30.0, 6.0, 40.0, "resumed"), (50.0, "d3", None, None, None, "ended")]
    assert a.ended and a.cause == "term"


def test_roles_become_spans_per_agent() -> None:
    events = [_req(0.0), _req(0.0, "d2"), ev.RolesChanged(1.0, "d1", None, ["d2"]),
              ev.RolesChanged(4.0, "d2", None, ["d1"]), ev.RolesChanged(6.0, "d2", None, ["d1"])]
    tl = Timeline(events)
    assert [(r.role, r.start, r.end, r.closed) for r in tl.agents["d1"].roles] == \
        [("exeDA", 1.0, 4.0, True), ("idleDA", 4.0, 6.0, False)]
    assert tl.exe_changes() == [(1.0, "d1"), (4.0, "d2")] and tl.exe_at(3.9) == "d1"


def test_person_roles_and_the_order_people_came_in() -> None:
    events = [_req(0.0, "d1", "guide_human"), _req(0.0, "d2", "human_fell"),
              ev.RoleChanged(2.0, "d2", "needs_help", "peter", "on"),
              ev.RoleChanged(3.0, "d1", "waiting", "john", "on"),
              ev.RoleChanged(8.0, "d2", "needs_help", "peter", "off")]
    tl = Timeline(events)
    assert tl.people_order == ["d2", "d1"]
    assert [(s.role, s.person, s.start, s.end, s.closed) for s in tl.agents["d2"].person_roles] == \
        [("needs_help", "peter", 2.0, 8.0, True)]
    assert tl.agents["d1"].person_role_at("waiting", 10.0)


def test_hazard_episodes_pair_on_with_off_and_an_unpaired_on_stays_open() -> None:
    def hz(t: float, status: str, agent: str | None = "d1", fact: tuple[str, ...] = ("cooker_on", "cooker")) -> \
            ev.HazardChanged:
        return ev.HazardChanged(t, agent, fact[0], list(fact[1:]), list(fact), status, 60.0, 3.0)

    events = [_req(0.0), hz(1.0, "on"), hz(2.0, "on"), hz(5.0, "off"), hz(6.0, "on", None, ("open", "door1")),
              ev.ModeChanged(9.0, "IT")]
    tl = Timeline(events)
    assert [(h.owner, h.label, h.start, h.end) for h in tl.hazards] == \
        [("d1", "cooker_on cooker", 1.0, 5.0), (None, "open door1", 6.0, None)]


def test_events_of_agents_never_requested_are_skipped() -> None:
    tl = Timeline([_tr(1.0, "initComm", "initialised", "compSP", agent="ghost"),
                   ev.StageChanged(1.0, "ghost", "exeTsk", 0, "x", [], "suspendable", "begin"),
                   ev.TaskEnded(2.0, "ghost", "cook", "finished", "finished")])
    assert tl.agents == {}
