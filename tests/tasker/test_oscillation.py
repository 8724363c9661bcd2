"""No oscillation, whatever the scheduler (the harmoniser's oscillation guard).

The TaBSA benchmark calls it oscillation when, with no new request in between, a task
becomes ``exeDA`` a third time within 180 s.  :class:`ThrashTask` is built to make
every preemptive scheduler thrash: a waiting task reports itself urgent (low cost,
high priority, short cTime, a deadline now) and an executing one the opposite, so
each scheduler wants to switch back as soon as it has switched.
"""

from __future__ import annotations

from typing import Any

import pytest

from tasker import schedulers
from tasker.errors import ConfigError
from tasker.harmoniser import OscillationGuard
from tasker.messages import CompletionCost, CostParams, SPRequest
from tasker.synthetic import SyntheticTask
from tasker.task import TaskContext

from .helpers import make_loop, st

WINDOW = 180.0
UNMOVED = {"tabsa-simple", "tabsa-simple2", "tabsa-distance", "tabsa-scheduler"}
"""TaBSA's own agents read no priority, cost or deadline of a report, and re-read cTime only
when a request arrives or the executing task changes (``tasker.schedulers.tabsa``): the
flip of :class:`ThrashTask` does not move them, so they do not thrash here."""


class ThrashTask(SyntheticTask):
    """Urgent while waiting, not urgent while executing: every ranking flips after each switch."""

    def compute_params(self, ctx: TaskContext) -> CostParams:
        if ctx.stage_started is not None:  # executing a stage of exeTsk
            return CostParams(self.name, cost=1000.0, cps=0.0, c_time=100.0, deadline=ctx.now + 1000.0, priority=0)
        return CostParams(self.name, cost=1.0, cps=10.0, c_time=1.0, deadline=ctx.now, priority=10)

    def request_sp(self, ctx: TaskContext, request: SPRequest) -> Any:
        p = self.compute_params(ctx)
        return CompletionCost(p.cost, p.cps)


def oscillations(events: list[dict[str, Any]], window: float = WINDOW, count: int = 2) -> list[str]:
    """Agents that became exeDA a (count+1)-th time within ``window`` s with no new request in between."""
    requests = [e["t"] for e in events if e["event"] == "request"]
    starts: dict[str, list[float]] = {}
    for e in events:
        if e["event"] == "command" and e["flag"] == "start":
            starts.setdefault(e["agent"], []).append(e["t"])
    bad = []
    for agent, ts in starts.items():
        for a, b in zip(ts, ts[count:], strict=False):
            if b - a < window and not any(a < r <= b for r in requests):
                bad.append(agent)
                break
    return bad


def thrash_loop(scheduler: str, guard: OscillationGuard | None) -> Any:
    loop = make_loop([ThrashTask("thrash", [st("work", 60.0)])], scheduler=scheduler)
    loop.harmoniser.guard = guard
    loop.request(0.0, "thrash")
    loop.request(0.0, "thrash")
    return loop


@pytest.mark.parametrize("scheduler", schedulers.names())
def test_no_task_becomes_exe_da_a_third_time_within_the_window(scheduler: str) -> None:
    loop = thrash_loop(scheduler, OscillationGuard(window_s=WINDOW, count=2))
    if not loop.harmoniser.scheduler.work_conserving:  # a time table: these tasks' slots (deadline now) never come
        assert oscillations(loop.run(until=600.0).events) == []
        return
    tr = loop.run()
    assert oscillations(tr.events) == []
    assert sorted(e["cause"] for e in tr.of("end")) == ["finished", "finished"]
    if loop.harmoniser.scheduler.preemptive and scheduler not in UNMOVED:  # the guard stopped it, and says so
        held = [e for e in tr.events if e["event"] == "decision" and "held" in e]
        assert held and all(e["switch"] is False and e["held"]["guard"] == "oscillation" for e in held)
        assert held[0]["held"]["count"] == 2 and held[0]["held"]["window_s"] == WINDOW


@pytest.mark.slow
@pytest.mark.parametrize("scheduler", [n for n in schedulers.names()
                                       if schedulers.create(n).preemptive and n not in UNMOVED])
def test_the_scenario_thrashes_without_the_guard(scheduler: str) -> None:
    """The scenario is built to thrash: without the guard every preemptive scheduler oscillates."""
    loop = thrash_loop(scheduler, None)
    tr = loop.run(until=30.0)
    assert oscillations(tr.events) != []


def test_a_new_request_may_preempt_again() -> None:
    """Appendix B: after a new request the history is cleared, so a legitimate preemption goes through."""
    loop = thrash_loop("priority", OscillationGuard(window_s=WINDOW, count=2))
    loop.run(until=20.0)
    held_before = len([e for e in loop.trace.of("decision") if "held" in e])
    assert held_before > 0
    exe = loop.harmoniser.exe_da
    loop.request(20.5, "thrash")  # d3: the request clears the history; the held switch goes through
    tr = loop.run(until=25.0)
    starts = [e for e in tr.of("command", flag="start") if e["t"] > 20.5]
    assert starts and starts[0]["t"] < 22.0 and starts[0]["agent"] != exe


def test_the_guard_is_configurable_and_checked() -> None:
    loop = thrash_loop("srtf", OscillationGuard(window_s=WINDOW, count=3))
    tr = loop.run(until=100.0)
    assert oscillations(tr.events, count=3) == [] and oscillations(tr.events, count=2) != []
    for bad in ({"window_s": -1.0}, {"count": 0}, {"count": 1.5}, {"window_s": float("inf")}):
        with pytest.raises(ConfigError, match="OscillationGuard"):
            OscillationGuard(**bad)
