"""Protocol metrics of simulated days, and the table that compares schedulers over many days.

:func:`day_metrics` reads one day's trace (never the model) and returns the TaBSA-like
metrics — tasks completed per type, completion minus deadline, falls that died,
interruptions per type and per task, oscillation, how the day ended — plus ours:
suspensions (interruptions that needed an ``exeSusp``), time spent suspending,
switches, and for whole-queue schedulers the longest queue ordered and the decisions
whose search hit its budget.  On the robot backend, :mod:`experiments.metrics.paths` adds
abandonment and travel distance from the recorded trajectory, and :func:`hazard_metrics`
the task folders' hazards as every run counts them (``safety`` of :mod:`experiments.metrics.run`).
Tasks are counted as needs: a request made again after its task failed (``renews`` in the
trace, :func:`tasker.trace.needs`) is the same need, served when any of its tasks finishes;
``failed`` counts the needs whose tasks failed and were never served, ``renewals`` the
requests made again.

:func:`run_days` runs N days x schedulers on a backend (days made by
:func:`experiments.days.pipeline.make`) and :func:`table` writes the Markdown table with 95 %
confidence intervals and paired comparisons of ``lookahead`` against each baseline
(Wilcoxon signed-rank over days, Holm-corrected)::

    python -m experiments.days.report --protocol tabsa --days 100 \\
        --schedulers lookahead alg2 simple simple2 distance --out out/day
    python -m experiments.days.report --protocol tabsa-short --backend robot --days 20 --out out/day-robot

``tasker day`` is the same command.  The days are jobs of the sweep runner
(:func:`run_days`): local processes or Dask, each day stored in ``OUT/days.db`` as it
ends (so ``--resume`` goes on where a stopped run stopped; :mod:`experiments.days.resume`
checks what it resumes), a failed day stored and listed while the others go on;
``--strategies`` compares strategies on the robot backend.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
import math
import sys
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

from experiments.analysis.stats import estimate, holm
from experiments.days import pipeline as day_pipeline
from experiments.days import protocol as protocols
from experiments.days.resume import check_resumable, import_log, scenario_key
from experiments.inputs.strategy import Strategy
from experiments.metrics.run import HazardCollector
from experiments.sweep.spec import MAX_JOBS, Job
from tasker.errors import ConfigError
from tasker.trace import FAILED, needs, number

OSCILLATION_SWITCHES = 3
OSCILLATION_WINDOW_S = 180.0
ENDINGS = ("all done", "a fall died", "oscillation", "time ran out")


# -- one day -----------------------------------------------------------------------------------------

def day_metrics(events: Iterable[Mapping[str, Any]], *, day_end: float | None = None,
                kinds: Mapping[str, str] | None = None) -> dict[str, Any]:
    """The protocol metrics of one day's trace (see the module docstring and ``docs/benchmark.md``).

    ``kinds`` maps a trace's task type to the protocol's task type (the robot backend runs
    task folders under their own names); per-type metrics are keyed by the protocol's.

    ``day_end`` is when the day stops (default: the time of the last event).  A fall is
    dead when it was not finished by its request's ``death_at`` and that time falls
    within the day.  A switch to a task is a ``start`` command to its agent; the day
    oscillates when a task gets its third switch within 180 s of the first of the three.
    """
    events = list(events)
    end_t = day_end if day_end is not None else (events[-1]["t"] if events else 0.0)
    kind: dict[str, str] = {}
    args: dict[str, Mapping[str, Any]] = {}
    finished: dict[str, float] = {}
    failed: set[str] = set()
    starts: dict[str, list[float]] = {}
    interruptions: dict[str, int] = {}
    suspensions = 0
    suspension_time = 0.0
    entered: dict[str, float] = {}
    longest_order = anytime = 0
    for e in events:
        ev = e["event"]
        if ev == "request":
            kind[e["agent"]] = (kinds or {}).get(e["task_type"], e["task_type"])
            args[e["agent"]] = e["args"]
        elif ev == "end" and e.get("cause") == "finished":
            finished[e["agent"]] = e["t"]
        elif ev == "end" and e.get("cause") in FAILED:  # a plan, a skill or a hook failed: not the scheduler's choice
            failed.add(e["agent"])
        elif ev == "command" and e.get("flag") == "start":
            starts.setdefault(e["agent"], []).append(e["t"])
        elif ev == "transition":
            a, to = e["agent"], e["to"]
            if to == "genSusp":
                if e.get("trigger") != "stage_failed":  # a failed task making itself safe was not interrupted
                    interruptions[a] = interruptions.get(a, 0) + 1
                entered[a] = e["t"]
            elif e["from"] == "exeSusp" or (e["from"] == "genSusp" and to != "exeSusp"):
                suspension_time += e["t"] - entered.pop(a, e["t"])
        elif ev == "plan" and e.get("purpose") == "genSusp" and e.get("stages"):
            suspensions += 1
        elif ev == "decision" and "order" in e:  # whole-queue decisions (lookahead)
            longest_order = max(longest_order, len(e["order"]))
            anytime += e.get("rule") == "anytime"
    first = needs(events)  # a renewed request (a failed fall asked again) is the same need
    firsts = {a for a in kind if first[a] == a}
    served: dict[str, float] = {}
    for a, when in finished.items():
        served[first[a]] = min(when, served.get(first[a], math.inf))
    unserved_failed = {first[a] for a in failed} - set(served)
    types = sorted(set(kind.values()))
    per_type: dict[str, dict[str, Any]] = {}
    dead: list[float] = []
    for t in types:
        agents = [a for a in kind if kind[a] == t]
        asked = [a for a in agents if a in firsts]
        done = [a for a in asked if a in served]
        gaps = [served[a] - number(args[a]["deadline"]) for a in done if args[a].get("deadline") is not None]
        n_int = sum(interruptions.get(a, 0) for a in agents)
        per_type[t] = {"requested": len(asked), "completed": len(done),
                       "failed": sum(a in unserved_failed for a in asked), "renewals": len(agents) - len(asked),
                       "completion_minus_deadline_s": _mean(gaps), "lateness_s": sum(max(0.0, g) for g in gaps),
                       "late": sum(1 for g in gaps if g > 0), "interruptions": n_int,
                       "interruptions_per_task": n_int / len(asked) if asked else None}
        for a in asked:
            death = args[a].get("death_at")
            if death is not None and number(death) <= end_t and served.get(a, math.inf) > number(death):
                dead.append(number(death))
    oscillation = _oscillation(starts)
    first_death = min(dead) if dead else None
    stops = [(first_death, "a fall died"), (oscillation, "oscillation")]
    stops_at = [(t, why) for t, why in stops if t is not None]
    if stops_at:
        ending = min(stops_at)[1]
    else:
        ending = "all done" if len(served) == len(firsts) else "time ran out"
    all_gaps = [served[a] - number(args[a]["deadline"]) for a in served if args[a].get("deadline") is not None]
    return {
        "requested": len(firsts), "completed": len(served), "failed": len(unserved_failed),
        "renewals": len(kind) - len(firsts),
        "completion_minus_deadline_s": _mean(all_gaps), "lateness_s": sum(max(0.0, g) for g in all_gaps),
        "dead_falls": len(dead), "first_death_t": first_death,
        "interruptions": sum(interruptions.values()), "suspensions": suspensions,
        "suspension_time_s": suspension_time, "switches": sum(len(v) for v in starts.values()),
        "oscillation_t": oscillation, "ending": ending, "per_type": per_type,
        "longest_order": longest_order, "anytime_decisions": anytime,
    }


def hazard_metrics(events: Iterable[Mapping[str, Any]]) -> dict[str, Any]:
    """Ours, robot backend: the hazards the task folders declare, as :mod:`experiments.metrics.run`
    counts them for every run (``safety``): time unattended (including what a task left on
    when it ended, to the day's end) and the part of it after the task ended, budget
    overruns, hazards left on at a switch."""
    c = HazardCollector()
    for e in events:
        c.on_event(e)
    h = c.result()
    return {"hazard_unattended_s": h["unattended_s"], "hazard_after_end_s": h["after_end_s"],
            "hazard_overruns": h["budget_overruns"], "hazards_left_at_switch": h["violations_at_switch"]}


def _mean(values: Sequence[float]) -> float | None:
    return sum(values) / len(values) if values else None


def _oscillation(starts: Mapping[str, list[float]]) -> float | None:
    """Earliest time a task got its third switch within the window, or None."""
    k = OSCILLATION_SWITCHES - 1
    hits = [ts[i + k] for ts in starts.values() for i in range(len(ts) - k)
            if ts[i + k] - ts[i] <= OSCILLATION_WINDOW_S]
    return min(hits) if hits else None


# -- many days -----------------------------------------------------------------------------------------

def scheduler_options(proto: protocols.Protocol, name: str, backend: str = "synthetic") -> dict[str, Any]:
    """Options each scheduler gets from the protocol (:func:`experiments.days.pipeline.scheduler_options`)."""
    return day_pipeline.scheduler_options(proto, name, backend)


def run_day(protocol: str, seed: int, scheduler: str, backend: str = "synthetic",
            keep: str | None = None, strategy: Strategy | None = None) -> dict[str, Any]:
    """One day under one scheduler: its metrics (a top-level function, so processes can run it).

    ``keep``: a folder to keep the run's files in (trace; robot: trajectory, run.json).
    ``strategy``: its update/suspension/policy/hazard-waiting factors (robot backend only;
    its scheduler, if any, must be ``scheduler``)."""
    settings = {k: v for k, v in (strategy.items() if strategy else []) if k != "scheduler"}
    if strategy is not None and strategy.scheduler not in (None, scheduler):
        raise ConfigError(f"run_day: strategy {strategy.label!r} names another scheduler than {scheduler!r}")
    day = day_pipeline.make(protocol, seed, backend=backend, scheduler=scheduler)
    run = day.run(out=keep, **settings)
    proto = day.protocol
    kinds = {v: k for k, v in day_pipeline.task_names(proto, backend).items()}
    out = {"scheduler": scheduler, "seed": seed, "backend": backend, "strategy": Strategy(**settings).label,
           **day_metrics(run.events, day_end=proto.length_s, kinds=kinds)}
    if backend == "robot":
        from experiments.metrics.paths import path_metrics

        out |= path_metrics(run.events, run.samples)
        out |= hazard_metrics(run.events)
        out["wall_time_s"] = run.record.get("wall_time_s")  # not in the table: how long the day took here
    return out


def day_job(job: Job, *, backend: str, keep: str | None = None,
            digest: str | None = None) -> tuple[dict[str, Any], dict[str, Any]]:
    """A sweep's ``run_fn`` for days: the job's scenario is ``PROTOCOL@BACKEND``, its source the
    protocol, its strategy's scheduler the day's.  Returns ``(record, metrics)``; the metrics are
    :func:`run_day`'s, the record holds the protocol's ``digest`` (:meth:`Protocol.digest`)."""
    st = job.strategy
    if st.scheduler is None:
        raise ConfigError(f"day job {job.key}: its strategy names no scheduler")
    rest = dataclasses.replace(st, scheduler=None)
    where = None if keep is None else str(Path(keep) / _folder(rest) / st.scheduler / str(job.seed))
    metrics = run_day(job.source, job.seed, st.scheduler, backend, where, strategy=rest)
    record = {"protocol": job.source, "backend": backend, "seed": job.seed, "scheduler": st.scheduler,
              "strategy": rest.label, "wall_time_s": metrics.get("wall_time_s"), "protocol_digest": digest}
    return record, metrics


def _folder(strategy: Strategy) -> str:
    """Where ``--keep-runs`` puts a strategy's days: nowhere extra for the day's own settings."""
    return "" if strategy.label == "default" else strategy.label.replace(",", "_").replace("=", "-")



def run_days(protocol: str | Path, days: int, names: Sequence[str], *, first_seed: int = 1,
             workers: int = 2, backend: str = "synthetic", db: Path | None = None,
             keep: Path | None = None, strategies: Sequence[Strategy] = (Strategy(),),
             address: str | None = None, progress: bool = False,
             retry_errors: bool = False) -> list[dict[str, Any]]:
    """Every (day, scheduler, strategy); results sorted by strategy, scheduler, then seed.

    The days are the jobs of a sweep (:func:`experiments.sweep.driver.run_sweep`, ``run_fn`` =
    :func:`day_job`): ``workers`` local processes, or the Dask cluster at ``address``;
    each day is stored in the results database ``db`` (a temporary one if ``None``) as it
    ends, and days already there are not run again (resumption).  A day that raises, or
    kills its worker, is stored as an ``error`` and the others go on: it comes back as
    ``{"scheduler", "seed", "strategy", "error"}`` (no metrics), which :func:`report` lists
    apart (``retry_errors``: run those again).  ``keep``: keep each run's files in
    ``keep/[STRATEGY/]SCHEDULER/SEED``."""
    from experiments.metrics.store import ResultStore, Status
    from experiments.sweep.driver import run_sweep

    proto = day_pipeline.load(protocol)  # a bad protocol fails here, once, with its file and line
    scenario = scenario_key(protocol, backend)
    if db is not None:
        check_resumable(db, scenario, proto)
    jobs = [Job(scenario, str(protocol), seed, dataclasses.replace(st, scheduler=name))
            for seed in range(first_seed, first_seed + days) for st in strategies for name in names]
    # seed-major: a run stopped early leaves every scheduler with (nearly) as many days
    run_fn = functools.partial(day_job, backend=backend, keep=None if keep is None else str(keep),
                               digest=proto.digest())
    with tempfile.TemporaryDirectory(prefix="tasker-days-") as tmp:
        path = db if db is not None else Path(tmp) / "days.db"
        run_sweep(jobs, path, workers=workers, scheduler_address=address, run_fn=run_fn, progress=progress,
                  retry_errors=retry_errors)
        with ResultStore(path, readonly=True) as store:
            rows = {r.key: r for r in store.rows()}
    results = []
    for job in jobs:
        row = rows.get(job.key)
        if row is None:  # not run (e.g. Dask cancelled it): left for a resumption
            continue
        st = dataclasses.replace(job.strategy, scheduler=None)
        if row.status is Status.OK:
            results.append(dict(row.metrics))
        else:
            results.append({"scheduler": job.strategy.scheduler, "seed": job.seed, "backend": backend,
                            "strategy": st.label, "error": row.error or "failed"})
    s_order = {st.label: k for k, st in enumerate(strategies)}
    order = {n: k for k, n in enumerate(names)}
    return sorted(results, key=lambda r: (s_order.get(r.get("strategy", "default"), 0), order[r["scheduler"]],
                                          r["seed"]))


# -- the table -------------------------------------------------------------------------------------------

def _ci(values: Sequence[float]) -> tuple[float, float]:
    """Mean and the half-width of its 95 % t confidence interval (:func:`experiments.analysis.stats.estimate`)."""
    e = estimate([float(v) for v in values])
    return e.mean, e.half


def _fmt(mean: float, half: float) -> str:
    if math.isnan(mean):
        return "–"
    return f"{mean:.2f} ± {half:.2f}" if not math.isnan(half) else f"{mean:.2f}"


def _robot(r: Mapping[str, Any], value: Any) -> Any:
    return value if r.get("backend") == "robot" else None


def _metric_rows(types: Sequence[str]) -> list[tuple[str, str, Any]]:
    rows: list[tuple[str, str, Any]] = [
        ("completed (of requested)", "completed", lambda r: r["completed"]),
        *((f"completed: {t}", f"completed_{t}", lambda r, t=t: r["per_type"].get(t, {}).get("completed", 0))
          for t in types),
        ("completion − deadline, mean (s)", "gap", lambda r: r["completion_minus_deadline_s"]),
        ("lateness, sum over tasks (s)", "lateness", lambda r: r["lateness_s"]),
        *((f"completion − deadline: {t} (s)", f"gap_{t}",
           lambda r, t=t: r["per_type"].get(t, {}).get("completion_minus_deadline_s")) for t in types),
        ("dead falls", "dead", lambda r: r["dead_falls"]),
        # robot rows: synthetic stages never fail; a day stored before renewals existed made none
        ("failed tasks not served by their renewals (robot)", "failed", lambda r: _robot(r, r["failed"])),
        ("requests made again after a failed task (robot)", "renewals", lambda r: _robot(r, r.get("renewals", 0))),
        ("interruptions", "interruptions", lambda r: r["interruptions"]),
        *((f"interruptions per task: {t}", f"int_{t}",
           lambda r, t=t: r["per_type"].get(t, {}).get("interruptions_per_task")) for t in types),
        ("suspensions with exeSusp (ours)", "suspensions", lambda r: r["suspensions"]),
        ("time suspending (s, ours)", "susp_time", lambda r: r["suspension_time_s"]),
        ("switches (ours)", "switches", lambda r: r["switches"]),
        ("hazard time unattended (s, ours)", "hazard_s", lambda r: r.get("hazard_unattended_s")),
        ("… of it after its task ended (s, ours)", "hazard_after", lambda r: r.get("hazard_after_end_s")),
        ("hazard budget overruns (ours)", "overruns", lambda r: r.get("hazard_overruns")),
        ("hazards left on at a switch (ours)", "left_on", lambda r: r.get("hazards_left_at_switch")),
        ("abandonments (robot leaves a fallen person's 2 m circle)", "abandonments", lambda r: r.get("abandonments")),
        ("falls abandoned at least once", "abandoned", lambda r: r.get("abandoned_falls")),
        ("abandonments for another task (ours: not while driving to the person)", "abandon_other",
         lambda r: r.get("abandonments_other_task")),
        ("travel distance (m)", "travel", lambda r: r.get("travel_m")),
        ("longest queue ordered (lookahead)", "longest", lambda r: r["longest_order"] or None),
        ("decisions not proven optimal (lookahead)", "anytime", lambda r: r["anytime_decisions"] if r["longest_order"]
         else None),
    ]
    return rows


PAIRED = ("dead", "abandonments", "lateness", "gap", "completed", "interruptions", "travel")
STRATEGY_PAIRED = (*PAIRED, "suspensions", "susp_time", "hazard_s", "hazard_after", "overruns", "left_on")
"""Strategies differ in how a task suspends: their comparison adds what the suspensions cost."""


def _wilcoxon(diff: np.ndarray) -> float:
    if len(diff) == 0 or np.all(diff == 0):
        return 1.0
    return float(stats.wilcoxon(diff, zero_method="zsplit").pvalue)


def table(results: Sequence[Mapping[str, Any]], *, reference: str = "lookahead", title: str = "") -> str:
    """The Markdown report: metrics per scheduler (mean ± 95 % CI over days), endings, paired tests."""
    names = list(dict.fromkeys(r["scheduler"] for r in results))
    by = {n: [r for r in results if r["scheduler"] == n] for n in names}
    types = sorted({t for r in results for t in r["per_type"]})
    rows = _metric_rows(types)
    days = len(by[names[0]]) if names else 0
    out = [f"## {title}" if title else "", f"{days} days per scheduler; mean ± half-width of the 95 % CI over days.",
           "", "| metric | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for label, _, get in rows:
        cells = []
        for n in names:
            vals = [v for v in (get(r) for r in by[n]) if v is not None]
            cells.append(_fmt(*_ci(vals)) if vals else "–")
        if any(c != "–" for c in cells):  # e.g. path metrics exist only on the robot backend
            out.append(f"| {label} | " + " | ".join(cells) + " |")
    out += ["", "How the days ended (TaBSA's first stopping condition; the day is run to its end):", "",
            "| ending | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for ending in ENDINGS:
        out.append(f"| {ending} | " + " | ".join(str(sum(1 for r in by[n] if r["ending"] == ending)) for n in names)
                   + " |")
    if reference in by and len(names) > 1:
        out += ["", f"Paired over days: {reference} − baseline (mean ± 95 % CI; negative is fewer/earlier); "
                "Wilcoxon signed-rank, Holm-corrected over every test in this table.", "",
                "| metric | baseline | difference | p (Holm) |", "|---|---|---|---|"]
        out += _paired(rows, [(n, by[reference], by[n]) for n in names if n != reference])
    return "\n".join(line for line in out if line is not None).lstrip("\n") + "\n"


def _paired(rows: Sequence[tuple[str, str, Any]],
            groups: Sequence[tuple[str, Sequence[Mapping[str, Any]], Sequence[Mapping[str, Any]]]],
            keys: Sequence[str] = PAIRED) -> list[str]:
    """Table lines ``| metric | name | a − b | p (Holm) |`` for each metric of ``keys`` and each
    ``(name, a days, b days)``, paired by seed; Holm over every line."""
    tests = []
    getters = {key: (label, get) for label, key, get in rows}
    for key in keys:
        label, get = getters[key]
        for name, a_days, b_days in groups:
            ref = {r["seed"]: get(r) for r in a_days}
            pairs = [(ref[r["seed"]], get(r)) for r in b_days if ref.get(r["seed"]) is not None and get(r) is not None]
            if not pairs:
                continue
            diff = np.array([a - b for a, b in pairs], dtype=float)
            tests.append((label, name, diff, _wilcoxon(diff)))
    adjusted = holm([p for *_, p in tests])
    return [f"| {label} | {n} | {_fmt(*_ci(list(diff)))} | {p:.3g} |"
            for (label, n, diff, _), p in zip(tests, adjusted, strict=True)]


def report(results: Sequence[Mapping[str, Any]], *, reference: str = "lookahead", title: str = "") -> str:
    """:func:`table` per strategy; with several strategies, each against the first under every
    scheduler (paired by seed); and the days that failed to run, listed, never dropped silently."""
    ok = [r for r in results if "error" not in r]
    failed = [r for r in results if "error" in r]
    labels = list(dict.fromkeys(r.get("strategy", "default") for r in ok))
    if len(labels) <= 1:
        text = table(ok, reference=reference, title=title) if ok else f"## {title}\nNo day ran to its end.\n"
    else:
        parts = [table([r for r in ok if r.get("strategy", "default") == label], reference=reference,
                       title=f"{title}, strategy `{label}`") for label in labels]
        first = labels[0]
        names = list(dict.fromkeys(r["scheduler"] for r in ok))
        of = {(lb, n): [r for r in ok if r.get("strategy", "default") == lb and r["scheduler"] == n]
              for lb in labels for n in names}
        types = sorted({t for r in ok for t in r["per_type"]})
        lines = [f"## Strategies compared: each − `{first}`, under the same scheduler",
                 "Paired over days (mean ± 95 % CI; negative is fewer/earlier); Wilcoxon signed-rank, "
                 "Holm-corrected over every test in this table.", "",
                 "| metric | strategy, scheduler | difference | p (Holm) |", "|---|---|---|---|"]
        lines += _paired(_metric_rows(types), [(f"`{lb}`, {n}", of[lb, n], of[first, n])
                                               for lb in labels[1:] for n in names], STRATEGY_PAIRED)
        text = "\n".join(parts) + "\n" + "\n".join(lines) + "\n"
    if failed:
        text += ("\nDays that did not run to their end (not in the tables above; stored with their error):\n\n"
                 + "\n".join(f"- `{r.get('strategy', 'default')}`, {r['scheduler']}, seed {r['seed']}: {r['error']}"
                             for r in failed) + "\n")
    return text


def run(a: argparse.Namespace) -> int:
    """Run the days into ``OUT/days.db``; write ``days.jsonl`` and ``table.md``; print the table.

    Bad input raises :class:`tasker.support.cliargs.UsageError` (or the protocol's
    :class:`tasker.support.reader.InputError`) before the first day runs.  Returns 1 if a day failed
    to run (it is listed under the table), else 0."""
    from tasker import schedulers
    from tasker.support.cliargs import SEED_LIMIT, UsageError, show_progress, writable_dir, writable_file
    from tasker.support.reader import suggest

    unknown = [n for n in a.schedulers if n not in schedulers.names()]
    if unknown:
        raise UsageError("--schedulers", f"unknown scheduler {unknown[0]!r}{suggest(unknown[0], schedulers.names())}; "
                                         f"known: {', '.join(schedulers.names())}")
    twice = sorted({n for n in a.schedulers if a.schedulers.count(n) > 1})
    if twice:
        raise UsageError("--schedulers", f"{twice[0]!r} is given twice")
    if a.days < 1:
        raise UsageError("--days", f"expected >= 1, got {a.days}")
    if a.first_seed + a.days > SEED_LIMIT:
        raise UsageError("--days", f"the last day's seed would be {a.first_seed + a.days - 1}: seeds are < 2**32")
    if a.workers is not None and a.workers < 1:
        raise UsageError("--workers", f"expected >= 1, got {a.workers}")
    strategies = []
    for text in a.strategies or ["default"]:
        try:
            st = Strategy.parse(text)
        except ValueError as exc:
            raise UsageError("--strategies", str(exc)) from exc
        if st.scheduler is not None:
            raise UsageError("--strategies", f"{text!r} names a scheduler: schedulers are --schedulers")
        strategies.append(st)
    if len({st.label for st in strategies}) != len(strategies):
        raise UsageError("--strategies", "a strategy is given twice")
    n_jobs = a.days * len(a.schedulers) * len(strategies)
    if n_jobs > MAX_JOBS:  # as a sweep refuses: a typo such as --days 1000000 would fill memory before any day
        raise UsageError("--days", f"{a.days} days x {len(a.schedulers)} schedulers x {len(strategies)} strategies "
                                   f"= {n_jobs} days to run, more than the {MAX_JOBS} a run may have")
    for st in strategies:
        try:
            day_pipeline.check_settings(a.backend, dict(st.items()))
        except ConfigError as exc:
            raise UsageError("--strategies", str(exc)) from exc
    try:
        proto = day_pipeline.load(a.protocol)
    except ConfigError as exc:
        raise UsageError("--protocol", str(exc)) from exc
    if a.backend == "robot" and proto.robot is None:
        raise UsageError("--backend", f"{proto.source} has no [robot_backend]: it runs on the synthetic backend only")
    try:  # what only a drawn day shows (e.g. more people than the world has): once, before any day runs
        day_pipeline.make(a.protocol, a.first_seed, backend=a.backend, scheduler=a.schedulers[0])
    except ConfigError as exc:
        raise UsageError("--protocol", str(exc)) from exc
    workers = a.workers if a.workers is not None else (2 if a.backend == "synthetic" else 1)
    writable_dir(a.out, "--out")
    db, log = a.out / "days.db", a.out / "days.jsonl"
    for written in (db, log, a.out / "table.md"):  # now, not after hours of days: their table would be lost
        writable_file(written, "--out")
    if not a.resume:
        from experiments.sweep.driver import lease

        with lease(db):  # a run still writing into OUT keeps its days: this one stops instead
            for old in (db, log):
                old.unlink(missing_ok=True)
    elif not db.exists() and log.is_file():
        import_log(log, db, a.protocol, a.backend)
    else:
        try:
            check_resumable(db, scenario_key(a.protocol, a.backend), proto)
        except ConfigError as exc:
            raise UsageError("--resume", f"{exc}; run without --resume to start afresh, or give another --out") \
                from None
    from experiments.cli.sweep import dask_scheduler

    with dask_scheduler(a.scheduler_address):
        results = run_days(a.protocol, a.days, a.schedulers, first_seed=a.first_seed, workers=workers,
                           backend=a.backend, db=db, keep=a.out / "runs" if a.keep_runs else None,
                           strategies=strategies, address=a.scheduler_address, progress=show_progress(a),
                           retry_errors=a.retry_errors)
    log.write_text("".join(json.dumps(r, sort_keys=True) + "\n" for r in results), encoding="utf-8")
    backend = "" if a.backend == "synthetic" else f" --backend {a.backend}"
    chosen = "" if not a.strategies else " --strategies " + " ".join(st.label for st in strategies)
    cmd = (f"python -m experiments.days.report --protocol {a.protocol}{backend} --days {a.days} "
           f"--first-seed {a.first_seed} --schedulers {' '.join(a.schedulers)}{chosen} --out {a.out}")
    title = f"{proto.name} ({a.backend} backend): seeds {a.first_seed}–{a.first_seed + a.days - 1}"
    text = report(results, title=title)
    (a.out / "table.md").write_text(text + f"\nGenerated by `{cmd}`.\n", encoding="utf-8")
    print(text)
    return 1 if any("error" in r for r in results) else 0


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m experiments.days.report ARGS`` is ``tasker day ARGS``: one command, with the same
    options (``-v``/``-q`` too), messages and exit statuses."""
    from experiments.cli import main as tasker

    return tasker(["day", *(sys.argv[1:] if argv is None else argv)])


if __name__ == "__main__":
    sys.exit(main())
