"""The live session: the one thread that owns the loop, paced against the wall clock.

:meth:`Session.run` runs the served scenario with :func:`experiments.run.runner.run_scenario`,
whose ``live`` hook hands the built loop to :meth:`Session._drive`, so the run folder is written
exactly as ``tasker run`` writes it.  The drive advances the loop to ``speed`` × the wall time
elapsed (it only runs late, never ahead), and between two calls of ``loop.run`` — at a tick
boundary — takes what the HTTP handlers queued with :meth:`Session.ask`:

* each action is read and checked (:mod:`experiments.serve.bodies`) and scheduled with the
  scenario's own path (:class:`experiments.run.runner.Actions`) at
  :meth:`tasker.loop.SimulationLoop.next_free`: the first tick after now at which nothing else
  is due, so it runs alone in its tick and first in it, as it will in the replay where it is a
  line of the saved scenario (:mod:`experiments.serve.record`);
* a request is answered with its agent's id once the tick that submits it has run.

Handlers never touch the loop: they put :class:`Ask` objects on a thread-safe queue and read
what the drive publishes — :meth:`Session.state_json` (a snapshot, encoded once) and
:attr:`Session.lines` (the trace as it is emitted, one ``trace.jsonl`` line each).

On stop (:meth:`Session.stop`: a signal, ``POST /stop``, or the served scenario's horizon) the
drive schedules a stop mark — a ``mode`` action that keeps the mode it has, at the next free
tick ``T`` — runs to it, and ends the loop as a run with ``horizon = T`` ends; the saved
scenario holds the same mark and that horizon, so its replay ends in the same way.
"""

from __future__ import annotations

import dataclasses
import queue
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future, InvalidStateError
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from experiments.inputs.actions import TimedAction
from experiments.inputs.robot_scenario import RobotScenario
from experiments.run.runner import Actions, RunResult, run_scenario
from experiments.serve import bodies
from experiments.serve.bodies import CONFLICT, NOT_FOUND, UNAVAILABLE, Refused
from experiments.serve.record import Record
from experiments.serve.snapshot import snapshot
from tasker import events as ev
from tasker.loop import SimulationLoop
from tasker.trace import encode

LIVE_HORIZON = 1e9
"""The loop's horizon while live (simulated seconds): the session ends when it is stopped, or at
the served scenario's own horizon, which the drive watches."""

CHUNK_S = 0.1
"""At most this much simulated time per ``loop.run`` call before the drive looks at its queue again."""

PUBLISH_S = 0.05
"""Wall seconds between two published snapshots."""

WAIT_S = 0.01
"""Longest wall-clock sleep of the drive when it has caught up with the clock."""


@dataclass
class Ask:
    """What a handler asks the session for: ``kind`` is ``request``, ``world``, ``change``,
    ``terminate`` or ``stop``; ``agent`` the agent a change or termination names."""

    kind: str
    body: Any = None
    agent: str | None = None
    reason: str | None = None
    reply: Future[dict[str, Any]] = field(default_factory=Future)


class Session:
    """A live session of ``scenario`` (``request_fields`` on, so every request may give a
    priority and a deadline) at ``speed``, writing its run folder and ``session.toml`` to ``out``."""

    def __init__(self, scenario: RobotScenario, *, speed: float, out: Path, served: str,
                 task_paths: tuple[str, ...] = (), pictures: bool = True,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not speed > 0:
            raise ValueError(f"speed must be > 0, got {speed!r}")
        self.scenario = dataclasses.replace(scenario, request_fields=True)
        self.speed, self.out, self.served = float(speed), Path(out), served
        self.task_paths, self.pictures, self.clock = task_paths, pictures, clock
        self.lines: list[str] = []  # the trace so far, as trace.jsonl writes it (appended by the drive only)
        self.stopped = threading.Event()  # the run folder is written (or the run failed)
        self.stop_reason: str | None = None
        self.t_stop: float | None = None  # where the session stopped (simulated s): its saved scenario's horizon
        self.result: RunResult | None = None
        self._inbox: queue.SimpleQueue[Ask] = queue.SimpleQueue()
        self._wake = threading.Event()
        self._stopping = threading.Event()  # no more asks are taken (the stop mark is set, the run folder next)
        self._state = encode({"status": "starting", "served": served}).encode()
        self._ended: dict[str, dict[str, Any]] = {}
        self._decision: dict[str, Any] | None = None
        self._tasks: list[Any] = []  # the session's task types (its loop's store), for checking requests

    # -- any thread ------------------------------------------------------------------------

    def ask(self, ask: Ask) -> Future[dict[str, Any]]:
        """Queue ``ask`` for the drive; its ``reply`` gets the answer or a :class:`Refused`."""
        if self.stopped.is_set() or self._stopping.is_set():
            ask.reply.set_exception(Refused(UNAVAILABLE, ask.kind, "the session has stopped"))
            return ask.reply
        self._inbox.put(ask)
        self._wake.set()
        if self.stopped.is_set() or self._stopping.is_set():  # it stopped meanwhile: nobody else drains the queue
            self._refuse_waiting("the session has stopped")
        return ask.reply

    def stop(self, why: str) -> None:
        """Stop at the next tick boundary (from a signal handler too: it only queues)."""
        self.ask(Ask("stop", reason=why))

    def state_json(self) -> bytes:
        """The last published snapshot (:func:`experiments.serve.snapshot.snapshot`), as JSON."""
        return self._state

    # -- the owning thread -----------------------------------------------------------------

    def run(self) -> RunResult:
        """Run the session until it is stopped; the run folder and ``session.toml`` are in ``out``."""
        live = dataclasses.replace(self.scenario, horizon=LIVE_HORIZON)
        try:
            self.result = run_scenario(live, out=self.out, task_paths=self.task_paths, pictures=self.pictures,
                                       live=self._drive)
            return self.result
        finally:
            self.stopped.set()
            self._refuse_waiting("the session has stopped")

    def _drive(self, loop: SimulationLoop, sim: Any, actions: Actions) -> RobotScenario:
        record = Record(self.scenario, self.task_paths)
        count = 0
        for a in sorted(self.scenario.actions, key=lambda a: a.t):  # as build_robot_actions numbered them
            count += a.kind == "request"
            record.add(a, f"d{count}" if a.kind == "request" else None)
        self.lines.extend(encode(r) for r in loop.trace.events)  # anything traced while it was built
        loop.trace.subscribe(lambda e: self._on_event(loop, e))
        self._tasks = [loop.store.get(n) for n in loop.store.names()]
        waiting: list[tuple[str, Ask, float, list[str]]] = []  # requests scheduled, not yet submitted
        loop.run(until=0.0)
        wall0, published, latest = self.clock(), -1.0, 0.0
        horizon = self.scenario.horizon
        while True:
            self._wake.clear()
            stop = False
            while not self._inbox.empty():
                ask = self._inbox.get()
                if ask.kind == "stop":
                    self.stop_reason = self.stop_reason or ask.reason
                    ask.reply.set_result({"t": loop.now})
                    stop = True
                    continue
                if stop:
                    self._inbox.put(ask)  # answered by the refusal below
                    break
                t = self._take(ask, loop, sim, actions, record, waiting)
                latest = max(latest, t)
            if stop:
                break
            target = min(horizon, (self.clock() - wall0) * self.speed)
            until = min(max(target, latest), loop.now + CHUNK_S)
            if until > loop.now:
                loop.run(until=until)
            made, waiting = self._made(waiting, actions)
            now = self.clock()
            if made or now - published >= PUBLISH_S:  # a requester sees its task in the state it is answered by
                self._publish(loop, sim, "running", lag=max(0.0, target - loop.now))
                published = now
            self._answer(made)
            if loop.now >= horizon:
                self.stop_reason = f"the scenario's horizon ({horizon:g} s)"
                break
            if loop.now >= target:
                self._wake.wait(WAIT_S)
        return self._finish(loop, sim, actions, record, waiting)

    def _finish(self, loop: SimulationLoop, sim: Any, actions: Actions, record: Record,
                waiting: list[tuple[str, Ask, float, list[str]]]) -> RobotScenario:
        """The stop mark at the next free tick, the loop ended there, the session saved."""
        self._stopping.set()
        self._refuse_waiting("the session is stopping")
        t_stop = self.t_stop = loop.next_free(loop.now)
        mark = TimedAction(t_stop, "mode", {"mode": loop.harmoniser.mode.value})
        record.add(mark, actions.schedule(mark))
        loop.run(until=t_stop)
        made, _ = self._made(waiting, actions)
        loop.horizon = t_stop
        loop.run()
        self._publish(loop, sim, "stopped", lag=0.0)
        self._answer(made)
        header = (f"A tasker serve session of {self.served}, saved when it stopped ({self.stop_reason or 'stopped'}).\n"
                  f"'tasker run {self.out / 'session.toml'}' replays it: the same trace.jsonl, byte for byte."
                  f"{' (with the same --path folders)' if self.task_paths else ''}\n"
                  "Each action is at the simulated time it was injected, a tick at which nothing else was due.\n"
                  f"The last mode change (t = {t_stop:g}, to the mode the session had) marks where it stopped: it\n"
                  "keeps the replay running to that time, and the horizon ends it there.")
        return record.write(self.out / "session.toml", t_stop, header)

    def _take(self, ask: Ask, loop: SimulationLoop, sim: Any, actions: Actions, record: Record,
              waiting: list[tuple[str, Ask, float, list[str]]]) -> float:
        """Read, check and schedule one action; its time (or the time now, if refused)."""
        t = loop.next_free(loop.now)
        try:
            if ask.kind == "request":
                a, warnings = bodies.read_request(ask.body, t=t, scn=self.scenario, tasks=self._tasks)
            elif ask.kind == "world":
                a, warnings = bodies.read_world(ask.body, t=t, scn=self.scenario, tasks=self._tasks)
            else:
                a, warnings = self._about_agent(ask, t, loop, sim, actions, record), []
        except Refused as exc:
            ask.reply.set_exception(exc)
            return loop.now
        except Exception as exc:  # a bug in reading it: this ask fails (500), the session goes on
            ask.reply.set_exception(exc)
            return loop.now
        sid = actions.schedule(a)
        record.add(a, sid)
        if sid is not None:
            waiting.append((sid, ask, t, warnings))
        else:
            ask.reply.set_result({"id": ask.agent, "t": t, "warnings": warnings} if ask.agent else
                                 {"t": t, "warnings": warnings})
        return t

    def _about_agent(self, ask: Ask, t: float, loop: SimulationLoop, sim: Any, actions: Actions,
                     record: Record) -> TimedAction:
        """A change or termination of the live agent ``ask.agent``, as the scenario's action on its request."""
        where = f"{'PATCH' if ask.kind == 'change' else 'DELETE'} /requests/{ask.agent}"
        sid = next((e.sid for e in record.entries if e.sid and ask.agent in actions.agents(e.sid)), None)
        if sid is None:
            made = sorted({a for e in record.entries if e.sid for a in actions.agents(e.sid)}, key=_number)
            raise Refused(NOT_FOUND, where, f"no task {ask.agent!r}: tasks are {', '.join(made) or 'none yet'}")
        agent = loop.harmoniser.agents.get(str(ask.agent))
        if agent is None or agent.ended:
            end = self._ended.get(str(ask.agent), {})
            raise Refused(CONFLICT, where, f"task {ask.agent!r} has ended (t={end.get('t', loop.now):g}, "
                                           f"{end.get('cause', 'ended')}: {end.get('reason', '')})")
        if ask.kind == "terminate":
            return TimedAction(t, "terminate", {"agent": sid, "reason": bodies.read_reason(ask.reason, "the user")})
        task = loop.store.get(agent.ctx.task_type)
        given = bodies.read_change(ask.body, where=where, task=task, args=agent.ctx.args, world=sim.spec)
        return TimedAction(t, "change", {"agent": sid, "args": given})

    @staticmethod
    def _made(waiting: list[tuple[str, Ask, float, list[str]]], actions: Actions
              ) -> tuple[list[tuple[Ask, dict[str, Any]]], list[tuple[str, Ask, float, list[str]]]]:
        """The answers of the requests whose agent is made, and the requests that still wait."""
        made, left = [], []
        for sid, ask, t, warnings in waiting:
            agents = actions.agents(sid)
            if agents:
                made.append((ask, {"id": agents[0], "t": t, "warnings": warnings}))
            else:
                left.append((sid, ask, t, warnings))
        return made, left

    @staticmethod
    def _answer(made: list[tuple[Ask, dict[str, Any]]]) -> None:
        for ask, answer in made:
            ask.reply.set_result(answer)

    def _refuse_waiting(self, why: str) -> None:
        while True:
            try:
                ask = self._inbox.get_nowait()
            except queue.Empty:
                return
            try:
                ask.reply.set_exception(Refused(UNAVAILABLE, ask.kind, why))
            except InvalidStateError:  # answered already
                pass

    def _on_event(self, loop: SimulationLoop, e: ev.Event) -> None:
        self.lines.append(encode(loop.trace.events[-1]))
        if isinstance(e, ev.TaskEnded):
            self._ended[e.agent] = {"t": e.t, "cause": e.cause, "reason": e.reason}
        elif isinstance(e, ev.Decision):
            self._decision = {"t": e.t, **e.data}

    def _publish(self, loop: SimulationLoop, sim: Any, status: str, lag: float) -> None:
        state = snapshot(loop, sim, ended=self._ended, decision=self._decision)
        state.update(status=status, served=self.served, speed=self.speed, lag_s=lag, events=len(self.lines),
                     stop_reason=self.stop_reason)
        self._state = encode(state).encode()


def _number(agent: str) -> tuple[int, str]:
    return (int(agent[1:]), agent) if agent[1:].isdigit() else (0, agent)
