"""The sweep spec: scenarios × seeds × strategies, read from a TOML file and checked.

:func:`load_spec` reads a spec file with :mod:`tasker.support.reader` (every error names the file,
the line and the field: :class:`SpecError`) into a frozen :class:`SweepSpec`, which expands
to the list of :class:`Job` a sweep runs (:func:`experiments.sweep.driver.run_sweep`).  The
strategies themselves are :mod:`experiments.inputs.strategy`.  See ``docs/sweeps.md``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from experiments.inputs.filekinds import expect
from experiments.inputs.perturbation import KINDS as perturbation_kinds
from experiments.inputs.perturbation import MODES as perturbation_modes
from experiments.inputs.perturbation import Perturbation
from experiments.inputs.scenario import InterruptionGrid
from experiments.inputs.strategy import FACTOR_LEVELS, FACTORS, Strategy, expand
from experiments.metrics.store import JobKey
from experiments.run.options import RunOptions
from tasker.errors import SpecError as SpecError  # defined there; re-exported here
from tasker.support import reader
from tasker.task import DEFAULT_TREE

MAX_JOBS = 100_000
"""A spec that expands to more jobs than this is refused (a typo such as ``seeds = 10000000``)."""


@dataclass(frozen=True)
class Job:
    """One run of a sweep: a scenario (as named in the spec and where to read it), a seed, a strategy."""

    scenario: str
    source: str
    seed: int
    strategy: Strategy
    task_paths: tuple[str, ...] = ()  # absolute task folders (--path), so a Dask worker elsewhere loads the same
    interruption: InterruptionGrid | None = None  # where variants place the interruption ([variants.NAME])
    perturbation: Perturbation | None = None  # exogenous world events around it ([perturbation])
    cold: bool = False  # planning caches forgotten before the run (cold_caches)

    @property
    def key(self) -> JobKey:
        return (self.scenario, self.seed, self.strategy.label)

    def options(self) -> RunOptions:
        """How the job runs: a randomised variant of its seed, with its strategy, interruption and perturbation."""
        return RunOptions.of(self.strategy, seed=self.seed, randomize=True, task_paths=self.task_paths,
                             interruption=self.interruption, perturbation=self.perturbation, cold=self.cold)


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
    perturbation: Perturbation | None = None
    """Exogenous world events drawn around each variant's interruption (:mod:`experiments.inputs.perturbation`)."""
    cold: bool = False
    """``cold_caches``: every job forgets what planning remembered before it runs (genSusp's wall time is
    then a first run's; the runs are the same)."""
    trees: Mapping[str, tuple[str | None, ...]] = field(default_factory=dict)
    """Per scenario, the decision trees its strategies run with (``[variants.NAME] trees``; None: the
    default tree); a scenario not listed runs each strategy as it is."""

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

    def strategies_of(self, scenario: str) -> list[Strategy]:
        """The strategies ``scenario`` runs: each strategy with each of its trees (tree-major)."""
        levels = self.trees.get(scenario)
        if not levels:
            return list(self.strategies)
        return [replace(st, tree=tree) if tree is not None else st for tree in levels for st in self.strategies]

    def jobs(self) -> list[Job]:
        """Every job, scenario-major then seed then strategy (so paired runs finish close together)."""
        return [Job(sc, self.sources.get(sc, sc), seed, st, self.task_paths, self.variants.get(sc),
                    self.perturbation if sc in self.variants else None, self.cold)
                for sc in self.scenarios for seed in self.seeds for st in self.strategies_of(sc)]

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "scenarios": list(self.scenarios), "seeds": list(self.seeds),
                               "strategies": [s.label for s in self.strategies], "sources": dict(self.sources)}
        if self.variants:
            out["variants"] = {sc: g.to_json() for sc, g in sorted(self.variants.items())}
        if self.perturbation is not None:
            out["perturbation"] = self.perturbation.to_json()
        if self.trees:
            out["trees"] = {sc: [t or DEFAULT_TREE for t in levels] for sc, levels in sorted(self.trees.items())}
        return out


def looks_like_path(text: str) -> bool:
    """Is ``text`` (a scenario as written) a file rather than a shipped scenario's name?"""
    return "/" in text or os.sep in text or text.endswith((".toml", ".json"))


SPEC_KEYS = ("name", "scenarios", "seeds", "seed_start", "strategies", "factors", "variants", "perturbation", "paths",
             "cold_caches")


def load_spec(path: str | Path, *, max_jobs: int | None = None) -> SweepSpec:
    """Read and check a sweep spec (TOML) with :mod:`tasker.support.reader`.

    Fields: ``name`` (optional), ``scenarios`` (list of files or shipped names), ``seeds``
    (a count, seeds ``seed_start`` … ``seed_start + count - 1``, or a list), ``seed_start``
    (optional, default 0), ``strategies`` (list of ``"update=…,suspension=…[,scheduler=…]"``
    strings or tables).  Scenario paths are relative to the spec file and come back
    absolute, so workers started anywhere (Dask) find them.  A spec that expands to more
    than ``max_jobs`` (default :data:`MAX_JOBS`) jobs is refused.
    """
    from experiments.inputs import scenario as scenarios

    limit = MAX_JOBS if max_jobs is None else max_jobs
    p = Path(path).resolve()
    top = reader.load(p, SpecError)
    expect(top, "sweep spec")
    top.declare(SPEC_KEYS)  # a misspelt 'scenario = [...]' is named where "scenarios: missing" is said
    name = str(top.string("name", p.stem))
    scenario_list = top.array("scenarios", nonempty=True)
    at = top.at("scenarios", {})
    sources: dict[str, str] = {}
    files: dict[Path, str] = {}  # the file each scenario is, so one file under two spellings is seen
    for i, sc in enumerate(scenario_list):
        if not isinstance(sc, str) or not sc:
            raise at.error(i, f"expected a scenario file or a shipped scenario name, got {sc!r}")
        if sc in scenario_list[:i]:
            raise at.error(i, f"{sc!r} is listed twice")
        if looks_like_path(sc):
            file = Path(sc) if Path(sc).is_absolute() else p.parent / sc
            if not file.is_file():
                raise at.error(i, f"no such file: {file} (scenario paths are relative to the spec file)")
            sources[sc] = str(file.resolve())
            resolved = file.resolve()
        else:
            try:  # a shipped scenario's name is passed on as it is: every worker has the package
                resolved = scenarios.resolve(sc).resolve()
            except reader.InputError as exc:
                raise at.error(i, exc.message) from None
        if resolved in files:  # its runs would be counted twice, as two scenarios
            raise at.error(i, f"{sc!r} is the scenario {files[resolved]!r} again (both are {resolved}): each "
                              "scenario once")
        files[resolved] = sc
    paths = _paths(top, p.parent)
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
    trees: dict[str, tuple[str | None, ...]] = {}
    variants = _variants(top.table("variants", {}), scenario_list, sources, trees)
    perturbation = _perturbation(top, variants) if "perturbation" in top else None
    _warn_ignored_factors(top, scenario_list, sources, strategies)
    cold = bool(top.boolean("cold_caches", False))
    return SweepSpec(tuple(scenario_list), seeds, tuple(strategies), name=name, sources=sources, variants=variants,
                     perturbation=perturbation, task_paths=paths, trees=trees, cold=cold)


def _paths(top: reader.Table, here: Path) -> tuple[str, ...]:
    """``paths``: task folders (or folders of them) the scenarios need besides the bundled ones,
    relative to the spec file; they come back absolute (``--path`` on the command line adds more)."""
    at = top.at("paths", {})
    out: list[str] = []
    for i, entry in enumerate(top.array("paths", [])):
        if not isinstance(entry, str) or not entry:
            raise at.error(i, f"expected a task folder (a path relative to the spec), got {entry!r}")
        folder = (here / entry).resolve()
        if not folder.is_dir():
            raise at.error(i, f"no such folder: {folder} (paths are relative to the spec file)")
        out.append(str(folder))
    return tuple(dict.fromkeys(out))


def select_seeds(spec: SweepSpec, text: str) -> SweepSpec:
    """``spec`` with only the seeds ``text`` names: ``A-B`` (inclusive), ``A,B,C`` or a mix
    (``1-20,40``); each must be a seed of the spec.  Raises ValueError saying what was expected."""
    chosen: list[int] = []
    for part in (x.strip() for x in text.split(",")):
        lo, dash, hi = part.partition("-")
        try:
            first, last = int(lo), int(hi if dash else lo)
        except ValueError:
            raise ValueError(f"expected seeds as A-B or A,B,C (e.g. 1-20), got {text!r}") from None
        if last < first:
            raise ValueError(f"{part!r}: expected a range low-high, got high < low")
        chosen += [s for s in range(first, last + 1) if s not in chosen]
    absent = [s for s in chosen if s not in spec.seeds]
    if absent:
        lo_s, hi_s = min(spec.seeds), max(spec.seeds)
        raise ValueError(f"seed {absent[0]} is not a seed of the spec (its seeds: {len(spec.seeds)} from {lo_s} to "
                         f"{hi_s})")
    return replace(spec, seeds=tuple(s for s in spec.seeds if s in chosen))


def _perturbation(top: reader.Table, variants: Mapping[str, InterruptionGrid]) -> Perturbation:
    """``[perturbation]``: the pre-registered rates of exogenous world events (drawn only for the
    scenarios with ``[variants.NAME]``: the window is placed around their interruption)."""
    t = top.table("perturbation")
    if not variants:
        raise top.error("perturbation", "needs [variants.NAME]: the events are drawn around each variant's "
                                        "interruption")
    kinds = t.array("kinds", list(perturbation_kinds))
    stand = t.array("stand_s", [10.0, 40.0])
    try:
        p = Perturbation(rate_per_min=float(t.number("rate_per_min", 3.0, min=0)),
                         before_s=float(t.number("before_s", 20.0, min=0)),
                         after_s=float(t.number("after_s", 60.0, min=0)),
                         kinds=tuple(str(k) for k in kinds),
                         stand_s=(float(stand[0]), float(stand[1])) if len(stand) == 2 and all(
                             isinstance(v, int | float) and not isinstance(v, bool) for v in stand) else (-1.0, -1.0),
                         mode=str(t.string("mode", "untargeted", choices=perturbation_modes)),
                         during_s=float(t.number("during_s", 8.0, min=0)))
    except ValueError as exc:
        raise t.error(str(exc).partition(":")[0].split(",")[0], str(exc).partition(": ")[2]) from None
    t.done()
    return p


def _warn_ignored_factors(top: reader.Table, scenario_list: Sequence[str], sources: Mapping[str, str],
                          strategies: Sequence[Strategy]) -> None:
    """An :class:`~tasker.support.reader.InputWarning` for each synthetic scenario that strategies set
    factors for: its timed stages have no suspension or update plans, no policy and no hazards
    (the run records them as static), so strategies that differ only there run alike."""
    from experiments.inputs import scenario as scenarios

    # only factors the strategies vary: one setting alone compares nothing (and runs as recorded)
    ignored = [k for k in FACTORS if k != "scheduler" and len({getattr(st, k) for st in strategies}) > 1]
    if not ignored:
        return
    for sc in scenario_list:
        try:
            kind = scenarios.kind_of(scenarios.resolve(sources.get(sc, sc)))
        except reader.InputError:
            continue  # the scenario's own fault: its loader names it (sweep.precheck, before any job runs)
        if kind == "synthetic":
            top.warn("strategies" if "strategies" in top else "factors",
                     f"{sc!r} is a synthetic scenario, whose timed stages ignore {', '.join(ignored)}: its runs of "
                     "strategies that differ only there are alike (compare them on robot scenarios; a synthetic "
                     "one varies with scheduler only)")


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
            elif key == "tree":
                try:
                    Strategy(tree=v)
                except ValueError as exc:
                    raise lt.error(i, str(exc).partition(": ")[2]) from None
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


def _variants(t: reader.Table, scenario_list: Sequence[str], sources: Mapping[str, str],
              trees: dict[str, tuple[str | None, ...]] | None = None) -> dict[str, InterruptionGrid]:
    """``[variants.NAME]`` tables: where the variants of scenario NAME place its interruption, and the
    decision trees its strategies are run with (``trees``, into ``trees`` if given).

    NAME must be a robot scenario (only those are randomised) with the request ``interrupt``
    names; its file is read for that (its own faults are left to the scenario's loader)."""
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
        levels = _tree_levels(vt) if "trees" in vt else None
        vt.done()
        if levels is not None and trees is not None:
            trees[sc] = levels
        if not (stop - start) / step <= MAX_JOBS:  # inf too: ceil() of it raised in every job
            raise times.error("step", f"{(stop - start) / step:.3g} strata of {step:g} s in [{start:g}, {stop:g}), "
                                      f"more than the {MAX_JOBS} a sweep may have jobs: a larger step")
        try:
            out[sc] = InterruptionGrid(interrupt, start, stop, step)
        except ValueError as exc:
            key = "interrupt" if str(exc).startswith("interrupt") else "times"
            raise vt.error(key, str(exc).partition(": ")[2]) from None
        _check_interrupt(t, vt, sc, sources.get(sc, sc), out[sc])
    return out


def _tree_levels(vt: reader.Table) -> tuple[str | None, ...]:
    """``trees = ["default", "cook:cooker"]``: the trees a scenario's strategies run with (``default``:
    each folder's ``[[suspension]]``; ``NAME`` or ``TYPE:NAME`` as ``tasker run --tree``)."""
    levels = vt.array("trees", nonempty=True)
    at = vt.at("trees", {})
    out: list[str | None] = []
    for i, level in enumerate(levels):
        if level == DEFAULT_TREE:
            out.append(None)
            continue
        try:
            out.append(Strategy(tree=level).tree)
        except ValueError as exc:
            raise at.error(i, f"expected {DEFAULT_TREE!r}, a tree's NAME or TYPE:NAME, got {level!r} "
                              f"({str(exc).partition(': ')[2]})") from None
    if len(set(out)) != len(out):
        raise vt.error("trees", f"duplicates in {levels}")
    return tuple(out)


def _check_interrupt(t: reader.Table, vt: reader.Table, sc: str, source: str, grid: InterruptionGrid) -> None:
    """The scenario of ``[variants.NAME]`` is a robot scenario that has the request ``interrupt`` names."""
    from experiments.inputs import scenario as scenarios

    try:
        top = reader.load(scenarios.resolve(source), scenarios.ScenarioError)
        kind = top.raw("kind", "synthetic")
        requests = top.raw("requests", [])
        horizon = top.table("settings", {}).raw("horizon", 1800.0)
    except reader.InputError:
        return  # the scenario's own fault: its loader names it (sweep.precheck, before any job runs)
    if kind != "robot":
        raise t.error(sc, f"{sc!r} is a {kind} scenario: only robot scenarios are randomised, so variants "
                          f"would be ignored")
    n = len(requests) if isinstance(requests, list) else 0
    if isinstance(horizon, int | float) and not isinstance(horizon, bool) and grid.start >= horizon:
        raise vt.error("times", f"start = {grid.start:g} s is not before {sc!r}'s horizon ({horizon:g} s): the "
                                "interruption would come after every run ended")
    if grid.index >= n:
        raise vt.error("interrupt", f"no {grid.interrupt} in {sc!r}: it has {n} requests"
                                    + (f", requests[0]..requests[{n - 1}]" if n else ""))
