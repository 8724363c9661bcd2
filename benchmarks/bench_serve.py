"""Benchmark: ``tasker serve`` under a burst of requests.

    python benchmarks/bench_serve.py [--requests N] [--speed X] [--after S]   # or: python benchmarks/run_all.py serve

Starts ``tasker serve paper --speed 20 --port 0 --no-pictures`` (a subprocess, as a user runs
it), reads ``GET /events`` from the start in a thread, samples ``GET /state`` every 20 ms for
2 s before the burst (the baseline, in the same run), then posts ``--requests`` (100)
requests at once from 32 threads — seven in ten valid (``guide_human`` and ``human_fell`` of
the world's people), three in ten not (an unknown task type, a person who is not there, a
body that is not JSON) — while sampling ``GET /state`` until the last one is answered, and
``--after`` (10) seconds more, while the loop initialises and schedules the queued tasks.
Then ``POST /stop``, and ``tasker run session.toml`` replays the session.

Checks, exit 1 if one fails: every request is answered ``201`` with an id or refused ``4xx``
with a ``detail``; every id answered ``201`` is a ``request`` event of ``trace.jsonl``, and
nothing else is; the events streamed over ``GET /events`` are ``trace.jsonl``'s lines, all of
them, in order; the replay's ``trace.jsonl`` is the same bytes.  Target: the p95 of the
``GET /state`` latency during the burst, and after it, is below 100 ms (wall time: what a user waits; the
machine is shared, so the idle baseline is printed beside it).
"""

from __future__ import annotations

import argparse
import json
import os
import re
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
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
TARGET_P95_MS = 100.0
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
    with urllib.request.urlopen(url + "events?from=0", timeout=600) as r:
        event = ""
        for raw in r:
            line = raw.decode("utf-8").rstrip("\n")
            if line.startswith("event: "):
                event = line[7:]
            elif line.startswith("data: ") and event == "trace":
                lines.append(line[6:])
            elif line.startswith("data: ") and event == "end":
                return


def pct(xs: list[float], q: float) -> float:
    return statistics.quantiles(xs, n=100, method="inclusive")[q - 1] if len(xs) > 1 else (xs or [float("nan")])[0]


def commit() -> str:
    """The commit measured (``+`` when the worktree has uncommitted changes)."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True,
                           text=True).stdout
    return (head.strip() or "?") + ("+" if dirty.strip() else "")


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=100)
    ap.add_argument("--speed", type=float, default=20.0)
    ap.add_argument("--after", type=float, default=10.0, help="wall seconds sampled after the burst")
    args = ap.parse_args(argv)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1"}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "live"
        proc = subprocess.Popen([sys.executable, "-m", "experiments.cli", "serve", "paper", "--speed", str(args.speed),
                                 "--port", "0", "--out", str(out), "--no-pictures", "-q"], cwd=ROOT, env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            assert proc.stdout is not None
            found = re.search(r"on (http://127\.0\.0\.1:\d+/)", proc.stdout.readline())
            if not found:
                print("tasker serve did not start:", proc.stderr.read() if proc.stderr else "")
                return 1
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
                    answers = list(pool.map(lambda b: call(url + "requests", "POST", b[0], b[1]),
                                            bodies(args.requests)))
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
        reader.join(timeout=30)
        ok = [a for a in answers if a[0] == 201]
        refused = [a for a in answers if 400 <= a[0] < 500 and isinstance(a[1], dict) and a[1].get("detail")]
        trace = (out / "trace.jsonl").read_text(encoding="utf-8").splitlines()
        traced = sorted(json.loads(line)["agent"] for line in trace if json.loads(line)["event"] == "request")
        ids = sorted(a[1]["id"] for a in ok)
        cpu0 = os.times()
        replay = Path(tmp) / "replay"
        done = subprocess.run([sys.executable, "-m", "experiments.cli", "run", str(out / "session.toml"), "--out",
                               str(replay), "--no-pictures", "-q"], cwd=ROOT, env=env, capture_output=True, text=True)
        cpu1 = os.times()
        same = done.returncode == 0 and (replay / "trace.jsonl").read_bytes() == (out / "trace.jsonl").read_bytes()
        run = json.loads((out / "run.json").read_text(encoding="utf-8"))
    checks = {
        f"every request answered: {len(ok)} queued (201) + {len(refused)} refused with a reason (4xx) = "
        f"{len(answers)}": len(ok) + len(refused) == len(answers) == args.requests,
        f"every queued id is a request event of the trace, and nothing else is ({len(traced)})": ids == traced,
        f"GET /events streamed every trace line, in order ({len(streamed)} of {len(trace)})": streamed == trace,
        "tasker run session.toml gives the same trace.jsonl, byte for byte": same,
    }
    latency = [a[2] * 1000 for a in answers]
    print(f"commit {commit()}, {os.cpu_count()} cores")
    print(f"tasker serve paper --speed {args.speed:g}: {args.requests} requests posted at once from 32 threads, all "
          f"answered in {burst_s:.2f} s wall; the session stopped at t={run['scenario']['horizon']:g} s")
    print(f"{'GET /state latency [ms]':28s} {'n':>5s} {'p50':>7s} {'p95':>7s} {'max':>7s}")
    for name, xs in (("idle (baseline, same run)", idle), ("during the burst", busy),
                     (f"{args.after:g} s after it", after)):
        print(f"{name:28s} {len(xs):5d} {pct(xs, 50):7.1f} {pct(xs, 95):7.1f} {max(xs):7.1f}")
    print(f"{'POST /requests answered in':28s} {len(latency):5d} {pct(latency, 50):7.1f} {pct(latency, 95):7.1f} "
          f"{max(latency):7.1f}")
    print(f"when stopped: t={last['t']:g} s, {last['lag_s']:.1f} simulated s behind the clock, "
          f"{sum(not a['ended'] for a in last['agents'])} tasks not ended")
    print(f"replay: {cpu1.children_user + cpu1.children_system - cpu0.children_user - cpu0.children_system:.1f} CPU s")
    for text, good in checks.items():
        print(f"  {'ok  ' if good else 'FAIL'} {text}")
    p95 = max(pct(busy, 95), pct(after, 95))
    print(f"  {'ok  ' if p95 < TARGET_P95_MS else 'MISSED'} p95 of GET /state during the burst and after it, the "
          f"larger: {p95:.1f} ms (target < {TARGET_P95_MS:g} ms)")
    return 0 if all(checks.values()) and p95 < TARGET_P95_MS else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
