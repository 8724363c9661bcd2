"""Experiments: scenario files, runs, sweeps, metrics, plots, and the ``tasker`` command line.

The calls a notebook needs are exported here (:mod:`experiments.facade`, imported on first use so
that ``import experiments`` stays cheap)::

    import experiments
    result = experiments.run_scenario("paper", out="out/paper")   # RunResult: record, metrics, trace
    loaded = experiments.load_run("out/paper")           # LoadedRun: record, metrics, timeline
    summary = experiments.run_sweep("my_sweep.toml", "out/my.db", workers=2)
    analysis = experiments.compare("out/my.db")
    files = experiments.sweep_report("out/my.db", "out/my-report")
    days = experiments.day(PROTOCOL, 3, ["edf", "lookahead"], out="out/day")
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from experiments.facade import DayReport, LoadedRun, compare, day, load_run, run_scenario, run_sweep, sweep_report

__all__ = ["DayReport", "LoadedRun", "compare", "day", "load_run", "run_scenario", "run_sweep", "sweep_report"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from experiments import facade

        return getattr(facade, name)
    raise AttributeError(f"module 'experiments' has no attribute {name!r}")
