"""Start a live session: what is served, the HTTP server in its own thread, the signals.

:func:`served` turns ``tasker serve``'s argument into the scenario of the session: a shipped
world (``paper``) or a world file gets the default settings (Alg. 2 with the priority classes
the task folders declare) and no requests; a scenario file (or a shipped scenario's name) keeps
its settings, people, objects and actions, which then happen at their times.  :func:`serve`
runs the session in the calling thread (the main thread: it owns the loop, and SIGINT and
SIGTERM only ask it to stop) and uvicorn in another, until the session has written its run
folder; then the server stops.
"""

from __future__ import annotations

import ipaddress
import signal
import threading
import time
from collections.abc import Callable
from pathlib import Path
from types import FrameType

from experiments.inputs import fields
from experiments.inputs import scenario as scenarios
from experiments.inputs.robot_scenario import RobotScenario
from experiments.run.runner import RunResult
from experiments.serve.app import create_app
from experiments.serve.guard import allowed_hosts
from experiments.serve.page import live_page
from experiments.serve.session import LIVE_HORIZON, Session
from experiments.trace.timeline import Timeline
from tasker.errors import UsageError
from tasker.support import reader

START_S = 30.0
"""How long the HTTP server may take to listen."""


def loopback(host: str) -> bool:
    """Whether ``host`` is reachable only from this machine (``127.0.0.1``, ``::1``, ``localhost``)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def scripted(scn: RobotScenario) -> list[str]:
    """What a session of ``scn`` will do on its own, and how to serve it without that, in words
    (``tasker serve``'s lines after its address): the world file's scripted falls and walks, the
    scenario's own requests and world events, each with its simulated time."""
    from robot.spec import load_world, world_path

    world = load_world(scn.world)
    path = world_path(scn.world)
    shown_path = str(path.relative_to(Path.cwd())) if path.is_relative_to(Path.cwd()) else str(path)
    said = [f"{p.name} {posture} at t={t:g} s" for p in world.people.values() for t, posture in p.events]
    for p in world.people.values():
        walk = scn.people.get(p.name, {}).get("walk", p.walk)
        if walk:
            said.append(f"{p.name} walking (t={walk[0][0]:g} s to {walk[-1][0]:g} s)")
    lines = []
    if said:
        flat = ", or the flat world (tasker serve flat)" if scn.world != "flat" else ""
        lines.append(f"on its own, the world file {shown_path} has {', '.join(said)} (simulated time), in every "
                     f"session; to serve it without them, serve a copy of it without those people's events and walk "
                     f"(tasker serve my_world.toml){flat}")
    requests = [a.t for a in scn.actions if a.kind == "request"]
    others = [a.t for a in scn.actions if a.kind != "request"]
    if requests or others:
        at = ", ".join(f"{t:g}" for t in sorted(requests)[:6]) + (", …" if len(requests) > 6 else "")
        lines.append(f"the scenario's own {len(requests)} requests (t={at} s) and {len(others)} other actions happen "
                     f"at their times besides what arrives over HTTP; to take requests only over HTTP, serve its world "
                     f"(tasker serve {scn.world})")
    return lines or ["nothing is scripted: the world changes and tasks come only over HTTP"]


def served(source: str, *, seed: int | None = None, task_paths: tuple[str, ...] = ()) -> tuple[RobotScenario, str]:
    """The scenario of a session of ``source`` (a world or a scenario, see the module docstring) and
    what it is, in words."""
    from robot.spec import WorldFileError, load_world, shipped_worlds

    p = Path(source)
    worlds, shipped = shipped_worlds(), sorted(q.stem for q in scenarios.SCENARIOS.glob("*.toml"))
    if p.suffix in (".toml", ".json") or p.exists():
        if not p.is_file():
            raise UsageError("WORLD", f"{source}: {'no such file' if not p.exists() else 'not a file'}")
        top = reader.load(p, WorldFileError)
        if "kind" not in top:  # a world file (its reader says what is wrong with it, if anything)
            load_world(p)
            return _world_session(str(p.resolve()), p.stem, seed, task_paths), f"the world file {p}"
        if scenarios.kind_of(p) != "robot":
            raise UsageError("WORLD", f"{source}: a synthetic scenario has no robot to serve; serve a world or a "
                                      "robot scenario")
        scn = scenarios.load(p, task_paths=task_paths)
        return _scenario_session(scn, seed), f"the scenario {p}"
    if source in worlds:
        return _world_session(source, source, seed, task_paths), f"the {source} world"
    if source in shipped:
        scn = scenarios.load(scenarios.resolve(source), task_paths=task_paths)
        return _scenario_session(scn, seed), f"the shipped scenario {source}"
    raise UsageError("WORLD", f"no world or scenario {source!r}{reader.suggest(source, [*worlds, *shipped])}: "
                              f"a shipped world ({', '.join(worlds)}), a shipped scenario ({', '.join(shipped)}), "
                              "or a world or scenario file")


def _world_session(world: str, name: str, seed: int | None, task_paths: tuple[str, ...]) -> RobotScenario:
    from planners.bundled import task_types

    options = fields.scheduler_defaults("alg2", {}, task_types(list(task_paths)))
    return RobotScenario(name=f"{name}-session", source=world, world=world, actions=(), scheduler="alg2",
                         scheduler_options=options, seed=1 if seed is None else seed, horizon=LIVE_HORIZON,
                         request_fields=True)


def _scenario_session(scn: RobotScenario, seed: int | None) -> RobotScenario:
    import dataclasses

    return dataclasses.replace(scn, name=f"{scn.name}-session", seed=scn.seed if seed is None else seed,
                               request_fields=True)


def serve(scenario: RobotScenario, *, what: str, speed: float, out: Path, host: str = "127.0.0.1", port: int = 8765,
          token: str | None = None, task_paths: tuple[str, ...] = (), pictures: bool = True,
          announce: Callable[[str], None] = print) -> tuple[Session, RunResult]:
    """Serve ``scenario`` until it is stopped; ``announce`` gets the address once the server listens."""
    import uvicorn

    from robot.spec import load_world

    session = Session(scenario, speed=speed, out=out, served=what, task_paths=task_paths, pictures=pictures)
    html = live_page(load_world(scenario.world), title=f"tasker serve: {what}")
    app = create_app(session, page=lambda: html, token=token, hosts=allowed_hosts(host))
    server = uvicorn.Server(uvicorn.Config(app, host=host, port=port, log_level="warning", lifespan="off",
                                           timeout_graceful_shutdown=5))
    thread = threading.Thread(target=server.run, name="tasker-serve-http", daemon=True)
    thread.start()
    deadline = time.monotonic() + START_S
    while not server.started:
        if not thread.is_alive() or time.monotonic() > deadline:
            raise UsageError("--port", f"cannot listen on {host}:{port} (in use, or not an address of this machine)")
        time.sleep(0.02)
    bound = server.servers[0].sockets[0].getsockname()[1] if server.servers else port
    shown = f"[{host}]" if ":" in host else host
    announce(f"http://{shown}:{bound}/")
    previous = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}

    def on_signal(sig: int, frame: FrameType | None) -> None:
        session.stop(f"{signal.Signals(sig).name}")

    for sig in previous:
        signal.signal(sig, on_signal)
    try:
        result = session.run()
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        server.should_exit = True
        thread.join(timeout=10)
    return session, result


def describe(result: RunResult) -> str:
    """How many tasks ran and how they ended, in words (for the command's last line), from the
    run's timeline (the one reader of a trace)."""
    tl = Timeline(result.trace.typed)
    ends = [a.end for a in tl.agents.values() if a.end is not None]
    causes: dict[str, int] = {}
    for e in ends:
        causes[e.cause] = causes.get(e.cause, 0) + 1
    how = f" ({', '.join(f'{n} {c}' for c, n in sorted(causes.items()))})" if causes else ""
    return f"{len(tl.agents)} tasks, {len(ends)} ended{how}"
