"""A small on-disk record of checks that passed, keyed by content hash.

Loading a task folder checks it completely — the PDDL, ``task.toml`` against the
domain, and the ``[example]`` problem solved by Fast Downward — and ``tasker plan``
checks a domain and a problem with unified-planning's reader.  Each process used to do
this again.  Now a check that passed leaves a marker named by the SHA-256 of
everything it read plus ``tasker.__version__`` (and the check's kind), so the next
process skips it: a changed file, or another tasker version, is a different key.
Only successes are recorded; a failing input is checked again (and fails again with
its message) every time.

The folder is ``$TASKER_CACHE``, else ``$XDG_CACHE_HOME/tasker``, else
``~/.cache/tasker``.  Markers are written to a temporary file and renamed into place
(atomic on POSIX), so concurrent processes — sweep workers — never see half a marker.
The cache is an optimisation: a folder that cannot be written just means no cache.
``TASKER_CACHE=off`` disables it.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

from tasker import __version__

ENV_VAR = "TASKER_CACHE"
log = logging.getLogger(__name__)


def cache_dir() -> Path | None:
    """Where markers go (see the module docstring); ``None`` when disabled."""
    explicit = os.environ.get(ENV_VAR)
    if explicit:
        return None if explicit.lower() in ("off", "0", "none") else Path(explicit).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "tasker"


def content_key(kind: str, parts: Iterable[str | bytes]) -> str:
    """SHA-256 over the check's kind, tasker's version and every part (length-prefixed)."""
    h = hashlib.sha256()
    for part in (kind, __version__, *parts):
        data = part.encode() if isinstance(part, str) else part
        h.update(len(data).to_bytes(8, "little"))
        h.update(data)
    return h.hexdigest()


def file_parts(files: Iterable[Path]) -> list[str | bytes]:
    """The names and bytes of the files a check reads (a missing one counts as absent)."""
    parts: list[str | bytes] = []
    for p in files:
        parts += [p.name, p.read_bytes() if p.is_file() else b"\0absent"]
    return parts


def _marker(kind: str, key: str) -> Path | None:
    root = cache_dir()
    return None if root is None else root / kind / key[:2] / f"{key}.json"


def passed(kind: str, key: str) -> bool:
    """Whether a check of ``kind`` with this content key passed before."""
    m = _marker(kind, key)
    return m is not None and m.is_file()


def record(kind: str, key: str, info: dict[str, object] | None = None) -> None:
    """Remember that a check passed (atomically; silently nothing when the folder is unwritable)."""
    m = _marker(kind, key)
    if m is None:
        return
    try:
        m.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=m.parent, prefix=".tmp-", suffix=".json")
        with os.fdopen(fd, "w") as f:
            json.dump({"kind": kind, "tasker": __version__, **(info or {})}, f)
        os.replace(tmp, m)
    except OSError as exc:
        log.debug("cache not written (%s): %s", m, exc)
