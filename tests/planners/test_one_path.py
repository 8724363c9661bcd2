"""One path from Fast Downward to a result, the engine's contract, and the check cache."""

from __future__ import annotations

import json
import multiprocessing
from pathlib import Path

import pytest
from unified_planning.shortcuts import OneshotPlanner

import planners.cache as cache
import tasker.support.diskcache
from planners.checks import load_problem
from planners.fd import FDExit, FDOutcome
from planners.planner import PddlText, Planner
from planners.registration import register_engine
from planners.results import PlanStatus, from_fd_outcome
from tests.planners.conftest import DOMAIN, problem_text


@pytest.mark.parametrize("exit_, status", [
    (FDExit.UNSOLVABLE, PlanStatus.UNSOLVABLE), (FDExit.TIMEOUT, PlanStatus.TIMEOUT),
    (FDExit.MEMOUT, PlanStatus.ERROR), (FDExit.ERROR, PlanStatus.ERROR),
])
def test_every_fd_failure_maps_to_one_status_with_a_message(exit_: FDExit, status: PlanStatus) -> None:
    r = from_fd_outcome(FDOutcome(exit_, 99, None, None, 0.01, 0.02), "tasker-fd", 0.05)
    assert r.status is status and r.plan is None and r.message
    assert ("memory" in r.message) == (exit_ is FDExit.MEMOUT)


def test_solved_outcome_keeps_plan_and_cost() -> None:
    steps = (("move", "a", "b"),)
    r = from_fd_outcome(FDOutcome(FDExit.SOLVED, 0, steps, 2.0, 0.0, 0.0), "tasker-fd", 0.1)
    assert r.solved and r.plan == steps and r.cost == 2.0
    r = from_fd_outcome(FDOutcome(FDExit.SOLVED, 0, steps, None, 0.0, 0.0), "tasker-fd", 0.1)
    assert r.cost == 1.0  # no cost line: unit cost


def test_engine_refuses_unknown_params() -> None:
    register_engine()
    with pytest.raises(TypeError, match="nope"):
        OneshotPlanner(name="tasker-fd", params={"nope": 1})
    with pytest.raises(ValueError, match="timeout"):
        OneshotPlanner(name="tasker-fd", params={"timeout": -1.0})


@pytest.mark.slow
@pytest.mark.parametrize("goal, solved", [("(item-at cup c)", True), ("(holding cup) (item-at cup c)", False)])
def test_engine_and_facade_agree_and_the_engine_logs(goal: str, solved: bool, tmp_path: Path) -> None:
    d, p = tmp_path / "d.pddl", tmp_path / "p.pddl"
    d.write_text(DOMAIN)
    p.write_text(problem_text(goal=goal))
    _, text, problem = load_problem(d, p)
    facade = Planner(cache_size=0).solve(PddlText(DOMAIN, text))
    register_engine()
    with OneshotPlanner(name="tasker-fd") as engine:
        engine.skip_checks = True
        res = engine.solve(problem)
    assert res.log_messages, "the engine says what happened"
    assert facade.solved == solved == (res.plan is not None)
    if solved:
        assert [(a.action.name, *map(str, a.actual_parameters)) for a in res.plan.actions] == \
            [list(s) for s in facade.plan or ()] or facade.cost == float(res.metrics["cost"])
    else:
        assert res.status.name == "UNSOLVABLE_PROVEN" and facade.status is PlanStatus.UNSOLVABLE


def test_planner_refuses_a_bad_timeout() -> None:
    for bad in (0.0, -1.0, float("inf"), float("nan")):
        with pytest.raises(ValueError, match="timeout"):
            Planner(timeout=bad)


# -- the check cache -----------------------------------------------------------------------------


@pytest.fixture
def cache_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "c"))
    return tmp_path / "c"


def test_cache_is_keyed_by_content_kind_and_version(cache_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    key = cache.content_key("k", ["a", b"b"])
    assert not cache.passed("k", key)
    cache.record("k", key)
    assert cache.passed("k", key) and not cache.passed("other", key)
    assert cache.content_key("k", ["a", b"c"]) != key
    assert cache.content_key("k", ["ab", b""]) != cache.content_key("k", ["a", b"b"])  # length-prefixed
    monkeypatch.setattr(tasker.support.diskcache, "__version__", "9.9.9")
    assert cache.content_key("k", ["a", b"b"]) != key


def test_cache_location(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.delenv("TASKER_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.cache_dir() == tmp_path / "xdg" / "tasker"
    monkeypatch.setenv("TASKER_CACHE", "off")
    assert cache.cache_dir() is None
    cache.record("k", "0" * 64)  # disabled: nothing, no error
    assert not cache.passed("k", "0" * 64)


def test_unwritable_cache_is_no_cache(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    (tmp_path / "file").write_text("")
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "file" / "c"))
    cache.record("k", "1" * 64)
    assert not cache.passed("k", "1" * 64)


def _writer(root: str, n: int) -> None:
    import os

    os.environ["TASKER_CACHE"] = root
    for i in range(n):
        cache.record("race", f"{i:064d}", {"pid": os.getpid()})


@pytest.mark.slow
def test_concurrent_writers_leave_whole_markers(cache_dir: Path) -> None:
    ctx = multiprocessing.get_context("spawn")
    procs = [ctx.Process(target=_writer, args=(str(cache_dir), 20)) for _ in range(3)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(60)
        assert p.exitcode == 0
    markers = list((cache_dir / "race").rglob("*.json"))
    assert len(markers) == 20
    for m in markers:
        assert json.loads(m.read_text())["kind"] == "race"
    assert not list((cache_dir / "race").rglob(".tmp-*"))


@pytest.mark.slow
def test_task_folder_example_is_solved_once_per_content(cache_dir: Path, tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    import planners.loader as loader
    from planners.scaffold import scaffold

    folder = tmp_path / "t"
    scaffold("t", folder)  # loads it once: the example solved and recorded
    calls: list[str] = []
    real = loader._check_example
    monkeypatch.setattr(loader, "_check_example", lambda task: calls.append(task.name) or real(task))
    loader.load_task(folder)
    assert calls == []
    loader.load_task(folder, use_cache=False)
    assert calls == ["t"]
    (folder / "task.toml").write_text((folder / "task.toml").read_text().replace("cps = 1.0", "cps = 2.0"))
    loader.load_task(folder)
    assert calls == ["t", "t"]
