"""The seam between experiments and robot: robot's Simulation offers every member of SimulatedWorld.

mypy holds it where the runner returns a ``Simulation`` as a ``SimulatedWorld``; this test says so
without mypy, and fails if the protocol names a member the simulation lost."""

from __future__ import annotations

import inspect

from experiments.run.simulation import SimulatedWorld
from robot.sim import Simulation
from tasker.protocols import CoreAgent, World


def _members(proto: type) -> set[str]:
    return {n for n in vars(proto) if not n.startswith("_")} | {n for n in getattr(proto, "__annotations__", {})}


def test_the_simulation_has_every_member_of_the_protocol() -> None:
    wanted = _members(SimulatedWorld) | _members(World) | _members(CoreAgent)
    assert {"spec", "motion", "people", "snapshot", "advance", "begin", "rate_hz"} <= wanted
    init = inspect.getsource(Simulation.__init__)
    missing = sorted(n for n in wanted if not hasattr(Simulation, n) and f"self.{n} " not in init
                     and f"self.{n}:" not in init)
    assert missing == []
