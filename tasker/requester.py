"""The task requester (tra): how a user, a device or a scenario asks for tasks.

A requester checks a request against the task store *before* it reaches the
harmoniser: a bad type or bad arguments raise a clear error and nothing else
changes.  It can also terminate a task and change a task's arguments while it runs
or waits (R2: e.g. a user raises a priority).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from tasker.errors import TaskerError
from tasker.harmoniser import Request, TaskHarmoniser
from tasker.store import TaskStore


class Requester:
    """A named requester attached to one harmoniser."""

    def __init__(self, store: TaskStore, harmoniser: TaskHarmoniser, name: str = "user") -> None:
        self.store = store
        self.harmoniser = harmoniser
        self.name = name

    def request(self, task_type: str, args: Mapping[str, Any] | None = None, *, renews: str | None = None) -> str:
        """Ask for a task; returns its agent id (``d1``, ``d2``, ...).  ``renews``: the agent
        whose task (ended without doing its work) this asks for again."""
        checked = self.store.validate(task_type, args or {})
        return self.harmoniser.submit(Request(task_type, checked, self.name, renews))

    def terminate(self, agent_id: str, reason: str | None = None) -> None:
        self.harmoniser.terminate(agent_id, reason or f"terminated by {self.name}")

    def change(self, agent_id: str, args: Mapping[str, Any]) -> None:
        """Change some arguments of a live task; the whole new set is validated first."""
        agent = self.harmoniser.agents.get(agent_id)
        if agent is None or agent.ended:
            raise TaskerError(f"no active task {agent_id!r}; active: {sorted(self.harmoniser.agents) or 'none'}")
        merged = {**agent.ctx.args, **dict(args)}
        checked = self.store.validate(agent.ctx.task_type, merged)
        agent.update_args(checked, requester=self.name, now=self.harmoniser.now)
