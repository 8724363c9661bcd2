"""Benchmark: the temporal engines on the shipped temporal set, against the commit before them.

For each problem of ``benchmarks/data/temporal`` and each temporal engine tasker ships, in a
fresh process each (CPU seconds counted with the engine's own processes once they are reaped):

* **first plan** — the engine as tasker calls it (one-shot, its deterministic settings), the
  plan validated by UP's ``up_time_triggered_validator``: seconds and makespan;
* **best plan** — the engine's anytime mode within ``--budget`` seconds (Kairos, Aries;
  LPG-td stops at its first plan), every plan validated: seconds to the best, its makespan.

In the same run, ``tasker plan --json`` of the commit before temporal support (``--baseline``,
default 60ed0ea, checked out into a temporary git worktree) on the same problems, and of this
tree (all engines in turn).  Run: ``python benchmarks/bench_temporal.py [--budget S]``;
``bench_planner.py --temporal`` runs it too.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "benchmarks" / "data" / "temporal"
BASELINE = "60ed0ea"

_CHILD = r"""
import json, sys, time, resource, warnings
sys.path.insert(0, sys.argv[1])
from planners.temporal.reading import parse
from planners.temporal.portfolio import attempt_engine, validate, timed_steps
from planners.temporal import engines
d, p, name, budget = sys.argv[2], sys.argv[3], sys.argv[4], float(sys.argv[5])
problem = parse(open(d).read(), open(p).read(), d, p)
def cpu():
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime
out = {}
w0, c0 = time.perf_counter(), cpu()
attempt, plan = attempt_engine(name, problem, budget)
out["first"] = {"outcome": attempt.outcome.value, "s": time.perf_counter() - w0, "cpu_s": cpu() - c0,
                "makespan": float(max((x.end for x in plan), default=0)) if plan is not None else None}
if name in ("kairos", "aries") and sys.argv[6:] != ["first"]:
    from unified_planning.shortcuts import AnytimePlanner
    spec = engines.spec(name)
    params = {k: v for k, v in spec.params.items() if k != "anytime"}
    best, w0, c0 = None, time.perf_counter(), cpu()
    with warnings.catch_warnings(), engines.settings(name), \
            AnytimePlanner(name=engines.register(name), params=params) as planner:
        warnings.simplefilter("ignore")
        planner.skip_checks = True
        import tempfile
        log = tempfile.TemporaryFile("w+")  # Aries' server output: else it leaves /tmp/aries-PORT.* behind
        for res in planner.get_solutions(problem, timeout=budget, output_stream=log):
            if res.plan is not None and validate(problem, res.plan) is None:
                steps = timed_steps(res.plan)
                m = float(max((x.end for x in steps), default=0))
                if best is None or m < best["makespan"]:
                    best = {"s": time.perf_counter() - w0, "makespan": m}
    out["best"] = best
    out["best_cpu_s"] = cpu() - c0
print(json.dumps(out))
"""


_FIRSTS = r"""
import json, sys
sys.path.insert(0, sys.argv[1])
from planners.temporal.reading import parse
from planners.temporal.portfolio import attempt_engine
d, p, names, budget = sys.argv[2], sys.argv[3], sys.argv[4].split(","), float(sys.argv[5])
try:
    problem = parse(open(d).read(), open(p).read(), d, p)
except Exception:
    print(json.dumps({}))
    raise SystemExit(0)
print(json.dumps({n: attempt_engine(n, problem, budget)[0].outcome.value for n in names}))
"""
"""One process, one pair, each engine alone (its first plan): the outcome per engine ({} if unread)."""


def _run(argv: list[str], cwd: Path | None = None, timeout: float = 600) -> tuple[int, str, float]:
    """Exit status, standard output and CPU seconds (the process and what it reaped) of a command."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    env = {**os.environ, "PYTHONPATH": str(cwd or ROOT)}
    proc = subprocess.run(argv, cwd=cwd or ROOT, capture_output=True, text=True, timeout=timeout, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return proc.returncode, proc.stdout, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def _plan_json(root: Path, d: Path, p: Path) -> tuple[int, str, float]:
    argv = [sys.executable, "-m", "experiments.cli", "plan", str(d), str(p), "--json", "--timeout", "60"]
    code, out, cpu = _run(argv, cwd=root)
    try:
        status = json.loads(out)["status"] if out.strip() else "refused (exit 2)"
    except json.JSONDecodeError:
        status = "?"
    return code, status, cpu


DISTRIBUTIONS = {"lpg": ["up-lpg"], "aries": ["up-aries", "grpcio", "grpcio-tools"],
                 "kairos": ["up-kairos", "kairos-planner"], "tamer": ["up-tamer", "pytamer"]}
"""What each engine installs besides unified-planning (grpcio and grpcio-tools come with up-aries)."""


def sizes() -> None:
    """Each engine's licence and installed size: the files its distributions record (importlib.metadata)."""
    from importlib import metadata

    from planners.temporal import engines

    print(f"{'engine':7s} {'installed':>10s}  {'distributions':40s} licence")
    for name, dists in DISTRIBUTIONS.items():
        total, found = 0, []
        for dist in dists:
            try:
                files = metadata.distribution(dist).files or []
            except metadata.PackageNotFoundError:
                continue
            found.append(f"{dist} {metadata.version(dist)}")
            total += sum(f.size or 0 for f in files)
        shown = f"{total / 2**20:8.1f} MB" if found else "(not installed)"
        print(f"{name:7s} {shown:>10s}  {', '.join(found) or '-':40s} {engines.spec(name).licence}")


def main(argv: list[str] | None = None) -> int:
    from planners.temporal import engines

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=float, default=10.0, help="seconds per engine and problem (default 10)")
    ap.add_argument("--baseline", default=BASELINE, help=f"the commit before temporal support (default {BASELINE})")
    ap.add_argument("--sizes", action="store_true", help="only each engine's licence and installed size")
    ap.add_argument("--corpus", type=Path, default=None, metavar="DIR",
                    help="only: each engine alone (first plan) and tasker plan (the engines in turn, --timeout = 3 x "
                         "budget) on every DIR/*/{domain,problem}.pddl")
    args = ap.parse_args(argv)
    if args.sizes:
        sizes()
        return 0
    if args.corpus is not None:
        return corpus(args.corpus, args.budget)
    problems = sorted(p for p in SHIPPED.iterdir() if (p / "domain.pddl").is_file())
    names = [n for n in engines.DEFAULT_ORDER if engines.installed(n)]
    print(f"temporal engines on {len(problems)} shipped problems (budget {args.budget:g} s each; first = one-shot as "
          "tasker calls it, best = anytime; s wall, CPU s with the engine's reaped processes; makespan)")
    print(f"{'problem':20s} {'engine':7s} {'first':>8s} {'s':>6s} {'CPU s':>6s} {'makespan':>9s} "
          f"{'best s':>7s} {'makespan':>9s}")
    solved_by: dict[str, int] = {n: 0 for n in names}
    for folder in problems:
        d, p = folder / "domain.pddl", folder / "problem.pddl"
        for name in names:
            code, out, _ = _run([sys.executable, "-c", _CHILD, str(ROOT), str(d), str(p), name, str(args.budget)])
            r = json.loads(out) if code == 0 and out.strip() else {"first": {"outcome": f"crash {code}", "s": 0,
                                                                               "cpu_s": 0, "makespan": None}}
            f, best = r["first"], r.get("best")
            solved_by[name] += f["outcome"] == "valid"
            mk = f"{f['makespan']:9.3f}" if f["makespan"] is not None else f"{'-':>9s}"
            tail = (f"{best['s']:7.2f} {best['makespan']:9.3f}" if best else f"{'-':>7s} {'-':>9s}") \
                if "best" in r else f"{'(first)':>7s} {'':>9s}"
            print(f"{folder.name:20s} {name:7s} {f['outcome']:>8s} {f['s']:6.2f} {f['cpu_s']:6.2f} {mk} {tail}")
    print("valid first plans per engine: " + ", ".join(f"{n} {k}/{len(problems)}" for n, k in solved_by.items()))
    with tempfile.TemporaryDirectory(prefix="tasker-baseline-") as tmp:
        base = Path(tmp) / "tree"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(base), args.baseline],
                       check=True, capture_output=True)
        try:
            rows = []
            for folder in problems:
                d, p = folder / "domain.pddl", folder / "problem.pddl"
                rows.append((folder.name, _plan_json(base, d, p), _plan_json(ROOT, d, p)))
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base)], capture_output=True)
    print(f"\ntasker plan --json --timeout 60, same run: {args.baseline} (before) against this tree")
    for name, (bc, bs, bcpu), (nc, ns, ncpu) in rows:
        print(f"{name:20s} before: exit {bc} {bs:18s} CPU {bcpu:5.2f} s   now: exit {nc} {ns:10s} CPU {ncpu:5.2f} s")
    before = sum(1 for _, b, _ in rows if b[1] == "solved")
    now = sum(1 for _, _, n in rows if n[1] == "solved")
    print(f"solved: before {before}/{len(rows)}, now {now}/{len(rows)}")
    return 0 if now >= len(rows) - 1 else 1  # the concurrency problem is solved by tasker plan; a folder refuses it


def corpus(root: Path, budget: float) -> int:
    """Each engine alone and ``tasker plan`` on every pair under ``root``: valid plans counted."""
    from planners.temporal import engines

    names = [n for n in engines.DEFAULT_ORDER if engines.installed(n)]
    pairs = sorted(p for p in root.iterdir() if (p / "domain.pddl").is_file() and (p / "problem.pddl").is_file())
    valid = {n: 0 for n in [*names, "tasker"]}
    exit3 = 0
    print(f"{'pair':60s} " + " ".join(f"{n:>12s}" for n in names) + f" {'tasker plan':>22s}")
    for folder in pairs:
        d, p = folder / "domain.pddl", folder / "problem.pddl"
        code, out, _ = _run([sys.executable, "-c", _FIRSTS, str(ROOT), str(d), str(p), ",".join(names), str(budget)],
                            timeout=budget * len(names) + 120)
        firsts = json.loads(out) if code == 0 and out.strip() else {}
        cells = [firsts.get(name, "unread") for name in names]
        for name, outcome in zip(names, cells, strict=True):
            valid[name] += outcome == "valid"
        argv = [sys.executable, "-m", "experiments.cli", "plan", str(d), str(p), "--json", "--timeout",
                str(budget * 3)]
        code, out, _ = _run(argv, timeout=budget * 3 + 120)
        status = json.loads(out).get("status", "?") if code in (0, 1) and out.strip() else f"exit {code}"
        engine = json.loads(out).get("planner", "") if code == 0 and out.strip() else ""
        valid["tasker"] += code == 0 and status == "solved"
        exit3 += code == 3
        print(f"{folder.name[:60]:60s} " + " ".join(f"{c:>12s}" for c in cells) + f" {status + ' ' + engine:>22s}")
    print(f"valid plans of {len(pairs)}: " + ", ".join(f"{n} {k}" for n, k in valid.items()) + f"; exit 3: {exit3}")
    best = max(valid[n] for n in names)
    return 0 if valid["tasker"] >= best and exit3 == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
