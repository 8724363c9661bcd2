"""Errors raised by the TaskER core.

Every error a user can cause (a bad request, an unknown scheduler, a malformed
task type) is a :class:`TaskerError`, so a command line can catch one class and
print a clear message instead of a traceback.
"""

from __future__ import annotations


class TaskerError(Exception):
    """Base class of every error the framework raises on purpose."""


class ConfigError(TaskerError, ValueError):
    """A configuration value (rate, scheduler option, task-type definition) is invalid."""


class UnknownName(TaskerError, KeyError):
    """A name was looked up in a registry that does not hold it.

    The message lists the names that are known, so a typo is easy to fix.
    """

    def __init__(self, kind: str, name: str, known: list[str]) -> None:
        self.kind = kind
        self.name = name
        self.known = sorted(known)
        listing = ", ".join(self.known) if self.known else "(none registered)"
        super().__init__(f"unknown {kind} {name!r}; known: {listing}")

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


class BadRequest(TaskerError, ValueError):
    """A task request names a known type but carries arguments that do not fit it."""


class PlanningFailed(TaskerError):
    """A task's planning hook (``upTsk`` or ``genSusp``) could not produce stages.

    ``status`` says why (``"unsolvable"``, ``"timeout"``, ``"error"``) so the agent can
    put the reason in the trace.
    """

    def __init__(self, status: str, message: str) -> None:
        self.status = status
        super().__init__(message)


class InvariantViolation(TaskerError, AssertionError):
    """The model's invariant broke (e.g. two agents in ``cmd``). Always a bug."""


class FSMError(TaskerError, RuntimeError):
    """A transition that the hierarchical FSM of Fig. 5 does not allow was attempted."""
