"""Problem-builder hook of human_fell: a person who is no longer down needs no check nor help."""

from __future__ import annotations

from collections.abc import Iterable

from tasker.task import TaskContext
from tasker.world import Fact, WorldState


def extra_facts(ctx: TaskContext, world: WorldState) -> Iterable[Fact]:
    """A person the world no longer says has fallen needs neither a check nor help (R6)."""
    person = ctx.args["person"]
    if not world.holds("fallen", person):
        yield ("checked", person)
        yield ("help_called", person)
