"""Sweeps: many runs of scenarios × seeds × strategies, in parallel, resumable.

A :class:`SweepSpec` (usually read from a small TOML file by :func:`load_spec`)
expands to a list of :class:`Job`; :func:`run_sweep` runs those whose key is not in
the results database yet, on local worker processes or on a Dask cluster, and the
driving process stores each result (:mod:`experiments.store`) the moment it
arrives.  Killing a sweep loses only the runs in flight; running it again resumes.
A job that raises, or that kills its worker process, is stored as an ``error`` run
and the sweep goes on.

The function that runs one job is injectable (``run_fn``): a picklable top-level
function ``job -> (record, metrics)``.  The default, :func:`run_job`, calls
:func:`experiments.runner.run_scenario` with ``randomize=True``, so each seed is a
different randomised variant of the scenario.  See ``docs/sweeps.md``.
"""

from __future__ import annotations

import ctypes
import dataclasses
import fcntl
import itertools
import logging
import multiprocessing
import os
import platform
import signal
import socket
import sys
import tempfile
import threading
import time
import traceback
from collections import deque
from collections.abc import Callable, Generator, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, CancelledError, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import tasker
from experiments.scenario import InterruptionGrid
from experiments.store import JobKey, ResultStore, RunRow, Status
from tasker import reader
from tasker.errors import TaskerError
from tasker.reader import InputError

STRATEGY_VALUES = ("static", "planned")

_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>

MAX_JOBS = 100_000
"""A spec that expands to more jobs than this is refused (a typo such as ``seeds = 10000000``)."""

log = logging.getLogger(__name__)

RunFn = Callable[["Job"], tuple[Mapping[str, Any], Mapping[str, Any]]]
"""Runs one job and returns ``(record, metrics)``; must be a picklable top-level function."""


class SpecError(InputError):
    """A sweep spec is malformed; the message names the file, the line and the field."""


class SweepError(TaskerError, RuntimeError):
    """A sweep cannot run (bad arguments, two jobs with the same key)."""


@dataclass(frozen=True)
class Strategy:
    """One cell of the sweep's factorial design: the factors a run varies.

    ``update``/``suspension``: how ``upTsk`` and ``genSusp`` build their plans (``static`` or
    ``planned``); ``policy``: when a suspension is required (``strict`` or ``conditional``,
    applied to both suspension strategies); ``hazard_waiting``: hazard-aware waiting off or
    on; ``scheduler``: the harmoniser's scheduler.  ``None`` leaves the scenario's own setting.
    """

    update: str | None = None
    suspension: str | None = None
    scheduler: str | None = None
    policy: str | None = None
    hazard_waiting: bool | None = None

    def __post_init__(self) -> None:
        for name in ("update", "suspension"):
            value = getattr(self, name)
            if value is not None and value not in STRATEGY_VALUES:
                raise ValueError(f"{name}: expected one of {list(STRATEGY_VALUES)}, got {value!r}")
        if self.policy is not None and self.policy not in POLICY_VALUES:
            raise ValueError(f"policy: expected one of {list(POLICY_VALUES)}, got {self.policy!r}")
        if self.hazard_waiting is not None and not isinstance(self.hazard_waiting, bool):
            raise ValueError(f"hazard_waiting: expected true or false, got {self.hazard_waiting!r}")
        if self.scheduler is not None and (not isinstance(self.scheduler, str) or not self.scheduler):
            raise ValueError(f"scheduler: expected a scheduler name, got {self.scheduler!r}")

    @property
    def label(self) -> str:
        """The key of the strategy in the results database, e.g. ``update=planned,suspension=static``.

        Factors left out (``None``) do not appear, so labels of older sweeps stay what they were."""
        parts = [f"{k}={_show(v)}" for k, v in self.items()]
        return ",".join(parts) if parts else "default"

    def items(self) -> list[tuple[str, Any]]:
        """The factors that are set, in label order (see :data:`FACTORS`)."""
        return [(k, v) for k in FACTORS if (v := getattr(self, k)) is not None]

    @classmethod
    def parse(cls, text: str) -> Strategy:
        """The inverse of :attr:`label`: ``"update=planned,suspension=static,policy=strict,hazard_waiting=on"``."""
        if text.strip() == "default":
            return cls()
        fields: dict[str, Any] = {}
        for part in text.split(","):
            key, sep, value = part.partition("=")
            key, value = key.strip(), value.strip()
            if not sep or key not in FACTORS or not value:
                raise ValueError(f"expected 'update=…,suspension=…[,policy=…][,hazard_waiting=on|off]"
                                 f"[,scheduler=…]', got {text!r}{reader.suggest(key, list(FACTORS))}")
            if key in fields:
                raise ValueError(f"{key} given twice in {text!r}")
            fields[key] = _switch(value) if key == "hazard_waiting" else value
        return cls(**fields)


FACTORS = ("update", "suspension", "policy", "hazard_waiting", "scheduler")
"""The factors of a :class:`Strategy`, in the order of its label."""

POLICY_VALUES = ("strict", "conditional")

_SWITCH = {"on": True, "off": False, "true": True, "false": False}


def _show(value: Any) -> str:
    return ("on" if value else "off") if isinstance(value, bool) else str(value)


def _switch(value: Any) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.lower() in _SWITCH:
        return _SWITCH[value.lower()]
    raise ValueError(f"hazard_waiting: expected on/off (or true/false), got {value!r}")


def expand(factors: Mapping[str, Sequence[Any]]) -> list[Strategy]:
    """Every combination of the levels of ``factors`` (a grid), in :data:`FACTORS` order, the first
    factor varying slowest: ``{"suspension": ["static", "planned"], "hazard_waiting": [False, True]}``
    gives four strategies."""
    unknown = [k for k in factors if k not in FACTORS]
    if unknown:
        raise ValueError(f"unknown factor {unknown[0]!r}{reader.suggest(unknown[0], list(FACTORS))}")
    names = [k for k in FACTORS if k in factors]
    levels: list[list[Any]] = [[_switch(v) if k == "hazard_waiting" else v for v in factors[k]] for k in names]
    combos: list[dict[str, Any]] = [dict(zip(names, c, strict=True)) for c in itertools.product(*levels)]
    return [Strategy(**c) for c in combos]


@dataclass(frozen=True)
class Job:
    """One run of a sweep: a scenario (as named in the spec and where to read it), a seed, a strategy."""

    scenario: str
    source: str
    seed: int
    strategy: Strategy
    task_paths: tuple[str, ...] = ()  # absolute task folders (--path), so a Dask worker elsewhere loads the same
    interruption: InterruptionGrid | None = None  # where variants place the interruption ([variants.NAME])

    @property
    def key(self) -> JobKey:
        return (self.scenario, self.seed, self.strategy.label)


@dataclass(frozen=True)
class SweepSpec:
    """Scenarios × seeds × strategies.  ``sources`` maps a scenario (as written) to the file to run."""

    scenarios: tuple[str, ...]
    seeds: tuple[int, ...]
    strategies: tuple[Strategy, ...]
    name: str = "sweep"
    sources: Mapping[str, str] = field(default_factory=dict)
    task_paths: tuple[str, ...] = ()
    variants: Mapping[str, InterruptionGrid] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.scenarios:
            raise ValueError("scenarios: expected at least one scenario")
        if not self.seeds:
            raise ValueError("seeds: expected at least one seed")
        if not self.strategies:
            raise ValueError("strategies: expected at least one strategy")
        unknown = sorted(set(self.variants) - set(self.scenarios))
        if unknown:
            raise ValueError(f"variants: {unknown[0]!r} is not one of the scenarios {list(self.scenarios)}")
        for what, items in (("scenarios", self.scenarios), ("seeds", self.seeds),
                            ("strategies", [s.label for s in self.strategies])):
            if len(set(items)) != len(items):
                raise ValueError(f"{what}: duplicates in {list(items)}")
        n = len(self.scenarios) * len(self.seeds) * len(self.strategies)
        if n > MAX_JOBS:
            raise ValueError(f"the spec expands to {n} jobs, more than the {MAX_JOBS} a sweep may have")

    def jobs(self) -> list[Job]:
        """Every job, scenario-major then seed then strategy (so paired runs finish close together)."""
        return [Job(sc, self.sources.get(sc, sc), seed, st, self.task_paths, self.variants.get(sc))
                for sc in self.scenarios for seed in self.seeds for st in self.strategies]

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "scenarios": list(self.scenarios), "seeds": list(self.seeds),
                               "strategies": [s.label for s in self.strategies], "sources": dict(self.sources)}
        if self.variants:
            out["variants"] = {sc: g.to_json() for sc, g in sorted(self.variants.items())}
        return out


@dataclass(frozen=True)
class SweepSummary:
    """What :func:`run_sweep` did: ``total`` jobs in the spec, ``skipped`` because stored, and the rest."""

    total: int
    skipped: int
    ran: int
    ok: int
    errors: int
    not_run: int
    wall: float
    backend: str


@dataclass(frozen=True)
class Outcome:
    """What a worker sends back for one job."""

    key: JobKey
    status: Status
    record: Mapping[str, Any]
    metrics: Mapping[str, Any]
    error: str | None
    wall: float
    worker: str


# ----------------------------------------------------------------------------------------- spec files


def _looks_like_path(text: str) -> bool:
    return "/" in text or os.sep in text or text.endswith((".toml", ".json"))


SPEC_KEYS = ("name", "scenarios", "seeds", "seed_start", "strategies", "factors", "variants")

FACTOR_LEVELS: dict[str, tuple[Any, ...] | None] = {
    "update": STRATEGY_VALUES, "suspension": STRATEGY_VALUES, "policy": POLICY_VALUES,
    "hazard_waiting": (False, True), "scheduler": None}
"""The levels each factor of a ``[factors]`` grid may take (``None``: a registered scheduler)."""


def load_spec(path: str | Path, *, max_jobs: int | None = None) -> SweepSpec:
    """Read and check a sweep spec (TOML) with :mod:`tasker.reader`.

    Fields: ``name`` (optional), ``scenarios`` (list of files or shipped names), ``seeds``
    (a count, seeds ``seed_start`` … ``seed_start + count - 1``, or a list), ``seed_start``
    (optional, default 0), ``strategies`` (list of ``"update=…,suspension=…[,scheduler=…]"``
    strings or tables).  Scenario paths are relative to the spec file and come back
    absolute, so workers started anywhere (Dask) find them.  A spec that expands to more
    than ``max_jobs`` (default :data:`MAX_JOBS`) jobs is refused.
    """
    from experiments import scenario as scenarios

    limit = MAX_JOBS if max_jobs is None else max_jobs
    p = Path(path).resolve()
    top = reader.load(p, SpecError)
    name = str(top.string("name", p.stem))
    scenario_list = top.array("scenarios", nonempty=True)
    at = top.at("scenarios", {})
    sources: dict[str, str] = {}
    for i, sc in enumerate(scenario_list):
        if not isinstance(sc, str) or not sc:
            raise at.error(i, f"expected a scenario file or a shipped scenario name, got {sc!r}")
        if sc in scenario_list[:i]:
            raise at.error(i, f"{sc!r} is listed twice")
        if _looks_like_path(sc):
            file = Path(sc) if Path(sc).is_absolute() else p.parent / sc
            if not file.is_file():
                raise at.error(i, f"no such file: {file} (scenario paths are relative to the spec file)")
            sources[sc] = str(file.resolve())
        else:
            try:  # a shipped scenario's name is passed on as it is: every worker has the package
                scenarios.resolve(sc)
            except reader.InputError as exc:
                raise at.error(i, exc.message) from None
    start = int(top.number("seed_start", 0, integer=True, min=0, max=reader.MAX_SEED))
    seeds_raw = top.raw("seeds")
    if isinstance(seeds_raw, int) and not isinstance(seeds_raw, bool):
        if seeds_raw < 1:
            raise top.error("seeds", f"expected a positive count, got {seeds_raw}")
        if seeds_raw > limit:
            raise top.error("seeds", f"{seeds_raw} seeds is more than the {limit} jobs a sweep may have")
        if start + seeds_raw - 1 > reader.MAX_SEED:
            raise top.error("seeds", f"seeds {start}..{start + seeds_raw - 1} go past the largest seed, "
                                     f"{reader.MAX_SEED}")
        seeds = tuple(range(start, start + seeds_raw))
    elif isinstance(seeds_raw, list) and seeds_raw:
        st = top.at("seeds", {})
        for i, s in enumerate(seeds_raw):
            reader.check_number(st, i, s, integer=True, min=0, max=reader.MAX_SEED)
        if "seed_start" in top:
            raise top.error("seed_start", "only with a count of seeds, not a list")
        dup = sorted({s for s in seeds_raw if seeds_raw.count(s) > 1})
        if dup:
            raise top.error("seeds", f"duplicates {dup} in the list of seeds")
        seeds = tuple(seeds_raw)
    else:
        raise top.error("seeds", f"expected a count or a non-empty list of integers, got {seeds_raw!r}")
    strategies: list[Strategy] = []
    strategies_t = top.at("strategies", {})
    if "strategies" not in top and "factors" not in top:
        raise top.error("strategies", "missing: give a list of strategies, a [factors] grid, or both")
    for i, st in enumerate(top.array("strategies", [], nonempty="strategies" in top)):
        try:
            if isinstance(st, str):
                strategies.append(Strategy.parse(st))
            elif isinstance(st, dict):
                t = strategies_t.at(i, st)
                values: dict[str, Any] = {k: t.string(k, choices=FACTOR_LEVELS[k]) for k in FACTORS
                                          if k in t and k != "hazard_waiting"}
                if "hazard_waiting" in t:
                    values["hazard_waiting"] = t.boolean("hazard_waiting")
                strategies.append(Strategy(**values))
                t.done(FACTORS)
            else:
                raise ValueError(f"expected a string such as 'update=planned,suspension=static' or a table, "
                                 f"got {st!r}")
        except (ValueError, TypeError) as exc:
            if isinstance(exc, reader.InputError):
                raise
            raise strategies_t.error(i, str(exc)) from None
        _check_scheduler(strategies_t, i, strategies[-1])
    if "factors" in top:
        strategies += _grid(top.table("factors"))
    labels = [s.label for s in strategies]
    dup_labels = sorted({x for x in labels if labels.count(x) > 1})
    if dup_labels:
        raise top.error("strategies", f"duplicates {dup_labels}")
    top.done(SPEC_KEYS)
    n = len(scenario_list) * len(seeds) * len(strategies)
    if n > limit:
        raise top.error("seeds", f"the spec expands to {len(scenario_list)} scenarios x {len(seeds)} seeds x "
                                 f"{len(strategies)} strategies = {n} jobs, more than the {limit} a sweep may have")
    variants = _variants(top.table("variants", {}), scenario_list)
    return SweepSpec(tuple(scenario_list), seeds, tuple(strategies), name=name, sources=sources, variants=variants)


def _check_scheduler(t: reader.Table, key: str | int, strategy: Strategy) -> None:
    if strategy.scheduler is not None:
        from tasker import schedulers

        reader.check_name(t, key, strategy.scheduler, schedulers.names(), "scheduler")


def _grid(t: reader.Table) -> list[Strategy]:
    """The strategies of a ``[factors]`` table: every combination of the factors' levels."""
    factors: dict[str, list[Any]] = {}
    for key in t.keys():
        if key not in FACTORS:
            raise t.error(key, f"unknown factor {key!r}{reader.suggest(key, FACTORS)} (factors: {', '.join(FACTORS)})")
        levels = t.array(key, nonempty=True)
        lt = t.at(key, {})  # for errors located at an element of the array
        for i, v in enumerate(levels):
            if key == "hazard_waiting":
                if not isinstance(v, bool):
                    raise lt.error(i, f"expected true or false, got {v!r}")
            elif key == "scheduler":
                if not isinstance(v, str) or not v:
                    raise lt.error(i, f"expected a scheduler name, got {v!r}")
                _check_scheduler(lt, i, Strategy(scheduler=v))
            else:
                choices = FACTOR_LEVELS[key] or ()
                if v not in choices:
                    raise lt.error(i, f"expected one of {list(choices)}, got {v!r}{reader.suggest(str(v), choices)}")
        dup = sorted({str(v) for v in levels if levels.count(v) > 1})
        if dup:
            raise t.error(key, f"duplicates {dup}")
        factors[key] = levels
    if not factors:
        raise t.error(None, "expected at least one factor, e.g. suspension = [\"static\", \"planned\"]")
    return expand(factors)


def _variants(t: reader.Table, scenario_list: Sequence[str]) -> dict[str, InterruptionGrid]:
    """``[variants.NAME]`` tables: where the variants of scenario NAME place its interruption."""
    out: dict[str, InterruptionGrid] = {}
    for sc, value in t.items():
        vt = t.at(sc, value)
        if sc not in scenario_list:
            raise t.error(sc, f"not one of the spec's scenarios{reader.suggest(sc, scenario_list)} "
                              f"(scenarios: {list(scenario_list)})")
        if not isinstance(value, dict):
            raise t.error(sc, f"expected a table (interrupt = \"requests[N]\", times = {{start, stop, step}}), "
                              f"got {value!r}")
        interrupt = vt.string("interrupt")
        times = vt.table("times")
        start = float(times.number("start", min=0))
        stop = float(times.number("stop", positive=True))
        step = float(times.number("step", positive=True))
        times.done()
        vt.done()
        try:
            out[sc] = InterruptionGrid(interrupt, start, stop, step)
        except ValueError as exc:
            key = "interrupt" if str(exc).startswith("interrupt") else "times"
            raise vt.error(key, str(exc).partition(": ")[2]) from None
    return out


# ----------------------------------------------------------------------------------------- running


def run_job(job: Job) -> tuple[dict[str, Any], dict[str, Any]]:
    """The default ``run_fn``: a randomised run of the job's scenario with its seed and strategy."""
    from experiments.runner import run_scenario  # imported in the worker, never shared across processes

    st = job.strategy
    result = run_scenario(job.source, seed=job.seed, update=st.update, suspension=st.suspension,
                          scheduler=st.scheduler, randomize=True, task_paths=job.task_paths, policy=st.policy,
                          hazard_waiting=st.hazard_waiting, interruption=job.interruption)
    return dict(result.record), dict(result.metrics)


def execute(run_fn: RunFn, job: Job) -> Outcome:
    """Run one job in a worker; an exception becomes an ``error`` outcome with its message."""
    worker = f"{socket.gethostname()}:{os.getpid()}"
    start = time.perf_counter()
    try:
        record, metrics = run_fn(job)
    except (Exception, SystemExit) as exc:  # a failing run is a result, and the sweep goes on
        tb = traceback.format_exc(limit=-3)
        return Outcome(job.key, Status.ERROR, {}, {}, f"{type(exc).__name__}: {exc}\n{tb}",
                       time.perf_counter() - start, worker)
    return Outcome(job.key, Status.OK, dict(record), dict(metrics), None, time.perf_counter() - start, worker)


def _failed(job: Job, error: str, wall: float = 0.0, worker: str = "") -> Outcome:
    """An ``error`` outcome made by the driving process (the worker could not send one)."""
    return Outcome(job.key, Status.ERROR, {}, {}, error, wall, worker)


def _exception_message(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}"


def _alive(pid: int) -> bool:
    """Is ``pid`` running (a zombie, killed but not yet reaped by its parent, is not)?"""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):  # no /proc (not Linux): the signal test alone
        return True


def die_with_parent(driver: int) -> None:
    """Make this worker process die when its parent does — even when the driver is killed with ``kill -9``.

    On Linux the kernel sends SIGKILL when the parent dies (``prctl(PR_SET_PDEATHSIG)``);
    everywhere a daemon thread also polls the parent and the driver (``driver`` is its
    pid) twice a second and exits when either is gone.  Used as the worker initializer,
    so an orphaned worker never goes on running (or holding memory) after its sweep.
    """
    parent = os.getppid()
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # no libc prctl: the watchdog alone
            pass
    if not _alive(driver) or (parent == 1 and driver != 1):  # the parent died before prctl took effect
        os._exit(1)

    def watch() -> None:
        while True:
            if os.getppid() != parent or not _alive(driver):
                os._exit(1)
            time.sleep(0.5)

    threading.Thread(target=watch, name="tasker-sweep-watchdog", daemon=True).start()


def _mp_context() -> multiprocessing.context.BaseContext:
    # never fork: MuJoCo and OMPL objects (and threads) of the parent must not leak into workers
    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    return multiprocessing.get_context(method)


def _execute_marked(run_fn: RunFn, job: Job, mark: str) -> Outcome:
    """:func:`execute`, after leaving a file at ``mark``: the driver then knows the job had started."""
    try:
        Path(mark).write_text(str(os.getpid()), encoding="utf-8")
    except OSError:  # only a hint; without it the driver suspects every job the broken pool held
        pass
    return execute(run_fn, job)


def _died(exitcode: int | None) -> str:
    """The message of a job whose worker process died while running it alone."""
    if exitcode is None:
        how = "exit code unknown"
    elif exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        how = f"killed by {name}, exit code {exitcode}"
    else:
        how = f"exit code {exitcode}"
    return (f"worker process died ({how}) while running this job alone "
            "(a crash in native code, os._exit, or the OOM killer)")


def _alone_child(conn: Any, run_fn: RunFn, job: Job, driver: int) -> None:
    """The body of the process that runs one job alone: send its outcome back, or die trying."""
    die_with_parent(driver)
    out = execute(run_fn, job)
    try:
        conn.send(out)
    except Exception as exc:  # e.g. a record that cannot be pickled
        conn.send(_failed(job, f"the result could not be sent back: {_exception_message(exc)}", out.wall,
                          out.worker))
    conn.close()


def _alone(run_fn: RunFn, job: Job, ctx: Any) -> Outcome:  # a multiprocessing context (spawn or forkserver)
    """Run one job alone in a fresh worker process; if the process dies, an ``error`` outcome that says so."""
    start = time.perf_counter()
    receiver, sender = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_alone_child, args=(sender, run_fn, job, os.getpid()),
                       name=f"tasker-sweep-alone-{job.seed}")
    proc.start()
    sender.close()  # so that receiving ends (EOFError) when the process dies without sending
    out: Outcome | None = None
    try:
        out = receiver.recv()
    except EOFError:  # it died without sending: wait for its exit code
        proc.join(timeout=30)
    finally:
        receiver.close()
        if proc.is_alive():  # interrupted (Ctrl-C), or it closed the pipe and kept going
            proc.terminate()
        proc.join()
    if out is not None:
        return out
    return _failed(job, _died(proc.exitcode), time.perf_counter() - start, f"{socket.gethostname()}:{proc.pid}")


def _pool_pass(run_fn: RunFn, queue: deque[Job], workers: int, ctx: multiprocessing.context.BaseContext,
               marks: Path, serial: Iterator[int]) -> Generator[Outcome, None, list[Job]]:
    """Run jobs from ``queue`` on one pool of ``workers`` processes, yielding outcomes as they finish.

    Returns ``[]`` when the queue is empty and every job finished.  If a worker process
    dies (the pool breaks), returns the jobs that had started and sent no result (those
    that may have killed it), after yielding every result that did arrive and putting
    the jobs that had not started back at the front of ``queue``.
    """
    pending: dict[Future[Outcome], tuple[Job, Path]] = {}
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=die_with_parent,
                             initargs=(os.getpid(),)) as pool:
        try:
            broken = False
            while not broken:
                while len(pending) < 2 * workers and queue:
                    job = queue.popleft()
                    mark = marks / str(next(serial))
                    try:
                        fut = pool.submit(_execute_marked, run_fn, job, str(mark))
                    except BrokenProcessPool:
                        queue.appendleft(job)
                        broken = True
                        break
                    pending[fut] = (job, mark)
                if not pending:
                    return []
                if not broken:
                    done, _ = wait(pending, return_when=FIRST_COMPLETED)
                    for fut in done:
                        try:
                            out = fut.result()
                        except BrokenProcessPool:
                            broken = True
                            continue
                        except Exception as exc:  # e.g. a result that could not be pickled
                            out = _failed(pending[fut][0], _exception_message(exc))
                        pending.pop(fut)
                        yield out
            # The pool is broken: every future it held fails at once.  Keep what did arrive.
            wait(pending, timeout=60)
            started: list[Job] = []
            not_started: list[Job] = []
            for fut, (job, mark) in pending.items():  # in the order submitted
                error = fut.exception(timeout=0) if fut.done() and not fut.cancelled() else BrokenProcessPool()
                if error is None:
                    yield fut.result()  # finished before the pool broke
                elif not isinstance(error, BrokenProcessPool):
                    yield _failed(job, _exception_message(error))
                else:
                    (started if mark.exists() else not_started).append(job)
            pending.clear()
            if not started:  # no job says it started (e.g. a worker died before taking one): suspect them all
                started, not_started = not_started, []
            queue.extendleft(reversed(not_started))
            return started
        finally:
            for fut in pending:
                fut.cancel()


def _local(run_fn: RunFn, jobs: Sequence[Job], workers: int) -> Iterator[Outcome]:
    """Outcomes as they finish from a pool of local worker processes (at most 2×workers queued).

    A job that kills its worker process breaks the pool.  Then the jobs that were in
    flight are run again one at a time, each alone in a fresh process: one that kills
    that process too becomes an ``error`` outcome that says so, the others run normally;
    and the remaining jobs go on in a fresh pool.  Every job thus ends with an outcome.
    """
    ctx = _mp_context()
    queue = deque(jobs)
    serial = itertools.count()
    with tempfile.TemporaryDirectory(prefix="tasker-sweep-") as marks:
        while queue:
            suspects = yield from _pool_pass(run_fn, queue, workers, ctx, Path(marks), serial)
            if suspects:
                log.warning("a worker process died; running the %d job(s) that were in flight one at a time to "
                            "find the one that kills it", len(suspects))
            for job in suspects:
                out = _alone(run_fn, job, ctx)
                if out.status is Status.ERROR and out.error and out.error.startswith("worker process died"):
                    log.warning("%s: %s", job.key, out.error)
                yield out


def _dask(run_fn: RunFn, jobs: Sequence[Job], address: str) -> Iterator[Outcome]:
    """Outcomes as they finish from the Dask cluster at ``address``.

    A job whose worker process dies is retried by Dask on other workers (up to the
    scheduler's ``allowed-failures``); when Dask gives up (``KilledWorker``), or the
    job's future fails otherwise, the job gets an ``error`` outcome.  A cancelled
    future (e.g. the cluster restarted) leaves its job for a later resumption.
    """
    import distributed
    from distributed.scheduler import KilledWorker

    with distributed.Client(address, set_as_default=False) as client:
        futures = {client.submit(execute, run_fn, job, pure=False): job for job in jobs}
        try:
            for fut in distributed.as_completed(list(futures), loop=client.loop):
                job = futures[fut]
                if fut.cancelled():
                    log.warning("%s: Dask cancelled the job; it stays for a later resumption", job.key)
                    continue
                try:
                    out = fut.result()
                except KilledWorker as exc:
                    out = _failed(job, f"worker process died while running this job, on every worker Dask "
                                       f"tried ({_exception_message(exc)})")
                except CancelledError:
                    log.warning("%s: Dask cancelled the job; it stays for a later resumption", job.key)
                    continue
                except Exception as exc:  # the future failed outside run_fn (e.g. a result that did not pickle)
                    out = _failed(job, _exception_message(exc))
                yield out
        finally:
            client.cancel([f for f in futures if not f.done()])


@contextmanager
def lease(db_path: str | Path) -> Iterator[None]:
    """Hold the sweep lease of a results database: one driver at a time, or a clear :class:`SweepError`.

    An exclusive ``flock`` on ``<db>.lock``, which says who holds it.  The kernel drops
    the lock when the holder dies, even by ``kill -9``, so a stale lease never blocks a
    resumption.  Readers (``tasker report``) take no lease.
    """
    lock = Path(f"{db_path}.lock")
    try:
        lock.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as exc:
        raise SweepError(f"{db_path}: cannot take the sweep lease ({lock}: {exc.strerror or exc})") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 512, 0).decode("utf-8", "replace").strip() or "another process"
        os.close(fd)
        raise SweepError(f"{db_path}: another sweep is running on this database ({holder}); two drivers would "
                         "run the same jobs. Wait for it to end (then run again to resume), or use another "
                         "database") from None
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} on {socket.gethostname()}, since "
                      f"{datetime.now(UTC).isoformat(timespec='seconds')}".encode(), 0)
        yield
    finally:
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


def absolute_source(source: str) -> str:
    """A job's scenario as an absolute path (a shipped scenario name stays a name): workers may run elsewhere."""
    p = Path(source)
    if p.is_absolute():
        return source
    if p.exists() or _looks_like_path(source):
        return str(p.resolve())
    return source


def precheck(jobs: Iterable[Job]) -> None:
    """Load every distinct scenario of ``jobs`` once, so a bad one fails before any job runs."""
    from experiments import scenario as scenarios
    from experiments import synthetic

    jobs = list(jobs)
    paths = {j.source: j.task_paths for j in jobs}
    for source in sorted({j.source for j in jobs}):
        path = scenarios.resolve(source)
        if scenarios.kind_of(path) == "robot":
            scenarios.load(path, task_paths=paths.get(source, ()))
        else:
            synthetic.load(path)


def _setup(workers: int, address: str | None) -> dict[str, Any]:
    return {"backend": "dask" if address else "local", "workers": None if address else workers,
            "scheduler_address": address,
            "host": socket.gethostname(), "platform": platform.platform(), "python": sys.version.split()[0],
            "tasker": tasker.__version__, "date": datetime.now(UTC).isoformat(timespec="seconds")}


def run_sweep(
    spec: SweepSpec | Iterable[Job],
    db_path: str | Path,
    *,
    workers: int | None = None,
    scheduler_address: str | None = None,
    run_fn: RunFn = run_job,
    retry_errors: bool = False,
    max_jobs: int | None = None,
    progress: bool = True,
) -> SweepSummary:
    """Run the jobs of ``spec`` that ``db_path`` does not hold yet; store each as it finishes.

    ``workers`` local processes (default: the CPU count) unless ``scheduler_address``
    names a Dask scheduler, whose workers are used instead.  A job that raises is stored
    with status ``error`` and its message; it is run again only with ``retry_errors``.
    So is a job that kills its worker process (a segfault, ``os._exit``, the OOM
    killer): locally, the jobs that were in flight are run again one at a time, each
    alone in a fresh process, to find it (the others are stored as they end), and the
    sweep goes on in a fresh pool; on Dask, once Dask gives up retrying it (``KilledWorker``).
    ``max_jobs`` stops after starting that many jobs (the rest stay missing, for a later
    resumption).  Results are written by this process only, one transaction per run.
    """
    jobs = [dataclasses.replace(j, source=absolute_source(j.source))
            for j in (spec.jobs() if isinstance(spec, SweepSpec) else list(spec))]
    keys = [j.key for j in jobs]
    if len(set(keys)) != len(keys):
        raise SweepError("two jobs have the same key (scenario, seed, strategy)")
    if workers is not None and workers < 1:
        raise SweepError(f"workers: expected a positive number, got {workers}")
    n_workers = workers or os.cpu_count() or 1
    start = time.perf_counter()
    backend = "dask" if scheduler_address else "local"
    if run_fn is run_job:
        precheck(jobs)
    with lease(db_path), ResultStore(db_path) as store:
        if retry_errors:
            store.forget(set(keys) & store.keys(Status.ERROR))
        stored = store.keys()
        todo = [j for j in jobs if j.key not in stored]
        missing = len(todo)
        if max_jobs is not None:
            todo = todo[:max(0, max_jobs)]
        spec_json = spec.to_json() if isinstance(spec, SweepSpec) else {"jobs": [list(k) for k in keys]}
        store.log_sweep(spec_json, _setup(n_workers, scheduler_address) | {"to_run": len(todo)})
        ok = errors = 0
        if todo:
            from tqdm import tqdm

            outcomes = (_dask(run_fn, todo, scheduler_address) if scheduler_address
                        else _local(run_fn, todo, n_workers))
            by_key = {j.key: j for j in todo}
            with tqdm(total=len(todo), unit="run", disable=not progress, desc=f"sweep ({backend})") as bar:
                for out in outcomes:
                    job = by_key[out.key]
                    store.add(RunRow(job.scenario, job.seed, job.strategy.label, out.status,
                                     dict(out.record), dict(out.metrics), out.error, out.wall, out.worker))
                    if out.status is Status.OK:
                        ok += 1
                    else:
                        errors += 1
                    bar.update()
                    bar.set_postfix(errors=errors, refresh=False)
    ran = ok + errors
    return SweepSummary(total=len(jobs), skipped=len(jobs) - missing, ran=ran, ok=ok, errors=errors,
                        not_run=missing - ran, wall=time.perf_counter() - start, backend=backend)
