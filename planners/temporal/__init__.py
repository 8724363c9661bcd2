"""Temporal PDDL 2.1 (durative actions) for tasker: PlanSys2's and ROSPlan's domains.

* :mod:`~planners.temporal.reading` — is a domain temporal; read it (and PlanSys2's empty blocks)
  with unified-planning's reader, errors located;
* :mod:`~planners.temporal.engines` — the engines (LPG, Aries, Kairos; TAMER when installed)
  through UP's factory, with the settings that make them work as installed and deterministic;
* :mod:`~planners.temporal.portfolio` — :class:`TemporalPlanner`: engines in turn within one
  budget, every plan validated by UP's ``up_time_triggered_validator``;
* :mod:`~planners.temporal.results` — timed steps, attempts, :class:`TemporalResult`.

Nothing here is imported by the classical path: a domain goes here only when
:func:`~planners.temporal.reading.is_temporal` says so.
"""

from __future__ import annotations

from planners.temporal.reading import is_temporal

__all__ = ["is_temporal"]
