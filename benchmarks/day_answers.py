"""Fingerprints of what whole days answer, to show that a speed-up changed no day.

    python benchmarks/day_answers.py [--robot] [--only PATTERN] > day-answers.txt

Runs days of the shipped protocols on the synthetic backend — every scheduler (but
``lookahead-cpsat``, whose search has a wall-clock limit), two seeds, and days made longer
and busier (:mod:`daysize`) where the cost of a day grows — and with ``--robot`` a few
days on the robot backend, and prints for each the SHA-256 of its trace
(``trace.jsonl``; on the robot also ``trajectory.jsonl``) and of its day metrics
(:func:`experiments.days.runner.run_day`, the host-dependent ``wall_time_s`` left out).
``diff`` the output of two commits.  The reference of the commit before the cost work
is ``tests/experiments/data/day-answers-f6c867e.txt`` (made with ``--robot`` on f6c867e, main
just before the cost work was merged; its 14 look-ahead lines re-made when the look-ahead learnt
to decide between searches, issue 38);
``tests/experiments/test_day_answers.py`` compares against it.

Like ``answers.py``, not a ``bench_*`` script.  It uses nothing newer than that commit,
so it runs against an older checkout put first on ``PYTHONPATH``.
"""

from __future__ import annotations

import fnmatch
import hashlib
import json
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from daysize import sized  # noqa: E402

PROTOCOLS = ("tabsa-original", "tabsa", "tabsa-rush", "tabsa-short", "tabsa-anywhere")
SCHEDULERS = ("alg2", "atc", "distance", "edf", "fifo", "lookahead", "priority", "simple", "simple2", "sjf", "srtf",
              "tabsa-distance", "tabsa-scheduler", "tabsa-simple", "tabsa-simple2", "wspt")
SEEDS = (1, 2)
GROWN = ("alg2", "edf", "tabsa-simple", "tabsa-simple2", "tabsa-distance", "tabsa-scheduler", "simple", "atc")
"""Schedulers also run on the long and the busy days (the look-ahead on shorter ones: it costs most)."""
ROBOT = (("tabsa-short", "alg2"), ("tabsa-short", "lookahead"), ("tabsa-short", "tabsa-simple"),
         ("tabsa-short", "edf"), ("tabsa-rush", "alg2"))


@dataclass(frozen=True)
class Case:
    """One day: protocol (made ``hours`` long, with ``requests`` requests, when set), backend, scheduler, seed."""

    protocol: str
    backend: str
    scheduler: str
    seed: int
    hours: float | None = None
    requests: int | None = None

    @property
    def label(self) -> str:
        size = "" if self.hours is None else f"@{self.hours:g}h"
        size += "" if self.requests is None else f"x{self.requests}"
        return f"{self.backend} {self.protocol}{size} {self.scheduler} {self.seed}"


def cases(robot: bool = False) -> list[Case]:
    """Every day this script fingerprints (the robot's only with ``robot``)."""
    out = [Case(p, "synthetic", s, seed) for p in PROTOCOLS for s in SCHEDULERS for seed in SEEDS]
    out += [Case("tabsa-original", "synthetic", s, 1, hours=8.0) for s in GROWN]
    out += [Case("tabsa-original", "synthetic", s, 1, requests=72) for s in GROWN]
    out += [Case("tabsa-original", "synthetic", "lookahead", seed, hours=2.0) for seed in SEEDS]
    out += [Case("tabsa-original", "synthetic", "lookahead", 1, requests=18)]
    if robot:
        out += [Case(p, "robot", s, 1) for p, s in ROBOT]
    return out


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def fingerprint(case: Case) -> str:
    """``TRACE_SHA METRICS_SHA  LABEL``: the day's trace (and trajectory) and its metrics."""
    from experiments.days.runner import run_day

    proto = sized(case.protocol, case.hours, case.requests)
    with tempfile.TemporaryDirectory() as tmp:
        metrics = run_day(proto, case.seed, case.scheduler, case.backend, keep=tmp)  # type: ignore[arg-type]
        files = [Path(tmp) / "trace.jsonl"] + ([Path(tmp) / "trajectory.jsonl"] if case.backend == "robot" else [])
        trace = hashlib.sha256(b"".join(p.read_bytes() for p in files)).hexdigest()
    metrics.pop("wall_time_s", None)
    return f"{trace} {_sha(json.dumps(metrics, sort_keys=True, default=str).encode())}  {case.label}"


def main(argv: list[str]) -> int:
    robot = "--robot" in argv
    pattern = argv[argv.index("--only") + 1] if "--only" in argv else "*"
    for case in cases(robot):
        if fnmatch.fnmatch(case.label, pattern):
            print(fingerprint(case), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
