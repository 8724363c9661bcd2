"""The agent's memory ``c_dy``: what the framework remembers per agent, typed, beside the task's own keys.

Packages used to share per-agent state through string keys of ``ctx.memory`` (the agent wrote
``"interruption_s"`` as a literal, the planners read it through a constant of their own).  What
the framework itself remembers now lives in typed fields of :class:`AgentMemory`, defined here
and nowhere else, so every writer and reader names the same attribute and mypy checks its type:

==========================  ==================  =====================================================
field                       written by          read by
==========================  ==================  =====================================================
``interruption_s``          the agent (``susp``  suspension trees (``conditional`` branches), the
                            carries             ``derived`` goal, a task folder's ``task.py`` hook
                            ``expected_s``)
``planned_from``            a planned task      :mod:`planners.stagecheck` (is a stage still
                            (each plan)         applicable?)
``restore_baseline``        a planned task      the same (``[problem] restore``)
``suspension_ahead``        a planned task      the same (a suspension planned while ``exeTsk`` runs)
==========================  ==================  =====================================================

A task type keeps its own state under keys of its choosing: ``AgentMemory`` is a ``dict``
for them (``ctx.memory["reached"] = ...``).  The one key the framework used to document,
``ctx.memory["interruption_s"]``, still reads and writes :attr:`AgentMemory.interruption_s`,
so a user's ``task.py`` written against it keeps working; new code uses the attribute.
"""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any

from tasker.stage import Stage
from tasker.world import Fact

INTERRUPTION_KEY = "interruption_s"
"""The old ``ctx.memory`` key of :attr:`AgentMemory.interruption_s`; still read and written through it."""

_NOT_SET = object()


class AgentMemory(dict[str, Any]):
    """One agent's memory: the framework's typed fields, and the task type's own keys as a ``dict``.

    The fields start empty (``None``): ``interruption_s`` unknown means a long interruption
    (the safe assumption); the others are made by the first plan that needs them.
    :meth:`copy` copies the keys and the fields shallowly — a copy made for an estimate shares
    ``planned_from``'s list once it exists, as the string-keyed memory did.
    """

    __slots__ = ("interruption_s", "planned_from", "restore_baseline", "suspension_ahead")

    interruption_s: float | None
    """How long the interruption the last ``susp`` announced is expected to last (s); None: unknown, long."""
    planned_from: list[tuple[tuple[Stage, ...], frozenset[Fact]]] | None
    """The last plans' stages, each with the facts it was made from (newest last)."""
    restore_baseline: frozenset[Fact] | None
    """The facts of ``[problem] restore``'s patterns that held when the task first planned."""
    suspension_ahead: tuple[Hashable, tuple[Fact, ...]] | None
    """The symbolic suspension problem planned while ``exeTsk`` ran and its plan's steps; None: no plan."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__()
        self.interruption_s = None
        self.planned_from = None
        self.restore_baseline = None
        self.suspension_ahead = None
        self.update(*args, **kwargs)

    def __setitem__(self, key: str, value: Any) -> None:
        if key == INTERRUPTION_KEY:
            self.interruption_s = None if value is None else float(value)
        else:
            super().__setitem__(key, value)

    def __missing__(self, key: str) -> Any:
        if key == INTERRUPTION_KEY and self.interruption_s is not None:
            return self.interruption_s
        raise KeyError(key)

    def __contains__(self, key: object) -> bool:
        if key == INTERRUPTION_KEY:
            return self.interruption_s is not None
        return super().__contains__(key)

    def __delitem__(self, key: str) -> None:
        if key == INTERRUPTION_KEY:
            if self.interruption_s is None:
                raise KeyError(key)
            self.interruption_s = None
        else:
            super().__delitem__(key)

    def get(self, key: str, default: Any = None) -> Any:
        if key == INTERRUPTION_KEY:
            return default if self.interruption_s is None else self.interruption_s
        return super().get(key, default)

    def pop(self, key: str, default: Any = _NOT_SET) -> Any:
        if key == INTERRUPTION_KEY:
            value = self.interruption_s
            if value is None:
                if default is _NOT_SET:
                    raise KeyError(key)
                return default
            self.interruption_s = None
            return value
        if default is _NOT_SET:
            return super().pop(key)
        return super().pop(key, default)

    def setdefault(self, key: str, default: Any = None) -> Any:
        if key == INTERRUPTION_KEY:
            if self.interruption_s is None:
                self[key] = default
            return self.interruption_s
        return super().setdefault(key, default)

    def update(self, *args: Any, **kwargs: Any) -> None:
        for key, value in dict(*args, **kwargs).items():
            self[key] = value

    def copy(self) -> AgentMemory:
        """The keys and the fields, copied shallowly (what an estimate's copy of the context gets)."""
        out = AgentMemory(super().items())
        out.copy_fields(self)
        return out

    def copy_fields(self, of: AgentMemory) -> None:
        """Take ``of``'s typed fields (shallowly): every field, so that no copy forgets a new one."""
        for name in AgentMemory.__slots__:
            setattr(self, name, getattr(of, name))

    def __repr__(self) -> str:
        fields = ", ".join(f"{n}={getattr(self, n)!r}" for n in AgentMemory.__slots__ if getattr(self, n) is not None)
        return f"AgentMemory({dict.__repr__(self)}{', ' + fields if fields else ''})"


class WatchedMemory(AgentMemory):
    """A copy of a memory, made for an estimate, that notes whether anything read ``interruption_s``
    (:attr:`interruption_read`): any way of reading it goes through the one attribute — ``memory["interruption_s"]``,
    :meth:`get`, ``in``, :meth:`copy`, ``repr``, :mod:`copy` and :mod:`pickle` included.  An estimate that
    never read it holds for any expected interruption (:func:`tasker.securing.suspend_estimate`).  Writing it
    is not reading it; reading it back after a write counts (conservatively)."""

    __slots__ = ("_interruption", "interruption_read")

    def __init__(self, of: AgentMemory) -> None:
        """What :meth:`AgentMemory.copy` gives of ``of``, watched from now on."""
        self._interruption: float | None = None
        super().__init__(dict.items(of))
        self.copy_fields(of)
        self.interruption_read = False

    @property
    def interruption_s(self) -> float | None:
        self.interruption_read = True
        return self._interruption

    @interruption_s.setter
    def interruption_s(self, value: float | None) -> None:
        self._interruption = value
