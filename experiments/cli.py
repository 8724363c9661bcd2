"""The ``tasker`` command line.

Subcommands live next to what they drive: ``run`` here (experiments), ``plan``,
``domains`` and ``fsm`` in :mod:`planners.cli`, ``world`` and ``cost`` in
:mod:`robot.cli`.  Each module offers ``register(subparsers)``; a handler returns
the exit status.  Every error the framework raises on purpose is printed as one
line on stderr with exit status 2, never as a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from tasker import __version__
from tasker.errors import TaskerError

SUBCOMMAND_MODULES = ("experiments.run_cli", "experiments.sweep_cli", "planners.cli", "robot.cli",
                      "experiments.explain")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tasker", description="TaskER: harmonise a robot's tasks.")
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
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except TaskerError as exc:
        print(f"tasker {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"tasker {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
