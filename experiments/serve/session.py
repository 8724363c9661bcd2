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

The record is never lost: ``trace.jsonl`` is written line by line as the session goes (the run
folder's final one, written by ``run_scenario``, is the same bytes); when ``session.toml`` or
the rest of the run folder cannot be written, :meth:`Session.run` still leaves the whole trace
and raises a :class:`tasker.errors.RunAborted` saying what failed and what was kept.
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
from typing import IO, Any

from experiments.inputs.actions import TimedAction
from experiments.inputs.robot_scenario import RobotScenario
from experiments.run.runner import Actions, RunResult, run_scenario
from experiments.run.simulation import SimulatedWorld
from experiments.serve import bodies
from experiments.serve.bodies import CONFLICT, NOT_FOUND, UNAVAILABLE, Refused
from experiments.serve.examples import task_types
from experiments.serve.record import Record
from experiments.serve.snapshot import snapshot
from tasker import events as ev
from tasker.errors import RunAborted
from tasker.loop import SimulationLoop
from tasker.support.reader import MAX_SECONDS
from tasker.trace import encode

LIVE_HORIZON = 1e9
"""The loop's horizon while live (simulated seconds): the session ends when it is stopped, or at
the served scenario's own horizon, which the drive watches."""

LONGEST_S = MAX_SECONDS - 1.0
"""A session stops itself here (simulated seconds, a week less a second), as at a horizon: a
scenario holds no later time, so ``session.toml`` could not hold what came after."""

CHUNK_S = 0.1
"""At most this much simulated time per ``loop.run`` call before the drive looks at its queue again."""

PUBLISH_S = 0.05
"""Wall seconds between two published snapshots (and flushes of the live ``trace.jsonl``)."""

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


@dataclass
class _Waiting:
    """A request scheduled (session id ``sid``, at ``t``) whose agent the loop has not made yet."""

    sid: str
    ask: Ask
    t: float
    warnings: list[str]


@dataclass
class _Drive:
    """What the drive keeps between two passes: the record, the requests not yet answered, the
    latest action's time, the wall clock's start and the last publication."""

    loop: SimulationLoop
    sim: SimulatedWorld
    actions: Actions
    record: Record
    wall0: float
    waiting: list[_Waiting] = field(default_factory=list)
    latest: float = 0.0
    published: float = -1.0


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
        self.problems: list[str] = []  # what could not be written, and why (the session's record is kept)
        self._inbox: queue.SimpleQueue[Ask] = queue.SimpleQueue()
        self._wake = threading.Event()
        self._stopping = threading.Event()  # no more asks are taken (the stop mark is set, the run folder next)
        self._state = encode({"status": "starting", "served": served}).encode()
        self._ended: dict[str, dict[str, Any]] = {}
        self._decision: dict[str, Any] | None = None
        self._tasks: list[Any] = []  # the session's task types (its loop's store), for checking requests
        self._types: list[dict[str, Any]] = []  # what GET /state says of them (examples.task_types)
        self._trace: IO[str] | None = None  # trace.jsonl, written as the session goes
        self._trace_error: str | None = None  # why writing it as the session went failed, if it did

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
        """Run the session until it is stopped; the run folder and ``session.toml`` are in ``out``.

        Raises :class:`RunAborted` (its ``result`` what ran, when there is one) when something of
        the session could not be written or the drive failed: its reason says what, and what was kept."""
        live = dataclasses.replace(self.scenario, horizon=LIVE_HORIZON)
        try:
            self.result = run_scenario(live, out=self.out, task_paths=self.task_paths, pictures=self.pictures,
                                       live=self._drive)
        except RunAborted as exc:  # the drive failed: run_scenario wrote the trace, run.json and metrics.json
            self.result = exc.result if isinstance(exc.result, RunResult) else None
            self.problems.append(f"the session failed: {exc.reason}")
        except Exception as exc:  # writing the run folder failed (the disk, the report): the trace is kept below
            self.problems.append(f"the run folder was not all written: {type(exc).__name__}: {exc}")
        finally:
            self._close_trace()
            self._keep_trace()
            self.stopped.set()
            self._refuse_waiting("the session has stopped")
        if self.problems:
            raise RunAborted(f"{'; '.join(self.problems)}; kept in {self.out}/: {', '.join(self.kept())}",
                             self.result)
        assert self.result is not None
        return self.result

    def kept(self) -> list[str]:
        """The session's files in its folder, the trace with its count of events."""
        names = ("trace.jsonl", "session.toml", "run.json", "metrics.json", "trajectory.jsonl", "report.html")
        return [f"trace.jsonl ({len(self.lines)} events)" if n == "trace.jsonl" else n
                for n in names if (self.out / n).is_file()] or ["nothing"]

    def _drive(self, loop: SimulationLoop, sim: SimulatedWorld, actions: Actions) -> RobotScenario:
        d = self._start(loop, sim, actions)
        horizon = min(self.scenario.horizon, LONGEST_S)
        while True:
            if self._take_all(d):
                break
            target = min(horizon, (self.clock() - d.wall0) * self.speed)
            until = min(max(target, d.latest), loop.now + CHUNK_S)
            if until > loop.now:
                loop.run(until=until)
            self._publish_and_answer(d, target)
            if loop.now >= horizon:
                self.stop_reason = (f"the scenario's horizon ({horizon:g} s)" if horizon < LONGEST_S else
                                    f"the longest session a scenario holds ({LONGEST_S:g} simulated s)")
                break
            if loop.now >= target:
                self._wake.wait(WAIT_S)
        return self._finish(d)

    def _start(self, loop: SimulationLoop, sim: SimulatedWorld, actions: Actions) -> _Drive:
        """The record of the served scenario's own actions, the live trace opened, the loop at 0."""
        record = Record(self.scenario, self.task_paths)
        count = 0
        for a in sorted(self.scenario.actions, key=lambda a: a.t):  # as build_robot_actions numbered them
            count += a.kind == "request"
            record.add(a, f"d{count}" if a.kind == "request" else None)
        self._open_trace()
        for r in loop.trace.events:  # anything traced while it was built
            self._line(encode(r))
        loop.trace.subscribe(lambda e: self._on_event(loop, e))
        self._tasks = [loop.store.get(n) for n in loop.store.names()]
        self._types = task_types(self.scenario, self._tasks, sim.spec)
        loop.run(until=0.0)
        return _Drive(loop, sim, actions, record, self.clock())

    def _take_all(self, d: _Drive) -> bool:
        """Take every queued ask; whether one of them asked to stop (those after it are refused)."""
        self._wake.clear()
        while not self._inbox.empty():
            ask = self._inbox.get()
            if ask.kind == "stop":
                self.stop_reason = self.stop_reason or ask.reason
                ask.reply.set_result({"t": d.loop.now})
                return True
            d.latest = max(d.latest, self._take(ask, d))
        return False

    def _publish_and_answer(self, d: _Drive, target: float) -> None:
        made = self._made(d)
        now = self.clock()
        if made or now - d.published >= PUBLISH_S:  # a requester sees its task in the state it is answered by
            self._publish(d.loop, d.sim, "running", lag=max(0.0, target - d.loop.now))
            d.published = now
        self._answer(made)

    def _finish(self, d: _Drive) -> RobotScenario:
        """The stop mark at the next free tick, the loop ended there, the session saved."""
        self._stopping.set()
        self._refuse_waiting("the session is stopping")
        loop = d.loop
        t_stop = self.t_stop = loop.next_free(loop.now)
        mark = TimedAction(t_stop, "mode", {"mode": loop.harmoniser.mode.value})
        d.record.add(mark, d.actions.schedule(mark))
        loop.run(until=t_stop)
        made = self._made(d)
        loop.horizon = t_stop
        loop.run()
        self._publish(loop, d.sim, "stopped", lag=0.0)
        self._answer(made)
        self._close_trace()
        header = (f"A tasker serve session of {self.served}, saved when it stopped ({self.stop_reason or 'stopped'}).\n"
                  f"'tasker run {self.out / 'session.toml'}' replays it: the same trace.jsonl, byte for byte."
                  f"{' (with the same --path folders)' if self.task_paths else ''}\n"
                  "Each action is at the simulated time it was injected, a tick at which nothing else was due.\n"
                  f"The last mode change (t = {t_stop!r}, to the mode the session had) marks where it stopped: it\n"
                  "keeps the replay running to that time, and the horizon ends it there.")
        try:
            return d.record.write(self.out / "session.toml", t_stop, header)
        except Exception as exc:  # the run folder (trace, run.json with every action) is still written
            self.problems.append(f"session.toml was not written ({type(exc).__name__}: {exc}); run.json holds "
                                 "the session's actions")
            return d.record.scenario(t_stop)

    def _take(self, ask: Ask, d: _Drive) -> float:
        """Read, check and schedule one action; its time (or the time now, if refused)."""
        loop = d.loop
        t = loop.next_free(loop.now)
        try:
            if ask.kind == "request":
                a, warnings = bodies.read_request(ask.body, t=t, scn=self.scenario, tasks=self._tasks)
                warnings += self._twins(loop, a)
            elif ask.kind == "world":
                a, warnings = bodies.read_world(ask.body, t=t, scn=self.scenario, tasks=self._tasks)
            else:
                a, warnings = self._about_agent(ask, t, d), []
        except Exception as exc:  # a Refused, or a bug in reading it: this ask fails, the session goes on
            ask.reply.set_exception(exc)
            return loop.now
        sid = d.actions.schedule(a)
        d.record.add(a, sid)
        if sid is not None:
            d.waiting.append(_Waiting(sid, ask, t, warnings))
        else:
            ask.reply.set_result({"id": ask.agent, "t": t, "warnings": warnings} if ask.agent else
                                 {"t": t, "warnings": warnings})
        return t

    def _twins(self, loop: SimulationLoop, a: TimedAction) -> list[str]:
        """A warning for each live agent that pursues the same request (task type and arguments)."""
        task = loop.store.get(a.fields["task"])
        args = task.validate_args(a.fields["args"])
        return [f"task: the same request as {g.id} ({g.ctx.task_type} {dict(g.ctx.args)}), which still runs "
                f"({g.state.value}): two agents would pursue one goal and preempt each other; terminate {g.id} "
                f"first (DELETE /requests/{g.id}) or drop this one"
                for g in loop.all_agents
                if not g.ended and g.ctx.task_type == task.name and dict(g.ctx.args) == args]

    def _about_agent(self, ask: Ask, t: float, d: _Drive) -> TimedAction:
        """A change or termination of the live agent ``ask.agent``, as the scenario's action on its request."""
        loop, record, actions = d.loop, d.record, d.actions
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
        given = bodies.read_change(ask.body, where=where, task=task, args=agent.ctx.args, world=d.sim.spec)
        return TimedAction(t, "change", {"agent": sid, "args": given})

    @staticmethod
    def _made(d: _Drive) -> list[tuple[Ask, dict[str, Any]]]:
        """The answers of the requests whose agent is made (those still waiting stay in ``d.waiting``)."""
        made, left = [], []
        for w in d.waiting:
            agents = d.actions.agents(w.sid)
            if agents:
                made.append((w.ask, {"id": agents[0], "t": w.t, "warnings": w.warnings}))
            else:
                left.append(w)
        d.waiting = left
        return made

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
        self._line(encode(loop.trace.events[-1]))
        if isinstance(e, ev.TaskEnded):
            self._ended[e.agent] = {"t": e.t, "cause": e.cause, "reason": e.reason}
        elif isinstance(e, ev.Decision):
            self._decision = {"t": e.t, **e.data}

    def _publish(self, loop: SimulationLoop, sim: SimulatedWorld, status: str, lag: float) -> None:
        state = snapshot(loop, sim, ended=self._ended, decision=self._decision, task_types=self._types)
        state.update(status=status, served=self.served, speed=self.speed, lag_s=lag, events=len(self.lines),
                     stop_reason=self.stop_reason)
        self._state = encode(state).encode()
        if self._trace is not None:
            try:
                self._trace.flush()
            except OSError as exc:
                self._trace_failed(exc)

    # -- the live trace.jsonl ----------------------------------------------------------------

    def _open_trace(self) -> None:
        try:
            self.out.mkdir(parents=True, exist_ok=True)
            self._trace = (self.out / "trace.jsonl").open("w", encoding="utf-8")
        except OSError as exc:
            self._trace_failed(exc)

    def _line(self, line: str) -> None:
        self.lines.append(line)
        if self._trace is not None:
            try:
                self._trace.write(line + "\n")
            except (OSError, UnicodeError) as exc:  # never the loop's failure: the lines are kept in memory
                self._trace_failed(exc)

    def _trace_failed(self, exc: BaseException) -> None:
        """Writing as it goes failed: the lines stay in memory, and :meth:`_keep_trace` tries again at the end."""
        self._trace_error = f"{type(exc).__name__}: {exc}"
        self._close_trace()

    def _close_trace(self) -> None:
        trace, self._trace = self._trace, None
        if trace is not None:
            try:
                trace.close()
            except OSError:
                pass

    def _keep_trace(self) -> None:
        """Make sure ``trace.jsonl`` holds every line of the session (the run folder's writer may
        have failed part-way, or never run): written again from memory when it does not."""
        path, text = self.out / "trace.jsonl", "".join(line + "\n" for line in self.lines)
        try:
            if path.is_file() and path.read_text(encoding="utf-8") == text:
                return
        except (OSError, UnicodeError):
            pass
        live = f" (nor as the session went: {self._trace_error})" if self._trace_error else ""
        try:
            path.write_text(text, encoding="utf-8")
        except (OSError, UnicodeError) as exc:
            self.problems.append(f"trace.jsonl could not be written ({type(exc).__name__}: {exc}){live}")
            return
        self.problems.append("trace.jsonl was not the session's whole trace: written again from its memory")


def _number(agent: str) -> tuple[int, str]:
    return (int(agent[1:]), agent) if agent[1:].isdigit() else (0, agent)
