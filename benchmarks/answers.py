"""Fingerprints of what scenarios answer, to show a speed-up changed no answer.

    python benchmarks/answers.py [SCENARIO ...] [--no-variants] > answers.txt    # default: paper household carry

Runs each scenario with ``tasker run --no-pictures`` twice — the check cache empty (a
first run: unified-planning checks every task folder) and as that run left it (checks
remembered) — and prints the SHA-256 of every file of the run's output except
``metrics.json`` and ``run.json`` (they hold wall-clock times and the host): the trace,
the trajectory, every PDDL problem and plan.  Run it on two commits and ``diff`` the
outputs; both cache states must also print the same lines.  Then, for every shipped
experiment (each sweep spec in ``experiments/sweep/specs/``), the trace digests of a few of its
randomised variants — per scenario, the first seed under one of the strategies in turn, with the
spec's ``[perturbation]`` if it has one (``--no-variants`` skips them).  Not a ``bench_*`` script:
``run_all.py`` does not run it.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SKIP = {"metrics.json", "run.json"}


def digests(scenario: str, out: Path, cache: Path) -> list[str]:
    env = {**os.environ, "TASKER_CACHE": str(cache), "PYTHONPATH": str(ROOT)}
    subprocess.run([sys.executable, "-m", "experiments.cli", "run", scenario, "--out", str(out), "--no-pictures", "-q"],
                   check=True, env=env, cwd=ROOT, stdout=subprocess.DEVNULL)
    return [f"{hashlib.sha256(p.read_bytes()).hexdigest()}  {scenario}/{p.relative_to(out)}"
            for p in sorted(out.rglob("*")) if p.is_file() and p.name not in SKIP]


def variants() -> list[str]:
    """``sha  spec:scenario:seed:strategy`` for a few randomised variants of every shipped sweep spec."""
    sys.path.insert(0, str(ROOT))
    from experiments.sweep import provenance
    from experiments.sweep.spec import load_spec

    out = []
    for path in sorted((ROOT / "experiments" / "sweep" / "specs").glob("*.toml")):
        spec = load_spec(path)
        first = spec.seeds[:1]
        jobs = [j for j in spec.jobs() if j.seed in first]
        for job in provenance.pick(jobs):
            out.append(f"{provenance.trace_digest(job)}  variant {path.name}:{Path(job.scenario).stem}:{job.seed}:"
                       f"{job.strategy.label}")
    return out


def main(argv: list[str]) -> int:
    with_variants = "--no-variants" not in argv
    argv = [a for a in argv if a != "--no-variants"]
    names = argv or ["paper", "household", "carry"]
    differ = False
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            cache = Path(tmp) / "cache"
            first = digests(name, Path(tmp) / f"{name}-first", cache)
            again = digests(name, Path(tmp) / f"{name}-again", cache)
            print("\n".join(first))
            if first != again:
                differ = True
                print(f"# {name}: the run with remembered checks answered differently", file=sys.stderr)
    if with_variants and not argv:
        print("\n".join(variants()))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
