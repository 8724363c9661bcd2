"""What ``tasker day --resume`` reads before it goes on: the results database and an older ``days.jsonl``.

A day is stored under ``(PROTOCOL@BACKEND, seed, strategy)`` (:func:`scenario_key`) with the
digest of the protocol it was drawn from (:meth:`experiments.days.protocol.Protocol.digest`);
:func:`check_resumable` refuses to go on with days of another version of the protocol.
:func:`import_log` reads the days of a ``days.jsonl`` written before the database existed.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

from experiments.days import protocol as protocols
from experiments.inputs.strategy import Strategy
from tasker.errors import ConfigError


def scenario_key(protocol: str | Path, backend: str) -> str:
    """The scenario column of a day in the results database: ``PROTOCOL@BACKEND``."""
    return f"{protocol}@{backend}"


def check_resumable(db: Path, scenario: str, proto: protocols.Protocol) -> None:
    """A :class:`ConfigError` when ``db`` holds days of ``scenario`` (``PROTOCOL@BACKEND``) drawn from
    another version of ``proto``: resumed, they would be compared with days of this one as if alike.
    Days stored without a digest (by an older tasker, or imported from a ``days.jsonl``) are kept."""
    from experiments.metrics.store import ResultStore, holds_results

    if not holds_results(db):  # nothing stored (or what a failed first write left): nothing to compare
        return
    with ResultStore(db, readonly=True) as store:
        rows = [r for r in store.rows() if r.scenario == scenario]
    for r in rows:  # the table reads every stored day: a damaged one is named now, not after the new days ran
        why = _day_problem(r.metrics) if r.status.value == "ok" else None
        if why:
            raise ConfigError(f"{db}: the stored day (seed {r.seed}, {r.strategy}): "
                              f"{why[0] + ': ' if why[0] else ''}{why[1]} (a damaged database)")
    stored = {r.record.get("protocol_digest") for r in rows}
    if stored - {None, proto.digest()}:
        raise ConfigError(f"{db} holds days of {proto.source} as it was when they ran, and it has changed since "
                          f"(a value of the protocol{', or its world file' if proto.robot else ''}): new days would "
                          "not be comparable with them")


_DAY_NUMBERS = ("completed", "lateness_s", "dead_falls", "interruptions", "suspensions", "suspension_time_s",
                "switches", "longest_order", "anytime_decisions")
"""Numbers every day of a ``days.jsonl`` carries (the table reads them); ``completion_minus_deadline_s``
may also be null."""


def _day_problem(r: Any) -> tuple[str, str] | None:
    """``(field, why)`` when ``r`` (a line of ``days.jsonl``) is not a day the table can read."""
    if not isinstance(r, dict):
        return "", f"expected a day (a JSON object), got {json.dumps(r)[:40]}"
    if "error" in r:  # a day that failed to run: skipped, so only where it belongs is read
        return None
    if not isinstance(r.get("scheduler"), str):
        return "scheduler", "expected a scheduler name"
    seed = r.get("seed")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        return "seed", f"expected an integer >= 0, got {json.dumps(seed)}"
    if not isinstance(r.get("strategy", "default"), str):
        return "strategy", f"expected a strategy label, got {json.dumps(r.get('strategy'))[:40]}"
    try:
        Strategy.parse(r.get("strategy", "default"))
    except (ValueError, TypeError) as exc:
        return "strategy", str(exc)
    for key in (*_DAY_NUMBERS, "completion_minus_deadline_s"):
        v = r.get(key)
        if (isinstance(v, bool) or not isinstance(v, int | float)) and not (
                v is None and key == "completion_minus_deadline_s" and key in r):
            return key, f"expected a number, got {json.dumps(v) if key in r else 'nothing'}"
    if not isinstance(r.get("per_type"), dict) or not all(isinstance(v, dict) for v in r["per_type"].values()):
        return "per_type", "expected an object of task type -> its metrics"
    if not isinstance(r.get("ending"), str):
        return "ending", "expected a string"
    return None


def import_log(log: Path, db: Path, protocol: str, backend: str) -> None:
    """Days of an older ``days.jsonl`` (before the database) into ``db``, so ``--resume`` keeps them.

    The whole file is checked first: a damaged line is an :class:`~tasker.support.reader.InputError`
    naming it (and nothing is imported)."""
    from experiments.metrics.store import ResultStore, RunRow, Status
    from tasker.support.reader import InputError, parse_json, read_text

    days = []
    for n, line in enumerate(read_text(log).splitlines(), start=1):
        if not line.strip():
            continue
        try:  # within the readers' limits: nesting, 64-bit integers
            r = parse_json(line, log, line=n)
        except InputError as exc:
            what = exc.message.removeprefix("not valid JSON: ").removeprefix("not readable JSON: ")
            raise InputError(log, f"not a JSON object: {what} (a days.jsonl that tasker day wrote, or resume "
                                  "without it)", line=n, field=exc.field) from None
        why = _day_problem(r)
        if why:
            raise InputError(log, f"{why[1]} (a days.jsonl that tasker day wrote, or resume without it)", line=n,
                             field=why[0])
        if r.get("backend", "synthetic") == backend and "error" not in r:
            days.append(r)
    with ResultStore(db) as store:
        for r in days:
            st = Strategy.parse(r.get("strategy", "default"))
            label = dataclasses.replace(st, scheduler=r["scheduler"]).label
            store.add(RunRow(scenario_key(protocol, backend), int(r["seed"]), label, Status.OK,
                             {"imported_from": str(log)}, r, None, 0.0, ""))
