"""Every ``__post_init__`` check of the model's data fires."""

from __future__ import annotations

import math

import pytest

from tasker import fsm
from tasker.agent import Rates
from tasker.errors import BadRequest, ConfigError, FSMError
from tasker.messages import Command, CostParams, Flag, FsmState
from tasker.protocols import SkillState, SkillStatus
from tasker.stage import Purpose, Stage, StageKind, StagePlan
from tasker.task import ArgSpec, Strategy
from tasker.world import MotionEstimate, WorldState


def test_command_checks() -> None:
    with pytest.raises(TypeError, match="Flag"):
        Command("start", 1)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="seq"):
        Command(Flag.START, 0)


def test_cost_params_checks() -> None:
    with pytest.raises(ValueError, match="cost must be a number"):
        CostParams("t", cost=math.nan)
    with pytest.raises(ValueError, match="c_time must be >= 0"):
        CostParams("t", c_time=-1)
    assert CostParams("t", cost=math.inf).cost == math.inf  # infeasible: infinite, allowed


def test_stage_and_plan_checks() -> None:
    with pytest.raises(ValueError, match="action"):
        Stage("")
    with pytest.raises(ValueError, match="duration"):
        Stage("x", duration=-1)
    with pytest.raises(TypeError, match="kind"):
        Stage("x", kind="blocking")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="args must be a tuple"):
        Stage("x", args=["a"])  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="expected Stage"):
        StagePlan(("x",), Purpose.UP_TSK)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="sim_time"):
        StagePlan((), Purpose.UP_TSK, sim_time=-1)


def test_plan_renders_as_mermaid_and_dot() -> None:
    plan = StagePlan((Stage("navigate", ("robot", "kitchen")), Stage("greet", ("john",), StageKind.BLOCKING)),
                     Purpose.UP_TSK, strategy="planned")
    m = plan.to_mermaid()
    assert m.startswith("stateDiagram-v2") and "navigate(robot, kitchen)" in m and "[blocking]" in m
    d = plan.to_dot()
    assert d.startswith('digraph "exeTsk"') and "peripheries=2" in d


def test_other_checks() -> None:
    with pytest.raises(ValueError, match="needs a reason"):
        SkillStatus(SkillState.FAILED)
    with pytest.raises(ValueError, match="unreachable"):
        MotionEstimate(False, 3.0, 1.0, None)
    with pytest.raises(ConfigError, match="rep_rate"):
        Rates(rep_rate=0)
    with pytest.raises(ConfigError, match="identifier"):
        ArgSpec("not an id")
    with pytest.raises(ConfigError, match="type must be one of"):
        ArgSpec("x", type="list")
    with pytest.raises(ConfigError, match="planned"):
        Strategy(update="random")
    with pytest.raises(BadRequest, match="expected one of"):
        ArgSpec("who", choices=("john", "alice")).coerce("guide", "bob")


def test_world_state_updates() -> None:
    w = WorldState(frozenset({("at", "robot", "hall")}))
    w2 = w.updated(add=[("at", "robot", "kitchen")], delete=[("at", "robot", "hall")])
    assert w2.holds("at", "robot", "kitchen") and not w2.holds("at", "robot", "hall")
    assert w.holds("at", "robot", "hall")


def test_fsm_allows_only_the_transitions_of_fig5() -> None:
    fsm.check(FsmState.EXE_TSK, FsmState.GEN_SUSP)
    with pytest.raises(FSMError, match="no transition upTsk -> wait"):
        fsm.check(FsmState.UP_TSK, FsmState.WAIT)
    with pytest.raises(FSMError):
        fsm.check(FsmState.INIT_COMM, FsmState.UP_TSK)
    assert [s.superstate for s in FsmState] == ["init", "init", "cmd", "cmd", "cmd", "cmd", "wait", "end"]
    assert "state susp {" in fsm.to_mermaid()


def test_one_table_drives_states_checks_and_diagrams() -> None:
    # the hierarchy, the checks and both diagrams come from fsm.PARENT and fsm.TRANSITIONS
    assert {s: s.superstate for s in FsmState} == {s: fsm._top(s) for s in FsmState}
    assert [s for s in FsmState if s.in_cmd] == [s for s in FsmState if fsm._top(s) == "cmd"]
    mermaid, dot = fsm.to_mermaid(), fsm.to_dot()
    for t in fsm.TRANSITIONS:
        fsm.check(t.source, t.target)
        if t.event != "error":
            assert f"{t.source.value} --> {t.target.value} : {t.event}" in mermaid
            assert f'"{t.source.value}" -> "{t.target.value}" [label="{t.event}' in dot
    assert "state susp {" in mermaid and "subgraph cluster_susp {" in dot
    assert "--> end : error" in fsm.to_mermaid(errors=True) and "error" not in mermaid


def test_events_resolve_through_guards() -> None:
    S = FsmState
    t = fsm.resolve(S.EXE_SUSP, "finished", lambda g: g == "ic_term")
    assert t.target is S.END
    assert fsm.resolve(S.EXE_SUSP, "finished", lambda g: g == "not_ic_term").target is S.WAIT
    with pytest.raises(FSMError, match=r"no event 'start' in exeTsk; it accepts \['suspend', 'finished'"):
        fsm.resolve(S.EXE_TSK, "start", lambda g: True)
    with pytest.raises(FSMError, match="no guard holds"):
        fsm.resolve(S.UP_TSK, "planned", lambda g: False)
    assert set(fsm.GUARDS) == {"has_stages", "no_stages", "ic_term", "not_ic_term", "ic_start", "ic_susp", "secure",
                               "recovers", "suspendable"}
