"""``tasker serve``: run the controller live, take requests over HTTP, save the session on stop.

Every argument is checked before the robot is built (the speed, the port, that ``--out`` can
be written, what is served); the session itself is :mod:`experiments.serve`.
"""

from __future__ import annotations

import argparse
import secrets
import sys
from pathlib import Path

from experiments.cli.args import EXIT_FAILED, EXIT_OK, UsageError, note, port, seed, speed, writable_dir
from experiments.cli.run import add_path_option, task_paths

EXAMPLES = """\
examples:
  tasker serve paper --speed 20                    # the paper's apartment, 20 simulated s a second
  curl -X POST localhost:8765/requests -H 'Content-Type: application/json' \\
       -d '{"task": "guide_human", "args": {"person": "john", "destination": "john_destination"}}'
  tasker serve experiments/inputs/scenarios/paper.toml --out out/live   # its requests come at their times
  tasker run out/live/session.toml                 # replays the session: the same trace.jsonl"""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("serve", help="run the controller live: requests over HTTP, a live page, the session saved "
                                     "as a replayable scenario",
                       description="Run the controller against the clock (the harmoniser, the agents, Fast Downward, "
                                   "OMPL, the MuJoCo robot) and take requests over HTTP: POST /requests, GET /state, "
                                   "DELETE and PATCH /requests/ID, POST /world, GET /events (server-sent events), "
                                   "the live page at /, the OpenAPI schema at /openapi.json. Ctrl-C, SIGTERM or "
                                   "POST /stop writes the run folder as 'tasker run' does, and session.toml, which "
                                   "'tasker run' replays byte for byte (docs/serve.md).",
                       epilog=EXAMPLES)
    p.add_argument("source", metavar="WORLD|SCENARIO",
                   help="a shipped world (paper, flat), a world file, or a robot scenario (its requests then come "
                        "at their times)")
    p.add_argument("--speed", type=speed, default=1.0, help="simulated seconds per wall second (default 1)")
    p.add_argument("--port", type=port, default=8765, help="port to listen on (default 8765; 0: any free one)")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1; another one exposes the robot: a token is then "
                        "required)")
    p.add_argument("--token", default=None, help="require this token on every call (default: none on this "
                                                 "machine's loopback, a generated one on any other address)")
    p.add_argument("--out", default=None, metavar="DIR", help="output folder (default: out/NAME-session)")
    p.add_argument("--seed", type=seed, default=None, help="seed, 0 <= N < 2**32 (default: the scenario's, or 1)")
    p.add_argument("--no-pictures", action="store_true", help="skip report.html and the PNG figures on stop")
    add_path_option(p)
    p.set_defaults(func=_serve)


def _serve(args: argparse.Namespace) -> int:
    from experiments.serve.server import describe, loopback, scripted, serve, served
    from tasker.errors import RunAborted

    if args.token is not None and not args.token:
        raise UsageError("--token", "expected a non-empty token")
    paths = tuple(task_paths(args))
    scenario, what = served(args.source, seed=args.seed, task_paths=paths)
    out = writable_dir(Path(args.out) if args.out else Path("out") / scenario.name, "--out")
    token = args.token
    if not loopback(args.host):
        token = token or secrets.token_urlsafe(16)
        print(f"tasker serve: warning: listening on {args.host}, not only this machine: anyone who reaches it can "
              f"move the robot; every call needs the token {token} (Authorization: Bearer TOKEN or ?token=TOKEN)",
              file=sys.stderr, flush=True)

    def announce(url: str) -> None:  # the address first (scripts read it from the first line), then the script
        page = url + (f"?token={token}" if token else "")
        print(f"tasker serve: {what} at ×{args.speed:g} on {url} (live page {page}, API schema {url}openapi.json); "
              f"Ctrl-C stops and writes {out}/", flush=True)
        for line in scripted(scenario):
            print(f"tasker serve: {line}", flush=True)

    try:
        session, result = serve(scenario, what=what, speed=args.speed, out=out, host=args.host, port=args.port,
                                token=token, task_paths=paths, pictures=not args.no_pictures, announce=announce)
    except RunAborted as exc:  # the session's record could not all be written: what failed, what was kept
        print(f"tasker serve: error: {exc.reason}", file=sys.stderr, flush=True)
        return EXIT_FAILED
    print(f"tasker serve: stopped at t={round(session.t_stop or 0.0, 6)!r} s ({session.stop_reason}): "
          f"{describe(result)}; replay: tasker run {out / 'session.toml'}", flush=True)
    note(args, f"wrote {out}/")
    return EXIT_OK if result.record.status is None else EXIT_FAILED
