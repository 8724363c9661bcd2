"""Day protocols made longer or busier, for the growth benchmark and the day fingerprints.

Not a benchmark (``run_all.py`` runs ``bench_*`` only).  It uses nothing newer than the
commit the growth benchmark compares against (``dataclasses.replace`` on a loaded
protocol, :func:`experiments.days.pipeline.make`, :func:`experiments.days.runner.run_day`),
so the same file runs against an older checkout put first on ``PYTHONPATH``.

:func:`longer` keeps the protocol's request rate (counts, arrival window and day length
scaled together: a day four times as long has four times the work); :func:`busier` keeps
its length and asks for more requests (the queue grows).  Counts are shared out in the
protocol's proportions, at least one request per type it has.
"""

from __future__ import annotations

import dataclasses
from typing import Any


def longer(proto: Any, hours: float) -> Any:
    """``proto`` with a day of ``hours`` hours at the same request rate."""
    factor = hours * 3600.0 / proto.length_s
    tasks = {k: dataclasses.replace(s, count=max(1, round(s.count * factor))) for k, s in proto.tasks.items()}
    return dataclasses.replace(proto, length_s=hours * 3600.0, last_call_s=proto.last_call_s * factor, tasks=tasks)


def busier(proto: Any, requests: int, hours: float = 1.0) -> Any:
    """``proto`` with a day of ``hours`` hours and ``requests`` requests in all (in the
    protocol's proportions)."""
    day = longer(proto, hours)
    total = sum(s.count for s in proto.tasks.values())
    kinds = list(proto.tasks)
    counts = {k: max(1, round(requests * proto.tasks[k].count / total)) for k in kinds}
    counts[kinds[0]] += requests - sum(counts.values())  # the rounding's remainder to the first type
    if counts[kinds[0]] < 1:
        raise ValueError(f"{requests} requests cannot give each of {kinds} one")
    return dataclasses.replace(day, tasks={k: dataclasses.replace(s, count=counts[k]) for k, s in day.tasks.items()})


def sized(name: str, hours: float | None = None, requests: int | None = None) -> Any:
    """The protocol ``name`` (registered, or a file), longer and/or busier as asked."""
    from experiments.days import pipeline

    proto = pipeline.load(name)
    if requests is not None:
        return busier(proto, requests, hours if hours is not None else 1.0)
    if hours is not None:
        return longer(proto, hours)
    return proto
