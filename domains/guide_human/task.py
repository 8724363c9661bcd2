"""Problem-builder hook of guide_human: passages without doors (:mod:`domains.doors`), so that
the robot opens a door it finds closed on its way to or with the person."""

from __future__ import annotations

from collections.abc import Iterable

from domains.doors import free_passages
from tasker.task import TaskContext
from tasker.world import Fact, WorldState


def extra_facts(ctx: TaskContext, world: WorldState) -> Iterable[Fact]:
    """Every ordered pair of places with no door between them is a free passage."""
    return free_passages(world)
