"""Metrics that declare themselves: name, unit, which way is better, host or strategy, meaning.

Every number a report compares is registered here, once.  A report's verdicts (which
strategy is better), its wins/ties/losses, the headline metrics of its tables and plots, the
readable names it shows and ``docs/metrics.md``'s table all come from the
:class:`Metric` declarations below — never from the spelling of a name.  A metric nobody
registered is still reported, with no verdict.

Names are the dotted paths of ``metrics.json`` flattened by :func:`numeric_metrics`
(``totals.makespan_s``), and the keys of a day's metrics (``day.dead_falls``); one segment may
be ``*`` for a family (``safety.hazards.*.unattended_s``: every declared hazard).

A direction is a statement about the quantity, chosen before any result: *lower* for costs
and harms (time, hazard exposure, failures), *higher* for what a task is for (tasks done),
*neither* for counts that describe what happened without being good or bad in themselves
(decisions, plans, switches) and for signed errors.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import Any


class Direction(StrEnum):
    """Which way is better."""

    LOWER = "lower"
    HIGHER = "higher"
    NEITHER = "neither"


L, H, N = Direction.LOWER, Direction.HIGHER, Direction.NEITHER


@dataclass(frozen=True, slots=True)
class Metric:
    """One registered metric (or a family: one ``*`` segment in ``name``)."""

    name: str
    unit: str
    direction: Direction
    meaning: str
    host: bool = False
    """It measures the machine the run ran on, not the strategy: reported, never given a verdict."""
    label: str = ""
    """A readable name for reports (default: the dotted name)."""

    def __post_init__(self) -> None:
        if self.name.count("*") > 1 or not re.fullmatch(r"[\w./*-]+", self.name):
            raise ValueError(f"Metric: bad name {self.name!r}")
        if not self.meaning:
            raise ValueError(f"Metric {self.name!r}: a one-line meaning is required")

    @property
    def title(self) -> str:
        return self.label or self.name

    @property
    def verdict(self) -> bool:
        """Whether a comparison on it says which side is better."""
        return not self.host and self.direction is not N


def _stats(name: str, unit: str, direction: Direction, meaning: str, label: str = "") -> tuple[Metric, ...]:
    return (Metric(f"{name}.mean", unit, direction, f"{meaning} (mean)", label=f"{label} (mean)" if label else ""),
            Metric(f"{name}.max", unit, direction, f"{meaning} (max)", label=f"{label} (max)" if label else ""))


_HAZARD = "safety.hazards.*"
_CAL = ("calibration.estimates", "calibration.interruptions")

METRICS: tuple[Metric, ...] = (
    # -- a run (metrics.json) ------------------------------------------------------------------
    Metric("run.events", "count", N, "events in the trace"),
    Metric("run.duration_s", "s", N, "the largest time in the trace"),
    Metric("run.horizon_reached", "bool", L, "the run was stopped (horizon, Ctrl-C or abort) before every task ended"),
    Metric("totals.requested", "count", N, "tasks requested"),
    Metric("totals.ended", "count", N, "tasks that ended"),
    Metric("totals.unfinished", "count", L, "tasks still alive when the run stopped", label="unfinished tasks"),
    Metric("totals.finished", "count", H, "tasks that did their work (cause finished)", label="tasks finished"),
    Metric("totals.failed", "count", L, "tasks that failed: a plan, a skill or a hook (causes failed, error)",
           label="tasks failed"),
    Metric("totals.ended_by_itself", "count", N, "tasks that ended themselves (ic_term, e.g. 'Peter is fine')"),
    Metric("totals.terminated", "count", N, "tasks a requester cancelled"),
    Metric("totals.by_cause.*", "count", N, "ended tasks by cause"),
    *_stats("totals.duration_s", "s", L, "request to end, over every ended task (failed ones included)"),
    Metric("totals.makespan_s", "s", L, "first request to last end (or to the end of the trace)", label="makespan (s)"),
    Metric("totals.suspensions", "count", N, "entries into genSusp (by susp, a failed stage or securing)"),
    Metric("totals.suspended_s", "s", N, "time tasks spent in wait"),
    *_stats("totals.suspension_s", "s", L, "entering genSusp to entering wait: the time to suspend safely",
            label="time to suspend (s)"),
    *_stats("totals.resumption_s", "s", L, "wait -> upTsk to the first stage that began: the time to resume",
            label="time to resume (s)"),
    Metric("totals.plans", "count", N, "plans made (upTsk and genSusp, planned and static)"),
    Metric("totals.plans_by.*", "count", N, "plans by purpose/strategy"),
    Metric("totals.static_fallbacks", "count", L, "planned calls that fell back to the static template",
           label="static fallbacks"),
    Metric("switching.switches", "count", N, "a susp followed by a start of another agent", label="switches"),
    *_stats("switching.switch_latency_s", "s", L, "susp to the replacement's start"),
    Metric("switching.commands.*", "count", N, "harmoniser commands by flag"),
    Metric("switching.mode_changes", "count", N, "IT/CT switches"),
    Metric("switching.changes", "count", N, "argument changes applied (R2)"),
    Metric("decisions.decisions", "count", N, "scheduling decisions"),
    Metric("decisions.switch_decisions", "count", N, "decisions that chose to switch"),
    Metric("decisions.decisions_by.*", "count", N, "decisions by algorithm/rule"),
    Metric("decisions.cost_compared", "count", N, "Alg. 2 decisions that compared finite costs"),
    Metric("decisions.margins.*", "count", N, "cost decisions by margin 1 − c_switch/c_wait (bins of 0.1)"),
    Metric("decisions.hysteresis_flips.*", "count", N, "cost decisions that would have gone the other way "
           "at this hysteresis"),
    Metric("safety.unattended_s", "s", L, "hazard time on while its owner was not in cmd, over owned hazards, "
           "until the hazard went off or the run ended, whether or not its owner had ended; the primary hazard "
           "outcome", label="hazard time unattended (s)"),
    Metric("safety.longest_unattended_s", "s", L, "the longest unbroken unattended stretch of an owned hazard"),
    Metric("safety.budget_overruns", "count", L, "unattended stretches longer than the hazard's budget",
           label="hazard budget overruns"),
    Metric("safety.overrun_s", "s", L, "unattended time beyond the budgets"),
    Metric("safety.after_end_s", "s", L, "unattended time after the owner ended (a task-design defect)",
           label="hazard on after its task ended (s)"),
    Metric("safety.violations_at_switch", "count", L, "hazards an agent left on as it entered wait",
           label="hazards left on at a switch"),
    Metric("safety.hazards_active_at_switch", "count", L, "owned hazards on, whoever's, at each entry into wait"),
    Metric("safety.unowned_hazards", "count", N, "hazard episodes nobody owns"),
    Metric("safety.unattended_alive_s", "s", L, "hazard time unattended while its owner was alive (what a "
           "suspension could attend to; 0.3's primary outcome, which a task that failed and ended stops "
           "counting)", label="hazard unattended, owner alive (s)"),
    Metric("safety.severity_unattended_s", "s", L, "unattended_alive_s weighted by each hazard's declared severity",
           label="severity-weighted unattended (s)"),
    Metric("safety.unowned_s", "s", L, "time hazards nobody owns were on (doors opened by a person or an "
           "exogenous event)", label="unowned hazard exposure (s)"),
    Metric("suspensions.count", "count", N, "suspension episodes that closed (wait or end)"),
    Metric("suspensions.safe", "count", H, "episodes that ended with their goal holding and no hazard of their "
           "agent, nor one the robot carries, on (goal-based judge)"),
    Metric("suspensions.unsafe", "count", L, "episodes that ended with their goal unmet, no plan, or a hazard of "
           "their agent or one the robot carries on", label="unsafe suspensions"),
    Metric("suspensions.all_safe", "bool", H, "every suspension of the run was safe (the binary outcome)",
           label="all suspensions safe"),
    Metric("suspensions.goal_unmet", "count", L, "episodes that ended with a literal of their goal not holding",
           label="suspensions with their goal unmet"),
    Metric("suspensions.no_plan", "count", L, "episodes whose genSusp made no plan (the task ended there)",
           label="suspensions with no plan"),
    Metric("suspensions.inapplicable_stages", "count", L, "suspension stages whose action could not run",
           label="inapplicable stages"),
    Metric("suspensions.already_done_stages", "count", N, "suspension stages skipped because their effects held "
           "already (someone else did it): not failures", label="stages already done"),
    Metric("suspensions.fallback_planned", "count", N, "fallback suspensions that planned (the tree's branch could "
           "not run, or a stage of it failed)", label="fallback suspensions planned"),
    Metric("carried.count", "count", L, "hazards the robot carried into another agent's execution (each pair "
           "of hazard and agent)", label="hazards carried into another task"),
    Metric("carried.seconds", "s", L, "time the robot ran another agent's task with a hazard of another agent in "
           "hand (e.g. helping with the hot pan held)", label="time with a carried hazard (s)"),
    *_stats("suspensions.time_to_safe_s", "s", L, "genSusp to wait or end, over safe suspensions",
            label="time to a safe suspension (s)"),
    Metric(f"{_HAZARD}.episodes", "count", N, "owned episodes of this hazard"),
    Metric(f"{_HAZARD}.budget_s", "s", N, "its declared budget"),
    Metric(f"{_HAZARD}.active_s", "s", N, "time it was on"),
    Metric(f"{_HAZARD}.unattended_s", "s", L, "time on while its owner was not in cmd"),
    Metric(f"{_HAZARD}.longest_unattended_s", "s", L, "its longest unattended stretch"),
    Metric(f"{_HAZARD}.overruns", "count", L, "its unattended stretches over budget"),
    Metric(f"{_HAZARD}.overrun_s", "s", L, "its unattended time beyond the budget"),
    Metric(f"{_HAZARD}.after_end_s", "s", L, "its unattended time after the owner ended"),
    Metric(f"{_HAZARD}.at_switch", "count", L, "times its owner entered wait with it on"),
    Metric(f"{_HAZARD}.active_at_end", "count", L, "still on when the trace ended"),
    Metric(f"{_HAZARD}.unowned", "count", N, "its episodes nobody owns"),
    Metric("people.people_waiting_s", "s", L, "time people waited for the robot (declared role waiting)",
           label="people waiting (s)"),
    Metric("people.people_following_s", "s", N, "time people followed the robot (being guided)",
           label="people following (s)"),
    Metric("people.people_told_to_wait_s", "s", L, "time people were told to wait"),
    Metric("people.needing_help", "count", N, "people who needed help"),
    Metric("people.not_helped", "count", L, "people who needed help and were not helped"),
    *_stats("people.time_to_help_s", "s", L, "request to the first helped edge", label="time to help (s)"),
    *(m for p in _CAL for m in (
        Metric(f"{p}.error_s.mean", "s", N, "realised − estimate (signed: read the sign)"),
        Metric(f"{p}.error_s.max", "s", N, "the largest realised − estimate"),
        Metric(f"{p}.abs_error_s.mean", "s", L, "|realised − estimate|"),
        Metric(f"{p}.ratio.mean", "ratio", N, "realised / estimate"),
        Metric(f"{p}.compared", "count", N, "estimates compared"),
        Metric(f"{p}.nonfinite", "count", N, "infinite estimates (counted, never averaged)"),
        Metric(f"{p}.underestimated", "count", N, "compared estimates that were too short"))),
    Metric("calibration.estimates.elapsed_error_s.mean", "s", N, "elapsed (interruptions included) − predicted"),
    Metric("calibration.estimates.not_compared", "count", N, "tasks whose prediction could not be compared"),
    Metric("calibration.interruptions.censored", "count", N, "interruptions that never ended in a start"),
    Metric("calibration.interruptions.unknown", "count", N, "interruptions with no expected length"),
    Metric("derived.finished_duration_s.mean", "s", L, "request to end over the tasks that finished",
           label="task duration, finished tasks (s)"),
    Metric("derived.finished_tasks", "count", H, "tasks that finished"),
    Metric("planner_wall_time_s", "s", L, "wall time in planner calls (cached solves count 0)", host=True),
    Metric("planner_cache_hits", "count", N, "planner calls answered from the cache", host=True),
    Metric("wall_time_s", "s", L, "wall time of the run", host=True),
    Metric("real_time_factor", "ratio", H, "simulated seconds per wall second", host=True),
    # -- a day (tasker day) ---------------------------------------------------------------------
    Metric("day.requested", "count", N, "needs requested (a renewal is the same need)"),
    Metric("day.completed", "count", H, "needs served (a task of the need finished)", label="completed"),
    Metric("day.failed", "count", L, "needs whose tasks failed and were never served"),
    Metric("day.renewals", "count", N, "requests made again after a failed task"),
    Metric("day.completion_minus_deadline_s", "s", L, "completion − deadline, mean over served needs"),
    Metric("day.lateness_s", "s", L, "sum over served needs of max(0, completion − deadline)"),
    Metric("day.dead_falls", "count", L, "falls not served by their death time"),
    Metric("day.first_death_t", "s", N, "when the first fall died"),
    Metric("day.interruptions", "count", L, "suspensions not caused by the task's own failed stage"),
    Metric("day.suspensions", "count", N, "entries into genSusp"),
    Metric("day.suspensions_with_stages", "count", N, "suspensions whose exeSusp ran stages"),
    Metric("day.suspension_time_s", "s", L, "time spent in genSusp and exeSusp"),
    Metric("day.switches", "count", N, "start commands"),
    Metric("day.oscillation_t", "s", N, "when a task first got its third start within 180 s"),
    Metric("day.longest_order", "count", N, "the longest queue a whole-queue scheduler ordered"),
    Metric("day.anytime_decisions", "count", N, "whole-queue decisions whose search hit its budget"),
    Metric("day.abandonments", "count", L, "the robot left a fallen person's 2 m circle before helping"),
    Metric("day.abandoned_falls", "count", L, "falls left at least once"),
    Metric("day.abandonments_other_task", "count", L, "abandonments while another task ran"),
    Metric("day.travel_m", "m", L, "length of the robot's path"),
    Metric("day.hazard_unattended_s", "s", L, "hazard time unattended (as safety.unattended_s)"),
    Metric("day.hazard_after_end_s", "s", L, "unattended after the owner ended (as safety.after_end_s)"),
    Metric("day.hazard_overruns", "count", L, "hazard budget overruns"),
    Metric("day.hazards_left_at_switch", "count", L, "hazards left on at a switch"),
    Metric("day.completion_minus_death_s", "s", L, "TaBSA: completion − death time, mean over served falls",
           label="completion − death time, falls (s)"),
    Metric("day.tabsa_oscillation_t", "s", N, "TaBSA: when the task of a step first had more than 2 gaps in 180 s"),
    Metric("day.tabsa_stop_t", "s", N, "TaBSA: when its day would stop (all done, a fall dead, oscillation, end)"),
    Metric("day.tabsa_completed", "count", H, "TaBSA: needs served by the time its day would stop",
           label="completed by TaBSA's stop"),
)
"""Every registered metric, in the order ``docs/metrics.md`` lists them."""

HEADLINE = (
    "derived.finished_duration_s.mean", "totals.makespan_s", "people.people_waiting_s", "people.people_following_s",
    "safety.unattended_s", "safety.budget_overruns", "safety.violations_at_switch", "safety.hazards_active_at_switch",
    "totals.suspension_s.mean", "totals.resumption_s.mean", "switching.switches", "totals.failed",
    "totals.unfinished", "totals.plans", "totals.static_fallbacks", "planner_wall_time_s", "wall_time_s",
)
"""The metrics shown in a sweep report's tables and plots, in this order, when the runs have them (and
they are not constant); every metric is in the CSV files.  If the runs have none, every metric is shown."""

EXCLUDED = ("tasks.", "people.people.", "run.seed", "totals.duration_s.")
"""Prefixes of metrics left out of reports: per-agent details, the seed itself, and the duration over
every ended task (failed ones included) — replaced by ``derived.finished_duration_s``."""

_EXACT = {m.name: m for m in METRICS if "*" not in m.name}
_FAMILIES = [(re.compile("^" + re.escape(m.name).replace(r"\*", r"[^.]+") + "$"), m) for m in METRICS
             if "*" in m.name]
if len(_EXACT) + len(_FAMILIES) != len(METRICS):
    raise RuntimeError("experiments.metrics.registry: a metric is registered twice")


def metric(name: str) -> Metric | None:
    """The registration of ``name`` (a run's flattened name, or ``day.KEY``), or None."""
    found = _EXACT.get(name)
    if found is not None:
        return found
    return next((m for rx, m in _FAMILIES if rx.match(name)), None)


def direction(name: str) -> Direction | None:
    """Which way is better for ``name``; None when it is not registered."""
    m = metric(name)
    return m.direction if m is not None else None


def host_dependent(name: str) -> bool:
    """True for a registered metric of the host (wall time, real-time factor): no verdict, no wins or losses."""
    m = metric(name)
    return m is not None and m.host


def has_verdict(name: str) -> bool:
    """Whether a comparison on ``name`` may say which side is better: registered, of the strategy, with a direction."""
    m = metric(name)
    return m is not None and m.verdict


def higher_is_better(name: str) -> bool:
    """True only for a registered metric whose larger values are better."""
    return direction(name) is Direction.HIGHER


def outcome(name: str, treatment: float, baseline: float) -> int | None:
    """+1 if the treatment is better, 0 if equal, -1 if worse; None without a verdict (unregistered,
    host-dependent or neither way better)."""
    if not has_verdict(name):
        return None
    if abs(treatment - baseline) <= 1e-9 * max(1.0, abs(treatment), abs(baseline)):
        return 0
    better = treatment > baseline if higher_is_better(name) else treatment < baseline
    return 1 if better else -1


def label(name: str) -> str:
    """A readable name for reports."""
    m = metric(name)
    if m is None or not m.label:
        return name
    return m.label


def headline(metrics: Iterable[str]) -> list[str]:
    """The metrics the tables and plots show: those of :data:`HEADLINE` present, else all."""
    present = set(metrics)
    chosen = [m for m in HEADLINE if m in present]
    return chosen or sorted(present)


def numeric_metrics(metrics: Mapping[str, Any], prefix: str = "") -> dict[str, float]:
    """The numeric values of a metrics dict, nested tables flattened to ``a.b``; others dropped.

    At the top level, ``derived.finished_duration_s.mean`` is added from the per-task details
    (``tasks.*`` with ``cause == "finished"``): the mean duration of the tasks that finished."""
    out: dict[str, float] = {}
    for key, value in metrics.items():
        name = f"{prefix}{key}"
        if name.startswith(EXCLUDED):
            continue
        if isinstance(value, Mapping):
            out.update(numeric_metrics(value, prefix=f"{name}."))
        elif isinstance(value, bool | int | float):
            out[name] = float(value)
        elif isinstance(value, str) and value in ("inf", "-inf", "nan"):
            out[name] = float(value)
    if not prefix:
        out.update(derived(metrics))
    return out


def derived(metrics: Mapping[str, Any]) -> dict[str, float]:
    """Metrics the report derives from a run's per-task details: duration over finished tasks only."""
    tasks = metrics.get("tasks")
    if not isinstance(tasks, Mapping):
        return {}
    finished = [float(t["duration_s"]) for t in tasks.values()
                if isinstance(t, Mapping) and t.get("cause") == "finished"
                and isinstance(t.get("duration_s"), int | float) and not isinstance(t.get("duration_s"), bool)]
    if not finished:
        return {"derived.finished_tasks": 0.0}
    return {"derived.finished_duration_s.mean": math.fsum(finished) / len(finished),
            "derived.finished_tasks": float(len(finished))}


def lookup(metrics: Mapping[str, float], paths: Sequence[str]) -> tuple[str, float] | None:
    """The first of ``paths`` a flattened metrics dict has, with its value."""
    for p in paths:
        if p in metrics:
            return p, metrics[p]
    return None
