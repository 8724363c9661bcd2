"""Fingerprints of what scenarios answer, to show a speed-up changed no answer.

    python benchmarks/answers.py [SCENARIO ...] > answers.txt    # default: paper household carry

Runs each scenario with ``tasker run --no-pictures`` twice — the check cache empty (a
first run: unified-planning checks every task folder) and as that run left it (checks
remembered) — and prints the SHA-256 of every file of the run's output except
``metrics.json`` and ``run.json`` (they hold wall-clock times and the host): the trace,
the trajectory, every PDDL problem and plan.  Run it on two commits and ``diff`` the
outputs; both cache states must also print the same lines.  Not a ``bench_*`` script:
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


def main(argv: list[str]) -> int:
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
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
