"""Run every benchmark in this folder, one after the other, each in its own process.

    python benchmarks/run_all.py [NAME ...]   # e.g. core planner estimates robot paper sweep throughput

Each benchmark prints ratios against baselines it measures in the same run.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    names = argv or [p.stem.removeprefix("bench_") for p in sorted(HERE.glob("bench_*.py"))]
    failed = []
    for name in names:
        script = HERE / f"bench_{name}.py"
        if not script.is_file():
            print(f"no benchmark {name!r}; known: {[p.stem[6:] for p in sorted(HERE.glob('bench_*.py'))]}")
            return 2
        print(f"== {name}", flush=True)
        if subprocess.run([sys.executable, str(script)]).returncode != 0:
            failed.append(name)
    if failed:
        print(f"failed: {failed}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
