"""The simulation loop's clock: what happens at the horizon itself still happens."""

from __future__ import annotations

from .helpers import guide, make_loop


def test_the_horizon_tick_runs_then_the_run_stops() -> None:
    """A run covers [0, horizon]: a request due at the horizon is taken, then the run stops there.
    (A planted off-by-one that stopped before the horizon's tick passed the fast lane before this.)"""
    loop = make_loop([guide()])
    loop.horizon = 10.0
    loop.request(0.0, "guide")
    loop.request(10.0, "guide")
    trace = loop.run()
    assert [(e["t"], e["agent"]) for e in trace.of("request")] == [(0.0, "d1"), (10.0, "d2")]
    stops = trace.of("run")[1:]
    assert [(e["t"], e["status"]) for e in stops] == [(10.0, "horizon reached")]
    assert trace.events[-1]["event"] == "run"  # the last line: nothing after the stop
