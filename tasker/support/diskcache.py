"""Where tasker's on-disk caches live, how their keys are made, how entries are written.

Every on-disk cache of tasker — the check cache (:mod:`planners.cache`), the robot's
dimensions (:func:`robot.tiago.robot_dimensions`), TIAGo's MuJoCo source
(:func:`robot.tiago.mujoco_source`), the grown roadmap
(:meth:`robot.roadmap.Roadmap.for_world`) — stores results that are pure functions of
their inputs under the SHA-256 of those inputs plus ``tasker.__version__``
(:func:`content_key`), so a changed input, or another tasker version, is another key and
nothing is ever invalidated by hand.

The folder is ``$TASKER_CACHE``, else ``$XDG_CACHE_HOME/tasker``, else
``~/.cache/tasker`` (:func:`cache_dir`); ``TASKER_CACHE=off`` (or ``0``, ``none``) disables every cache.  An
entry is written to a temporary file in its own folder and renamed into place
(:func:`write_atomic`; atomic on POSIX), so concurrent processes — sweep workers — never
see half an entry.  A cache is an optimisation: a folder that cannot be written just means
no cache, and a reader that finds an entry it cannot use computes the result again.

Standard library only: ``robot/`` and ``planners/`` both use it, neither imports the other.
"""

from __future__ import annotations

import hashlib
import logging
import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TypeVar

from tasker import __version__

ENV_VAR = "TASKER_CACHE"
T = TypeVar("T")
log = logging.getLogger(__name__)


def cache_dir() -> Path | None:
    """The cache folder (see the module docstring); ``None`` when disabled."""
    explicit = os.environ.get(ENV_VAR)
    if explicit:
        return None if explicit.lower() in ("off", "0", "none") else Path(explicit).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "tasker"


def content_key(kind: str, parts: Iterable[str | bytes]) -> str:
    """SHA-256 over the entry's kind, tasker's version and every part (length-prefixed)."""
    h = hashlib.sha256()
    for part in (kind, __version__, *parts):
        data = part.encode() if isinstance(part, str) else part
        h.update(len(data).to_bytes(8, "little"))
        h.update(data)
    return h.hexdigest()


def entry_path(kind: str, key: str, suffix: str) -> Path | None:
    """Where the entry of ``kind`` with ``key`` lives (``kind/ab/abcd….suffix``); ``None`` when disabled."""
    root = cache_dir()
    return None if root is None else root / kind / key[:2] / f"{key}{suffix}"


def write_atomic(path: Path, data: bytes) -> bool:
    """Write ``data`` to ``path`` through a temporary file and a rename; ``False`` (and a debug
    log) when the folder cannot be written."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=path.suffix)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError as exc:
        log.debug("cache entry not written (%s): %s", path, exc)
        return False
    return True


def read_entry(path: Path | None) -> bytes | None:
    """The bytes of an entry, or ``None`` when the cache is off or the entry is missing or unreadable."""
    if path is None:
        return None
    try:
        return path.read_bytes()
    except FileNotFoundError:
        return None
    except OSError as exc:
        log.debug("cache entry not read (%s): %s", path, exc)
        return None


def remembered(kind: str, key: str, suffix: str, compute: Callable[[], T], encode: Callable[[T], bytes],
               decode: Callable[[bytes], T | None]) -> T:
    """The value of the entry of ``kind`` with ``key``, if there is one ``decode`` can use
    (``None``: it cannot); else ``compute()``, written (``encode``) for the next process."""
    path = entry_path(kind, key, suffix)
    data = read_entry(path)
    value = None if data is None else decode(data)
    if value is None:
        value = compute()
        if path is not None:
            write_atomic(path, encode(value))
    return value


def installed_version(*dists: str) -> str:
    """``"name version"`` of the first of ``dists`` installed (a distribution's name differs by
    installer: ``pin`` or ``pinocchio``), for a key; ``"name absent"`` when none is."""
    from importlib import metadata

    for dist in dists:
        try:
            return f"{dist} {metadata.version(dist)}"
        except metadata.PackageNotFoundError:
            continue
    return f"{dists[0]} absent"
