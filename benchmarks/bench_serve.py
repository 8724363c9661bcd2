"""Benchmark: ``tasker serve`` under a burst of requests, against a baseline commit in the same run.

    python benchmarks/bench_serve.py [--requests N] [--speed X] [--after S] [--baseline COMMIT | --no-baseline]
    python benchmarks/run_all.py serve

Starts ``tasker serve paper --speed 20 --port 0 --no-pictures`` (a subprocess, as a user runs
it), reads ``GET /events`` from the start in a thread, samples ``GET /state`` every 20 ms for
2 s before the burst (the baseline, in the same run), then posts ``--requests`` (100)
requests at once from 32 threads — seven in ten valid (``guide_human`` and ``human_fell`` of
the world's people), three in ten not (an unknown task type, a person who is not there, a
body that is not JSON) — while sampling ``GET /state`` until the last one is answered, and
``--after`` (10) seconds more, while the loop initialises and schedules the queued tasks.
Then ``POST /stop``, and ``tasker run session.toml`` replays the session.

The same run is made on this code and on ``--baseline`` (default ``60ed0ea``, before the
server was hardened: issue 37), checked out with ``git worktree add --detach`` into a temporary
folder, alternately, in subprocesses whose ``PYTHONPATH`` is that folder.  Besides the wall-clock
latencies, each run reports the CPU seconds of the ``tasker serve`` process (the whole session:
start, idle, burst, the queued tasks' planning, stop and the run folder; the machine is shared,
so CPU time is what compares) and of the replay.

Checks on each run, exit 1 if one fails on this code: every request is answered ``201`` with an
id or refused ``4xx`` with a ``detail``; every id answered ``201`` is a ``request`` event of
``trace.jsonl``, and nothing else is; the events streamed over ``GET /events`` are
``trace.jsonl``'s lines, all of them, in order; the replay's ``trace.jsonl`` is the same bytes.
Targets: the p95 of the ``GET /state`` latency during the burst, and after it, is below 100 ms
(wall time: what a user waits), and this code's ``tasker serve`` CPU seconds are at most
:data:`SLOWER` times the baseline's.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
BASELINE = "60ed0ea"
TARGET_P95_MS = 100.0
SLOWER = 1.15
"""This code may take at most this times the baseline's CPU seconds for the same session."""
PEOPLE = ("john", "alice", "peter", "sara")


def call(url: str, method: str = "GET", body: Any = None, raw: bytes | None = None) -> tuple[int, Any, float]:
    data = raw if raw is not None else (None if body is None else json.dumps(body).encode())
    req = urllib.request.Request(url, data=data, method=method, headers={"Content-Type": "application/json"})
    t = time.perf_counter()
    try:
        with urllib.request.urlopen(req, timeout=300) as r:
            status, payload = r.status, r.read()
    except urllib.error.HTTPError as e:
        status, payload = e.code, e.read()
    return status, json.loads(payload or b"null"), time.perf_counter() - t


def bodies(n: int) -> list[tuple[Any, bytes | None]]:
    out: list[tuple[Any, bytes | None]] = []
    for k in range(n):
        person = PEOPLE[k % len(PEOPLE)]
        if k % 10 == 3:
            out.append(({"task": "guide_humn", "args": {"person": person}}, None))
        elif k % 10 == 6:
            out.append(({"task": "human_fell", "args": {"person": "nobody"}}, None))
        elif k % 10 == 9:
            out.append((None, b'{"task": "human_fell", '))
        elif k % 2:
            out.append(({"task": "human_fell", "args": {"person": person}, "priority": k % 3}, None))
        else:
            out.append(({"task": "guide_human", "args": {"person": person, "destination": f"{person}_destination"
                                                          if person in ("john", "alice") else "kitchen"}}, None))
    return out


@contextmanager
def sampling(url: str, out: list[float]) -> Iterator[None]:
    """GET /state latencies into ``out`` from a thread of its own while the block runs."""
    stop = threading.Event()
    sampler = threading.Thread(target=sample, args=(url, stop, out))
    sampler.start()
    try:
        yield
    finally:
        stop.set()
        sampler.join()


def sample(url: str, until: threading.Event, out: list[float]) -> None:
    while not until.is_set():
        status, _, dt = call(url + "state")
        if status == 200:
            out.append(dt * 1000)
        time.sleep(0.02)


def stream(url: str, lines: list[str]) -> None:
    req = urllib.request.Request(url + "events?from=0", headers={"Accept": "text/event-stream"})
    with urllib.request.urlopen(req, timeout=600) as r:
        event = ""
        for raw in r:
            line = raw.decode("utf-8").rstrip("\n")
            if line.startswith("event: "):
                event = line[7:]
            elif line.startswith("data: ") and event == "trace":
                lines.append(line[6:])
            elif line.startswith("data: ") and event == "end":
                return


def pct(xs: list[float], q: int) -> float:
    return statistics.quantiles(xs, n=100, method="inclusive")[q - 1] if len(xs) > 1 else (xs or [float("nan")])[0]


def commit() -> str:
    """The commit measured (``+`` when the worktree has uncommitted changes)."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True,
                           text=True).stdout
    return (head.strip() or "?") + ("+" if dirty.strip() else "")


@dataclass(frozen=True)
class Run:
    """One measured session of one commit's code."""

    label: str
    idle: list[float]
    busy: list[float]
    after: list[float]
    posted: list[float]
    burst_s: float
    serve_cpu: float
    replay_cpu: float
    stopped_t: float
    last: dict[str, Any]
    checks: dict[str, bool]

    @property
    def p95(self) -> float:
        return max(pct(self.busy, 95), pct(self.after, 95))


def cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def measure(label: str, code: Path, tmp: Path, args: argparse.Namespace) -> Run:
    """One session of ``code`` (a checkout): the burst, the samples, the stop and the replay."""
    env = {**os.environ, "PYTHONPATH": str(code), "PYTHONUNBUFFERED": "1"}
    out = tmp / f"live-{label}"
    cpu0 = cpu_children()
    proc = subprocess.Popen([sys.executable, "-m", "experiments.cli", "serve", "paper", "--speed", str(args.speed),
                             "--port", "0", "--out", str(out), "--no-pictures", "-q"], cwd=code, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        found = re.search(r"on (http://127\.0\.0\.1:\d+/)", proc.stdout.readline())
        if not found:
            raise SystemExit(f"tasker serve ({label}) did not start: {proc.stderr.read() if proc.stderr else ''}")
        url = found.group(1)
        streamed: list[str] = []
        reader = threading.Thread(target=stream, args=(url, streamed), daemon=True)
        reader.start()
        while call(url + "state")[1].get("status") != "running":
            time.sleep(0.1)
        idle: list[float] = []
        with sampling(url, idle):
            time.sleep(2.0)
        busy: list[float] = []
        with sampling(url, busy):
            t0 = time.perf_counter()
            with ThreadPoolExecutor(max_workers=32) as pool:
                answers = list(pool.map(lambda b: call(url + "requests", "POST", b[0], b[1]), bodies(args.requests)))
            burst_s = time.perf_counter() - t0
        after: list[float] = []
        with sampling(url, after):
            time.sleep(args.after)
        last = call(url + "state")[1]
        call(url + "stop", "POST")
        proc.communicate(timeout=600)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    serve_cpu = cpu_children() - cpu0
    reader.join(timeout=30)
    ok = [a for a in answers if a[0] == 201]
    refused = [a for a in answers if 400 <= a[0] < 500 and isinstance(a[1], dict) and a[1].get("detail")]
    trace = (out / "trace.jsonl").read_text(encoding="utf-8").splitlines()
    traced = sorted(json.loads(line)["agent"] for line in trace if json.loads(line)["event"] == "request")
    ids = sorted(a[1]["id"] for a in ok)
    cpu1 = cpu_children()
    replay = tmp / f"replay-{label}"
    done = subprocess.run([sys.executable, "-m", "experiments.cli", "run", str(out / "session.toml"), "--out",
                           str(replay), "--no-pictures", "-q"], cwd=code, env=env, capture_output=True, text=True)
    replay_cpu = cpu_children() - cpu1
    same = done.returncode == 0 and (replay / "trace.jsonl").read_bytes() == (out / "trace.jsonl").read_bytes()
    run = json.loads((out / "run.json").read_text(encoding="utf-8"))
    checks = {
        f"every request answered: {len(ok)} queued (201) + {len(refused)} refused with a reason (4xx) = "
        f"{len(answers)}": len(ok) + len(refused) == len(answers) == args.requests,
        f"every queued id is a request event of the trace, and nothing else is ({len(traced)})": ids == traced,
        f"GET /events streamed every trace line, in order ({len(streamed)} of {len(trace)})": streamed == trace,
        "tasker run session.toml gives the same trace.jsonl, byte for byte": same,
    }
    return Run(label, idle, busy, after, [a[2] * 1000 for a in answers], burst_s, serve_cpu, replay_cpu,
               float(run["scenario"]["horizon"]), last, checks)


def report(r: Run, args: argparse.Namespace) -> None:
    print(f"-- {r.label}: {args.requests} requests posted at once from 32 threads, all answered in {r.burst_s:.2f} s "
          f"wall; the session stopped at t={r.stopped_t:g} s")
    print(f"{'GET /state latency [ms]':28s} {'n':>5s} {'p50':>7s} {'p95':>7s} {'max':>7s}")
    rows = (("idle (same run)", r.idle), ("during the burst", r.busy), (f"{args.after:g} s after it", r.after))
    for name, xs in rows:
        print(f"{name:28s} {len(xs):5d} {pct(xs, 50):7.1f} {pct(xs, 95):7.1f} {max(xs):7.1f}")
    print(f"{'POST /requests answered in':28s} {len(r.posted):5d} {pct(r.posted, 50):7.1f} {pct(r.posted, 95):7.1f} "
          f"{max(r.posted):7.1f}")
    print(f"when stopped: t={r.last['t']:g} s, {r.last['lag_s']:.1f} simulated s behind the clock, "
          f"{sum(not a['ended'] for a in r.last['agents'])} tasks not ended")
    print(f"CPU: tasker serve {r.serve_cpu:.1f} s, replay {r.replay_cpu:.1f} s")
    for text, good in r.checks.items():
        print(f"  {'ok  ' if good else 'FAIL'} {text}")


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=100)
    ap.add_argument("--speed", type=float, default=20.0)
    ap.add_argument("--after", type=float, default=10.0, help="wall seconds sampled after the burst")
    ap.add_argument("--baseline", default=BASELINE, help=f"commit to compare with (default {BASELINE})")
    ap.add_argument("--no-baseline", action="store_true", help="measure this code only")
    args = ap.parse_args(argv)
    runs: dict[str, Run] = {}
    with tempfile.TemporaryDirectory() as name:
        tmp = Path(name)
        base = tmp / "baseline"
        if not args.no_baseline:
            subprocess.run(["git", "worktree", "add", "--detach", "-q", str(base), args.baseline], cwd=ROOT, check=True)
        try:
            if not args.no_baseline:
                runs["baseline"] = measure("baseline", base, tmp, args)
            runs["this"] = measure("this", ROOT, tmp, args)
        finally:
            if not args.no_baseline:
                subprocess.run(["git", "worktree", "remove", "--force", str(base)], cwd=ROOT, check=False)
    against = "" if args.no_baseline else f", baseline {args.baseline}"
    print(f"commit {commit()}{against}, {os.cpu_count()} cores")
    for r in runs.values():
        report(r, args)
    this = runs["this"]
    good = all(this.checks.values())
    print(f"  {'ok  ' if this.p95 < TARGET_P95_MS else 'MISSED'} this code: p95 of GET /state during the burst and "
          f"after it, the larger: {this.p95:.1f} ms (target < {TARGET_P95_MS:g} ms)")
    if "baseline" in runs:
        ratio = this.serve_cpu / runs["baseline"].serve_cpu
        print(f"  {'ok  ' if ratio <= SLOWER else 'MISSED'} tasker serve CPU, this / baseline: {this.serve_cpu:.1f} / "
              f"{runs['baseline'].serve_cpu:.1f} s = {ratio:.2f} (target <= {SLOWER:g}); GET /state p95 "
              f"{this.p95:.1f} / {runs['baseline'].p95:.1f} ms")
        good = good and ratio <= SLOWER
    return 0 if good and this.p95 < TARGET_P95_MS else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
