"""What happened in the world, at a fixed rate: the robot's and people's poses and postures.

:class:`Recorder` keeps one :class:`Sample` every ``1 / RECORD_HZ`` simulated seconds
(on the control-tick grid, so the times are exact multiples) and the places where the
robot handled objects (:class:`Mark`).  :meth:`Recorder.write` saves them as
``trajectory.jsonl`` next to a run's ``trace.jsonl``; :func:`read_trajectory` reads the
file back.  The format is documented in ``docs/robot.md``; it holds no wall-clock value,
so the same scenario and seed give the same file byte for byte.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

from tasker.world import Pose

_T = TypeVar("_T")

RECORD_HZ = 10.0  # samples per simulated second
FORMAT = "tasker-trajectory/1"


@dataclass(frozen=True, slots=True)
class PersonState:
    """A person at one instant: where, facing where, and in which posture."""

    name: str
    x: float
    y: float
    yaw: float
    posture: str


@dataclass(frozen=True, slots=True)
class Sample:
    """The world at simulated time ``t``: the robot's pose and every person's state."""

    t: float
    robot: Pose
    people: tuple[PersonState, ...]

    def to_json(self) -> dict[str, object]:
        return {"t": round(self.t, 4), "robot": [round(v, 4) for v in self.robot],
                "people": {p.name: [round(p.x, 4), round(p.y, 4), round(p.yaw, 4), p.posture] for p in self.people}}

    def as_written(self) -> Sample:
        """This sample as :func:`read_trajectory` reads it back from the file: numbers rounded
        to 4 places (the file's ``repr`` of them reads back as the same float), people by name."""
        x, y, yaw = (round(float(v), 4) for v in self.robot)
        return Sample(round(float(self.t), 4), (x, y, yaw), tuple(
            _remembered(_rounded, p) for p in sorted(self.people, key=lambda p: p.name)))

    def line(self) -> str:
        """``json.dumps(self.to_json(), sort_keys=True)``, written out directly: a day has tens
        of thousands of samples and the general encoder cost a second of it.  Numbers are
        ``repr`` of the rounded float, as the encoder writes them; strings go through it."""
        people = sorted(self.people, key=lambda p: p.name)
        inner = ", ".join(_remembered(_person, p) for p in people)
        x, y, yaw = (round(float(v), 4) for v in self.robot)
        return f'{{"people": {{{inner}}}, "robot": [{x!r}, {y!r}, {yaw!r}], "t": {round(float(self.t), 4)!r}}}'


def _remembered(fn: Callable[[PersonState], _T], p: PersonState) -> _T:
    """``fn(p)`` through ``fn``'s memo (most people stand still most of a day), except when a
    coordinate is zero: ``0.0 == -0.0``, so the memo would hand one of them the other's answer."""
    return fn(p) if p.x and p.y and p.yaw else fn.__wrapped__(p)  # type: ignore[attr-defined]


@functools.lru_cache(maxsize=4096)
def _rounded(p: PersonState) -> PersonState:
    """``p`` as the file gives it back (:meth:`Sample.as_written`)."""
    return PersonState(p.name, round(float(p.x), 4), round(float(p.y), 4), round(float(p.yaw), 4), p.posture)


@functools.lru_cache(maxsize=4096)
def _person(p: PersonState) -> str:
    """``p``'s part of :meth:`Sample.line`."""
    return f"{_str(p.name)}: [{round(float(p.x), 4)!r}, {round(float(p.y), 4)!r}, {round(float(p.yaw), 4)!r}, " \
           f"{_str(p.posture)}]"


def _str(s: str) -> str:
    return json.dumps(s)


@dataclass(frozen=True, slots=True)
class Mark:
    """Where the robot handled an object: a ``manipulate`` stage that succeeded."""

    t: float
    item: str
    action: str
    x: float
    y: float

    def to_json(self) -> dict[str, object]:
        return {"t": round(self.t, 4), "mark": "manipulated", "object": self.item, "action": self.action,
                "at": [round(self.x, 4), round(self.y, 4)]}


class Recorder:
    """Collects samples at ``rate_hz`` and marks; writes and reads ``trajectory.jsonl``."""

    def __init__(self, world: str, rate_hz: float = RECORD_HZ) -> None:
        if not rate_hz > 0:
            raise ValueError(f"Recorder rate_hz must be > 0, got {rate_hz}")
        self.world = world
        self.rate_hz = float(rate_hz)
        self.samples: list[Sample] = []
        self.marks: list[Mark] = []
        self._next = 0

    def due(self, t: float) -> bool:
        """Is a sample due at simulated time ``t``?"""
        return t >= self._next / self.rate_hz - 1e-9

    def next_time(self) -> float:
        """When the next sample is due."""
        return self._next / self.rate_hz

    def record(self, t: float, robot: Pose, people: Iterable[PersonState]) -> None:
        self.samples.append(Sample(t, robot, tuple(people)))
        self._next = int(round(t * self.rate_hz)) + 1

    def mark(self, t: float, obj: str, action: str, x: float, y: float) -> None:
        self.marks.append(Mark(t, obj, action, x, y))

    def lines(self) -> list[str]:
        """The file's lines: a header, then samples and marks in time order (marks after a
        sample of the same time)."""
        head = {"format": FORMAT, "world": self.world, "rate_hz": self.rate_hz,
                "fields": {"robot": ["x", "y", "yaw"], "people": ["x", "y", "yaw", "posture"]}}
        rows: list[tuple[float, int, int]] = [(s.t, 0, k) for k, s in enumerate(self.samples)]
        rows += [(m.t, 1, k) for k, m in enumerate(self.marks)]
        rows.sort(key=lambda r: (r[0], r[1]))
        return [json.dumps(head, sort_keys=True)] + [
            self.samples[k].line() if kind == 0 else json.dumps(self.marks[k].to_json(), sort_keys=True)
            for _, kind, k in rows]

    def samples_as_read(self) -> list[Sample]:
        """The samples :func:`read_trajectory` would read from :meth:`write`'s file, without
        the file: what a day needs of its run, kept in memory (``tests/robot/test_recording.py``
        holds the two equal)."""
        return [s.as_written() for s in sorted(self.samples, key=lambda s: s.t)]

    def write(self, path: str | Path) -> Path:
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text("\n".join(self.lines()) + "\n")
        return out


def read_trajectory(path: str | Path) -> tuple[dict[str, object], list[Sample], list[Mark]]:
    """The header, samples and marks of a ``trajectory.jsonl`` file."""
    lines = Path(path).read_text().splitlines()
    if not lines:
        raise ValueError(f"{path}: empty trajectory file")
    head = json.loads(lines[0])
    if head.get("format") != FORMAT:
        raise ValueError(f"{path}:1: format: expected {FORMAT!r}, got {head.get('format')!r}")
    samples, marks = [], []
    for n, line in enumerate(lines[1:], start=2):
        row = json.loads(line)
        if row.get("mark") == "manipulated":
            marks.append(Mark(row["t"], row["object"], row["action"], row["at"][0], row["at"][1]))
        elif "robot" in row:
            people = tuple(PersonState(k, v[0], v[1], v[2], v[3]) for k, v in sorted(row["people"].items()))
            x, y, yaw = row["robot"]
            samples.append(Sample(row["t"], (x, y, yaw), people))
        else:
            raise ValueError(f"{path}:{n}: expected a sample (robot, people) or a mark, got keys {sorted(row)}")
    return head, samples, marks
