"""Problem-builder hook of carry_object: passages without doors (:mod:`domains.doors`).

Closing the doors on a suspension is declared in ``task.toml`` (``[[suspension]]``), so the
static and the planned strategy pursue the same goal."""

from __future__ import annotations

from collections.abc import Iterable

from domains.doors import free_passages
from tasker.task import TaskContext
from tasker.world import Fact, WorldState


def extra_facts(ctx: TaskContext, world: WorldState) -> Iterable[Fact]:
    """Every ordered pair of places with no door between them is a free passage."""
    return free_passages(world)
