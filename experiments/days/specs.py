"""Scheduler specs of a day run: a registered scheduler with options, ``NAME[:OPTION=VALUE]...``.

``tasker day --schedulers`` takes specs, so one table can hold a baseline at several values
of its parameter, as TaBSA sweeps its agents::

    tabsa-simple                        the scheduler with the options the day gives it
    tabsa-simple:hesitance=0.25         and hesitance 0.25
    tabsa-distance:ratio=0.5:estimates=reports
    tabsa-simple:hesitance=*            one spec per value of the scheduler's sweep grid
                                        (:func:`tasker.schedulers.sweep`: 0, 0.25, 0.5, 0.75, 1)

A value reads as an integer, a number, ``true``/``false``, or else as text.  The spec's
:attr:`SchedulerSpec.label` is canonical (options sorted, numbers written with ``:g``), and is
the scheduler's name in the results database and the tables, so ``hesitance=0.50`` and
``hesitance=0.5`` are one spec.  The options the day gives a scheduler
(:func:`experiments.days.pipeline.scheduler_options`: the day's seed, the protocol's
non-preemptive types, priority classes, hazard budgets) come first; a spec's options are
applied over them.  Every option is checked by making the scheduler: a wrong one is a
:class:`~tasker.errors.ConfigError` naming it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from tasker import schedulers
from tasker.errors import ConfigError
from tasker.support.reader import suggest

SWEEP = "*"
"""The value that expands a spec over the scheduler's sweep grid."""


@dataclass(frozen=True)
class SchedulerSpec:
    """A registered scheduler ``name`` and the ``options`` a spec sets (sorted by option)."""

    name: str
    options: tuple[tuple[str, Any], ...] = ()

    @property
    def label(self) -> str:
        """``NAME`` or ``NAME:OPT=VALUE:...``, canonical: the key of its days and its column in the table."""
        return ":".join([self.name, *(f"{k}={show(v)}" for k, v in self.options)])

    def as_dict(self) -> dict[str, Any]:
        return dict(self.options)


def show(value: Any) -> str:
    """A value as a spec writes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _value(text: str) -> Any:
    low = text.lower()
    if low in ("true", "false"):
        return low == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def parse(text: str) -> SchedulerSpec:
    """A spec from ``NAME[:OPTION=VALUE]...``; an unknown scheduler or option, a malformed or
    repeated option is a :class:`ConfigError` (with "did you mean").  ``VALUE`` may not be ``*``
    here (:func:`expand` expands it)."""
    name, *parts = text.strip().split(":")
    known = schedulers.names()
    if name not in known:
        raise ConfigError(f"unknown scheduler {name!r}{suggest(name, known)}; known: {', '.join(known)}")
    options: dict[str, Any] = {}
    for part in parts:
        key, sep, raw = part.partition("=")
        key, raw = key.strip(), raw.strip()
        if not sep or not key or not raw:
            raise ConfigError(f"{text!r}: expected NAME:OPTION=VALUE[:OPTION=VALUE...], got {part!r}")
        why = schedulers.unknown_option(name, key)
        if why:
            raise ConfigError(f"{text!r}: {why}")
        if key in options:
            raise ConfigError(f"{text!r}: option {key!r} is given twice")
        if raw == SWEEP:
            raise ConfigError(f"{text!r}: {key}={SWEEP} sweeps the option: give it where specs are expanded")
        options[key] = _value(raw)
    if options:
        schedulers.create(name, **options)  # the scheduler checks its own values (range, type, choices)
    return SchedulerSpec(name, tuple(sorted(options.items())))


def expand(texts: Sequence[str]) -> list[SchedulerSpec]:
    """The specs of ``texts``, each ``OPTION=*`` replaced by one spec per value of the scheduler's
    sweep grid (:func:`tasker.schedulers.sweep`), in order; a spec given twice (after
    canonicalisation) is an error."""
    out: list[SchedulerSpec] = []
    for text in texts:
        name, *parts = text.strip().split(":")
        swept = [p.partition("=")[0].strip() for p in parts if p.partition("=")[2].strip() == SWEEP]
        if len(swept) > 1:
            raise ConfigError(f"{text!r}: sweep one option at a time (got {', '.join(swept)})")
        if not swept:
            out.append(parse(text))
            continue
        grid = schedulers.sweep(name) if name in schedulers.names() else {}
        if swept[0] not in grid:
            has = f"its sweep grid has {', '.join(grid)}" if grid else "it has no sweep grid"
            raise ConfigError(f"{text!r}: scheduler {name!r} does not sweep {swept[0]!r} ({has})")
        for value in grid[swept[0]]:
            out.append(parse(text.replace(f"{swept[0]}={SWEEP}", f"{swept[0]}={show(value)}")))
    labels = [s.label for s in out]
    twice = sorted({x for x in labels if labels.count(x) > 1})
    if twice:
        raise ConfigError(f"{twice[0]!r} is given twice")
    return out

