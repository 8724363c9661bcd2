"""Fast Downward without the driver: the translator in-process, then the ``downward`` binary.

``OneshotPlanner(name="fast-downward-opt")`` costs about 150 ms a call, most of it
starting Python twice (FD's driver script, then the translator as a subprocess).  Here
the installed ``fast_downward.translate`` package runs in this process and only the
C++ search binary shipped with ``up_fast_downward`` is started, which brings a small
problem down to a few tens of milliseconds.

The translation (:mod:`planners.translate`) reads each domain once per process and
writes the SAS task to memory; :func:`search` runs one search configuration on it and
returns a :class:`SearchRun`: how it ended and every plan it wrote (an iterated search
writes one per improvement), read back as tuples of strings exactly as FD wrote them.
The search schedules (:mod:`planners.schedules`) chain such runs; :func:`run_fast_downward`
is the simplest chain, one optimal search.

**A budget of expansions, not of seconds.**  FD's searches take a time limit but no
limit on the states they expand.  :func:`search` reads the binary's progress lines as
they come (``f = 12, 340 evaluated, 120 expanded``) and its final count (``Expanded N
state(s).``): a run given ``expansions=N`` that expands more is stopped and reported
:attr:`FDExit.OVER_BUDGET`, and its plan is not used.  What a run answers under such a
budget is therefore a function of the task alone (FD's search is deterministic), never of
how busy the machine was: that is what keeps in-run planning reproducible.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import re
import resource
import selectors
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

LAMA_FIRST = ("let(hlm,eval_modify_costs(landmark_sum(lm_factory=lm_reasonable_orders_hps(lm_rhw()),pref=false),"
              "cost_type=one),let(hff,eval_modify_costs(ff(),cost_type=one),"
              "lazy_greedy([hff,hlm],preferred=[hff,hlm],cost_type=one,reopen_closed=false)))")
"""LAMA's first iteration, as FD's ``lama-first`` alias (``driver/aliases.py``): a plan at once,
action costs ignored."""

UNSUPPORTED_FEATURE = 34
"""The search's exit code when its heuristic cannot handle the task (LM-cut and axioms)."""

MEMORY_LIMIT_MB = 3072
"""Address space a search may take (``RLIMIT_AS``): a long blind search fills the shared machine's
memory otherwise.  Past it FD exits 22, reported as out of memory."""


def lama_iterated(bound: float | None) -> str:
    """LAMA's later iterations (costs counted): greedy, then weighted A* with w = 5, 3, 2, 1, the last
    repeated while it improves; each plan cheaper than the one before (and than ``bound``)."""
    h = ("let(hlm,eval_modify_costs(landmark_sum(lm_factory=lm_reasonable_orders_hps(lm_rhw()),pref=false),"
         "cost_type=plusone),let(hff,eval_modify_costs(ff(),cost_type=plusone),")
    phases = ["lazy_greedy([hff,hlm],preferred=[hff,hlm],reopen_closed=false)"]
    phases += [f"lazy_wastar([hff,hlm],preferred=[hff,hlm],w={w})" for w in (5, 3, 2, 1)]
    return h + f"iterated([{','.join(phases)}],repeat_last=true{_bound(bound)})))"


def optimal_below(heuristic: str, bound: float | None) -> str:
    """A* with an admissible ``heuristic``, pruning plans that cost ``bound`` or more: it finds the
    optimum when one is cheaper, and exhausts its space (exit 12) when ``bound`` is the optimum."""
    return f"astar({heuristic}(){_bound(bound)})"


def _bound(bound: float | None) -> str:
    return "" if bound is None else f",bound={int(bound)}"


class FDExit(StrEnum):
    """What a Fast Downward run ended with, from its documented exit codes (and tasker's budget)."""

    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"
    TIMEOUT = "timeout"
    MEMOUT = "memout"
    ERROR = "error"
    OVER_BUDGET = "over-budget"
    """Stopped by tasker: it expanded more states than its budget (never an FD exit code)."""

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
class FoundPlan:
    """A plan a search wrote: its steps as FD wrote them, its cost, and when (seconds after the search began)."""

    steps: tuple[tuple[str, ...], ...]
    cost: float
    at_s: float


@dataclass(frozen=True, slots=True)
class SearchRun:
    """One run of the search binary on a SAS task.

    ``plans`` are the complete plans it wrote, in the order found (each cheaper than the one
    before for an iterated search); a run stopped at its deadline keeps those it finished.
    ``expanded`` is the last count of expanded states it reported (``None`` if none).
    """

    exit: FDExit
    code: int
    plans: tuple[FoundPlan, ...]
    expanded: int | None
    seconds: float
    message: str = ""

    def __post_init__(self) -> None:
        if self.exit is FDExit.SOLVED and not self.plans:
            raise ValueError("a solved SearchRun needs a plan")
        if self.exit is FDExit.OVER_BUDGET and self.plans:
            raise ValueError("a SearchRun over its expansion budget must not carry a plan (it is not used)")

    @property
    def best(self) -> FoundPlan | None:
        return self.plans[-1] if self.plans else None


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


_PROGRESS = re.compile(rb"(\d+) expanded")
_FINAL = re.compile(rb"Expanded (\d+) state")


def search(sas: str, config: str, *, timeout: float | None = None, expansions: int | None = None,
           memory_mb: int | None = MEMORY_LIMIT_MB) -> SearchRun:
    """Run the ``downward`` binary with search ``config`` on a SAS task (text).

    ``timeout`` (seconds, wall clock) stops it and keeps the plans it finished; ``expansions``
    stops it once it reports more expanded states than that, and a run that ends having
    expanded more is :attr:`FDExit.OVER_BUDGET` even if it found a plan (module doc).
    """
    if timeout is not None and timeout <= 0:
        return SearchRun(FDExit.TIMEOUT, 23, (), None, 0.0, "no time left for this search")
    with tempfile.TemporaryDirectory(prefix="tasker-fd-") as tmp:
        sas_file, plan_file, err_file = (os.path.join(tmp, n) for n in ("output.sas", "plan", "stderr"))
        Path(sas_file).write_text(sas)
        started, t0 = time.time(), time.perf_counter()
        with open(sas_file, "rb") as stdin, open(err_file, "wb") as stderr:
            proc = subprocess.Popen([str(DOWNWARD_BIN), "--search", config, "--internal-plan-file", plan_file],
                                    stdin=stdin, stdout=subprocess.PIPE, stderr=stderr)
        _limit_memory(proc.pid, memory_mb)
        stopped, expanded = _follow(proc, None if timeout is None else t0 + timeout, expansions)
        seconds = time.perf_counter() - t0
        plans = _plans(Path(tmp), started)
        errors = Path(err_file).read_text(errors="replace").strip().splitlines()
    code = proc.returncode
    if stopped == "expansions" or (expansions is not None and expanded is not None and expanded > expansions):
        return SearchRun(FDExit.OVER_BUDGET, code, (), expanded, seconds,
                         f"expanded more than {expansions} states")
    if stopped == "deadline":
        return SearchRun(FDExit.TIMEOUT, 23, plans, expanded, seconds, "search time limit reached")
    outcome = FDExit.from_code(code)
    if outcome is FDExit.SOLVED and not plans:
        return SearchRun(FDExit.ERROR, code, (), expanded, seconds, "no plan file written")
    message = ""
    if outcome is not FDExit.SOLVED:
        last = errors[-3:]  # its standard error, as before: the standard output holds measured values
        message = f"downward exited with code {code}" + (f": {' '.join(last)}" if last else "")
    return SearchRun(outcome, code, plans, expanded, seconds, message)


def _limit_memory(pid: int, memory_mb: int | None) -> None:
    """Cap the child's address space (Linux ``prlimit``; nothing where it is missing)."""
    if memory_mb is None or not hasattr(resource, "prlimit"):
        return
    limit = memory_mb * 1024 * 1024
    with contextlib.suppress(OSError, ValueError):  # the child may have ended already
        resource.prlimit(pid, resource.RLIMIT_AS, (limit, limit))


def _follow(proc: subprocess.Popen[bytes], deadline: float | None, expansions: int | None
            ) -> tuple[str, int | None]:
    """Read the child's output until it ends; stop it at ``deadline`` or past ``expansions``.

    Returns why it was stopped (``"deadline"``, ``"expansions"`` or ``""``) and the last count of
    expanded states it printed."""
    assert proc.stdout is not None
    fd = proc.stdout.fileno()
    expanded: int | None = None
    pending = b""
    stopped = ""
    with selectors.DefaultSelector() as sel:
        sel.register(fd, selectors.EVENT_READ)
        while True:
            wait = None if deadline is None else deadline - time.perf_counter()
            if wait is not None and wait <= 0:
                stopped = "deadline"
                break
            if not sel.select(wait):
                continue
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                break
            *lines, pending = (pending + chunk).split(b"\n")
            for line in lines:
                m = _FINAL.search(line) or _PROGRESS.search(line)
                if m:
                    expanded = int(m.group(1))
            if expansions is not None and expanded is not None and expanded > expansions:
                stopped = "expansions"
                break
    if stopped:
        proc.kill()
    proc.wait()
    proc.stdout.close()
    return stopped, expanded


def _plans(folder: Path, started: float) -> tuple[FoundPlan, ...]:
    """The complete plans a run wrote: ``plan``, or ``plan.1``, ``plan.2``, ... for an iterated
    search.  FD writes the ``; cost`` line last, so a plan cut off by a kill has none and is skipped."""
    files = [folder / "plan"] if (folder / "plan").is_file() else sorted(
        folder.glob("plan.*"), key=lambda p: int(p.suffix[1:]) if p.suffix[1:].isdigit() else -1)
    out: list[FoundPlan] = []
    for f in files:
        steps, cost = parse_plan_text(f.read_text(errors="replace"))
        if cost is not None:
            out.append(FoundPlan(steps, cost, max(0.0, f.stat().st_mtime - started)))
    return tuple(out)


def run_fast_downward(
    domain: str, problem: str, *, search: str = OPTIMAL_SEARCH, timeout: float | None = None
) -> FDOutcome:
    """Solve a PDDL domain/problem pair given as text with one search configuration.

    With the default optimal search, a task whose translation has axioms (which LM-cut
    does not support, exit code 34) is searched again with :data:`AXIOM_SEARCH`.

    ``timeout`` (seconds) bounds translation plus search; the translator cannot be
    interrupted, so an over-long translation is reported as a time-out after it ends.
    """
    start = time.perf_counter()
    out = translate(domain, problem)
    t_translate = time.perf_counter() - start
    if out.code != 0:
        return FDOutcome(FDExit.from_code(out.code), out.code, None, None, t_translate, 0.0, out.message)
    remaining = None if timeout is None else timeout - t_translate
    if remaining is not None and remaining <= 0:
        return FDOutcome(FDExit.TIMEOUT, 21, None, None, t_translate, 0.0, "time limit reached while translating")
    run = _search(out.sas, search, timeout=remaining)
    if run.code == UNSUPPORTED_FEATURE and run.exit is FDExit.ERROR and search == OPTIMAL_SEARCH:
        left = None if remaining is None else remaining - run.seconds
        run = _search(out.sas, AXIOM_SEARCH, timeout=left)
    t_search = time.perf_counter() - start - t_translate
    if run.exit is FDExit.SOLVED:
        best = run.best
        assert best is not None
        return FDOutcome(FDExit.SOLVED, run.code, best.steps, best.cost, t_translate, t_search)
    return FDOutcome(run.exit, run.code, None, None, t_translate, t_search, run.message)


_search = search  # ``run_fast_downward``'s parameter of the same name hides the function
