"""Fast Downward without the driver: the translator in-process, then the ``downward`` binary.

``OneshotPlanner(name="fast-downward-opt")`` costs about 150 ms a call, most of it
starting Python twice (FD's driver script, then the translator as a subprocess).  Here
the installed ``fast_downward.translate`` package runs in this process and only the
C++ search binary shipped with ``up_fast_downward`` is started, which brings a small
problem down to a few tens of milliseconds.

The translation (:mod:`planners.translate`) reads each domain once per process and
writes the SAS task to memory; it goes to the search binary on its standard input.

This module works on PDDL *text*: :func:`run_fast_downward` takes a domain and a
problem and returns an :class:`FDOutcome` with the plan as tuples of strings, exactly
as Fast Downward wrote it.  The unified-planning engine (:mod:`planners.engine`) and
the :class:`~planners.planner.Planner` facade are built on it.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import tempfile
import time
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

from planners.translate import translate


def _downward_bin() -> Path:
    # Located, not imported: importing ``up_fast_downward`` pulls in UP's engine framework (about 1 s).
    spec = importlib.util.find_spec("up_fast_downward")
    if spec is None or not spec.submodule_search_locations:
        raise ImportError("up-fast-downward is not installed; it ships the Fast Downward search binary")
    return Path(next(iter(spec.submodule_search_locations))) / "downward" / "builds" / "release" / "bin" / "downward"


DOWNWARD_BIN = _downward_bin()
"""The search binary that ships inside the ``up-fast-downward`` wheel."""

OPTIMAL_SEARCH = "astar(lmcut())"
"""A* with LM-cut: optimal with respect to action costs (what ``fast-downward-opt`` runs)."""

AXIOM_SEARCH = "astar(blind())"
"""Optimal fallback when the translated task has axioms (ADL conditions), which LM-cut refuses."""

UNSUPPORTED_FEATURE = 34


class FDExit(StrEnum):
    """What a Fast Downward run ended with, from its documented exit codes."""

    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"
    TIMEOUT = "timeout"
    MEMOUT = "memout"
    ERROR = "error"

    @classmethod
    def from_code(cls, code: int) -> FDExit:
        """Map an exit code (fast-downward.org/ExitCodes) to an outcome."""
        if code in (0, 1, 2, 3):
            return cls.SOLVED
        if code in (10, 11, 12, 13):  # 10/11 proven unsolvable, 12/13 search space exhausted incompletely
            return cls.UNSOLVABLE
        if code in (21, 23):
            return cls.TIMEOUT
        if code in (20, 22, 24):
            return cls.MEMOUT
        return cls.ERROR


@dataclass(frozen=True, slots=True)
class FDOutcome:
    """One Fast Downward run: how it ended, the plan as FD wrote it, its cost and timings."""

    exit: FDExit
    code: int
    plan: tuple[tuple[str, ...], ...] | None
    cost: float | None
    translate_s: float
    search_s: float
    message: str = ""

    def __post_init__(self) -> None:
        if self.exit is FDExit.SOLVED and self.plan is None:
            raise ValueError("a solved FDOutcome needs a plan")
        if self.exit is not FDExit.SOLVED and self.plan is not None:
            raise ValueError(f"an FDOutcome with exit {self.exit.value} must not carry a plan")


def parse_plan_text(text: str) -> tuple[tuple[tuple[str, ...], ...], float | None]:
    """Read FD's ``sas_plan`` format: one ``(action arg ...)`` per line and ``; cost = N ...``.

    Only FD's own output format is read (it is line-based, never nested), which is why
    this is a few string splits rather than a PDDL parser.
    """
    steps: list[tuple[str, ...]] = []
    cost: float | None = None
    for raw in text.splitlines():
        line = raw.strip()
        if not line:
            continue
        if line.startswith(";"):
            if "cost =" in line:
                cost = float(line.split("cost =", 1)[1].split()[0])
            continue
        steps.append(tuple(line.strip("()").split()))
    return tuple(steps), cost


def _translate(domain: str, problem: str) -> tuple[int, str, bytes]:
    """Translate in this process (:func:`planners.translate.translate`): ``(exit code, message, SAS)``."""
    out = translate(domain, problem)
    return out.code, out.message, out.sas.encode()


def _search(sas: bytes, search: str, plan_file: str, timeout: float | None
            ) -> subprocess.CompletedProcess[bytes] | None:
    """Run the ``downward`` binary on a SAS task (its standard input); ``None`` if it ran out of time."""
    if timeout is not None and timeout <= 0:
        return None
    try:
        return subprocess.run(
            [str(DOWNWARD_BIN), "--search", search, "--internal-plan-file", plan_file],
            input=sas, capture_output=True, timeout=timeout, check=False,
        )
    except subprocess.TimeoutExpired:
        return None


def run_fast_downward(
    domain: str, problem: str, *, search: str = OPTIMAL_SEARCH, timeout: float | None = None
) -> FDOutcome:
    """Solve a PDDL domain/problem pair given as text.

    With the default optimal search, a task whose translation has axioms (which LM-cut
    does not support, exit code 34) is searched again with :data:`AXIOM_SEARCH`.

    ``timeout`` (seconds) bounds translation plus search; the translator cannot be
    interrupted, so an over-long translation is reported as a time-out after it ends.
    """
    start = time.perf_counter()
    code, message, sas = _translate(domain, problem)
    t_translate = time.perf_counter() - start
    if code != 0:
        return FDOutcome(FDExit.from_code(code), code, None, None, t_translate, 0.0, message)
    remaining = None if timeout is None else timeout - t_translate
    if remaining is not None and remaining <= 0:
        return FDOutcome(FDExit.TIMEOUT, 21, None, None, t_translate, 0.0, "time limit reached while translating")
    with tempfile.TemporaryDirectory(prefix="tasker-fd-") as tmp:
        plan_file = os.path.join(tmp, "plan")
        t0 = time.perf_counter()
        proc = _search(sas, search, plan_file, remaining)
        if proc is not None and proc.returncode == UNSUPPORTED_FEATURE and search == OPTIMAL_SEARCH:
            left = None if remaining is None else remaining - (time.perf_counter() - t0)
            proc = _search(sas, AXIOM_SEARCH, plan_file, left)
        if proc is None:
            t_search = time.perf_counter() - t0
            return FDOutcome(FDExit.TIMEOUT, 23, None, None, t_translate, t_search, "search time limit reached")
        t_search = time.perf_counter() - t0
        outcome = FDExit.from_code(proc.returncode)
        if outcome is not FDExit.SOLVED:
            tail = proc.stderr.decode(errors="replace").strip().splitlines()[-3:]
            msg = f"downward exited with code {proc.returncode}" + (f": {' '.join(tail)}" if tail else "")
            return FDOutcome(outcome, proc.returncode, None, None, t_translate, t_search, msg)
        if not os.path.exists(plan_file):
            return FDOutcome(FDExit.ERROR, proc.returncode, None, None, t_translate, t_search, "no plan file written")
        steps, cost = parse_plan_text(Path(plan_file).read_text())
    return FDOutcome(FDExit.SOLVED, proc.returncode, steps, cost, t_translate, t_search)
