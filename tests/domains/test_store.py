"""The bundled task types in the core's task store: requests are checked against their arguments."""

from __future__ import annotations

import pytest

from planners.bundled import task_types
from tasker.errors import BadRequest
from tasker.store import TaskStore


def test_bundled_task_types_register() -> None:
    store = TaskStore(task_types())
    assert store.names() == ["carry_object", "cook", "guide_human", "human_fell"]
    assert store.validate("guide_human", {"person": "john", "destination": "kitchen"}) == {
        "person": "john", "destination": "kitchen"}
    assert store.validate("cook", {}) == {"pan": "pan", "cooker": "cooker"}
    with pytest.raises(BadRequest, match="missing required argument 'destination'"):
        store.validate("guide_human", {"person": "john"})
    with pytest.raises(BadRequest, match="unknown argument"):
        store.validate("human_fell", {"person": "peter", "speed": 2})
