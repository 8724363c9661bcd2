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


class WorldError(TaskerError):
    """The world (``World.advance`` or ``World.snapshot``) raised: the run cannot go on meaningfully.

    Unlike an exception in one task's hook or skill, which ends only that task, a
    broken world leaves every task blind; the loop ends every live agent (cause
    ``error``) and stops the run with a ``run`` event ``{"status": "aborted"}``.
    """


class RunAborted(TaskerError):
    """A run stopped before its end because something outside the tasks failed.

    ``reason`` says what; ``result`` carries what the run produced so far (the runner
    puts its partial :class:`~experiments.run.runner.RunResult` here after writing the trace,
    ``run.json`` and ``metrics.json``), or ``None`` when raised by the loop itself.
    The original exception is the ``__cause__``.
    """

    def __init__(self, reason: str, result: object = None) -> None:
        self.reason = reason
        self.result = result
        super().__init__(f"run aborted: {reason}")


class RunInterrupted(KeyboardInterrupt):
    """The user stopped a run (Ctrl-C).  Still a :class:`KeyboardInterrupt`, so whatever
    catches those goes on doing so; ``result`` carries what the run produced so far (the
    runner writes the trace, ``run.json`` and ``metrics.json`` first)."""

    def __init__(self, reason: str, result: object = None) -> None:
        self.reason = reason
        self.result = result
        super().__init__(reason)


class AgentEnded(TaskerError):
    """An agent ended (a hook raised) while the harmoniser was asking it something (``reqSP``).

    The harmoniser catches it: the agent is no longer a candidate, the schedule is
    made again without it.
    """

    def __init__(self, agent: str, reason: str) -> None:
        self.agent = agent
        self.reason = reason
        super().__init__(f"agent {agent} ended: {reason}")


class UsageError(TaskerError, ValueError):
    """A command-line argument is invalid; the message starts with the argument's name."""

    def __init__(self, argument: str, message: str) -> None:
        self.argument = argument
        super().__init__(f"argument {argument}: {message}")
