"""The bundled task types: one folder per type (``domain.pddl``, ``task.toml``, ``task.py``).

This package is data plus task hooks that import only ``tasker``; the loader that
turns a folder into a task type is :mod:`planners.loader`, and
``planners.bundled.task_types()`` returns them all (it is the ``tasker.tasks`` entry
point).  Folders named in ``$TASKER_TASKS`` (separated by ``os.pathsep``) are loaded
too.  See ``docs/domains.md`` for the format.
"""

from __future__ import annotations

from pathlib import Path

BUNDLED = Path(__file__).resolve().parent


def bundled_names() -> list[str]:
    """Names of the task folders shipped in this package."""
    return sorted(p.name for p in BUNDLED.iterdir() if (p / "task.toml").is_file())
