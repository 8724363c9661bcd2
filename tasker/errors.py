"""Errors raised by the TaskER core.

Every error a user can cause (a bad request, an unknown scheduler, a malformed
task type) is a :class:`TaskerError`, so a command line can catch one class and
print a clear message instead of a traceback.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any


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


# -- reading a user's files ------------------------------------------------------------------------
# Every error class of the project lives here (house style 15); the modules that raise them
# re-export them under their old names (``from experiments.inputs.fields import ScenarioError``
# still works and is the same class).


def located(file: str, line: int | None, field: str, message: str) -> str:
    """``file:line: field: message``, leaving out what is unknown: how every input error reads."""
    where = f"{file}:{line}" if line else file
    return f"{where}: {field}: {message}" if field else f"{where}: {message}"


class InputError(TaskerError, ValueError):
    """A user's file is malformed.  ``str()`` is ``file:line: field: message``.

    ``InputError(text)`` with a single argument is a whole message (the older subclasses
    :class:`ScenarioError` and :class:`WorldFileError` were raised that way, and still may be).
    Raised by :mod:`tasker.support.reader`, the one strict reader.
    """

    def __init__(self, file: str | Path, message: str | None = None, *, line: int | None = None,
                 field: str = "") -> None:
        if message is None:
            self.file, self.line, self.field, self.message = "", None, "", str(file)
            super().__init__(str(file))
            return
        self.file = str(file)
        self.line = line
        self.field = field
        self.message = message
        super().__init__(located(self.file, line, field, message))


class ScenarioError(InputError):
    """A scenario file is malformed; the message names the file, the line and the field."""


class WorldFileError(InputError):
    """A world file is missing, unreadable or holds a field of the wrong shape (an :class:`InputError`)."""


class SpecError(InputError):
    """A sweep spec is malformed; the message names the file, the line and the field."""


class ExplainError(InputError):
    """A run folder, agent or time that ``tasker explain`` cannot explain (a damaged file of the
    run folder is named with its line and field, as every reader's errors are)."""


class TraceError(TaskerError, ValueError):
    """An event that is not one of :data:`tasker.events.KINDS` or whose fields are wrong."""


class BadInput(UsageError):
    """A command-line argument that names no place and is no ``x,y[,yaw]`` (``tasker world``)."""


# -- task definitions and planners -----------------------------------------------------------------


class DefinitionError(TaskerError, ValueError):
    """A task definition (PDDL file, ``task.toml``, ``task.py``) is malformed.

    ``file`` names it, ``line``/``col`` locate the fault when known, ``reason`` says
    what is wrong; ``str()`` gives ``file:line:col: reason`` like a compiler.
    """

    def __init__(self, file: str | Path, reason: str, line: int | None = None, col: int | None = None) -> None:
        self.file = str(file)
        self.reason = reason
        self.line = line
        self.col = col
        where = self.file + (f":{line}" if line is not None else "") + (f":{col}" if col is not None else "")
        super().__init__(f"{where}: {reason}")


class PddlError(DefinitionError):
    """A PDDL domain or problem is malformed or needs a feature no planner here supports.

    ``reader_only`` marks legal PDDL that only unified-planning's reader cannot read
    (``(either ...)`` types, ``:derived`` predicates, a predicate naming a parameter twice, a name
    glued to a variable, action costs without ``(= (total-cost) 0)``): ``tasker plan`` then reads
    the task with Fast Downward's translator (:mod:`planners.plan_files`); task folders, which need
    UP's model, refuse it.
    Any other refusal is an error in the PDDL, which the translator must not be left to
    accept (it takes an undeclared type for an empty one, for one).
    """

    def __init__(self, file: str | Path, reason: str, line: int | None = None, col: int | None = None,
                 *, reader_only: bool = False) -> None:
        super().__init__(file, reason, line, col)
        self.reader_only = reader_only


class HookExited(DefinitionError):
    """A ``task.py`` hook called ``sys.exit()``: an exception like any other the hook raises, so its
    task ends alone (cause ``error``) and the message names the folder, not a bare exit status."""


class SchemaError(TaskerError, ValueError):
    """Fast Downward's parser refused the domain; the message is the parser's (:mod:`planners.schema`)."""


class EngineNotInstalled(TaskerError):
    """A temporal engine was named that is not installed here; the message says which package brings it."""


# -- experiments: results, sweeps, the live session ------------------------------------------------


class StoreError(TaskerError, RuntimeError):
    """The results database cannot be opened, does not have the expected schema, or holds a corrupt row."""


class SweepError(TaskerError, RuntimeError):
    """A sweep cannot run (bad arguments, two jobs with the same key)."""


class Refused(TaskerError, ValueError):
    """Something asked over HTTP that the session does not do; ``str()`` is the whole message
    (``where: field: message``), :meth:`to_json` the body of the 4xx answer."""

    def __init__(self, status: int, where: str, message: str, field: str = "") -> None:
        self.status, self.where, self.field, self.message = status, where, field, message
        super().__init__(f"{where}: {field}: {message}" if field else f"{where}: {message}")

    def to_json(self) -> dict[str, Any]:
        return {"detail": str(self), "field": self.field, "message": self.message}
