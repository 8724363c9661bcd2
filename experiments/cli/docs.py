"""``tasker docs``: rewrite the generated parts of ``docs/`` from the definitions they describe.

``--check`` writes nothing and exits 1 when a part is out of date (CI runs it through a
test).  :mod:`experiments.report.reference` says which parts there are.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from experiments.cli.args import EXIT_FAILED, EXIT_OK, UsageError

ROOT = Path(__file__).resolve().parents[2]


def _docs(args: argparse.Namespace) -> int:
    from experiments.report.reference import update

    root = Path(args.root)
    if not (root / "docs").is_dir():
        raise UsageError("--root", f"{root} has no docs/ folder (give the project's folder)")
    stale = update(root, check=args.check)
    for path in stale:
        print(f"{path}: {'out of date' if args.check else 'rewritten'}", file=sys.stderr)
    return EXIT_FAILED if stale and args.check else EXIT_OK


EXAMPLES = """\
examples:
  tasker docs            # rewrite docs/trace.md's event fields and docs/metrics.md's registry table
  tasker docs --check    # exit 1 if one is out of date (CI runs this through a test)"""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("docs", help="rewrite docs/'s generated parts (event fields, the metric registry)",
                       description="Rewrite the parts of docs/ generated from the code (the trace's event types, "
                                   "the metric registry); --check only reports the ones out of date (exit 1).",
                       epilog=EXAMPLES)
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 if a part is out of date")
    p.add_argument("--root", default=str(ROOT), help="the project folder (default: this checkout)")
    p.set_defaults(func=_docs)
