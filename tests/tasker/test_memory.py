"""The agent's memory: the framework's typed fields, one module, and the old key still working."""

from __future__ import annotations

import pickle
import random

import pytest

from tasker.agent import DynamicAgent
from tasker.memory import INTERRUPTION_KEY, AgentMemory
from tasker.messages import Command, Flag
from tasker.synthetic import SyntheticTask
from tasker.task import TaskContext
from tasker.trace import Trace
from tests.tasker.helpers import st


def test_the_old_key_reads_and_writes_the_typed_field() -> None:
    m = AgentMemory()
    assert m.interruption_s is None
    assert INTERRUPTION_KEY not in m and m.get(INTERRUPTION_KEY) is None
    assert m.get(INTERRUPTION_KEY, 7.0) == 7.0
    with pytest.raises(KeyError):
        _ = m[INTERRUPTION_KEY]
    m["interruption_s"] = 30  # a user's task.py written against the old key
    assert m.interruption_s == 30.0 and isinstance(m.interruption_s, float)
    assert m["interruption_s"] == 30.0 and m.get("interruption_s", 1.0) == 30.0
    assert "interruption_s" in m
    assert dict(m) == {}  # a field, not a key: the task's own keys stay its own
    assert m.pop("interruption_s") == 30.0 and m.interruption_s is None
    assert m.pop("interruption_s", None) is None
    assert m.setdefault("interruption_s", 5.0) == 5.0 and m.interruption_s == 5.0
    del m["interruption_s"]
    assert m.interruption_s is None
    with pytest.raises(KeyError):
        del m["interruption_s"]


def test_a_tasks_own_keys_are_a_dict() -> None:
    m = AgentMemory({"reached": 1}, interruption_s=2.0)
    m["waiting"] = True
    assert dict(m) == {"reached": 1, "waiting": True}
    assert m.interruption_s == 2.0
    assert m.pop("reached") == 1 and m.pop("nothing", "x") == "x"
    with pytest.raises(KeyError):
        m.pop("nothing")


def test_a_copy_shares_the_plans_list_once_it_exists_and_nothing_else() -> None:
    """An estimate plans on a copy: its plans reach the agent's list only if the list existed."""
    m = AgentMemory({"k": [1]})
    early = m.copy()
    early.planned_from = []
    assert m.planned_from is None
    m.planned_from = []
    m.interruption_s = 4.0
    late = m.copy()
    assert late.planned_from is m.planned_from and late.interruption_s == 4.0
    late.interruption_s = 9.0
    late["k2"] = 2
    assert m.interruption_s == 4.0 and "k2" not in m
    assert late["k"] is m["k"]  # shallow, as dict(memory) was


def test_memory_pickles_with_its_fields() -> None:
    m = AgentMemory({"a": 1})
    m.interruption_s = 3.0
    m.restore_baseline = frozenset({("on", "cooker")})
    back = pickle.loads(pickle.dumps(m))
    assert dict(back) == {"a": 1} and back.interruption_s == 3.0
    assert back.restore_baseline == frozenset({("on", "cooker")})


def test_a_context_given_a_plain_dict_wraps_it() -> None:
    ctx = TaskContext("d1", "t", {}, 0.0, random.Random(0), memory={"interruption_s": 12, "mine": 1})
    assert isinstance(ctx.memory, AgentMemory)
    assert ctx.memory.interruption_s == 12.0 and ctx.memory["mine"] == 1


def test_a_susp_with_expected_s_sets_the_field() -> None:
    """The agent writes what ``susp`` announces into ``memory.interruption_s`` (what trees read)."""
    task = SyntheticTask("t", [st("a", 1.0)], weight=1.0)
    ctx = TaskContext("d1", "t", {}, 0.0, random.Random(0))
    agent = DynamicAgent("d1", task, ctx, trace=Trace())
    agent.deliver(Command(flag=Flag.SUSP, seq=1, data={"expected_s": 42}))
    agent._read_inbox()
    assert agent.ctx.memory.interruption_s == 42.0
    assert agent.ctx.memory["interruption_s"] == 42.0


def test_a_watched_copy_notes_every_way_of_reading_the_interruption() -> None:
    """An estimate's copy that notes whether its suspension read ``interruption_s`` (then the estimate is
    made per expected interruption; otherwise one holds for all): every way of reading it is noted, writing
    it is not, and the copy holds what :meth:`AgentMemory.copy` gives with the expectation set."""
    import copy as copying

    from tasker.memory import WatchedMemory

    own = AgentMemory({"k": [1]})
    own.planned_from = []
    own.interruption_s = 3.0
    reads = [lambda m: m.interruption_s, lambda m: m[INTERRUPTION_KEY], lambda m: m.get(INTERRUPTION_KEY),
             lambda m: INTERRUPTION_KEY in m, lambda m: m.copy(), lambda m: repr(m), lambda m: copying.copy(m),
             lambda m: copying.deepcopy(m), lambda m: pickle.dumps(m), lambda m: m.pop(INTERRUPTION_KEY, None),
             lambda m: m.setdefault(INTERRUPTION_KEY, 1.0)]
    for read in reads:
        m = WatchedMemory(own)
        m.interruption_s = 12.0
        assert not m.interruption_read
        read(m)
        assert m.interruption_read, read
    m = WatchedMemory(own)
    m["k2"] = 1
    m[INTERRUPTION_KEY] = 4.0
    m.interruption_s = 5.0
    assert dict(m) == {"k": [1], "k2": 1} and m["k"] is own["k"] and m.planned_from is own.planned_from
    assert not m.interruption_read
    assert m.interruption_s == 5.0 and m.interruption_read
    assert own.interruption_s == 3.0 and "k2" not in own  # a copy: the agent's own memory is untouched
    copied = WatchedMemory(own)
    assert copied.copy().interruption_s == 3.0 and copied.interruption_read  # as AgentMemory.copy gives it
