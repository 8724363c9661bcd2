"""``tasker paper``: reproduce Appendix B in both scenarios under both cost models, into ``docs/paper.md``.

The runs and the tables are :mod:`experiments.paper.report`'s (and the recorded comparisons,
:mod:`experiments.paper.recorded`'s); this module holds the options,
names the commit in the generated text and writes it (``--out``: the block between the
report's markers; otherwise stdout).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from experiments.cli.args import UsageError, non_negative_int, note, positive_int, show_progress, writable_file

ROOT = Path(__file__).resolve().parents[2]

EXAMPLES = """\
examples:
  tasker paper --variants 50 --jobs 2 --out docs/paper.md --readme README.md   # docs/paper.md and the README's lines
  tasker paper --variants 0 --scenario paper-2019             # the shipped runs only, to stdout
  tasker paper --variants 5 --json runs.json                  # also every run's checked steps"""


def commit() -> str:
    """The checkout's commit (``+changes`` when the work tree differs from it), or ``unknown``."""
    try:
        head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+changes" if dirty else "")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("paper", help="Appendix B in both paper scenarios under both cost models (docs/paper.md)",
                       description="Run the paper scenarios (paper: Fig. 10 as we draw it; paper-2019: the layout "
                                   "reconstructed from the original verification's record) with our cost model at "
                                   "hysteresis 1.0 and 0.9 and the original TaskER model with its rule (0.9), as "
                                   "shipped and as --variants randomised variants; check every step of Appendix B "
                                   "with its cause and write the tables of docs/paper.md.",
                       epilog=EXAMPLES)
    p.add_argument("--variants", type=non_negative_int, default=50,
                   help="randomised variants per scenario and configuration (default 50)")
    p.add_argument("--jobs", type=positive_int, default=2, help="worker processes (default 2)")
    p.add_argument("--scenario", action="append", choices=("paper", "paper-2019"), default=None,
                   help="only this scenario (repeatable; default both)")
    p.add_argument("--out", default=None, help="a Markdown file whose generated block to replace (e.g. docs/paper.md)")
    p.add_argument("--json", default=None, help="also write every run's checked steps and predictions here")
    p.add_argument("--readme", default=None,
                   help="also rewrite this file's paper_summary block (steps 3, 4 and the whole sequence) from "
                        "the tables written (e.g. README.md)")
    p.set_defaults(func=_command)


def _command(args: argparse.Namespace) -> int:
    from experiments.paper import recorded, report, summary
    from tasker.errors import ConfigError

    out = Path(args.out) if args.out else None
    if out is not None and not out.is_file():
        raise UsageError("--out", f"{out}: no such file (the document whose generated block to replace)")
    readme = Path(args.readme) if args.readme else None
    if readme is not None:  # checked before the runs: they cost minutes
        if out is None:
            raise UsageError("--readme", "needs --out: the summary is made from the page written there")
        if not readme.is_file():
            raise UsageError("--readme", f"{readme}: no such file (the document whose summary block to replace)")
        try:
            summary.splice(readme.read_text(), "", str(readme))
        except ConfigError as exc:
            raise UsageError("--readme", str(exc)) from None
    js = writable_file(args.json, "--json") if args.json else None
    made_at = commit()  # before the runs: what is edited meanwhile is not what ran
    scenarios = tuple(args.scenario or report.SCENARIOS)
    todo = report.jobs(scenarios, args.variants)
    note(args, f"{len(todo)} runs on {args.jobs} process(es)")
    progress = (lambda k: print(f"\r{k}/{len(todo)} runs", end="", file=sys.stderr, flush=True)) \
        if show_progress(args) else None
    results = report.run_all(todo, args.jobs, progress)
    if progress is not None:
        print(file=sys.stderr)
    command = "tasker paper --variants {}{}{}{}".format(
        args.variants, "".join(f" --scenario {s}" for s in args.scenario or ()), f" --out {args.out}" if out else "",
        f" --readme {args.readme}" if readme else "")
    block = report.render(results, scenarios, args.variants, command, made_at, recorded.rows())
    if js is not None:
        runs = [{"scenario": s, "model": c.model, "hysteresis": c.hysteresis, "variant": v, **r}
                for (s, c, v), r in results.items()]
        js.write_text(json.dumps(runs, indent=1, default=str) + "\n")
    if out is None:
        sys.stdout.write(block)
    else:
        out.write_text(report.splice(out.read_text(), block))
        print(f"wrote {out}", file=sys.stderr)
    if readme is not None:
        lines = summary.render(summary.read_verdicts(block, "the generated block"), args.out)
        readme.write_text(summary.splice(readme.read_text(), lines, str(readme)))
        print(f"wrote {readme}", file=sys.stderr)
    return 0
