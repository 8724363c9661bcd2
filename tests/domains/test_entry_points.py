"""The installed entry points: the bundled task types and the PDDL folder loader reach the core's store."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import domains
from tasker.store import TaskStore


def test_default_store_has_the_bundled_task_types() -> None:
    store = TaskStore.default()
    assert {"guide_human", "human_fell", "cook", "carry_object"} <= set(store.names())
    assert store.source("cook").startswith("entry point")


@pytest.mark.slow
def test_store_loads_a_pddl_task_folder_a_user_points_at(tmp_path: Path) -> None:
    shutil.copytree(domains.BUNDLED / "guide_human", tmp_path / "escort", ignore=shutil.ignore_patterns("__pycache__"))
    toml = tmp_path / "escort" / "task.toml"
    toml.write_text(toml.read_text().replace('name = "guide_human"', 'name = "escort"', 1))
    store = TaskStore()
    assert store.load_folder(tmp_path) == ["escort"]
    assert store.validate("escort", {"person": "john", "destination": "kitchen"}) == {
        "person": "john", "destination": "kitchen"}
