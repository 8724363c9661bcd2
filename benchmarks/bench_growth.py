"""Benchmark: how the cost of a synthetic day grows with its length and with its queue.

    python benchmarks/bench_growth.py                      # or: python benchmarks/run_all.py growth
    python benchmarks/bench_growth.py --quick              # fewer sizes and seeds, no baseline
    python benchmarks/bench_growth.py --incremental-study 20   # the look-ahead between decisions: what it costs
    python benchmarks/bench_growth.py --budget-curve       # what smaller node budgets cost in optimality
    python benchmarks/bench_growth.py --budget-days 20     # node_budget = 500 against the default, whole days
    python benchmarks/bench_growth.py --stepping           # the clock's own cost (what an event-driven one saves)
    python benchmarks/bench_growth.py --horizon-days 20    # the look-ahead with a rolling horizon, whole days
    python benchmarks/bench_growth.py --protocols          # the x4 ratio of each scheduler on each shipped protocol
    python benchmarks/bench_growth.py --stale              # what re-estimating waiting agents costs (a measurement)
    python benchmarks/bench_growth.py --protocol FILE.toml --schedulers alg2 edf --base 60ed0ea

Days of a protocol (default ``tabsa-original``, TaBSA's day) on the synthetic backend,
made longer at the same request rate (1, 2, 4, 8 h) and, in one hour, busier (9 to 144
requests; :mod:`daysize`), under ``tabsa-simple``, ``alg2``, ``edf`` and ``lookahead``.
Each size is the sum over seeds 1..N of the CPU seconds (``time.process_time``, the best
of two runs of each day, of six for a day under half a CPU second) of building and running the
day, in a process of its own.  The
baseline is the commit before the cost work (``--base``, default 60ed0ea), checked out
with ``git archive`` into a temporary folder and run the same way in the same run
(``PYTHONPATH`` first on that folder).  A series stops when it has spent ``--budget`` CPU
seconds: the size it was running and the later ones print ``-``.

Printed per scheduler and dimension: CPU seconds per size (now, and the baseline's),
the *work* (trace events, summed over the seeds: what the day produced), the exponent
of cost against size (least squares on the logarithms; 1 is linear) and against the
work, and the ratio of the cost for four times the size (2 -> 8 h; 36 -> 144 requests).
Target (issue 38): a day four times as long costs at most 5 times as much.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SCHEDULERS = ("tabsa-simple", "alg2", "edf", "lookahead")
README_DAY = ("tabsa-simple", "tabsa-simple2", "tabsa-distance", "tabsa-scheduler", "edf", "lookahead", "alg2",
              "simple", "simple2", "distance")
"""The schedulers of the README's ``tasker day`` commands."""
SHIPPED = ("tabsa", "tabsa-short", "tabsa-rush", "tabsa-original", "tabsa-anywhere")
"""The protocols ``experiments.days.pipeline`` registers."""
HOURS = (1.0, 2.0, 4.0, 8.0)
REQUESTS = (9, 18, 36, 72, 144)
TARGET = 5.0
SHORT_S, SHORT_REPEAT = 0.5, 6
"""A day shorter than this many CPU seconds is run up to this many times (the best counts): its time is
small against the noise of a shared machine."""


# -- the worker: one series in one process, on whatever tree PYTHONPATH puts first ---------------------

def _day(protocol: str, scheduler: str, seed: int, hours: float | None,
         requests: int | None) -> tuple[float, int, int]:
    sys.path.insert(0, str(HERE))
    from daysize import sized

    from experiments.days import pipeline

    proto = sized(protocol, hours, requests)
    start = time.process_time()
    loop = pipeline.make(proto, seed, scheduler=scheduler).build()
    trace = loop.run()
    cpu = time.process_time() - start
    return cpu, len(trace.events), len(trace.dumps().encode())  # the trace's bytes: not timed


def worker(args: argparse.Namespace) -> int:
    sizes = [float(x) if args.dimension == "hours" else int(x) for x in args.sizes.split(",")]
    if args.stale:  # a diagnostic, not the model: parked agents keep their estimates when the robot moves
        from tasker import parking

        parking.Lot.changed = lambda self: []  # type: ignore[method-assign]
    spent = 0.0
    for size in sizes:
        cpu, work, output = 0.0, 0, 0
        for seed in range(1, args.seeds + 1):
            runs: list[tuple[float, int, int]] = []
            while len(runs) < args.repeat or (len(runs) < SHORT_REPEAT and min(r[0] for r in runs) < SHORT_S):
                runs.append(_day(args.protocol, args.scheduler, seed, size if args.dimension == "hours" else None,
                                 int(size) if args.dimension == "requests" else None))
                spent += runs[-1][0]
                if spent > args.budget:  # this size costs too much to finish: the series stops before it
                    return 0
            cpu += min(r[0] for r in runs)
            work += runs[0][1]
            output += runs[0][2]
        print(json.dumps({"size": size, "cpu": cpu, "work": work, "bytes": output}), flush=True)
    return 0


def one_day(protocol: str, scheduler: str, hours: float) -> None:
    """Worker: the CPU seconds of :func:`experiments.days.runner.run_day` (draw, run, metrics) of one day."""
    sys.path.insert(0, str(HERE))
    from daysize import sized

    from experiments.days.runner import run_day

    start = time.process_time()
    run_day(sized(protocol, hours), 1, scheduler)
    print(json.dumps({"cpu": time.process_time() - start}), flush=True)


def _cpu_cap(limit: float) -> Any:
    """A ``preexec_fn`` that limits the child to ``limit`` CPU seconds (then the system stops it)."""
    import resource

    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_CPU, (int(limit) + 1, int(limit) + 1))

    return cap


def eight_hours(tree: Path, protocol: str, scheduler: str, limit: float) -> float | None:
    """CPU seconds of an 8-hour day (seed 1) on ``tree``; None past ``limit`` CPU seconds."""
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", "--one-day", "--protocol", protocol,
           "--schedulers", scheduler]
    done = subprocess.run(cmd, env={**os.environ, "PYTHONPATH": str(tree)}, cwd=tree, capture_output=True, text=True,
                          preexec_fn=_cpu_cap(limit))
    if done.returncode != 0:
        return None
    return float(json.loads(done.stdout.splitlines()[-1])["cpu"])


def print_eight_hours(base: Path | None, limit: float, base_name: str = "") -> None:
    print(f"an 8-hour synthetic day (seed 1, run_day: draw, run, metrics) of each scheduler of the README's "
          f"`tasker day`, CPU seconds (> {limit:g}: stopped at that)")
    for protocol in ("tabsa-original", "tabsa"):
        for name in README_DAY:
            now = eight_hours(ROOT, protocol, name, limit)
            old = eight_hours(base, protocol, name, limit) if base is not None else None
            print(f"  {protocol:15} {name:16} now {_cell(now, limit)}"
                  + (f"   {base_name} {_cell(old, limit)}" if base is not None else ""), flush=True)


def _cell(value: float | None, limit: float) -> str:
    return f"{value:9.2f}" if value is not None else f"{'>' + format(limit, 'g'):>9}"


def _day_problems(protocol: str, hours: float, seed: int, scheduler: str) -> list[tuple[Any, int, float]]:
    """The look-ahead's problems of one synthetic day, as :meth:`LookAhead.problem` built them, each with the
    deciding scheduler's node budget and hysteresis."""
    sys.path.insert(0, str(HERE))
    from daysize import sized

    from experiments.days import pipeline
    from tasker.schedulers import lookahead

    seen: list[tuple[Any, int, float]] = []
    build = lookahead.LookAhead.problem

    def recording(self: Any, view: Any) -> Any:
        prob, jobs = build(self, view)
        seen.append((prob, self.node_budget, self.hysteresis))
        return prob, jobs

    lookahead.LookAhead.problem = recording  # type: ignore[method-assign]
    try:
        pipeline.make(sized(protocol, hours), seed, scheduler=scheduler).build().run()
    finally:
        lookahead.LookAhead.problem = build  # type: ignore[method-assign]
    return seen


def _decide(prob: Any, budget: int, hysteresis: float) -> tuple[list[int], bool]:
    """The order a look-ahead decision with ``budget`` nodes takes on ``prob`` (searched, as
    :meth:`LookAhead.schedule` searches), and whether its search ended on its own."""
    from tasker.schedulers import lookahead

    if not prob.has_exe:
        order, _, _, exact = lookahead.solve(prob, node_budget=budget)
        return order, exact
    keep, keep_obj, n1, e1 = lookahead.solve(prob, node_budget=max(1, budget // 2), fixed_first=0)
    alt, alt_obj, _, e2 = lookahead.solve(prob, node_budget=budget - n1, exclude_first=0)
    return (alt if alt_obj < hysteresis * keep_obj else keep), e1 and e2


def budget_study(protocol: str, hours: float, seed: int, every: int, factor: int) -> dict[str, Any]:
    """What the look-ahead's node budget does to its decisions: the problems of every ``every``-th
    decision of a day (as :meth:`LookAhead.problem` built them), decided again with ``factor`` times
    the budget; prints how often the first job differs and the objective of the default's choice
    over the larger budget's (both orders evaluated on the same problem: 1 means as good)."""
    seen = _day_problems(protocol, hours, seed, "lookahead")
    sample = [x for x in seen if x[0].n >= 3][::every]
    differ = exact = 0
    ratios = []
    for prob, budget, hysteresis in sample:
        small, was_exact = _decide(prob, budget, hysteresis)
        big, _ = _decide(prob, budget * factor, hysteresis)
        exact += was_exact
        differ += small[0] != big[0]
        ratios.append(prob.evaluate(small) / prob.evaluate(big))
    return {"decisions": len(seen), "sampled": len(sample), "jobs_mean": sum(p.n for p, _, _ in sample)
            / max(1, len(sample)), "jobs_max": max((p.n for p, _, _ in sample), default=0), "exact": exact,
            "first_differs": differ, "ratio_mean": sum(ratios) / max(1, len(ratios)),
            "ratio_worst": max(ratios, default=1.0), "ratio_best": min(ratios, default=1.0),
            "budget": sample[0][1] if sample else 0, "factor": factor}


def print_budget_study(protocol: str) -> None:
    r = budget_study(protocol, 4.0, 1, every=10, factor=10)
    print(f"look-ahead node budget on the day's own decisions ({protocol}, 4 h, seed 1; every 10th decision with "
          f"3 jobs or more): {r['sampled']} of {r['decisions']} decisions, {r['jobs_mean']:.1f} jobs on average "
          f"(at most {r['jobs_max']}); with the default budget ({r['budget']} nodes) the search ended on its own in "
          f"{r['exact']}; with {r['factor']}x the budget the first job differs in {r['first_differs']}, and the "
          f"default's order costs x{r['ratio_mean']:.4f} the larger budget's on average (worst x{r['ratio_worst']:.4f},"
          f" best x{r['ratio_best']:.4f})")


def budget_curve(protocol: str, hours: float, seed: int, every: int, budgets: tuple[int, ...],
                 reference: int) -> tuple[int, int, float, list[dict[str, Any]]]:
    """:func:`budget_study` for several node budgets against one larger ``reference`` budget, on the
    searched decisions of a day (``rule`` exact or anytime, 3 jobs or more; every ``every``-th)."""
    seen = [(prob, h) for prob, _, h in _day_problems(protocol, hours, seed, "lookahead:incremental=false")]

    def decide(prob: Any, budget: int, hysteresis: float) -> list[int]:
        return _decide(prob, budget, hysteresis)[0]

    sample = [x for x in seen if x[0].n >= 3][::every]
    best = [decide(prob, reference, h) for prob, h in sample]
    rows = []
    for budget in budgets:
        start = time.process_time()
        chosen = [decide(prob, budget, h) for prob, h in sample]
        cpu = time.process_time() - start
        ratios = [prob.evaluate(c) / prob.evaluate(b) for (prob, _), c, b in zip(sample, chosen, best, strict=True)]
        rows.append({"budget": budget, "first_differs": sum(c[0] != b[0] for c, b in zip(chosen, best, strict=True)),
                     "ratio_mean": sum(ratios) / max(1, len(ratios)), "ratio_worst": max(ratios, default=1.0),
                     "ms": 1000 * cpu / max(1, len(sample))})
    jobs_mean = sum(p.n for p, _ in sample) / max(1, len(sample))
    return len(seen), len(sample), jobs_mean, rows


CURVE_BUDGETS = (125, 250, 500, 1000, 2000)


def print_budget_curve(protocol: str) -> None:
    print(f"look-ahead node budget against 10x the default (20000 nodes) on a day's decisions, each searched "
          f"({protocol}, seed 1, incremental = false; every 5th decision with 3 jobs or more); commit {_head()}")
    for hours in (4.0, 8.0):
        decisions, sampled, jobs, rows = budget_curve(protocol, hours, 1, 5, CURVE_BUDGETS, 20000)
        print(f"  {hours:g} h: {sampled} of {decisions} decisions, {jobs:.1f} jobs on average")
        for r in rows:
            print(f"    budget {r['budget']:5d}: first job differs in {r['first_differs']:3d}; order costs "
                  f"x{r['ratio_mean']:.4f} the reference's on average (worst x{r['ratio_worst']:.4f}); "
                  f"{r['ms']:.2f} CPU-ms a decision")


def print_stepping(protocols: tuple[str, ...] = ("tabsa-original", "tabsa"), scheduler: str = "alg2") -> None:
    """What an event-driven clock could save: the CPU seconds of a day against the same day with one request
    of each type (the loop stepping through the day with almost nothing to do), best of three."""
    import dataclasses

    sys.path.insert(0, str(HERE))
    from daysize import sized

    from experiments.days import pipeline

    def cpu(proto: Any) -> float:
        best = math.inf
        for _ in range(3):
            start = time.process_time()
            pipeline.make(proto, 1, scheduler=scheduler).build().run()
            best = min(best, time.process_time() - start)
        return best

    print(f"the clock's own cost: a synthetic day under {scheduler} (seed 1) against the same day with one request "
          f"of each type, CPU seconds (best of 3); commit {_head()}")
    for name in protocols:
        for hours in (2.0, 8.0):
            proto = sized(name, hours)
            one = dataclasses.replace(proto, tasks={k: dataclasses.replace(v, count=1) for k, v in proto.tasks.items()})
            full, idle = cpu(proto), cpu(one)
            print(f"  {name:15} {hours:g} h ({proto.length_s / proto.step_s:.0f} steps): day {full:.3f}, "
                  f"stepping with one request a type {idle:.3f} ({100 * idle / full:.0f} %)")


QUALITY_KEYS = ("completed", "dead_falls", "lateness_s", "completion_minus_deadline_s", "switches", "interruptions")


def compare_days(protocol: str, seeds: int, first: str, second: str, title: str, hours: float | None = None) -> None:
    """Whole days of ``protocol`` (seeds 1..``seeds``; made ``hours`` long if given) under two look-ahead
    specs, their day metrics side by side (means, the paired difference, the days alike, and the days the
    first is lower and higher) and the CPU seconds of each."""
    sys.path.insert(0, str(HERE))
    from daysize import sized

    from experiments.days.runner import run_day

    proto = sized(protocol, hours) if hours is not None else protocol
    rows: dict[str, list[dict[str, Any]]] = {first: [], second: []}
    for seed in range(1, seeds + 1):
        for name, out in rows.items():
            start = time.process_time()
            m = run_day(proto, seed, name)
            m["cpu_s"] = time.process_time() - start
            out.append(m)
    days = "whole days" + (f", {hours:g} h long" if hours is not None else "")
    print(f"{title} ({protocol}, seeds 1-{seeds}, {days}): {first} against {second}; commit {_head()}")
    print(f"  {'metric':30s} {'first':>12s} {'second':>12s} {'diff mean':>10s} {'min':>9s} {'max':>9s}  same days"
          f"  lower/higher")
    one, two = rows[first], rows[second]
    for key in (*QUALITY_KEYS, "cpu_s"):
        x, y = [float(m[key]) for m in one], [float(m[key]) for m in two]
        d = [u - v for u, v in zip(x, y, strict=True)]
        print(f"  {key:30s} {sum(x) / len(x):12.2f} {sum(y) / len(y):12.2f} {sum(d) / len(d):10.2f} {min(d):9.2f} "
              f"{max(d):9.2f}  {sum(1 for u in d if u == 0):>5}/{len(d):<3}  {sum(1 for u in d if u < 0):>5}/"
              f"{sum(1 for u in d if u > 0)}")
    hit = [sum(float(m["anytime_decisions"]) for m in r) / len(r) for r in (one, two)]
    print(f"  decisions that hit the node budget, a day: {hit[0]:.0f} against {hit[1]:.0f}")


def print_incremental_study(protocol: str, seeds: int) -> None:
    """What deciding between searches costs: the look-ahead as shipped against ``incremental = false``."""
    compare_days(protocol, seeds, "lookahead", "lookahead:incremental=false", "the look-ahead between decisions")


def print_budget_days(protocol: str, seeds: int, budget: int = 500) -> None:
    """What a smaller node budget does to whole days: ``node_budget = budget`` against the default."""
    compare_days(protocol, seeds, f"lookahead:node_budget={budget}", "lookahead",
                 "the look-ahead's node budget on whole days")


def print_horizon_days(protocol: str, seeds: int, horizons: tuple[int, ...] = (6, 8)) -> None:
    """What a rolling horizon does to whole days: ``lookahead:horizon=h`` against the whole queue, on the
    protocol's own days and on days four times as long as the growth table's 2 h (8 h)."""
    for h in horizons:
        for hours in (None, 8.0):
            compare_days(protocol, seeds, f"lookahead:horizon={h}", "lookahead", "the look-ahead's horizon", hours)


def print_protocols(protocols: tuple[str, ...], schedulers: tuple[str, ...], seeds: int, repeat: int,
                    budget: float) -> bool:
    """The x4 ratio (2 -> 8 h, seeds 1..``seeds``) of every scheduler on every protocol: the cost, the work
    (events) and the trace's bytes, and the cost per event (1: the cost grows as the work does).  True if
    every cost ratio meets the target."""
    print(f"a day four times as long (2 -> 8 h, sum over seeds 1-{seeds}, best of {repeat}), per protocol; "
          f"commit {_head()}; load average {os.getloadavg()[0]:.2f}")
    print(f"  {'protocol':16} {'scheduler':20} {'cost':>7} {'events':>7} {'trace':>7} {'cost/event':>10}  target")
    ok = True
    for protocol in protocols:
        for name in schedulers:
            x4 = _x4(protocol, name, seeds, repeat, budget)
            if x4 is None:
                print(f"  {protocol:16} {name:20} {'-':>7}  (past the {budget:g} CPU-s budget)")
                ok = False
                continue
            cost, work, output = x4
            ok = ok and cost <= TARGET
            print(f"  {protocol:16} {name:20} {cost:6.2f}x {work:6.2f}x {output:6.2f}x {cost / work:9.2f}x  "
                  + ("met" if cost <= TARGET else "ABOVE"))
    return ok


def _x4(protocol: str, name: str, seeds: int, repeat: int, budget: float,
        stale: bool = False) -> tuple[float, float, float] | None:
    """The ratios of an 8-hour day to a 2-hour one (cost, events, trace bytes), None past the budget."""
    data = series(ROOT, protocol, name, "hours", (2.0, 8.0), seeds, repeat, budget, stale)
    if 2.0 not in data or 8.0 not in data:
        return None
    (c2, w2, b2), (c8, w8, b8) = data[2.0], data[8.0]
    return c8 / c2, w8 / w2, b8 / b2


def print_stale(protocols: tuple[str, ...], schedulers: tuple[str, ...], seeds: int, repeat: int,
                budget: float) -> None:
    """Where the cost above the work goes: the x4 ratio (2 -> 8 h) as shipped against the same days with
    parked agents never re-estimated when the robot moves.  The second is *not* the model — their estimates
    go stale, and traces differ — only a measure of what re-estimation costs as the queue grows."""
    print(f"re-estimating waiting agents when the robot moves: a day four times as long (2 -> 8 h, sum over "
          f"seeds 1-{seeds}, best of {repeat}) as shipped, and with parked agents never re-estimated (stale "
          f"estimates: a measurement, not the model); commit {_head()}")
    print(f"  {'protocol':16} {'scheduler':14} {'as shipped':>11} {'stale':>8}")
    for protocol in protocols:
        for name in schedulers:
            cells = [f"{x4[0]:7.2f}x" if (x4 := _x4(protocol, name, seeds, repeat, budget, stale)) else "-"
                     for stale in (False, True)]
            print(f"  {protocol:16} {name:14} {cells[0]:>11} {cells[1]:>8}")


# -- the driver ---------------------------------------------------------------------------------------

def series(tree: Path, protocol: str, scheduler: str, dimension: str, sizes: tuple[float, ...], seeds: int,
           repeat: int, budget: float, stale: bool = False) -> dict[float, tuple[float, int, int]]:
    """``size -> (CPU s, work)`` of one series run on ``tree``; ``stale``: with parked agents never
    re-estimated (:func:`print_stale`)."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", "--protocol", protocol,
           "--schedulers", scheduler, "--dimension", dimension, "--sizes", ",".join(f"{s:g}" for s in sizes),
           "--seeds", str(seeds), "--repeat", str(repeat), "--budget", str(budget)] + (["--stale"] if stale else [])
    done = subprocess.run(cmd, env=env, cwd=tree, capture_output=True, text=True, preexec_fn=_cpu_cap(2 * budget))
    if done.returncode != 0 and not done.stdout.strip():  # a run past the cap ends the series where it is
        raise RuntimeError(f"{scheduler} on {tree}: {done.stderr[-1500:]}")
    out = {}
    for line in done.stdout.splitlines():
        row = json.loads(line)
        out[float(row["size"])] = (float(row["cpu"]), int(row["work"]), int(row["bytes"]))
    return out


def exponent(xs: list[float], ys: list[float]) -> float:
    """The slope of log y against log x (least squares): 1 is linear, 2 quadratic."""
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    var = sum((x - mx) ** 2 for x in lx)
    return sum((x - mx) * (y - my) for x, y in zip(lx, ly, strict=True)) / var if var else math.nan


def checkout(commit: str, into: Path) -> Path:
    """``commit``'s files (``git archive``) in ``into``."""
    archive = subprocess.run(["git", "archive", commit], cwd=ROOT, capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    return into


def report(name: str, dimension: str, now: dict[float, tuple[float, int, int]],
           base: dict[float, tuple[float, int, int]] | None, sizes: tuple[float, ...],
           base_name: str = "60ed0ea") -> bool:
    """Print one series (``base``: the series on commit ``base_name``); True if it meets the target (or cannot be
    judged)."""
    unit = "h" if dimension == "hours" else " req"
    print(f"  {name:14} {dimension:8} " + "  ".join(f"{s:>8g}{unit}" for s in sizes))
    rows = [("now CPU s", now)] + ([(f"{base_name} CPU s", base)] if base is not None else [])
    for label, data in rows:
        cells = [f"{data[s][0]:>10.3f}" if s in data else f"{'-':>10}" for s in sizes]
        print(f"  {'':14} {label:>14} " + "  ".join(cells))
    print(f"  {'':14} {'work (events)':>14} " + "  ".join(f"{now[s][1]:>10d}" if s in now else f"{'-':>10}"
                                                          for s in sizes))
    print(f"  {'':14} {'trace (kB)':>14} " + "  ".join(f"{now[s][2] / 1000:>10.0f}" if s in now else f"{'-':>10}"
                                                       for s in sizes))
    ok = True
    for label, data in rows:
        have = [s for s in sizes if s in data]
        if len(have) < 2:
            continue
        e_size = exponent(have, [data[s][0] for s in have])
        e_work = exponent([float(now[s][1]) for s in have if s in now], [data[s][0] for s in have if s in now])
        big, small = sizes[-1], sizes[-1] / 4
        ratio = data[big][0] / data[small][0] if big in data and small in data else math.nan
        work = now[big][1] / now[small][1] if big in now and small in now else math.nan
        output = now[big][2] / now[small][2] if big in now and small in now else math.nan
        verdict = ""
        if label == "now CPU s" and dimension == "hours" and not math.isnan(ratio):
            verdict = "OK" if ratio <= TARGET else f"ABOVE TARGET ({TARGET:g}x)"
            ok = ratio <= TARGET
        print(f"  {'':14} {label:>14} exponent {e_size:4.2f} against size, {e_work:4.2f} against work; "
              f"x4 size ({small:g} -> {big:g}): cost x{ratio:.2f}, work x{work:.2f}, trace x{output:.2f} {verdict}")
    return ok


def print_queues(protocol: str, hours: tuple[float, ...] = (2.0, 8.0), seed: int = 1) -> None:
    """What the look-ahead's search meets as the day grows: per day length, its decisions, the queue at each
    (the length of the order it searched), and how many of its searches ended on their own (``exact``)."""
    sys.path.insert(0, str(HERE))
    from daysize import sized

    from experiments.days import pipeline

    print(f"the look-ahead's queue at its decisions ({protocol}, seed {seed}):")
    for h in hours:
        loop = pipeline.make(sized(protocol, h, None), seed, scheduler="lookahead").build()
        decisions = [e for e in loop.run().events if e.get("event") == "decision" and "order" in e]
        lengths = [len(e["order"]) for e in decisions]
        rules = {r: sum(1 for e in decisions if e.get("rule") == r) for r in ("incremental", "exact", "anytime")}
        searched = rules["exact"] + rules["anytime"]
        print(f"  {h:g} h: {len(decisions)} decisions, queue {sum(lengths) / len(lengths):.1f} jobs on average "
              f"(at most {max(lengths)}); {rules['incremental']} priced without a search; of the {searched} searched, "
              f"the search ended on its own in {rules['exact']} ({100 * rules['exact'] / max(1, searched):.0f} %)"
              if decisions else f"  {h:g} h: no decision")


def _seeds(text: str) -> int:
    """A number of days (seeds 1..N) for a day comparison: an integer of at least 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of days (an integer >= 1), got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a number of days (an integer >= 1), got {value}")
    return value


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--protocol", default="tabsa-original")
    p.add_argument("--schedulers", nargs="+", default=list(SCHEDULERS))
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--repeat", type=int, default=2)
    p.add_argument("--budget", type=float, default=400.0, help="CPU s after which a series stops")
    p.add_argument("--base", default="60ed0ea", help="the commit to compare with ('' for none)")
    p.add_argument("--quick", action="store_true", help="sizes 2 and 8 h, 36 and 144 requests, 1 seed, no base")
    p.add_argument("--budget-study", action="store_true",
                   help="only: what the look-ahead's node budget does to a 4-hour day's decisions (seed 1)")
    p.add_argument("--eight-hours", action="store_true",
                   help="only: an 8-hour day of each scheduler of the README's `tasker day` (tabsa-original, tabsa)")
    p.add_argument("--stepping", action="store_true",
                   help="the clock's own cost: a day against the same day with one request of each type")
    p.add_argument("--budget-curve", action="store_true",
                   help="the look-ahead's node budgets 125-2000 against 10x the default, on searched decisions")
    p.add_argument("--budget-days", type=_seeds, metavar="SEEDS", default=0,
                   help="whole days, the look-ahead with node_budget = 500 against the default")
    p.add_argument("--incremental-study", type=_seeds, metavar="SEEDS", default=0,
                   help="whole days, the look-ahead as shipped against a full search at every decision")
    p.add_argument("--horizon-days", type=_seeds, metavar="SEEDS", default=0,
                   help="whole days, the look-ahead with horizon = 6 and 8 against the whole queue (also 8 h long)")
    p.add_argument("--protocols", nargs="*", metavar="PROTOCOL",
                   help="only: the x4 ratio of each scheduler on each protocol (default: every shipped one)")
    p.add_argument("--stale", action="store_true",
                   help="only: what re-estimating waiting agents costs, against days where they are never "
                        "re-estimated (a measurement, not the model)")
    p.add_argument("--queues", action="store_true",
                   help="only: the look-ahead's queue at its decisions in a 2-hour and an 8-hour day (seed 1)")
    p.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--one-day", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--dimension", help=argparse.SUPPRESS)
    p.add_argument("--sizes", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.stale and not args.worker:
        print_stale(("tabsa-original", "tabsa-rush"), ("tabsa-simple", "alg2", "edf"), args.seeds, args.repeat,
                    args.budget)
        return 0
    if args.worker:
        args.scheduler = args.schedulers[0]
        if args.one_day:
            one_day(args.protocol, args.scheduler, 8.0)
            return 0
        return worker(args)
    if args.eight_hours:
        with tempfile.TemporaryDirectory(prefix="tasker-base-") as tmp:
            print_eight_hours(checkout(args.base, Path(tmp)) if args.base else None, args.budget, args.base)
        return 0
    if args.budget_study:
        print_budget_study(args.protocol)
        return 0
    if args.queues:
        print_queues(args.protocol)
        return 0
    if args.stepping:
        print_stepping()
        return 0
    if args.budget_curve:
        print_budget_curve(args.protocol)
        return 0
    if args.budget_days:
        print_budget_days(args.protocol, args.budget_days)
        return 0
    if args.protocols is not None:
        from experiments.days import pipeline

        for name in args.protocols:
            try:
                pipeline.load(name)
            except Exception as exc:  # a name not registered, a file missing or malformed: said, not raised
                p.error(f"--protocols: {name}: {exc}")
        print_protocols(tuple(args.protocols) or SHIPPED, tuple(args.schedulers), args.seeds, args.repeat,
                        args.budget)
        return 0
    if args.horizon_days:
        print_horizon_days(args.protocol, args.horizon_days)
        return 0
    if args.incremental_study:
        print_incremental_study(args.protocol, args.incremental_study)
        return 0
    hours: tuple[float, ...] = HOURS
    requests: tuple[int, ...] = REQUESTS
    if args.quick:
        hours, requests, args.seeds, args.repeat, args.base = (2.0, 8.0), (36, 144), 1, 1, ""
    print(f"cost growth of synthetic days of {args.protocol}: CPU seconds, sum over seeds 1-{args.seeds} "
          f"(best of {args.repeat}); commit {_head()}; load average {os.getloadavg()[0]:.2f}")
    ok = True
    with tempfile.TemporaryDirectory(prefix="tasker-base-") as tmp:
        base_tree = checkout(args.base, Path(tmp)) if args.base else None
        for name in args.schedulers:
            for dimension, sizes in (("hours", hours), ("requests", requests)):
                sizes_f = tuple(float(s) for s in sizes)
                now = series(ROOT, args.protocol, name, dimension, sizes_f, args.seeds, args.repeat, args.budget)
                base = (series(base_tree, args.protocol, name, dimension, sizes_f, args.seeds, args.repeat,
                               args.budget) if base_tree is not None else None)
                ok = report(name, dimension, now, base, sizes_f, args.base) and ok
    print("target (a day four times as long costs at most 5 times as much): " + ("met" if ok else "NOT MET"))
    if "lookahead" in args.schedulers and not args.quick:
        print_budget_study(args.protocol)
    return 0


def _head() -> str:
    done = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True,
                           text=True).stdout.strip()
    return done.stdout.strip() + (" (with uncommitted changes)" if dirty else "")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
