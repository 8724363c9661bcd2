"""A live session saved as a scenario file that ``tasker run`` replays byte for byte.

:class:`Record` keeps every action of the session in the order the session scheduled it: the
served scenario's own (as ``build_robot_actions`` scheduled them) and each one that arrived
over HTTP, at the time it was injected.  :meth:`Record.write` writes ``session.toml``: the
world, the seed, the settings, the people, objects and devices of the served scenario, and every
action at its simulated time.  A scenario names its requests ``d1``, ``d2``, … in the order
of its file; a live session numbered the served scenario's first and the arrivals after
them, so every reference (a termination's or change's ``agent``, a world event's ``after``)
is renumbered to the file's order.  The written file is read back with the scenario reader
and must give the same actions, or the session is not saved as replayable (a bug, raised).
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path
from typing import Any

import tomli_w

from experiments.inputs import scenario as scenarios
from experiments.inputs.actions import TABLES, TimedAction
from experiments.inputs.robot_scenario import RobotScenario
from tasker.support.reader import InputWarning

KEYS = {kind: key for key, kind in TABLES}
"""The array-of-tables key of each action kind (``request`` -> ``requests``)."""


@dataclasses.dataclass(frozen=True)
class Entry:
    """One action of the session, in scheduling order; ``sid``: a request's id in the session's numbering."""

    action: TimedAction
    sid: str | None
    order: int


class Record:
    """The actions of a session (see the module docstring) and the scenario they are played in;
    ``task_paths``: the task folders it loaded besides the bundled ones (``--path``), to read it back."""

    def __init__(self, base: RobotScenario, task_paths: tuple[str, ...] = ()) -> None:
        self.base, self.task_paths = base, task_paths
        self.entries: list[Entry] = []

    def add(self, action: TimedAction, sid: str | None) -> None:
        self.entries.append(Entry(action, sid, len(self.entries)))

    def renumbering(self) -> dict[str, str]:
        """The session's request ids -> the file's (the K-th request of the file, by time, is ``dK``)."""
        requests = sorted((e for e in self.entries if e.action.kind == "request"), key=lambda e: (e.action.t, e.order))
        return {str(e.sid): f"d{k}" for k, e in enumerate(requests, start=1)}

    def data(self, horizon: float) -> dict[str, Any]:
        """The scenario as TOML-ready data, stopping at ``horizon``."""
        b = self.base
        settings: dict[str, Any] = {
            "scheduler": b.scheduler, "mode": b.mode, "s_freq": b.s_freq, "rep_rate": b.rep_rate,
            "task_exe_rate": b.task_exe_rate, "sp_up_rate": b.sp_up_rate, "update": b.update,
            "suspension": b.suspension, "policy": b.policy, "horizon": horizon,
            "secure_over_higher": b.secure_over_higher, "request_fields": True}
        if b.scheduler_options:
            settings["scheduler_options"] = dict(b.scheduler_options)
        if b.strategies:
            settings["strategies"] = {t: dict(s) for t, s in b.strategies.items()}
        out: dict[str, Any] = {"kind": "robot", "name": b.name, "world": b.world, "seed": b.seed, "settings": settings}
        if b.people:
            out["people"] = {n: {k: [list(w) for w in v] if k == "walk" else list(v) for k, v in p.items()}
                             for n, p in b.people.items()}
        if b.objects:
            out["objects"] = {n: {"type": o["type"], "place": o["place"], "facts": [list(f) for f in o["facts"]]}
                              for n, o in b.objects.items()}
        if b.devices:
            out["devices"] = {n: {"type": d["type"], "place": d["place"], "state": d["state"]}
                              for n, d in b.devices.items()}
        ids = self.renumbering()
        for e in sorted(self.entries, key=lambda e: (e.action.t, e.order)):
            out.setdefault(KEYS[e.action.kind], []).append(_entry(e.action, ids))
        return out

    def write(self, path: Path, horizon: float, header: str) -> RobotScenario:
        """Write the session to ``path`` (``header``: comment lines) and read it back, checked."""
        text = tomli_w.dumps(self.data(horizon))
        comment = "".join(f"# {line}\n" if line else "#\n" for line in header.splitlines())
        path.write_text(comment + "\n" + text, encoding="utf-8")
        with warnings.catch_warnings():  # actions after the stop are kept on purpose (docs/serve.md)
            warnings.simplefilter("ignore", InputWarning)
            loaded = scenarios.load(path, task_paths=self.task_paths)
        wanted = self.actions()
        if [(a.t, a.kind, a.fields) for a in loaded.actions] != [(a.t, a.kind, a.fields) for a in wanted]:
            raise AssertionError(f"{path}: the saved session does not read back as the actions it ran")
        return loaded

    def actions(self) -> list[TimedAction]:
        """The session's actions as its file's reader gives them: by time, then by table, then by place
        in the file, every request id renumbered to the file's."""
        ids, table = self.renumbering(), {kind: i for i, (_, kind) in enumerate(TABLES)}
        return [_renamed(e.action, ids) for e in sorted(self.entries, key=lambda e: (e.action.t,
                                                                                     table[e.action.kind], e.order))]

    def scenario(self, horizon: float) -> RobotScenario:
        """The session as a scenario, built in memory (what :meth:`write` returns once read back): what
        ``run.json`` records when ``session.toml`` cannot be written."""
        return dataclasses.replace(self.base, horizon=horizon, actions=tuple(self.actions()), request_fields=True)


def _renamed(a: TimedAction, ids: dict[str, str]) -> TimedAction:
    fields = dict(a.fields)
    for key in ("agent", "after"):
        if key in fields:
            fields[key] = ids.get(fields[key], fields[key])
    return TimedAction(a.t, a.kind, fields, a.origin)


def _entry(a: TimedAction, ids: dict[str, str]) -> dict[str, Any]:
    """One action as its scenario table entry (``{"t", "task", "args"}``, ``{"t", "posture", "note"}``, ...)."""
    f = _renamed(a, ids).fields
    out: dict[str, Any] = {"t": a.t}
    if a.kind == "world":
        out[f["what"]] = f["value"]
        if f.get("note"):
            out["note"] = f["note"]
        if "after" in f:
            out["after"] = f["after"]
    else:
        out.update({k: v for k, v in f.items() if not (k == "args" and a.kind == "request" and not v)})
    return out
