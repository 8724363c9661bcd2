"""The path beyond one machine, as docs/sweeps.md ("On a cluster") tells a user to take it.

A cluster manager (``dask_jobqueue.SLURMCluster`` on SLURM) hands out a Dask scheduler
address; ``tasker sweep`` and ``tasker day`` are pointed at it with
``--scheduler-address`` while the driver, the one writer of the shared results database,
runs where the user started it.  Dask's ``LocalCluster`` has the same interface
(``scheduler_address``, ``scale``), so it stands in for SLURM here: the jobs run in the
cluster's worker processes, the database is written by the driver, and a second command
on the same database — after widening the sweep or the days — runs only what is missing.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from experiments.cli import main
from experiments.metrics.store import ResultStore

DEMO = Path(__file__).parents[2] / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml"


def _spec(path: Path, seeds: int) -> Path:
    path.write_text(f'scenarios = ["{DEMO}"]\nseeds = {seeds}\nseed_start = 1\n'
                    'strategies = ["update=static,suspension=static"]\n')
    return path


@pytest.mark.slow
def test_a_sweep_and_a_day_on_a_cluster_share_the_database_and_resume(tmp_path: Path) -> None:
    from distributed import LocalCluster

    db, out = tmp_path / "results.db", tmp_path / "day"
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        cluster.scale(2)  # what a user does with SLURMCluster: ask for workers
        address = cluster.scheduler_address
        assert main(["sweep", str(_spec(tmp_path / "s.toml", 2)), "--db", str(db), "--scheduler-address", address,
                     "--no-progress"]) == 0
        with ResultStore(db, readonly=True) as store:
            first = {r.key: r for r in store.rows()}
        # widened: two more seeds; the same database, a new driver
        assert main(["sweep", str(_spec(tmp_path / "s.toml", 4)), "--db", str(db), "--scheduler-address", address,
                     "--no-progress"]) == 0
        with ResultStore(db, readonly=True) as store:
            rows = {r.key: r for r in store.rows()}
        day = ["day", "--protocol", "tabsa-short", "--schedulers", "fifo", "--out", str(out),
               "--scheduler-address", address, "-q"]
        assert main([*day, "--days", "1"]) == 0
        with ResultStore(out / "days.db", readonly=True) as store:
            day_one = {r.key: r for r in store.rows()}
        assert main([*day, "--days", "2", "--resume"]) == 0
        with ResultStore(out / "days.db", readonly=True) as store:
            days = {r.key: r for r in store.rows()}
    assert len(first) == 2 and len(rows) == 4
    assert all(rows[k] == r for k, r in first.items())  # stored once, never run again
    assert len(day_one) == 1 and len(days) == 2 and all(days[k] == r for k, r in day_one.items())
    # the jobs ran in the cluster's worker processes, not in the driver (this process)
    assert {r.worker for r in [*rows.values(), *days.values()]}.isdisjoint({f"{os.uname().nodename}:{os.getpid()}"})
    assert all(r.status.value == "ok" for r in [*rows.values(), *days.values()])
