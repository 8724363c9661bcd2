"""The dynamic agent's latched initial conditions: its command buffer as the FSM's guards read it.

Fig. 5 changes state on initial conditions the harmoniser sets -- ``ic_start``,
``ic_susp``, ``ic_term`` (eqs. 13-17 carry them as commands) -- and on the agent's own
``ic_term``.  A command acts at once only where the FSM has a row for it; elsewhere
the agent either holds it (a ``susp`` during a blocking stage is honoured at the next
suspendable one, eqs. 25-26) or drops it (a ``start`` to an agent in ``cmd``).
:data:`tasker.fsm.LATCHES` says which, per state; :data:`tasker.fsm.TERM_CAUSES` which
``ic_term`` wins.  This module only runs that definition: :class:`Latched` holds the
conditions, and the rows of :data:`tasker.fsm.TRANSITIONS` read them as guards
(:meth:`Latched.holds`).  Stdlib only.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from tasker import fsm
from tasker.errors import FSMError
from tasker.fsm import FsmState

_START, _SUSP, _TERM = (fsm.LATCH_OF[c] for c in ("start", "susp", "term"))


@dataclass(frozen=True, slots=True)
class Term:
    """A latched ``ic_term``: why the task ends, and who latched it (one of :data:`tasker.fsm.TERM_CAUSES`)."""

    reason: str
    cause: str

    def __post_init__(self) -> None:
        if self.cause not in fsm.TERM_CAUSES:
            raise FSMError(f"ic_term cause must be one of {list(fsm.TERM_CAUSES)}, got {self.cause!r}")


class Latched:
    """The initial conditions one agent holds now.

    ``start`` (with its ``secure`` data), ``susp`` and ``term`` are set by
    :meth:`receive` and :meth:`terminate` and dropped by :meth:`enter`, each as
    :data:`tasker.fsm.LATCHES` says.
    """

    __slots__ = ("start", "secure", "susp", "term")

    def __init__(self) -> None:
        self.start = False
        self.secure = False
        self.susp = False
        self.term: Term | None = None

    def receive(self, command: str, data: Mapping[str, Any], state: FsmState) -> None:
        """A command (``start``, ``susp`` or ``term``) read in ``state``: latch it, unless it is void there."""
        latch = fsm.LATCH_OF[command]
        if state not in latch.held_in:
            return
        if latch is _START:
            self.start, self.secure = True, bool(data.get("secure"))
        elif latch is _SUSP:
            self.susp = True
        else:
            self.terminate(str(data.get("reason", "terminated by the harmoniser")), "term")

    def terminate(self, reason: str, cause: str) -> None:
        """Latch ``ic_term`` unless one of an equal or higher cause is latched already."""
        rank = fsm.TERM_CAUSES.index(cause)
        if self.term is None or fsm.TERM_CAUSES.index(self.term.cause) < rank:
            self.term = Term(reason, cause)

    def enter(self, state: FsmState) -> None:
        """The agent entered ``state``: drop what it does not hold."""
        if state not in _START.held_in:
            self.start = self.secure = False
        if state not in _SUSP.held_in:
            self.susp = False
        if state not in _TERM.held_in:
            self.term = None

    def holds(self, name: str) -> bool:
        """The guard ``name`` of a latched condition (``ic_start``, ``ic_susp``, ``ic_term``, ``secure``)."""
        if name == "ic_start":
            return self.start
        if name == "ic_susp":
            return self.susp
        if name == "ic_term":
            return self.term is not None
        if name == "secure":
            return self.start and self.secure
        raise FSMError(f"{name!r} is not a latched condition")
