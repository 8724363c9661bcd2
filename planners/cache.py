"""A small on-disk record of checks that passed, keyed by content hash.

Loading a task folder checks it completely — the PDDL, ``task.toml`` against the
domain, and the ``[example]`` problem solved by Fast Downward — and ``tasker plan``
checks a domain and a problem with unified-planning's reader.  Each process used to do
this again.  Now a check that passed leaves a marker named by the SHA-256 of
everything it read plus ``tasker.__version__`` (and the check's kind), so the next
process skips it: a changed file, or another tasker version, is a different key.
Only successes are recorded; a failing input is checked again (and fails again with
its message) every time.

The folder, the key and the atomic write are :mod:`tasker.support.diskcache`'s, shared with the
robot's caches: ``$TASKER_CACHE``, else ``$XDG_CACHE_HOME/tasker``, else
``~/.cache/tasker``; markers are written to a temporary file and renamed into place
(atomic on POSIX), so concurrent processes — sweep workers — never see half a marker.
The cache is an optimisation: a folder that cannot be written just means no cache.
``TASKER_CACHE=off`` disables it.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from tasker import __version__
from tasker.support.diskcache import ENV_VAR, cache_dir, content_key, entry_path, write_atomic

__all__ = ["ENV_VAR", "cache_dir", "content_key", "file_parts", "passed", "record", "remembered"]


def file_parts(files: Iterable[Path]) -> list[str | bytes]:
    """The names and bytes of the files a check reads (a missing one counts as absent)."""
    parts: list[str | bytes] = []
    for p in files:
        parts += [p.name, p.read_bytes() if p.is_file() else b"\0absent"]
    return parts


def passed(kind: str, key: str) -> bool:
    """Whether a check of ``kind`` with this content key passed before."""
    m = entry_path(kind, key, ".json")
    return m is not None and m.is_file()


def remembered(kind: str, key: str) -> dict[str, Any] | None:
    """What :func:`record` kept of a check of ``kind`` that passed with this content key (e.g. the
    warnings it gave, to be given again), or ``None``; an unreadable marker counts as none."""
    m = entry_path(kind, key, ".json")
    if m is None or not m.is_file():
        return None
    try:
        info = json.loads(m.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return info if isinstance(info, dict) else None


def record(kind: str, key: str, info: dict[str, object] | None = None) -> None:
    """Remember that a check passed (atomically; silently nothing when the folder is unwritable)."""
    m = entry_path(kind, key, ".json")
    if m is not None:
        write_atomic(m, json.dumps({"kind": kind, "tasker": __version__, **(info or {})}).encode())
