"""Hazard-aware waiting: a waiting task secures its hazard before the budget runs out, whatever the scheduler.

A synthetic system with a declared hazard: ``stew`` lights a flame (a fact the test
world keeps), simmers, and puts the flame out.  Its suspension follows the two policies:
``conditional`` leaves the flame on for an interruption it expects to be short,
``strict`` puts it out.  ``chore`` interrupts it for much longer than the flame's budget.
The hazard metric is the project's own (``experiments.metrics.run``, ``safety.budget_overruns``).
"""

from __future__ import annotations

import random
from collections.abc import Sequence
from typing import Any

import pytest

from experiments.metrics import run as metrics
from tasker import fsm, schedulers
from tasker.agent import Rates
from tasker.errors import ConfigError
from tasker.harmoniser import TaskHarmoniser
from tasker.loop import SimulationLoop
from tasker.meaning import Hazard, Meaning, Monitor
from tasker.messages import FsmState
from tasker.protocols import SkillState, SkillStatus
from tasker.stage import Stage
from tasker.store import TaskStore
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.task import Strategy, TaskContext
from tests.tasker.helpers import BLOCK, st

FLAME = ("flame", "burner")
BUDGET = 20.0


class Facts:
    """The test world: a set of facts that stages change (``data["add"]``/``data["delete"]``) when they succeed."""

    def __init__(self) -> None:
        self.facts: set[tuple[str, ...]] = set()

    def snapshot(self) -> frozenset[tuple[str, ...]]:
        return frozenset(self.facts)


class EffectExecutor(TimedExecutor):
    """A timed core agent whose stages apply their effects to :class:`Facts` when they succeed."""

    def __init__(self, world: Facts, seed: int = 0, jitter: float = 0.0) -> None:
        super().__init__(seed=seed, jitter=jitter)
        self.world = world

    def poll(self, agent: str, stage: Stage, now: float) -> SkillStatus:
        status = super().poll(agent, stage, now)
        if status.state is SkillState.SUCCEEDED:
            if "add" in stage.data:
                self.world.facts.add(tuple(stage.data["add"]))
            if "delete" in stage.data:
                self.world.facts.discard(tuple(stage.data["delete"]))
        return status


def stew(world: Facts, short_s: float = 1000.0) -> SyntheticTask:
    """Light, simmer, put out; suspension: leave the flame on (conditional, short) or put it out (strict)."""

    def suspension(ctx: TaskContext) -> Sequence[Stage]:
        expected = ctx.memory.get("interruption_s", float("inf"))
        if FLAME not in world.facts or (ctx.strategy.policy == "conditional" and expected <= short_s):
            return ()
        return (st("put_out", 2.0, delete=FLAME),)

    task = SyntheticTask("stew", [st("light", 1.0, add=FLAME), st("simmer", 40.0), st("put_out", 2.0, delete=FLAME)],
                         weight=1.0, suspension=suspension, resume_prefix=[st("light", 1.0, add=FLAME)])
    task.meaning = Meaning(hazards=(Hazard("flame", FLAME, budget_s=BUDGET),))
    return task


def chore() -> SyntheticTask:
    return SyntheticTask("chore", [st("sweep", 40.0), st("mop", 40.0)], weight=1.0)


def watched(world: Facts, scheduler: Any, *, policy: str = "conditional", hazard_waiting: bool = True,
            **loop_options: Any) -> SimulationLoop:
    """A loop of stew and chore over ``world`` whose Monitor writes hazard events and tells the
    harmoniser which hazards hold (as the runner wires it)."""
    store = TaskStore([stew(world), chore()])
    loop_options.setdefault("core", EffectExecutor(world))
    loop = SimulationLoop(store, scheduler, strategy=Strategy("static", "static", policy),
                          hazard_waiting=hazard_waiting, **loop_options)
    monitor = Monitor(loop.trace, lambda: loop.all_agents, lambda name: store.get(name).meaning, world.snapshot,
                      task_types=store.names())
    loop.observers.append(monitor.observe)
    loop.harmoniser.hazards = monitor.active
    return loop


def run(scheduler: str, *, hazard_waiting: bool, policy: str = "conditional", swap_to: str | None = None,
        seed: int = 0, jitter: float = 0.0, secure_over_higher: bool = True,
        **options: Any) -> tuple[list[dict[str, Any]], SimulationLoop]:
    """stew at 0, chore (more urgent under ``scheduler``) at 5; ``swap_to`` replaces the scheduler at 6.
    ``secure_over_higher``: the scenario lets securing preempt the more urgent chore (these tests'
    premise; the safety rule, which holds it back by default, has tests of its own)."""
    world = Facts()
    loop = watched(world, schedulers.create(scheduler, **options), policy=policy, hazard_waiting=hazard_waiting,
                   seed=seed, core=EffectExecutor(world, seed, jitter),
                   rates=Rates(rep_rate=1.0, task_exe_rate=10.0, sp_up_rate=1.0),
                   secure_over_higher=secure_over_higher)
    loop.request(0.0, "stew", {"priority": 1, "deadline": 1000.0})
    loop.request(5.0, "chore", {"priority": 5, "deadline": 100.0})
    if swap_to is not None:
        loop.at(6.0, lambda: setattr(loop.harmoniser, "scheduler", schedulers.create(swap_to)))
    return loop.run().events, loop


def overruns(events: list[dict[str, Any]]) -> int:
    return int(metrics.compute(events)["safety"]["budget_overruns"])


def secures(events: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [e for e in events if e["event"] == "decision" and e.get("rule") == "secure"]


def test_without_hazard_waiting_the_conditional_policy_overruns_the_budget() -> None:
    events, _ = run("priority", hazard_waiting=False)
    assert overruns(events) == 1 and not secures(events)


def test_with_hazard_waiting_the_waiting_task_secures_in_time() -> None:
    events, loop = run("priority", hazard_waiting=True)
    assert overruns(events) == 0
    [decision] = secures(events)
    assert decision["dac"] == "d1" and decision["exeDA"] == "d2" and decision["hazard"] == "flame"
    assert decision["remaining_s"] <= decision["secure_s"] + decision["suspend_s"] + decision["margin_s"]
    assert decision["remaining_s"] > 0  # before the budget ran out, not after
    # the chore was suspended the normal way, then the stew secured (wait -> genSusp) and waited again
    t = decision["t"]
    after = [e for e in events if e["t"] >= t]
    susp = next(e for e in after if e["event"] == "command" and e["flag"] == "susp")
    assert susp["agent"] == "d2" and susp["by"] == "d1"
    start = next(e for e in after if e["event"] == "command" and e["flag"] == "start")
    assert start["agent"] == "d1" and start["secure"] is True
    moves = [(e["trigger"], e["from"], e["to"]) for e in after if e["event"] == "transition" and e["agent"] == "d1"]
    assert moves[:4] == [("secure", "wait", "genSusp"), ("planned", "genSusp", "exeSusp"),
                         ("finished", "exeSusp", "wait"), ("start", "wait", "upTsk")]
    plan = next(e for e in after if e["event"] == "plan" and e["agent"] == "d1")
    assert [s["action"] for s in plan["stages"]] == ["put_out"]  # the strict safe state, not the conditional one
    assert [e["status"] for e in events if e["event"] == "secure"] == ["start", "done"]
    # both tasks still finish
    assert sorted(e["agent"] for e in events if e["event"] == "end" and e["cause"] == "finished") == ["d1", "d2"]
    assert all(a.ended for a in loop.all_agents)


def test_the_relit_flame_is_a_new_episode_and_no_episode_is_secured_twice() -> None:
    events, _ = run("priority", hazard_waiting=True)
    ons = [e for e in events if e["event"] == "hazard" and e["status"] == "on"]
    assert len(ons) == 2  # lit, secured, lit again on resumption
    assert len(secures(events)) == 1  # the second episode is attended to the end


def test_alg2_with_classes_secures_against_a_higher_class() -> None:
    off, _ = run("alg2", hazard_waiting=False, classes=[["chore"], ["stew"]])
    on, _ = run("alg2", hazard_waiting=True, classes=[["chore"], ["stew"]])
    assert overruns(off) == 1 and overruns(on) == 0
    [decision] = secures(on)
    assert decision["algorithm"] == "alg2" and decision["dac"] == "d1"


def test_strict_policy_needs_no_securing() -> None:
    events, _ = run("priority", hazard_waiting=True, policy="strict")
    assert overruns(events) == 0 and not secures(events)


@pytest.mark.parametrize("name", schedulers.names())
def test_every_scheduler_secures_in_time(name: str) -> None:
    # the chore preempts under the priority scheduler; from t = 6 the scheduler under test decides
    off, _ = run("priority", hazard_waiting=False, swap_to=name)
    on, _ = run("priority", hazard_waiting=True, swap_to=name)
    assert overruns(on) == 0
    if overruns(off):  # the scheduler left the flame unattended: hazard-aware waiting secured it
        assert len(secures(on)) == 1 and secures(on)[0]["algorithm"] == name


@pytest.mark.parametrize("seed", range(6))
def test_randomised_durations_never_overrun(seed: int) -> None:
    events, _ = run("priority", hazard_waiting=True, seed=seed, jitter=0.5)
    assert overruns(events) == 0


def test_the_trace_is_reproducible() -> None:
    a, _ = run("alg2", hazard_waiting=True, seed=3, jitter=0.3)
    b, _ = run("alg2", hazard_waiting=True, seed=3, jitter=0.3)
    assert a == b


def test_a_hazard_whose_agent_ended_or_executes_is_not_secured() -> None:
    events, _ = run("priority", hazard_waiting=True)
    for d in secures(events):
        ended = {e["agent"] for e in events if e["event"] == "end" and e["t"] <= d["t"]}
        assert d["dac"] not in ended and d["dac"] != d["exeDA"]


def test_the_fsm_table_has_the_secure_transition() -> None:
    t = fsm.resolve(FsmState.WAIT, "secure", lambda g: True)
    assert t.target is FsmState.GEN_SUSP
    assert "wait --> genSusp : secure" in fsm.to_mermaid()


def test_the_margin_must_be_a_finite_number() -> None:
    for bad in (-1.0, float("inf"), "5", True):
        with pytest.raises(ConfigError, match="secure_margin_s"):
            TaskHarmoniser(schedulers.create("fifo"), lambda *a: None, trace=None,  # type: ignore[arg-type]
                           secure_margin_s=bad)  # type: ignore[arg-type]


def test_a_task_terminated_while_securing_ends_after_reaching_its_safe_state() -> None:
    world = Facts()
    loop = watched(world, schedulers.create("priority"), secure_over_higher=True)  # the chore is more urgent
    loop.request(0.0, "stew", {"priority": 1})
    loop.request(5.0, "chore", {"priority": 5})
    trace = loop.trace

    def term_when_securing() -> None:
        if any(e["event"] == "secure" for e in trace.events):
            loop.harmoniser.terminate("d1", "not hungry any more")
        else:
            loop.at(loop.now + 0.5, term_when_securing)

    loop.at(6.0, term_when_securing)
    events = loop.run().events
    end = next(e for e in events if e["event"] == "end" and e["agent"] == "d1")
    assert end["cause"] == "term"
    assert FLAME not in world.facts  # it put the flame out before ending
    assert [e["status"] for e in events if e["event"] == "secure"] == ["start", "ended"]
    assert overruns(events) == 0
    assert next(e for e in events if e["event"] == "end" and e["agent"] == "d2")["cause"] == "finished"


def test_a_hazard_whose_task_ended_is_not_secured() -> None:
    world = Facts()
    loop = watched(world, schedulers.create("priority"))
    loop.request(0.0, "stew", {"priority": 1})
    loop.request(5.0, "chore", {"priority": 5})
    loop.terminate(7.0, "d1", "ends in wait: the flame stays on, nobody's task")
    events = loop.run().events
    assert FLAME in world.facts and not secures(events)


def test_the_monitor_says_since_when_each_hazard_holds() -> None:
    world = Facts()
    store = TaskStore([stew(world), chore()])
    loop = SimulationLoop(store, schedulers.create("priority"), core=EffectExecutor(world))
    monitor = Monitor(loop.trace, lambda: loop.all_agents, lambda name: store.get(name).meaning, world.snapshot,
                      task_types=store.names())
    loop.observers.append(monitor.observe)
    loop.request(0.0, "stew", {"priority": 1})
    loop.run(until=10.0)
    [hz] = monitor.active()
    on = next(e for e in loop.trace.events if e["event"] == "hazard" and e["status"] == "on")
    assert (hz.agent, hz.name, hz.fact, hz.budget_s, hz.since) == ("d1", "flame", FLAME, BUDGET, on["t"])
    loop.run()
    assert monitor.active() == ()


def test_suspend_estimate_counts_the_blocking_stages_left() -> None:
    world = Facts()
    task = SyntheticTask("bake", [st("prep", 2.0), st("bake", 30.0, BLOCK), st("cool", 3.0, BLOCK), st("serve", 1.0)],
                         suspension={"bake": [st("tidy", 9.0)], "serve": [st("tidy", 4.0)]})
    loop = SimulationLoop(TaskStore([task]), schedulers.create("fifo"), core=EffectExecutor(world))
    loop.request(0.0, "bake")
    loop.run(until=1.0)
    [agent] = loop.all_agents
    assert agent.progress == (FsmState.EXE_TSK, 0)
    # in prep (suspendable, nothing to do on suspension) it may enter bake right after: the worst case
    assert agent.suspend_estimate(1.0) == pytest.approx(30.0 + 3.0 + 4.0)
    loop.run(until=12.0)
    assert agent.state is FsmState.EXE_TSK and agent.progress == (FsmState.EXE_TSK, 1)
    started = agent.ctx.stage_started
    assert started is not None
    # what is left of bake, all of cool (blocking), then the suspension at serve, where it would stop
    assert agent.suspend_estimate(12.0) == pytest.approx(started + 30.0 - 12.0 + 3.0 + 4.0)
    assert agent.secure_estimate(12.0) == 0.0  # nothing interrupted yet: the tree has no branch


def test_the_runner_gives_the_harmoniser_the_monitors_hazards() -> None:
    from experiments.inputs import scenario as scenarios
    from experiments.run.options import RunOptions
    from experiments.run.runner import build_robot

    loop, _ = build_robot(scenarios.load(scenarios.resolve("household")), RunOptions(seed=1, hazard_waiting=True))
    harm = loop.harmoniser
    assert harm.hazard_waiting and harm.hazards is not None
    assert isinstance(harm.hazards.__self__, Monitor)  # type: ignore[attr-defined]
    assert harm.hazards() == ()  # nothing observed yet


def test_a_shared_pattern_hazard_is_owned_by_whoever_made_it_true() -> None:
    """Two task types declare the same door hazard (a pattern without $args), a third does
    not.  A door open from the start is nobody's; a door a declaring task opens is that
    task's (not the earliest live agent of some declaring type); a door opened by a task
    that does not declare the hazard is nobody's.  One fact, one owner, one edge."""
    door = Hazard("door_open", ("open", "?d"), budget_s=60.0)
    world = Facts()
    world.facts.add(("open", "front"))
    opener_a = SyntheticTask("a", [st("wait", 5.0), st("open_kitchen", 1.0, add=("open", "kitchen"))])
    opener_b = SyntheticTask("b", [st("open_bath", 1.0, add=("open", "bath"))])
    other = SyntheticTask("c", [st("open_hall", 1.0, add=("open", "hall"))])
    opener_a.meaning = opener_b.meaning = Meaning(hazards=(door,))
    store = TaskStore([opener_a, opener_b, other])
    loop = SimulationLoop(store, schedulers.create("fifo"), core=EffectExecutor(world))
    monitor = Monitor(loop.trace, lambda: loop.all_agents, lambda name: store.get(name).meaning, world.snapshot,
                      task_types=store.names())
    loop.observers.append(monitor.observe)
    loop.request(0.0, "a")  # d1: opens the kitchen at ~6 s
    loop.request(0.0, "b")  # d2: opens the bathroom after d1
    loop.request(0.0, "c")  # d3: opens the hall, declares nothing
    loop.run()
    on = {tuple(e["fact"]): e["agent"] for e in loop.trace.events if e["event"] == "hazard" and e["status"] == "on"}
    assert on == {("open", "front"): None, ("open", "kitchen"): "d1", ("open", "bath"): "d2", ("open", "hall"): None}


@pytest.mark.parametrize(("scheduler", "options"), [("priority", {}), ("alg2", {"classes": [["chore"], ["stew"]]})])
def test_the_safety_rule_securing_never_preempts_a_higher_class_unless_allowed(scheduler: str,
                                                                               options: dict[str, Any]) -> None:
    """Before: hazard-aware waiting preempted a fallen person's task to turn off a tap.  By default it
    waits for the more urgent task, and the trace says which rule decided; the scenario may allow it."""
    held, _ = run(scheduler, hazard_waiting=True, secure_over_higher=False, **options)
    assert not secures(held) or all(d["exeDA"] != "d2" for d in secures(held))
    [why] = [e for e in held if e["event"] == "decision" and e.get("rule") == "secure held"]
    assert (why["dac"], why["exeDA"], why["switch"], why["hazard"]) == ("d1", "d2", False, "flame")
    assert not any(e["event"] == "command" and e["flag"] == "susp" and e["agent"] == "d2" for e in held)
    allowed, _ = run(scheduler, hazard_waiting=True, secure_over_higher=True, **options)
    assert [d["exeDA"] for d in secures(allowed)] == ["d2"]
    assert not any(e["event"] == "decision" and e.get("rule") == "secure held" for e in allowed)


def test_the_safety_rule_does_not_hold_back_securing_against_a_lower_class() -> None:
    """The stew outranks the chore here: securing goes ahead, as before."""
    events, _ = run("alg2", hazard_waiting=True, secure_over_higher=False, classes=[["stew"], ["chore"]])
    assert not any(e["event"] == "decision" and e.get("rule") == "secure held" for e in events)


def test_the_monitor_sees_every_agent_that_ends_or_arrives() -> None:
    """Monitor._alive answers from its memo only while the same agents are there and none of
    the live ones has ended: an end, a new agent or another list is always seen."""
    from types import SimpleNamespace

    from tasker.trace import Trace

    agents = [SimpleNamespace(id=f"d{i}", ended=False) for i in range(4)]
    m = Monitor(Trace(), lambda: agents, lambda name: Meaning(), lambda: frozenset())

    def truth(xs: list[Any]) -> tuple[tuple[str, bool], ...]:
        return tuple((a.id, a.ended) for a in xs)

    rng = random.Random(5)
    for _ in range(200):
        move = rng.random()
        if move < 0.3:
            rng.choice(agents).ended = True
        elif move < 0.5:
            agents.append(SimpleNamespace(id=f"d{len(agents)}", ended=rng.random() < 0.2))
        elif move < 0.55:
            agents = [SimpleNamespace(id=a.id, ended=a.ended) for a in agents]  # the same ids, other agents
            agents[rng.randrange(len(agents))].ended = False
        assert m._alive(list(agents)) == truth(agents)
