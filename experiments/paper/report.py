"""The numbers of ``docs/paper.md``, generated from traces: each Appendix B step and its reproduction rate.

    python -m experiments.paper.report --variants 50 --out docs/paper.md

runs the paper scenario (``experiments/inputs/scenarios/paper.toml``) as shipped and
``--variants`` randomised variants of it (:func:`experiments.inputs.scenario.randomize`,
seeds 1..N: request and event times within ±25 %, people's poses and John's walk
within 0.5 m), each with Alg. 2's hysteresis 1.0 (the paper's rule) and 0.9 (the
original ROS code), checks every trace with :func:`experiments.paper.appendix_b.check`,
and writes Markdown: per step, the time, ``c_switch``, ``c_wait`` and the margin
``1 - c_switch/c_wait`` of the shipped run, then how many variants reproduce each
step and the whole sequence.  With ``--out FILE`` the text replaces what lies between
the markers ``<!-- paper_report:begin -->`` and ``<!-- paper_report:end -->`` in FILE
(appended if the markers are absent); without it, it is printed.  Nothing in it is
typed by hand; the same arguments give the same text (runs are deterministic).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

BEGIN = "<!-- paper_report:begin -->"
END = "<!-- paper_report:end -->"
HYSTERESES = (1.0, 0.9)


def _scenario(hysteresis: float, variant: int | None, scenario: str = "paper") -> Any:
    from experiments.inputs import scenario as scenarios

    scn = scenarios.load(scenarios.resolve(scenario))
    if variant is not None:
        scn = scenarios.randomize(scn, variant)
    options = {**scn.scheduler_options, "hysteresis": hysteresis}
    return dataclasses.replace(scn, scheduler_options=options)


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


def run_one(job: tuple[float, int | None, str]) -> dict[str, Any]:
    """Run the scenario (``variant`` None: as shipped) with ``hysteresis``; check Appendix B
    (``steps``) and compare each start's predicted cTime with what followed (``predictions``)."""
    from experiments.paper import appendix_b
    from experiments.run.runner import RunAborted, RunResult, run_scenario

    hysteresis, variant, scenario = job
    scn = _scenario(hysteresis, variant, scenario)
    try:
        events = list(run_scenario(scn, seed=scn.seed, pictures=False).trace.events)
    except RunAborted as exc:  # the trace so far still says which steps happened
        if not isinstance(exc.result, RunResult):
            raise
        events = list(exc.result.trace.events)
    steps = [{"name": s.name, "ok": s.ok, "t": s.t, "c_switch": s.c_switch, "c_wait": s.c_wait,
              "margin": s.margin, "detail": s.detail} for s in appendix_b.check(events)]
    return {"steps": steps, "predictions": predictions(events)}


def _f(x: float | None, digits: int = 1) -> str:
    if x is None:
        return "–"
    return f"{x:.{digits}f}" if math.isfinite(x) else str(x)


Run = dict[str, Any]


def _pct(x: float | None) -> str:
    return "–" if x is None or not math.isfinite(x) else f"{100 * x:+.1f} %"


def _median(xs: Sequence[float]) -> float | None:
    xs = sorted(x for x in xs if math.isfinite(x))
    if not xs:
        return None
    m = len(xs) // 2
    return xs[m] if len(xs) % 2 else (xs[m - 1] + xs[m]) / 2


def _estimate_rows(runs: Sequence[Run]) -> tuple[int, float | None, float | None, int]:
    """Over the starts that ran to their end: n, median and largest |realised/predicted - 1|,
    and how many starts had no finite prediction."""
    errs = [abs(p["realised_s"] / p["predicted_s"] - 1) for r in runs for p in r["predictions"]
            if p["ended"] and math.isfinite(p["predicted_s"]) and p["predicted_s"] > 0]
    unknown = sum(1 for r in runs for p in r["predictions"] if not math.isfinite(p["predicted_s"]))
    return len(errs), _median(errs), max(errs, default=None), unknown


def render(shipped: dict[float, Run], variants: dict[float, list[Run]], n: int, command: str) -> str:
    lines = [BEGIN, "", f"*Generated by `{command}` from the runs' traces; do not edit by hand.*", ""]
    for h in HYSTERESES:
        steps = shipped[h]["steps"]
        lines += [f"#### The shipped scenario, hysteresis {h}", "",
                  "`margin` is `1 - c_switch / c_wait` of the deciding comparison (a switch needs more than "
                  f"`1 - {h}`); for a cost step that did not happen, of the comparison that came closest.", "",
                  "| # | step | holds | t (s) | c_switch | c_wait | margin |", "|---|---|---|---|---|---|---|"]
        for k, st in enumerate(steps, 1):
            lines.append(f"| {k} | {st['name']} | {'yes' if st['ok'] else '**no**'} | {_f(st['t'])} | "
                         f"{_f(st['c_switch'])} | {_f(st['c_wait'])} | {_pct(st['margin'])} |")
        lines += ["", "What the checker saw:", ""]
        lines += [f"{k}. {st['detail']}" for k, st in enumerate(steps, 1)]
        lines += ["", "Each `start`: the cTime the agent reported (predicted) and the seconds until it was "
                  "suspended or ended (realised; comparable only when it ran to its end):", "",
                  "| agent | started at (s) | predicted (s) | realised (s) | ran to its end |", "|---|---|---|---|---|"]
        for p in shipped[h]["predictions"]:
            lines.append(f"| {p['agent']} | {_f(p['t'])} | {_f(p['predicted_s'])} | {_f(p['realised_s'])} | "
                         f"{'yes' if p['ended'] else 'no'} |")
        lines.append("")
    if n:
        names = [st["name"] for st in shipped[HYSTERESES[0]]["steps"]]
        lines += [f"#### Reproduction over {n} randomised variants (seeds 1..{n})", "",
                  "Per step: variants in which it holds with its cause; for the cost steps, the median "
                  "margin over all variants that made the comparison.", "",
                  "| # | step | " + " | ".join(f"h = {h} | median margin" for h in HYSTERESES) + " |",
                  "|---|---|" + "---|---|" * len(HYSTERESES)]
        for k, name in enumerate(names):
            cells = []
            for h in HYSTERESES:
                runs = variants[h]
                margins = [r["steps"][k]["margin"] for r in runs if r["steps"][k]["margin"] is not None]
                cells += [f"{sum(1 for r in runs if r['steps'][k]['ok'])}/{n}", _pct(_median(margins))]
            lines.append(f"| {k + 1} | {name} | " + " | ".join(cells) + " |")
        whole = []
        for h in HYSTERESES:
            whole += [f"{sum(1 for r in variants[h] if all(st['ok'] for st in r['steps']))}/{n}", ""]
        lines.append("| | **the whole sequence, every step with its cause** | " + " | ".join(whole) + " |")
        lines += ["", "Estimates against what happened, over the variants' starts that ran to their end:", "",
                  "| hysteresis | starts | median \\|realised/predicted − 1\\| | largest | starts with no finite "
                  "prediction |", "|---|---|---|---|---|"]
        for h in HYSTERESES:
            m, med, worst, unknown = _estimate_rows(variants[h])
            lines.append(f"| {h} | {m} | {_pct(med).lstrip('+')} | {_pct(worst).lstrip('+')} | {unknown} |")
        lines.append("")
    lines.append(END)
    return "\n".join(lines) + "\n"


def splice(text: str, block: str) -> str:
    """``text`` with the generated block replaced (or appended when it has no markers)."""
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        return head + block.rstrip("\n") + tail
    return text.rstrip("\n") + "\n\n" + block


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m experiments.paper.report", description=__doc__.split("\n\n")[0],
                                epilog="example: python -m experiments.paper.report --variants 50 --out docs/paper.md")
    p.add_argument("--variants", type=int, default=50, help="randomised variants per hysteresis (default 50)")
    p.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--out", type=Path, help="Markdown file whose generated block to replace")
    p.add_argument("--json", type=Path, help="also write every run's checked steps and predictions here (JSON)")
    p.add_argument("--scenario", default="paper", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.variants < 0:
        p.error(f"--variants must be >= 0, got {args.variants}")
    if args.jobs < 1:
        p.error(f"--jobs must be >= 1, got {args.jobs}")
    if args.out is not None and not args.out.is_file():
        p.error(f"--out {args.out}: no such file")
    jobs: list[tuple[float, int | None, str]] = [(h, None, args.scenario) for h in HYSTERESES]
    jobs += [(h, v, args.scenario) for h in HYSTERESES for v in range(1, args.variants + 1)]
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        results = list(pool.map(run_one, jobs))
    shipped = {h: results[k] for k, h in enumerate(HYSTERESES)}
    rest = results[len(HYSTERESES):]
    variants = {h: rest[k * args.variants:(k + 1) * args.variants] for k, h in enumerate(HYSTERESES)}
    command = f"python -m experiments.paper.report --variants {args.variants}" + (
        f" --out {args.out}" if args.out else "")
    block = render(shipped, variants, args.variants, command)
    if args.json is not None:
        runs = [{"hysteresis": h, "variant": v, **r} for (h, v, _), r in zip(jobs, results, strict=True)]
        args.json.write_text(json.dumps(runs, indent=1, default=str) + "\n")
    if args.out is None:
        sys.stdout.write(block)
    else:
        args.out.write_text(splice(args.out.read_text(), block))
        print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
