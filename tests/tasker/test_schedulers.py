"""Every registered scheduler honours the contract; baselines decide as their names say."""

from __future__ import annotations

import pytest

from tasker import schedulers
from tasker.errors import ConfigError, UnknownName
from tasker.messages import CompletionCost, CostParams, SPRequest
from tasker.schedulers.base import Candidate, Decision, ScheduleView


def cand(agent: str, order: int, *, cost: float = 1, c_time: float = 1, deadline: float | None = None,
         priority: int | None = None, task_type: str = "t") -> Candidate:
    return Candidate(agent, task_type, CostParams(task_type, cost=cost, cps=1, c_time=c_time, end_pose=(0.0, 0.0),
                                                  deadline=deadline, priority=priority), float(order), order)


def answer(agent: str, req: SPRequest) -> CompletionCost:
    return CompletionCost(1.0, 1.0)


def v(exe: Candidate | None, cands: list[Candidate]) -> ScheduleView:
    return ScheduleView(0.0, exe, cands, answer)


class Unaged(CostParams):
    """Parameters whose ``cost`` must not be read: a waiting candidate's, as a scheduler that says it reads no
    waiting cost (``Scheduler.reads_cost = False``) gets it — its agent's estimate, not aged to now."""

    def __getattribute__(self, name: str) -> object:
        if name == "cost" and super().__getattribute__("__dict__").get("armed"):
            raise AssertionError("a scheduler with reads_cost = False read a waiting candidate's cost")
        return super().__getattribute__(name)


@pytest.mark.parametrize("name", [n for n in schedulers.names() if not schedulers.create(n).reads_cost])
def test_a_scheduler_that_says_it_reads_no_waiting_cost_reads_none(name: str) -> None:
    s = schedulers.create(name)

    def unaged(agent: str, order: int, c_time: float, deadline: float | None, priority: int | None) -> Candidate:
        params = Unaged("t", cost=c_time, cps=1.0 + order, c_time=c_time, end_pose=(order, 0.0), deadline=deadline,
                        priority=priority)
        object.__setattr__(params, "armed", True)  # built (its own check reads the cost): from now on, none may
        return Candidate(agent, "t", params, float(order), order)

    waiting = [unaged("d2", 1, 3.0, 9.0, 1), unaged("d3", 2, 2.0, None, 2), unaged("d4", 3, 7.0, 4.0, None)]
    for exe in (None, cand("d1", 0, cost=9, c_time=9, deadline=99, priority=1)):
        s.schedule(v(exe, waiting))  # decides on cTime, deadlines, priorities, poses and cps: never the cost


@pytest.mark.parametrize("name", schedulers.names())
def test_contract(name: str) -> None:
    s = schedulers.create(name)
    assert s.schedule(v(None, [])) == Decision()
    cands = [cand("d2", 1, cost=3, c_time=3, deadline=9), cand("d3", 2, cost=2, c_time=2, deadline=8)]
    d = s.schedule(v(None, cands))
    if s.work_conserving:
        assert d.irr_da in {"d2", "d3"}  # with no agent executing, something is started
    else:  # a time table may leave the robot idle, and says why
        assert d.irr_da in {None, "d2", "d3"} and d.record is not None and d.record["switch"] is (d.irr_da is not None)
    d = s.schedule(v(cand("d1", 0, cost=9, c_time=9, deadline=99), cands))
    assert d.irr_da is None or d.irr_da in {"d2", "d3"}
    if not s.preemptive:
        assert d.irr_da is None


def test_the_sweep_grids_are_tabsas() -> None:
    grid = (0.0, 0.25, 0.5, 0.75, 1.0)  # Smit-Sim run_all_agents_100_days.sh
    assert schedulers.sweep("tabsa-simple") == {"hesitance": grid}
    assert schedulers.sweep("tabsa-simple2") == {"hesitance": grid}
    assert schedulers.sweep("tabsa-distance") == {"ratio": grid}
    assert schedulers.sweep("alg2") == {} and schedulers.sweep("tabsa-scheduler") == {}
    for name in schedulers.names():  # every value of a grid is a valid option
        for option, values in schedulers.sweep(name).items():
            for value in values:
                schedulers.create(name, **{option: value})


def test_unknown_name_lists_known_ones() -> None:
    with pytest.raises(UnknownName) as err:
        schedulers.create("round-robin")
    assert "round-robin" in str(err.value)
    for n in ("alg2", "edf", "fifo", "priority", "sjf", "srtf"):
        assert n in str(err.value)


def test_fifo_runs_in_request_order() -> None:
    assert schedulers.create("fifo").schedule(v(None, [cand("d3", 2), cand("d2", 1)])).irr_da == "d2"


def test_sjf_picks_shortest_and_never_preempts() -> None:
    s = schedulers.create("sjf")
    assert s.schedule(v(None, [cand("d2", 1, c_time=5), cand("d3", 2, c_time=2)])).irr_da == "d3"
    assert s.schedule(v(cand("d1", 0, c_time=100), [cand("d3", 2, c_time=1)])).irr_da is None


def test_srtf_preempts_for_shorter_remaining_time() -> None:
    s = schedulers.create("srtf")
    assert s.schedule(v(cand("d1", 0, c_time=10), [cand("d2", 1, c_time=4)])).irr_da == "d2"
    assert s.schedule(v(cand("d1", 0, c_time=3), [cand("d2", 1, c_time=4)])).irr_da is None


def test_edf_preempts_for_earlier_deadline_and_puts_none_last() -> None:
    s = schedulers.create("edf")
    assert s.schedule(v(cand("d1", 0, deadline=50), [cand("d2", 1, deadline=20)])).irr_da == "d2"
    assert s.schedule(v(cand("d1", 0, deadline=10), [cand("d2", 1, deadline=20)])).irr_da is None
    assert s.schedule(v(None, [cand("d2", 1), cand("d3", 2, deadline=1e9)])).irr_da == "d3"


def test_fixed_priority_from_config_and_from_params() -> None:
    s = schedulers.create("priority", priorities={"fell": 10, "guide": 1})
    exe = cand("d1", 0, task_type="guide")
    assert s.schedule(v(exe, [cand("d2", 1, task_type="fell")])).irr_da == "d2"
    assert s.schedule(v(cand("d1", 0, task_type="fell"), [cand("d2", 1, task_type="guide")])).irr_da is None
    assert s.schedule(v(exe, [cand("d2", 1, task_type="guide", priority=5)])).irr_da == "d2"


def test_registering_a_scheduler() -> None:
    class Never(schedulers.Scheduler):
        name = "never"

        def schedule(self, view: ScheduleView) -> Decision:
            return Decision()

    schedulers.register("never", Never)
    try:
        assert isinstance(schedulers.create("never"), Never)
        assert "never" in schedulers.names()
    finally:
        schedulers._registry.pop("never")


@pytest.mark.parametrize(("name", "options", "fragment"), [
    ("alg2", {"cclasses": [["a"]]}, "scheduler 'alg2' has no option 'cclasses'; did you mean 'classes'?"),
    ("fifo", {"hysteresis": 0.5}, "scheduler 'fifo' has no option 'hysteresis' (it takes no options)"),
    ("alg2", {"classes": False}, "alg2: classes must be a list"),
    ("alg2", {"classes": [[1]]}, "alg2: classes[0] must be a list of task types (strings)"),
    ("priority", {"priorities": ["a"]}, "priority: priorities must be a table"),
    ("priority", {"priorities": {"a": "high"}}, "priority: priorities['a'] must be a number"),
    ("priority", {"default": float("nan")}, "priority: default must be a number"),
    ("lookahead", {"budgets": 5}, "lookahead: budgets must be a table"),
    ("lookahead", {"budgets": {"a": -1}}, "lookahead: budgets['a'] must be a finite number of seconds >= 0"),
    ("tabsa-simple", {"hesitance": 1.5}, "tabsa-simple: hesitance must be a number in [0, 1], got 1.5"),
    ("tabsa-simple2", {"hesitance": "high"}, "tabsa-simple2: hesitance must be a number in [0, 1], got 'high'"),
    ("tabsa-simple", {"hesitance": True}, "tabsa-simple: hesitance must be a number in [0, 1], got True"),
    ("tabsa-simple", {"seed": 1.5}, "tabsa-simple: seed must be an integer, got 1.5"),
    ("tabsa-distance", {"ratio": -0.25}, "tabsa-distance: ratio must be a number in [0, 1], got -0.25"),
    ("tabsa-distance", {"ratio": float("nan")}, "tabsa-distance: ratio must be a number in [0, 1], got nan"),
    ("tabsa-distance", {"hesitance": 0.5}, "scheduler 'tabsa-distance' has no option 'hesitance'"),
    ("tabsa-scheduler", {"non_preemptive": "fall"}, "tabsa-scheduler: non_preemptive must be a list of task type"),
    ("tabsa-simple", {"estimates": "event"}, "tabsa-simple: estimates must be one of 'events', 'reports', "
                                             "got 'event'; did you mean 'events'?"),
    ("wspt", {"weight": "cost"}, "wspt: weight must be one of 'priority', 'cps', got 'cost'"),
    ("atc", {"k": 0}, "atc: k must be a number in (0, inf), got 0"),
    ("atc", {"k": float("inf")}, "atc: k must be a number in (0, inf), got inf"),
])
def test_bad_options_are_config_errors_naming_the_option(name: str, options: dict[str, object],
                                                         fragment: str) -> None:
    """A user's scheduler_options reach create(): an unknown option or a value of the wrong
    type is a ConfigError that says which, never a TypeError from Python's call machinery."""
    with pytest.raises(ConfigError) as info:
        schedulers.create(name, **options)
    assert fragment in str(info.value)
