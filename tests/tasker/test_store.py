"""The task store: registration, folders, clear errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from tasker.errors import ConfigError, UnknownName
from tasker.store import TaskStore

from .helpers import guide


def test_duplicate_names_are_refused_naming_both_sources() -> None:
    store = TaskStore([guide("g")])
    with pytest.raises(ConfigError, match="registered twice: by python and by plugin"):
        store.register(guide("g"), source="plugin")


def test_unknown_type_lists_known_ones() -> None:
    with pytest.raises(UnknownName, match="unknown task type 'x'; known: a, b"):
        TaskStore([guide("b"), guide("a")]).get("x")


def test_load_a_folder_of_python_task_types(tmp_path: Path) -> None:
    (tmp_path / "mine.py").write_text(
        "from tasker.synthetic import SyntheticTask\n"
        "from tasker.stage import Stage\n"
        "def task_types():\n"
        "    return [SyntheticTask('water_plants', [Stage('water', duration=3)])]\n"
    )
    store = TaskStore()
    assert store.load_folder(tmp_path) == ["water_plants"]
    assert store.validate("water_plants", {"weight": 2}) ["weight"] == 2.0


def test_a_folder_without_task_types_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="no task types found"):
        TaskStore().load_folder(tmp_path)
    with pytest.raises(ConfigError, match="not a folder"):
        TaskStore().load_folder(tmp_path / "missing")


def test_a_broken_plugin_raises(tmp_path: Path) -> None:
    (tmp_path / "broken.py").write_text("import does_not_exist\n")
    with pytest.raises(ModuleNotFoundError):
        TaskStore().load_folder(tmp_path)
