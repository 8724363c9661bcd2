"""Problem-builder hook of human_fell: a person who is no longer down needs no check nor help;
passages without doors (:mod:`domains.doors`), so that the robot opens a door it finds closed."""

from __future__ import annotations

from collections.abc import Iterable

from domains.doors import free_passages
from tasker.task import TaskContext
from tasker.world import Fact, WorldState


def extra_facts(ctx: TaskContext, world: WorldState) -> Iterable[Fact]:
    """A person the world no longer says has fallen needs neither a check nor help (R6); every
    ordered pair of places with no door between them is a free passage."""
    person = ctx.args["person"]
    if not world.holds("fallen", person):
        yield ("checked", person)
        yield ("help_called", person)
    yield from free_passages(world)


def check_terminate(ctx: TaskContext, world: WorldState) -> str | None:
    """``ic_term`` (paper, Appendix B): the person got up before the robot came, so nothing is needed.

    Only while the task is not executing a check (``compSP``, ``wait``); once the robot has
    checked the person the task finishes normally.
    """
    person = ctx.args["person"]
    if not world.holds("fallen", person) and not ctx.done:
        return f"{person} is fine"
    return None
