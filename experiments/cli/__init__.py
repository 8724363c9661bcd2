"""The ``tasker`` command line.

Subcommands live next to what they drive; each module in :data:`SUBCOMMAND_MODULES`
offers ``register(subparsers)`` and sets ``func`` on its parsers to a handler
``(args) -> int`` returning the exit status.  This module adds what every subcommand
shares: ``--verbose``/``--quiet``, the exit statuses in every ``--help``, "did you
mean" for misspelt subcommands and choices, and one error format,
``tasker CMD: error: …`` on stderr, never a traceback for a user's mistake.

It imports only ``argparse`` and the subcommand modules, which import their heavy
dependencies inside the handlers: ``tasker --help`` must stay fast.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from experiments.cli.args import EXIT_EPILOG, EXIT_USAGE, Parser, run_handler
from tasker import __version__

SUBCOMMAND_MODULES = (
    "experiments.cli.run",    # run
    "experiments.cli.sweep",  # sweep, report
    "experiments.cli.check",  # check
    "experiments.cli.plan",   # plan, domains, fsm, new
    "experiments.cli.world",  # world, cost
    "experiments.cli.explain",  # explain
    "experiments.cli.day",    # day
    "experiments.cli.docs",   # docs
    "experiments.cli.results",  # results
    "experiments.cli.paper",  # paper
    "experiments.cli.serve",  # serve
    # Add a subcommand here: a module with ``register(subparsers)`` (e.g. explain, an HTML report).
)
"""Modules that add subcommands, in the order ``tasker --help`` lists them."""

def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="tasker", description="TaskER: harmonise a robot's tasks (PDDL planned by Fast Downward, "
                                               "OMPL motion costs, MuJoCo execution).",
                    epilog="Run 'tasker COMMAND --help' for a command's options and examples.\n\n" + EXIT_EPILOG,
                    formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"tasker {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in SUBCOMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:  # that part of the project is not built yet
                continue
            raise
        module.register(sub)
    for name, p in sub.choices.items():
        add_common_options(p)
        p.prog = f"tasker {name}"
    return parser


def add_common_options(p: argparse.ArgumentParser) -> None:
    """``--verbose``/``--quiet`` and the exit statuses in the epilog of one subcommand."""
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.epilog = ((p.epilog or "").rstrip() + "\n\n" + EXIT_EPILOG).lstrip()
    g = p.add_mutually_exclusive_group()
    g.add_argument("-v", "--verbose", action="count", default=0,
                   help="say more (-vv: debug logging; an internal error shows its traceback)")
    g.add_argument("-q", "--quiet", action="store_true", help="only results and errors: no progress bars or notes")


def _logging(args: argparse.Namespace) -> None:
    verbose = int(getattr(args, "verbose", 0) or 0)
    level = logging.ERROR if getattr(args, "quiet", False) else (
        logging.DEBUG if verbose > 1 else logging.INFO if verbose else logging.WARNING)
    logging.basicConfig(level=level, format="%(name)s: %(message)s", stream=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error argparse already printed
        return exc.code if isinstance(exc.code, int) else EXIT_USAGE
    _logging(args)
    return run_handler(args.func, args)


if __name__ == "__main__":
    sys.exit(main())
