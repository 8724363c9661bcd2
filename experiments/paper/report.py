"""The numbers of ``docs/paper.md``, generated from traces: each Appendix B step, per scenario and model.

``tasker paper`` (:mod:`experiments.cli.paper`) runs, for each scenario of :data:`SCENARIOS`
and each :class:`Config` of :data:`CONFIGS` (a cost model with a switching rule), the
scenario as shipped and ``variants`` randomised variants of it
(:func:`experiments.inputs.scenario.randomize`, seeds 1..N: request and event times within
±25 %, every person's poses and walk within 0.5 m), checks every trace with
:func:`experiments.paper.appendix_b.check`, and renders Markdown: side by side, which step
holds in which scenario under which model; then, per scenario and configuration, each step's
time, ``c_switch``, ``c_wait`` and margin ``1 - c_switch/c_wait``, how many variants reproduce
each step and the whole sequence, and (for our model, in seconds) each start's predicted
``cTime`` against what followed.  :func:`splice` puts the text between the markers
``<!-- paper_report:begin -->`` and ``<!-- paper_report:end -->`` of a document.  Nothing
in it is typed by hand; the same arguments give the same text (runs are deterministic).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

from experiments.analysis.tables import markdown_table

BEGIN = "<!-- paper_report:begin -->"
END = "<!-- paper_report:end -->"
SCENARIOS = ("paper", "paper-2019")
"""Fig. 10 as we draw it, and the layout reconstructed from the original verification's record."""

ORIGINAL_FACTORS: dict[str, tuple[float, float, float]] = {"john": (0.15, 0.15, 0.3), "alice": (0.2, 0.2, 0.3)}
"""(walk, stand, sit) cost per metre of each guided person in the original code
(``bin/tiago_guideHuman`` at ``56ab62c``: ``factor_walk/stand/sit[0]`` John, ``[1]`` Alice)."""


@dataclass(frozen=True)
class Config:
    """A cost model (``planners.taskspec.COST_MODELS``) and Alg. 2's hysteresis."""

    model: str
    hysteresis: float

    @property
    def label(self) -> str:
        return f"{'ours' if self.model == 'seconds' else self.model}, h = {self.hysteresis}"


CONFIGS = (Config("seconds", 1.0), Config("seconds", 0.9), Config("taskER-2019", 0.9))
"""Ours with the paper's rule (1.0) and the original code's (0.9); the original model with its own
rule (``c_switch < 0.9 * c_wait``, the 2019 harmoniser)."""

Job = tuple[str, Config, int | None]
"""(scenario, configuration, variant seed or None for the scenario as shipped)."""
Run = dict[str, Any]


def with_model(scn: Any, model: str) -> Any:
    """``scn`` with every request of a task type that offers ``model`` asking for it; where the
    model takes factors, each person's from :data:`ORIGINAL_FACTORS` (the person is the request
    argument the task folder's model names)."""
    if model == "seconds":
        return scn
    from experiments.inputs.actions import TimedAction
    from planners.bundled import task_types
    from planners.pddl_task import PddlTaskType
    from planners.taskspec import COST_MODEL_ARG
    from tasker.errors import ConfigError

    offers = {t.name: t.spec.original_costs for t in task_types()
              if isinstance(t, PddlTaskType) and t.spec.original_costs is not None}
    actions = []
    for a in scn.actions:
        costs = offers.get(a.fields.get("task")) if a.kind == "request" else None
        if costs is not None:
            args = {**a.fields["args"], COST_MODEL_ARG: model}
            if costs.factors:
                person = args[costs.person[1:]]
                if person not in ORIGINAL_FACTORS:
                    raise ConfigError(f"{scn.source}: the original model has no factors for {person!r} "
                                      f"(known: {', '.join(ORIGINAL_FACTORS)})")
                args.update(zip((f[1:] for f in costs.factors), ORIGINAL_FACTORS[person], strict=True))
            a = TimedAction(a.t, a.kind, {**a.fields, "args": args}, a.origin)
        actions.append(a)
    return dataclasses.replace(scn, actions=tuple(actions))


def scenario_for(job: Job) -> Any:
    """The scenario a job runs: loaded, randomised (a variant), its model and hysteresis set."""
    from experiments.inputs import scenario as scenarios

    name, config, variant = job
    scn = scenarios.load(scenarios.resolve(name))
    if variant is not None:
        scn = scenarios.randomize(scn, variant)
    scn = with_model(scn, config.model)
    return dataclasses.replace(scn, scheduler_options={**scn.scheduler_options, "hysteresis": config.hysteresis})


def predictions(events: Sequence[Any]) -> list[dict[str, Any]]:
    """Each ``start`` command's predicted cTime against what followed: the seconds until that
    agent's next ``susp`` command or ``end`` (``ended``: True when it ran to its end)."""
    from experiments.paper.appendix_b import num

    out: list[dict[str, Any]] = []
    open_: dict[str, dict[str, Any]] = {}
    for e in events:
        agent = e.get("agent")
        if e.get("event") == "command" and e.get("flag") == "start":
            open_[agent] = {"agent": agent, "t": num(e["t"]), "predicted_s": num(e.get("predicted_s"))}
        elif agent in open_ and ((e.get("event") == "command" and e.get("flag") == "susp") or e.get("event") == "end"):
            row = open_.pop(agent)
            row.update(realised_s=num(e["t"]) - row["t"], ended=e.get("event") == "end"
                       and e.get("cause") == "finished")
            out.append(row)
    return out


def run_one(job: Job) -> Run:
    """Run one job; check Appendix B (``steps``) and each start's prediction (``predictions``)."""
    from experiments.paper import appendix_b
    from experiments.run.runner import RunAborted, RunResult, run_scenario

    scn = scenario_for(job)
    try:
        events = list(run_scenario(scn, seed=scn.seed, pictures=False).trace.events)
    except RunAborted as exc:  # the trace so far still says which steps happened
        if not isinstance(exc.result, RunResult):
            raise
        events = list(exc.result.trace.events)
    steps = [{"name": s.name, "ok": s.ok, "t": s.t, "c_switch": s.c_switch, "c_wait": s.c_wait,
              "margin": s.margin, "detail": s.detail} for s in appendix_b.check(events)]
    return {"steps": steps, "predictions": predictions(events)}


def jobs(scenarios: Sequence[str], variants: int) -> list[Job]:
    """Every scenario × configuration, as shipped then variants 1..``variants``."""
    return [(s, c, v) for s in scenarios for c in CONFIGS for v in (None, *range(1, variants + 1))]


def run_all(todo: Sequence[Job], workers: int, done: Callable[[int], None] | None = None) -> dict[Job, Run]:
    """Run ``todo`` on ``workers`` processes (in order; ``done(k)`` after each result)."""
    out: dict[Job, Run] = {}
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for k, (job, result) in enumerate(zip(todo, pool.map(run_one, todo), strict=True)):
            out[job] = result
            if done is not None:
                done(k + 1)
    return out


def _f(x: float | None, digits: int = 1) -> str:
    if x is None:
        return "–"
    return f"{x:.{digits}f}" if math.isfinite(x) else str(x)


def _pct(x: float | None) -> str:
    return "–" if x is None or not math.isfinite(x) else f"{100 * x:+.1f} %"


def _median(xs: Sequence[float]) -> float | None:
    xs = sorted(x for x in xs if math.isfinite(x))
    if not xs:
        return None
    m = len(xs) // 2
    return xs[m] if len(xs) % 2 else (xs[m - 1] + xs[m]) / 2


def _estimates(runs: Sequence[Run]) -> tuple[int, float | None, float | None, int]:
    """Over the starts that ran to their end: n, median and largest |realised/predicted - 1|,
    and how many starts had no finite prediction."""
    errs = [abs(p["realised_s"] / p["predicted_s"] - 1) for r in runs for p in r["predictions"]
            if p["ended"] and math.isfinite(p["predicted_s"]) and p["predicted_s"] > 0]
    unknown = sum(1 for r in runs for p in r["predictions"] if not math.isfinite(p["predicted_s"]))
    return len(errs), _median(errs), max(errs, default=None), unknown


def _whole(runs: Sequence[Run]) -> int:
    return sum(1 for r in runs if all(st["ok"] for st in r["steps"]))


def _summary(results: dict[Job, Run], scenarios: Sequence[str], n: int) -> list[str]:
    names = [st["name"] for st in results[(scenarios[0], CONFIGS[0], None)]["steps"]]
    header = ["#", "step"] + [f"{s}: {c.label}" for s in scenarios for c in CONFIGS]
    rows = []
    for k, name in enumerate(names):
        cells = []
        for s in scenarios:
            for c in CONFIGS:
                st = results[(s, c, None)]["steps"][k]
                held = sum(1 for v in range(1, n + 1) if results[(s, c, v)]["steps"][k]["ok"])
                mark = "yes" if st["ok"] else "**no**"
                margin = f" {_pct(st['margin'])}" if st["margin"] is not None else ""
                cells.append(f"{mark}{margin}" + (f"; {held}/{n}" if n else ""))
        rows.append((str(k + 1), name, *cells))
    rows.append(("", "**the whole sequence, every step with its cause**",
                 *(("yes" if all(st["ok"] for st in results[(s, c, None)]["steps"]) else "**no**")
                   + (f"; {_whole([results[(s, c, v)] for v in range(1, n + 1)])}/{n}" if n else "")
                   for s in scenarios for c in CONFIGS)))
    return markdown_table(header, rows)


def _shipped(run: Run, scenario: str, config: Config) -> list[str]:
    lines = [f"##### `{scenario}`, {config.label}", "",
             *markdown_table(["#", "step", "holds", "t (s)", "c_switch", "c_wait", "margin"],
                             [(str(k), st["name"], "yes" if st["ok"] else "**no**", _f(st["t"]), _f(st["c_switch"], 3),
                               _f(st["c_wait"], 3), _pct(st["margin"])) for k, st in enumerate(run["steps"], 1)]),
             "", "What the checker saw:", ""]
    lines += [f"{k}. {st['detail']}" for k, st in enumerate(run["steps"], 1)]
    if config.model == "seconds":
        lines += ["", "Each `start`: the cTime the agent reported (predicted) and the seconds until it was "
                  "suspended or ended (realised; comparable only when it ran to its end):", "",
                  *markdown_table(["agent", "started at (s)", "predicted (s)", "realised (s)", "ran to its end"],
                                  [(p["agent"], _f(p["t"]), _f(p["predicted_s"]), _f(p["realised_s"]),
                                    "yes" if p["ended"] else "no") for p in run["predictions"]])]
    return [*lines, ""]


def _variants(results: dict[Job, Run], scenario: str, n: int) -> list[str]:
    names = [st["name"] for st in results[(scenario, CONFIGS[0], None)]["steps"]]
    rows = []
    for k, name in enumerate(names):
        cells = []
        for c in CONFIGS:
            runs = [results[(scenario, c, v)] for v in range(1, n + 1)]
            margins = [r["steps"][k]["margin"] for r in runs if r["steps"][k]["margin"] is not None]
            cells += [f"{sum(1 for r in runs if r['steps'][k]['ok'])}/{n}", _pct(_median(margins))]
        rows.append((str(k + 1), name, *cells))
    rows.append(("", "**the whole sequence, every step with its cause**",
                 *(x for c in CONFIGS for x in (f"{_whole([results[(scenario, c, v)] for v in range(1, n + 1)])}/{n}",
                                                ""))))
    header = ["#", "step"] + [x for c in CONFIGS for x in (c.label, "median margin")]
    est = []
    for c in CONFIGS:
        if c.model == "seconds":
            m, med, worst, unknown = _estimates([results[(scenario, c, v)] for v in range(1, n + 1)])
            est.append((c.label, str(m), _pct(med).lstrip("+"), _pct(worst).lstrip("+"), str(unknown)))
    return [f"##### `{scenario}`: reproduction over {n} randomised variants (seeds 1..{n})", "",
            "Per step: variants in which it holds with its cause; for the cost steps, the median margin over all "
            "variants that made the comparison.", "", *markdown_table(header, rows), "",
            "Our estimates against what happened, over the variants' starts that ran to their end (the original "
            "model's cTime is in metres: not comparable):", "",
            *markdown_table(["configuration", "starts", "median |realised/predicted − 1|", "largest",
                             "starts with no finite prediction"], est), ""]


def _recorded(rows: Sequence[tuple[float, str, float, float, float | None, float | None]]) -> list[str]:
    table = [(_f(t), "ours" if model == "seconds" else model, _f(cs, 3), _f(cw, 3), _pct(1 - cs / cw),
              "yes" if cs < cw else "no", "yes" if cs < 0.9 * cw else "no", _f(rcs, 3), _f(rcw, 3))
             for t, model, cs, cw, rcs, rcw in rows]
    return ["#### The recorded comparisons of step 3, recomputed on their geometry", "",
            "Guide John (dac) over guide Alice (exeDA) where the record puts the robot, John and Alice "
            "(`experiments.paper.recorded`: straight-line distances equal to those the record implies; both tasks "
            "aged 0, so that the ages, which add the same to both sides, do not dilute the margin):", "",
            *markdown_table(["recorded t", "model", "c_switch", "c_wait", "margin", "switch at h = 1.0", "at h = 0.9",
                             "recorded c_switch", "recorded c_wait"], table), ""]


def _layout() -> list[str]:
    from experiments.paper.reconstruction import derive, residuals

    lay = derive()
    points = [("Alice's destination", lay.alice_dest), ("John's destination", lay.john_dest), ("Alice", lay.alice),
              ("where John waited", lay.john_waited), ("John's start", lay.john_walk[0][1]),
              ("the robot at 2508.6", lay.robot), ("Peter", lay.peter), ("Sara", lay.sara)]
    guided = [abs(rec - got) for _, what, rec, got in residuals(lay) if "guided" in what]
    return ["#### The reconstruction of `paper-2019`", "",
            "`experiments.paper.reconstruction.derive()`, in its frame (metres; the files shift it by [2.5, 2.0]); "
            f"the destinations are {_f(lay.john_dest[0], 2)} m apart; the straight guided walk fits the 9 recorded "
            f"rows with rms {_f(lay.fit_rms, 3)} m (largest {_f(max(guided), 3)} m); every other recorded distance "
            "it is made from, it meets exactly.", "",
            *markdown_table(["point", "x", "y"], [(name, _f(x, 2), _f(y, 2)) for name, (x, y) in points]), ""]


def _speed() -> list[str]:
    from experiments.paper.reconstruction import CLOCK, EVENTS, derive, robot_legs
    from robot.spec import load_world

    lay = derive()
    legs = robot_legs()
    fastest = max(legs, key=lambda leg: leg.speed)
    files = {w: load_world(w).robot.max_speed for w in ("paper-2019", "paper")}
    rows = [(_f(leg.t0), _f(leg.t1), f"{leg.path0:.3f} → {leg.path1:.3f}", f"{leg.path0 - leg.path1:.3f}",
             f"**{leg.speed:.3f}**" if leg is fastest else f"{leg.speed:.3f}") for leg in legs]
    return ["#### The robot's speed and the clock of `paper-2019`", "",
            "`experiments.paper.reconstruction.robot_legs()`: Alice's remaining path (approach + guidance, her "
            "recorded cost / f_stand) between consecutive rows while the robot drove toward her. She sat still and "
            "had not been greeted, so each fall is the robot's progress; the fastest leg is its driving speed, "
            f"{lay.robot_speed:.3f} m/s (the slower legs hold its stops). `robot/worlds/paper-2019.toml` drives at "
            f"{files['paper-2019']:g} m/s; `paper`'s robot at {files['paper']:g} m/s.", "",
            *markdown_table(["from (recorded t)", "to", "Alice's remaining path (m)", "fell (m)", "m/s"], rows), "",
            f"The clock is the record's: t = recorded t − {CLOCK:g} (Alice's request at t = 1.0, her first "
            "comparison), for John's walk and the two requests as for the falls, placed at the recorded rows "
            "that bound them (`reconstruction.EVENTS`):", "",
            *markdown_table(["event", "recorded t", "t in `paper-2019`", "from"],
                            [(e.what, _f(e.t), _f(e.t - CLOCK), e.why) for e in EVENTS]), ""]


def render(results: dict[Job, Run], scenarios: Sequence[str], n: int, command: str, commit: str,
           recorded: Sequence[tuple[float, str, float, float, float | None, float | None]] = ()) -> str:
    """The generated block of ``docs/paper.md``: made by ``command`` at ``commit``; ``recorded``
    is :func:`experiments.paper.recorded.rows` (left out when empty)."""
    lines = [BEGIN, "", f"*Generated by `{command}` at commit `{commit}` from the runs' traces; do not edit by "
             "hand.*", "", *(_recorded(recorded) if recorded else []),
             *(_layout() + _speed() if "paper-2019" in scenarios else []),
             "#### Side by side: which step holds, per scenario and model", "",
             "Each cell: the scenario as shipped (with the deciding comparison's margin `1 - c_switch / c_wait`, "
             "or for a cost step that did not happen the closest one's), then in how many randomised variants the "
             "step holds with its cause.", "", *_summary(results, scenarios, n), ""]
    for s in scenarios:
        lines += [f"#### `{s}`", ""]
        for c in CONFIGS:
            lines += _shipped(results[(s, c, None)], s, c)
        if n:
            lines += _variants(results, s, n)
    lines.append(END)
    return "\n".join(lines) + "\n"


def splice(text: str, block: str) -> str:
    """``text`` with the generated block replaced (or appended when it has no markers)."""
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        return head + block.rstrip("\n") + tail
    return text.rstrip("\n") + "\n\n" + block
