"""Problem-builder hook of carry_object: passages without doors.

Closing the doors on a suspension is declared in ``task.toml`` (``[[suspension]]``), so the
static and the planned strategy pursue the same goal."""

from __future__ import annotations

from collections.abc import Iterable

from tasker.task import TaskContext
from tasker.world import Fact, WorldState


def extra_facts(ctx: TaskContext, world: WorldState) -> Iterable[Fact]:
    """Every ordered pair of places with no door between them is a free passage."""
    places = sorted(n for n, t in world.objects.items() if t == "place")
    doors = {(f[2], f[3]) for f in world.matching("door_between") if len(f) == 4}
    for a in places:
        for b in places:
            if a != b and (a, b) not in doors:
                yield ("free_passage", a, b)
