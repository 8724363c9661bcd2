"""Fast Downward without the driver: the translator in-process, then the ``downward`` binary.

``OneshotPlanner(name="fast-downward-opt")`` costs about 150 ms a call, most of it
starting Python twice (FD's driver script, then the translator as a subprocess).  Here
the installed ``fast_downward.translate`` package runs in this process and only the
C++ search binary shipped with ``up_fast_downward`` is started, which brings a small
problem down to a few tens of milliseconds.

The translator keeps its options in a module global (``options.options``) and prints
to ``sys.stdout``, so every call holds :data:`TRANSLATE_LOCK` while it runs.

This module works on PDDL *text*: :func:`run_fast_downward` takes a domain and a
problem and returns an :class:`FDOutcome` with the plan as tuples of strings, exactly
as Fast Downward wrote it.  The unified-planning engine (:mod:`planners.engine`) and
the :class:`~planners.planner.Planner` facade are built on it.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import os
import subprocess
import tempfile
import threading
import time
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path


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

TRANSLATE_LOCK = threading.Lock()


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


def _translate(domain_file: str, problem_file: str, sas_file: str) -> tuple[int, str]:
    """Run FD's translator in this process; return ``(exit code, message)``."""
    from fast_downward.translate import main as translate_main
    from fast_downward.translate import options as translate_options

    out = io.StringIO()
    with TRANSLATE_LOCK, contextlib.redirect_stdout(out):
        translate_options.set_options([domain_file, problem_file, "--sas-file", sas_file])
        try:
            translate_main.main()
        except MemoryError:
            return 20, "translator ran out of memory"
        except SystemExit as exc:  # the translator reports input errors this way
            return 30, f"translator: {exc}"
        except Exception as exc:  # noqa: BLE001 - any translator failure is an input error for us
            return 30, f"translator: {type(exc).__name__}: {exc}"
    return 0, ""


def _search(sas: str, search: str, plan_file: str, timeout: float | None) -> subprocess.CompletedProcess[bytes] | None:
    """Run the ``downward`` binary on a SAS file; ``None`` if it ran out of time."""
    if timeout is not None and timeout <= 0:
        return None
    with open(sas, "rb") as sas_in:
        try:
            return subprocess.run(
                [str(DOWNWARD_BIN), "--search", search, "--internal-plan-file", plan_file],
                stdin=sas_in, capture_output=True, timeout=timeout, check=False,
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
    with tempfile.TemporaryDirectory(prefix="tasker-fd-") as tmp:
        dom, prob, sas, plan_file = (os.path.join(tmp, n) for n in ("domain.pddl", "problem.pddl", "out.sas", "plan"))
        Path(dom).write_text(domain)
        Path(prob).write_text(problem)
        code, message = _translate(dom, prob, sas)
        t_translate = time.perf_counter() - start
        if code != 0:
            return FDOutcome(FDExit.from_code(code), code, None, None, t_translate, 0.0, message)
        remaining = None if timeout is None else timeout - t_translate
        if remaining is not None and remaining <= 0:
            return FDOutcome(FDExit.TIMEOUT, 21, None, None, t_translate, 0.0, "time limit reached while translating")
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
