"""The factorial design of a sweep: the factors a run varies, their levels, and :class:`Strategy`.

A :class:`Strategy` is one cell of the design (``update``, ``suspension``, ``policy``,
``hazard_waiting``, ``scheduler``, ``tree``); its :attr:`~Strategy.label` is the strategy's key in the
results database and in reports, and :meth:`Strategy.parse` reads it back.  :func:`expand`
makes every cell of a grid of levels.  The sweep spec (:mod:`experiments.sweep.spec`) builds
strategies from its file; reports (:mod:`experiments.sweep.report`) parse them back from labels.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from tasker.support import reader
from tasker.task import SUSPENSIONS

STRATEGY_VALUES = ("static", "planned")
SUSPENSION_VALUES = ("static", *(s for s in SUSPENSIONS if s != "static"))
"""``suspension``'s levels, the baseline first: ``static`` (the tree's stages), ``planned`` (plan to the
tree's goal), ``derived`` (plan to the goal the task folder's declarations give), ``fallback`` (the
tree where it can run, a plan to the derived goal where it cannot)."""


@dataclass(frozen=True)
class Strategy:
    """One cell of the sweep's factorial design: the factors a run varies.

    ``update``/``suspension``: how ``upTsk`` and ``genSusp`` build their plans (``static`` or
    ``planned``); ``policy``: when a suspension is required (``strict`` or ``conditional``,
    applied to both suspension strategies); ``hazard_waiting``: hazard-aware waiting off or
    on; ``scheduler``: the harmoniser's scheduler; ``tree``: the decision tree genSusp reads
    (``NAME`` or ``TYPE:NAME``, :class:`experiments.run.options.RunOptions`).  ``None`` leaves the
    scenario's own setting.
    """

    update: str | None = None
    suspension: str | None = None
    scheduler: str | None = None
    policy: str | None = None
    hazard_waiting: bool | None = None
    tree: str | None = None

    def __post_init__(self) -> None:
        for name, values in (("update", STRATEGY_VALUES), ("suspension", SUSPENSION_VALUES)):
            value = getattr(self, name)
            if value is not None and value not in values:
                raise ValueError(f"{name}: expected one of {list(values)}, got {value!r}")
        if self.policy is not None and self.policy not in POLICY_VALUES:
            raise ValueError(f"policy: expected one of {list(POLICY_VALUES)}, got {self.policy!r}")
        if self.hazard_waiting is not None and not isinstance(self.hazard_waiting, bool):
            raise ValueError(f"hazard_waiting: expected true or false, got {self.hazard_waiting!r}")
        if self.scheduler is not None and (not isinstance(self.scheduler, str) or not self.scheduler):
            raise ValueError(f"scheduler: expected a scheduler name, got {self.scheduler!r}")
        if self.tree is not None and (not isinstance(self.tree, str) or not 1 <= len(self.tree.split(":")) <= 2
                                      or not all(p.isidentifier() for p in self.tree.split(":"))):
            raise ValueError(f"tree: expected a tree's NAME or TYPE:NAME, got {self.tree!r}")

    @property
    def label(self) -> str:
        """The key of the strategy in the results database, e.g. ``update=planned,suspension=static``.

        Factors left out (``None``) do not appear, so labels of older sweeps stay what they were."""
        parts = [f"{k}={_show(v)}" for k, v in self.items()]
        return ",".join(parts) if parts else "default"

    def items(self) -> list[tuple[str, Any]]:
        """The factors that are set, in label order (see :data:`FACTORS`)."""
        return [(k, v) for k in FACTORS if (v := getattr(self, k)) is not None]

    @classmethod
    def parse(cls, text: str) -> Strategy:
        """The inverse of :attr:`label`: ``"update=planned,suspension=static,policy=strict,hazard_waiting=on"``."""
        if text.strip() == "default":
            return cls()
        fields: dict[str, Any] = {}
        for part in text.split(","):
            key, sep, value = part.partition("=")
            key, value = key.strip(), value.strip()
            if sep and key in FACTORS and not value:  # the factor is right: "did you mean" it would mislead
                levels = FACTOR_LEVELS[key]
                one_of = (("a tree's name" if key == "tree" else "a scheduler name") if levels is None
                          else " or ".join(_show(v) for v in levels))
                raise ValueError(f"{key}: expected {one_of} after '{key}=', got nothing in {text!r}")
            if not sep or key not in FACTORS or not value:
                raise ValueError(f"expected 'update=…,suspension=…[,policy=…][,hazard_waiting=on|off]"
                                 f"[,scheduler=…][,tree=…]', got {text!r}{reader.suggest(key, list(FACTORS))}")
            if key in fields:
                raise ValueError(f"{key} given twice in {text!r}")
            fields[key] = _switch(value) if key == "hazard_waiting" else value
        return cls(**fields)


FACTORS = ("update", "suspension", "policy", "hazard_waiting", "scheduler", "tree")
"""The factors of a :class:`Strategy`, in the order of its label."""

POLICY_VALUES = ("strict", "conditional")

_SWITCH = {"on": True, "off": False, "true": True, "false": False}


def _show(value: Any) -> str:
    return ("on" if value else "off") if isinstance(value, bool) else str(value)


def _switch(value: Any) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.lower() in _SWITCH:
        return _SWITCH[value.lower()]
    raise ValueError(f"hazard_waiting: expected on/off (or true/false), got {value!r}")


def expand(factors: Mapping[str, Sequence[Any]]) -> list[Strategy]:
    """Every combination of the levels of ``factors`` (a grid), in :data:`FACTORS` order, the first
    factor varying slowest: ``{"suspension": ["static", "planned"], "hazard_waiting": [False, True]}``
    gives four strategies."""
    unknown = [k for k in factors if k not in FACTORS]
    if unknown:
        raise ValueError(f"unknown factor {unknown[0]!r}{reader.suggest(unknown[0], list(FACTORS))}")
    names = [k for k in FACTORS if k in factors]
    levels: list[list[Any]] = [[_switch(v) if k == "hazard_waiting" else v for v in factors[k]] for k in names]
    combos: list[dict[str, Any]] = [dict(zip(names, c, strict=True)) for c in itertools.product(*levels)]
    return [Strategy(**c) for c in combos]


FACTOR_LEVELS: dict[str, tuple[Any, ...] | None] = {
    "update": STRATEGY_VALUES, "suspension": SUSPENSION_VALUES, "policy": POLICY_VALUES,
    "hazard_waiting": (False, True), "scheduler": None, "tree": None}
"""The levels each factor of a ``[factors]`` grid may take (``None``: a registered scheduler; a tree's name)."""

