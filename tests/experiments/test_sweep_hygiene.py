"""Sweep hygiene: no orphans after ``kill -9``, one driver per database, paths resolved before dispatch."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from experiments.inputs.strategy import Strategy
from experiments.metrics.store import ResultStore, Status
from experiments.sweep.driver import SweepError, lease, run_sweep
from experiments.sweep.spec import Job, SweepSpec, load_spec
from tests.experiments import standin

ROOT = Path(__file__).parents[2]

_DRIVER = """
import sys
from experiments.inputs.strategy import Strategy
from experiments.sweep.driver import run_sweep
from experiments.sweep.spec import SweepSpec
from tests.experiments import standin

if __name__ == "__main__":
    demo = str(standin.DEMO)
    spec = SweepSpec(("demo",), tuple(range(int(sys.argv[2]))), (Strategy("static", "static"),),
                     sources={"demo": demo})
    run_sweep(spec, sys.argv[1], workers=2, run_fn=standin.slow_run, progress=False)
"""


def _children() -> dict[int, list[int]]:
    """``ppid -> [pid]`` for every live (non-zombie) process, from ``/proc``."""
    out: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        state, ppid = stat.rsplit(")", 1)[1].split()[:2]
        if state != "Z":
            out.setdefault(int(ppid), []).append(int(entry.name))
    return out


def _descendants(pid: int) -> set[int]:
    tree, out, todo = _children(), set(), [pid]
    while todo:
        for child in tree.get(todo.pop(), []):
            if child not in out:
                out.add(child)
                todo.append(child)
    return out


def _alive(pids: set[int]) -> set[int]:
    live = set()
    for pid in pids:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if state != "Z":
            live.add(pid)
    return live


def _start_driver(tmp_path: Path, db: Path, seeds: int, sleep: float) -> subprocess.Popen[bytes]:
    script = tmp_path / "driver.py"
    script.write_text(_DRIVER)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "STANDIN_SLEEP": str(sleep)}
    return subprocess.Popen([sys.executable, str(script), str(db), str(seeds)], cwd=ROOT, env=env,
                            start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _wait_for(condition, proc: subprocess.Popen[bytes], timeout: float = 60.0) -> None:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + timeout
    while not condition():
        assert proc.poll() is None, proc.stderr.read().decode() if proc.stderr else "the driver ended"
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.1)


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_kill_9_of_the_driver_leaves_no_process_behind(tmp_path: Path) -> None:
    proc = _start_driver(tmp_path, tmp_path / "r.db", seeds=6, sleep=60.0)
    family: set[int] = set()
    try:
        # the forkserver, the resource tracker and both workers, running jobs that would take a minute
        _wait_for(lambda: len(_descendants(proc.pid)) >= 3, proc)
        time.sleep(1.0)  # let the workers take their jobs
        family = _descendants(proc.pid)
        assert len(family) >= 2
        os.kill(proc.pid, signal.SIGKILL)  # only the driver: nothing else is signalled
        proc.wait()
        deadline = time.monotonic() + 10
        while _alive(family) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _alive(family), f"orphans survived the driver: {sorted(_alive(family))}"
    finally:
        for pid in _alive(family | _descendants(proc.pid)) | ({proc.pid} if proc.poll() is None else set()):
            os.kill(pid, signal.SIGKILL)  # only what this test started, should the assertion fail


@pytest.mark.slow
def test_a_second_driver_on_the_same_database_is_refused(tmp_path: Path) -> None:
    db = tmp_path / "r.db"
    spec = SweepSpec(("demo",), tuple(range(4)), (Strategy("static", "static"),), sources={"demo": str(standin.DEMO)})
    proc = _start_driver(tmp_path, db, seeds=4, sleep=2.0)
    lock = Path(f"{db}.lock")
    try:
        _wait_for(lambda: lock.exists() and lock.read_text().startswith("pid "), proc)
        with pytest.raises(SweepError, match=rf"another sweep is running on this database \(pid {proc.pid} "):
            run_sweep(spec, db, workers=1, run_fn=standin.run, progress=False)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    # the kernel dropped the dead driver's lease: the sweep resumes, each job stored once
    summary = run_sweep(spec, db, workers=2, run_fn=standin.run, progress=False)
    assert summary.skipped + summary.ran == 4 and summary.errors == 0
    with ResultStore(db, readonly=True) as store:
        rows = store.rows()
    assert sorted(r.seed for r in rows) == [0, 1, 2, 3] and all(r.status is Status.OK for r in rows)


def test_the_lease_is_exclusive_and_released(tmp_path: Path) -> None:
    db = tmp_path / "r.db"
    with lease(db):
        with pytest.raises(SweepError, match="another sweep is running"), lease(db):
            pass
    with lease(db):  # released on exit
        pass


def _spec_dir(tmp_path: Path) -> Path:
    d = tmp_path / "study"
    (d / "scenarios").mkdir(parents=True)
    (d / "scenarios" / "demo.toml").write_text(standin.DEMO.read_text())
    (d / "spec.toml").write_text('scenarios = ["scenarios/demo.toml"]\nseeds = 2\n'
                                 'strategies = ["update=static,suspension=static"]\n')
    return d


def test_relative_spec_path_resolves_to_absolute_sources(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    d = _spec_dir(tmp_path)
    monkeypatch.chdir(d)
    spec = load_spec("spec.toml")
    assert all(Path(j.source).is_absolute() and Path(j.source).is_file() for j in spec.jobs())


@pytest.mark.slow
def test_dask_sweep_with_a_relative_spec_path_and_workers_started_elsewhere(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from distributed import LocalCluster

    d = _spec_dir(tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # the workers start here, where no scenarios/ folder exists
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        monkeypatch.chdir(d)  # the driver reads the spec by a relative path
        spec = load_spec("spec.toml")
        relative = [Job("rel", "scenarios/demo.toml", 7, Strategy("static", "static"))]
        summary = run_sweep(spec, "r.db", scheduler_address=cluster.scheduler_address, run_fn=standin.run,
                            progress=False)
        extra = run_sweep(relative, "r2.db", scheduler_address=cluster.scheduler_address, run_fn=standin.run,
                          progress=False)
    assert (summary.ok, summary.errors) == (2, 0)
    assert (extra.ok, extra.errors) == (1, 0)
    with ResultStore(d / "r2.db", readonly=True) as store:
        (row,) = store.rows()
    assert row.record["path"] == str(d / "scenarios" / "demo.toml")
