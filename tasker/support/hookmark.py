"""Which ``task.py`` hook a process is running, readable by its parent after the process died.

A hook that calls ``os._exit()`` or kills its own process leaves no exception to report: the
process is gone.  A sweep runs such a job alone in a child process (:mod:`experiments.sweep.workers`)
and gives the child a small mark file (:func:`use`); while a hook runs (:func:`inside`), its name
and task folder are written into the file through a shared memory map — a memory copy, no system
call — so the page holds them even when the process is killed with ``SIGKILL``.  The parent then
reads the mark (:func:`read`) and names the hook and the folder in the job's error.

Without a mark file (a plain ``tasker run``) :func:`inside` does nothing.  Stdlib only.
"""

from __future__ import annotations

import mmap
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

SIZE = 4096
"""Bytes of the mark: a hook's name and its ``task.py`` path, NUL-terminated."""

_map: mmap.mmap | None = None


def create(path: str | Path) -> Path:
    """Make an empty mark file at ``path`` for a child process to :func:`use`."""
    p = Path(path)
    p.write_bytes(b"\0" * SIZE)
    return p


def use(path: str | Path) -> None:
    """In the child: write marks into the file at ``path`` (made by :func:`create`)."""
    global _map
    fd = os.open(path, os.O_RDWR)
    try:
        _map = mmap.mmap(fd, SIZE, mmap.MAP_SHARED, mmap.PROT_READ | mmap.PROT_WRITE)
    finally:
        os.close(fd)


@contextmanager
def inside(where: str) -> Iterator[None]:
    """Mark ``where`` (e.g. ``check_args of /x/task.py``) as running for the time of the block."""
    m = _map
    if m is None:
        yield
        return
    data = where.encode("utf-8", "replace")[: SIZE - 1]
    m[: len(data) + 1] = data + b"\0"
    try:
        yield
    finally:
        m[0] = 0


def read(path: str | Path) -> str | None:
    """The hook that was running when the child died, or ``None`` (no hook was running)."""
    try:
        data = Path(path).read_bytes()[:SIZE]
    except OSError:
        return None
    text = data.split(b"\0", 1)[0].decode("utf-8", "replace")
    return text or None
