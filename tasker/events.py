"""The trace's events, one frozen type per kind: the only things :meth:`tasker.trace.Trace.emit` takes.

The trace is the one interface between the model and everything that measures it, so its
vocabulary is defined here, once, as data: each class names its ``event`` kind
(:attr:`Event.KIND`), its fields in the order they are written, which of them may be left
out, and what each means (``docs/trace.md`` is generated from these definitions and a test
holds it to them).  A field is written under its JSON name (``from``, ``exeDA``, ...) where
that is not a Python name.

* :meth:`Event.fields` gives the JSON fields (``None`` optional fields left out), in the
  fixed order the canonical encoding of :mod:`tasker.trace` writes;
* :func:`parse` reads one event back from a decoded JSON object, checking every field,
  so a damaged trace is refused with the field that is wrong (never a ``KeyError`` later).

Values are stored as given (lists stay lists, so a live trace and its records compare as
before); :func:`parse` turns the trace's ``"inf"`` strings back into floats where a number is
expected.  Standard library only.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import MISSING, dataclass, field
from dataclasses import fields as dc_fields
from typing import Any, ClassVar

from tasker.errors import TraceError as TraceError  # defined there; re-exported here


def _json(name: str, doc: str, *, default: Any = MISSING) -> Any:
    meta = {"json": name, "doc": doc}
    return field(metadata=meta) if default is MISSING else field(default=default, metadata=meta)


def _doc(doc: str, *, default: Any = MISSING) -> Any:
    return field(metadata={"doc": doc}) if default is MISSING else field(default=default, metadata={"doc": doc})


@dataclass(frozen=True, slots=True)
class Event:
    """One event of the trace at simulated time ``t`` (seconds since the start of the run)."""

    KIND: ClassVar[str] = ""
    """The ``event`` field of the JSON line."""
    OPTIONAL: ClassVar[frozenset[str]] = frozenset()
    """Fields left out of the JSON line when they are ``None``."""
    _SPEC: ClassVar[tuple[tuple[str, str, bool], ...]] = ()

    t: float

    @classmethod
    def spec(cls) -> tuple[tuple[str, str, bool], ...]:
        """``(attribute, JSON name, optional)`` of each field after ``t``, in the written order."""
        if not cls.__dict__.get("_SPEC"):
            cls._SPEC = tuple((f.name, f.metadata.get("json", f.name), f.name in cls.OPTIONAL)
                              for f in dc_fields(cls) if f.name != "t")
        return cls._SPEC

    def fields(self) -> dict[str, Any]:
        """The JSON fields after ``t`` and ``event``, in their written order."""
        out: dict[str, Any] = {}
        for attr, name, optional in self.spec():
            value = getattr(self, attr)
            if value is None and optional:
                continue
            out[name] = value
        return out

    def record(self) -> dict[str, Any]:
        """The event as the dict a reader of ``trace.jsonl`` would see (before number rounding)."""
        return {"t": self.t, "event": self.KIND, **self.fields()}


# -- the run ------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class RunStarted(Event):
    """First line of a run: its seed, scheduler, harmonisation mode, rates and default strategies."""

    KIND: ClassVar[str] = "run"
    seed: int = _doc("the run's seed")
    scheduler: str = _doc("the schedule algorithm's registered name")
    mode: str = _doc("harmonisation: `IT` (interruptible tasks) or `CT` (constant task)")
    s_freq: float = _json("sFreq", "the harmoniser's scheduling rate (Hz)")
    rep_rate: float = _json("repRate", "the agents' report rate (Hz)")
    task_exe_rate: float = _json("taskExeRate", "the rate stages are advanced at (Hz)")
    sp_up_rate: float = _json("SPupRate", "the rate an executing agent recomputes its parameters (Hz)")
    update: str = _doc("the default `upTsk` strategy (`planned` or `static`)")
    suspension: str = _doc("the default `genSusp` strategy (`planned`, `static`, `derived` or `fallback`)")


@dataclass(frozen=True, slots=True)
class RunStopped(Event):
    """The last line of a run that did not end by itself: cut by its horizon, stopped by the
    user (Ctrl-C), or aborted because the world, a scheduled event or a model invariant broke."""

    KIND: ClassVar[str] = "run"
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"reason"})
    status: str = _doc("`horizon reached`, `interrupted` or `aborted`")
    reason: str | None = _doc("what raised (only when `aborted`)", default=None)
    active: Sequence[str] = _doc("the agents still alive", default=())


# -- requests and the agents' FSM -----------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class TaskRequested(Event):
    """``pf_initDA`` created an agent for a request."""

    KIND: ClassVar[str] = "request"
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"renews"})
    agent: str = _doc("the new agent's id (`d1`, `d2`, ... in request order)")
    task_type: str = _doc("the requested task type")
    args: Mapping[str, Any] = _doc("its arguments, validated, defaults filled in")
    requester: str = _doc("who asked")
    renews: str | None = _doc("the agent whose task this request asks for again after it ended without doing "
                              "its work; absent for a first request", default=None)


@dataclass(frozen=True, slots=True)
class Transition(Event):
    """An agent's FSM changed leaf state; every ``(from, trigger, to)`` is a row of ``tasker.fsm.TRANSITIONS``."""

    KIND: ClassVar[str] = "transition"
    agent: str = _doc("the agent")
    trigger: str = _doc("the FSM event the agent fired")
    source: str = _json("from", "the state it left")
    target: str = _json("to", "the state it entered")


@dataclass(frozen=True, slots=True)
class CommandSent(Event):
    """The harmoniser wrote an agent's command buffer (Alg. 1)."""

    KIND: ClassVar[str] = "command"
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"by", "expected_s", "predicted_s", "secure"})
    agent: str = _doc("the agent")
    flag: str = _doc("`start`, `susp` or `term`")
    by: str | None = _doc("`susp`: the replacement (`irrDA`)", default=None)
    expected_s: float | None = _doc("`susp`: the expected length of the interruption (s)", default=None)
    predicted_s: float | None = _doc("`start`: the agent's cTime computed at this start (s)", default=None)
    secure: bool | None = _doc("`start`: the waiting agent secures its hazard instead of resuming", default=None)


@dataclass(frozen=True, slots=True)
class RolesChanged(Event):
    """The harmoniser's roles changed."""

    KIND: ClassVar[str] = "roles"
    exe_da: str | None = _json("exeDA", "the executing agent, or null")
    irr_da: str | None = _json("irrDA", "the agent chosen to replace it, or null")
    idle_da: Sequence[str] = _json("idleDA", "the idle agents (`D_r`), in request order")


@dataclass(frozen=True, slots=True)
class Decision(Event):
    """A scheduling decision.  Its keys depend on the algorithm, so the record is kept whole, in
    the order the scheduler wrote it; ``algorithm`` and ``switch`` are always there."""

    KIND: ClassVar[str] = "decision"
    data: Mapping[str, Any] = _doc("`algorithm`, `switch`, usually `rule`, `dac`, `exeDA` and what was "
                                   "compared (written as the record's own fields)")

    def __post_init__(self) -> None:
        if not isinstance(self.data.get("algorithm"), str):
            raise TraceError("decision: 'algorithm' must be a string")
        if not isinstance(self.data.get("switch"), bool):
            raise TraceError("decision: 'switch' must be true or false")
        for key in ("t", "event"):
            if key in self.data:
                raise TraceError(f"decision: a record may not set {key!r}")

    def fields(self) -> dict[str, Any]:
        return dict(self.data)

    @property
    def algorithm(self) -> str:
        return str(self.data["algorithm"])

    @property
    def switch(self) -> bool:
        return bool(self.data["switch"])

    @property
    def rule(self) -> str | None:
        rule = self.data.get("rule")
        return None if rule is None else str(rule)

    @property
    def dac(self) -> str | None:
        """The candidate the decision was about."""
        dac = self.data.get("dac")
        return None if dac is None else str(dac)

    @property
    def exe_da(self) -> str | None:
        """The executing agent at the decision (``None``: no agent executed)."""
        exe = self.data.get("exeDA")
        return None if exe is None else str(exe)

    def get(self, key: str, default: Any = None) -> Any:
        return self.data.get(key, default)


@dataclass(frozen=True, slots=True)
class PlanMade(Event):
    """``upTsk`` built ``exeTsk`` or ``genSusp`` built ``exeSusp``."""

    KIND: ClassVar[str] = "plan"
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"note", "info", "goal"})
    agent: str = _doc("the agent")
    purpose: str = _doc("`upTsk` or `genSusp`")
    strategy: str = _doc("`planned`, `static`, `derived` or `fallback`")
    stages: Sequence[Mapping[str, Any]] = _doc("`{action, args, kind}` of each stage, `kind` `suspendable` or "
                                               "`blocking`")
    note: str | None = _doc("e.g. why a static fallback was used, or `planned ahead`", default=None)
    info: Mapping[str, Any] | None = _doc("planner name, plan cost, ... (never wall-clock values)", default=None)
    goal: Sequence[Sequence[str]] | None = _doc("`genSusp`: the ground literals `exeSusp` aims for (`[\"not\", ...]` "
                                                "for a fact that must not hold), when the task type says", default=None)


@dataclass(frozen=True, slots=True)
class StageChanged(Event):
    """A stage of ``exeTsk`` or ``exeSusp`` began or closed."""

    KIND: ClassVar[str] = "stage"
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"reason"})
    agent: str = _doc("the agent")
    fsm: str = _doc("`exeTsk` or `exeSusp`")
    index: int = _doc("the stage's index in its plan")
    action: str = _doc("its action")
    args: Sequence[Any] = _doc("its arguments")
    kind: str = _doc("`suspendable` or `blocking`")
    status: str = _doc("`begin`, `done`, `stopped`, `failed`, or `already_done` (its effects held already: it "
                       "did not run, and that is no failure)")
    reason: str | None = _doc("with `failed`: the skill's reason, or the exception; with `already_done`: the "
                              "effects that held", default=None)


@dataclass(frozen=True, slots=True)
class ModeChanged(Event):
    """Harmonisation switched between IT and CT while running."""

    KIND: ClassVar[str] = "mode"
    mode: str = _doc("`IT` or `CT`")


@dataclass(frozen=True, slots=True)
class ArgsChanged(Event):
    """A requester changed a live task's arguments (R2), or tried to after it ended."""

    KIND: ClassVar[str] = "change"
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"requester", "ignored"})
    agent: str = _doc("the agent")
    args: Mapping[str, Any] = _doc("only what changed")
    requester: str | None = _doc("who changed them", default=None)
    ignored: str | None = _doc("why nothing changed (the task had ended)", default=None)


@dataclass(frozen=True, slots=True)
class WorldChanged(Event):
    """A world event as it happened: a scenario's, a world file's, or an exogenous perturbation's."""

    KIND: ClassVar[str] = "world"
    what: str = _doc("`posture`, `door`, `walk`, `add`, `delete`, `move`, `device` or `stand`")
    value: Any = _doc("what changed, as the scenario gave it")
    note: str = _doc("a free text: the scenario's note, `world file`, or the perturbation that made it",
                     default="")


@dataclass(frozen=True, slots=True)
class HazardChanged(Event):
    """A hazard a task folder declares became true or false in the world, whatever the cause."""

    KIND: ClassVar[str] = "hazard"
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"carried"})
    agent: str | None = _doc("the agent it belongs to, or null if nobody owns it")
    hazard: str = _doc("its declared name")
    args: Sequence[str] = _doc("the ground fact's arguments")
    fact: Sequence[str] = _doc("the whole ground fact")
    status: str = _doc("`on` or `off`")
    budget_s: float = _doc("how long it may stay unattended (s)")
    severity: float = _doc("its declared severity")
    carried: bool | None = _doc("true when the fact is something the robot holds (a `held` binding): it goes "
                                "wherever the robot goes, into other tasks too", default=None)


@dataclass(frozen=True, slots=True)
class SecureChanged(Event):
    """Hazard-aware waiting: a waiting agent starts securing its hazards, is done, or ended meanwhile."""

    KIND: ClassVar[str] = "secure"
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"hazards"})
    agent: str = _doc("the agent")
    status: str = _doc("`start`, `done` or `ended`")
    hazards: Sequence[Mapping[str, Any]] | None = _doc("with `start`: `{hazard, args}` of the episodes it secures",
                                                       default=None)


@dataclass(frozen=True, slots=True)
class GoalChecked(Event):
    """A suspension ended (its agent left ``genSusp``/``exeSusp``): the literals of the goal its
    ``exeSusp`` aimed for that do not hold in the world at that moment (none: the goal holds)."""

    KIND: ClassVar[str] = "goal"
    agent: str = _doc("the agent")
    goal: Sequence[Sequence[str]] = _doc("the goal, as in its `plan` event")
    unmet: Sequence[Sequence[str]] = _doc("the literals of `goal` that do not hold")


@dataclass(frozen=True, slots=True)
class RoleChanged(Event):
    """A person's role, as the task folder declares it, started or stopped."""

    KIND: ClassVar[str] = "role"
    agent: str = _doc("the agent whose request names the person")
    role: str = _doc("`waiting`, `following`, `told_to_wait`, `needs_help` or `helped`")
    person: str = _doc("the person")
    status: str = _doc("`on` or `off`")


@dataclass(frozen=True, slots=True)
class TaskEnded(Event):
    """An agent ended."""

    KIND: ClassVar[str] = "end"
    agent: str = _doc("the agent")
    task_type: str = _doc("its task type")
    reason: str = _doc("`finished`, or why it ended")
    cause: str = _doc("`finished`, `self`, `term`, `failed` or `error`")


TYPES: tuple[type[Event], ...] = (
    RunStarted, RunStopped, TaskRequested, Transition, CommandSent, RolesChanged, Decision, PlanMade,
    StageChanged, ModeChanged, ArgsChanged, WorldChanged, HazardChanged, SecureChanged, GoalChecked, RoleChanged,
    TaskEnded,
)
"""Every event type, in the order ``docs/trace.md`` documents them."""

KINDS: tuple[str, ...] = tuple(dict.fromkeys(cls.KIND for cls in TYPES))
"""Every ``event`` kind a trace may hold."""

_BY_KIND: dict[str, tuple[type[Event], ...]] = {}
for _cls in TYPES:
    _BY_KIND[_cls.KIND] = _BY_KIND.get(_cls.KIND, ()) + (_cls,)

# -- reading back -------------------------------------------------------------------------------

_NUMBERS = {"inf": math.inf, "-inf": -math.inf, "nan": math.nan}


def _number(kind: str, name: str, value: Any, *, optional: bool = False) -> float | None:
    if value is None and optional:
        return None
    if isinstance(value, str) and value in _NUMBERS:
        return _NUMBERS[value]
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TraceError(f"{kind}: {name!r} must be a number, got {value!r:.40}")
    try:
        return float(value)
    except OverflowError:
        raise TraceError(f"{kind}: {name!r} is too large a number") from None


def _check(kind: str, name: str, value: Any, annotation: str) -> Any:
    """``value`` as the field's annotation asks (a number read back from ``"inf"``), or a TraceError."""
    optional = annotation.endswith("| None")
    base = annotation.removesuffix(" | None")
    if value is None:
        if optional:
            return None
        raise TraceError(f"{kind}: {name!r} may not be null")
    if base == "float":
        return _number(kind, name, value, optional=optional)
    if base == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise TraceError(f"{kind}: {name!r} must be an integer, got {value!r:.40}")
        return value
    if base == "str":
        if not isinstance(value, str):
            raise TraceError(f"{kind}: {name!r} must be a string, got {value!r:.40}")
        return value
    if base == "bool":
        if not isinstance(value, bool):
            raise TraceError(f"{kind}: {name!r} must be true or false, got {value!r:.40}")
        return value
    if base.startswith("Sequence"):
        if not isinstance(value, list):
            raise TraceError(f"{kind}: {name!r} must be a list, got {value!r:.40}")
        return value
    if base.startswith("Mapping"):
        if not isinstance(value, dict):
            raise TraceError(f"{kind}: {name!r} must be an object, got {value!r:.40}")
        return value
    return value  # Any


def parse(record: Mapping[str, Any]) -> Event:
    """The typed event of one decoded JSON line; a :class:`TraceError` naming the field if it is damaged."""
    kind = record.get("event")
    if not isinstance(kind, str):
        raise TraceError("not an event: expected \"event\" (a string)")
    choices = _BY_KIND.get(kind)
    if choices is None:
        raise TraceError(f"unknown event {kind!r}; known: {', '.join(KINDS)}")
    t = _number(kind, "t", record.get("t"))
    assert t is not None
    if not math.isfinite(t) or t < 0:
        raise TraceError(f"{kind}: 't' must be a finite number >= 0, got {record.get('t')!r:.40}")
    if kind == "decision":
        return Decision(t, {k: v for k, v in record.items() if k not in ("t", "event")})
    cls = choices[0] if len(choices) == 1 else (RunStopped if "status" in record else RunStarted)
    kwargs: dict[str, Any] = {}
    known = {"t", "event"}
    for f in dc_fields(cls):
        if f.name == "t":
            continue
        name = f.metadata.get("json", f.name)
        known.add(name)
        if name not in record:
            if f.default is not MISSING:
                kwargs[f.name] = f.default
                continue
            raise TraceError(f"{kind}: missing {name!r}")
        kwargs[f.name] = _check(kind, name, record[name], str(f.type))
    extra = sorted(set(record) - known)
    if extra:
        raise TraceError(f"{kind}: unexpected field {extra[0]!r}")
    return cls(t, **kwargs)
