"""Every ``__post_init__`` check of the product's dataclasses fires on the value it refuses.

A check that never fires in a test may be dead, inverted or unreachable and nobody would know
(unified-planning's misspelt ``__post__init`` silently never ran).  :func:`_cases` builds one
bad value per ``raise`` of every ``__post_init__``; :func:`test_every_post_init_raise_has_a_case`
finds those ``raise`` statements in the source (``ast``) and requires a case that ends on each
one, so a new check without a test fails here.
"""

from __future__ import annotations

import ast
import math
import re
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("tasker", "domains", "planners", "robot", "experiments")


@dataclass(frozen=True)
class Case:
    """One refused value: ``build`` must raise ``error`` with a message matching ``match``."""

    id: str
    build: Callable[[], object]
    error: type[BaseException]
    match: str


def _cases() -> list[Case]:
    """The bad values, imported lazily (the robot and planner modules are not light)."""
    import numpy as np

    from experiments.analysis.family import Contrast, Outcome
    from experiments.inputs.actions import TimedAction
    from experiments.inputs.perturbation import Perturbation
    from experiments.inputs.scenario import InterruptionGrid
    from experiments.inputs.strategy import Strategy as SweepStrategy
    from experiments.metrics.exposure import Stretch
    from experiments.metrics.registry import Direction, Metric
    from experiments.metrics.store import RunRow, Status
    from experiments.paper.summary import Verdict
    from experiments.run.options import RunOptions
    from experiments.sweep.spec import MAX_JOBS, SweepSpec
    from planners.estimates import Estimate, Source
    from planners.fd import FDExit, FDOutcome, FoundPlan, SearchRun
    from planners.plan_files import FilesAnswer, Reader
    from planners.results import Attempt, Failure, PlanResult, PlanStatus
    from planners.temporal.engines import EngineSpec
    from planners.temporal.results import Attempt as EngineAttempt
    from planners.temporal.results import Outcome as EngineOutcome
    from planners.temporal.results import TemporalResult, TimedStep
    from planners.translate import Translation
    from planners.treecheck import BranchRun, HazardOn, Maker, Point, UnseenCondition
    from robot.drive import DriveLimits
    from robot.estimator import TravelMatrix
    from tasker.agent import Rates
    from tasker.conditions import Term
    from tasker.errors import ConfigError, FSMError
    from tasker.events import Decision, TraceError
    from tasker.fsm import FsmState, Transition
    from tasker.inputs import EstimateInputs
    from tasker.meaning import Binding, Hazard, Meaning, People
    from tasker.messages import Command, CostParams, Flag
    from tasker.oscillation import OscillationGuard
    from tasker.protocols import SkillState, SkillStatus
    from tasker.stage import Purpose, Stage, StagePlan
    from tasker.task import ArgSpec, Strategy
    from tasker.world import MotionEstimate

    hazard = Hazard("cooker_on", ("on", "?d"), 10.0)
    one = SweepStrategy("static", "static")
    z2 = np.zeros((2, 2))
    solved = PlanResult(PlanStatus.SOLVED, (("go", "a"),), 1.0, "fd", 0.0, search="lama-first")
    unsolvable = PlanResult(PlanStatus.UNSOLVABLE, None, None, "fd", 0.0)
    point = Point("planned", 0, "go(a)")
    f0, f1, f2 = Fraction(0), Fraction(1), Fraction(2)
    return [
        Case("Rates", lambda: Rates(rep_rate=0.0), ConfigError, r"Rates\.rep_rate must be a positive number"),
        Case("EstimateInputs.key", lambda: EstimateInputs(["a"]), TypeError, "key must be hashable"),
        Case("EstimateInputs.until", lambda: EstimateInputs("k", float("nan")), TypeError, "until must be a time"),
        Case("Term", lambda: Term("why", "bored"), FSMError, "ic_term cause must be one of"),
        Case("Decision.algorithm", lambda: Decision(0.0, {"switch": False}), TraceError, "'algorithm' must be"),
        Case("Decision.switch", lambda: Decision(0.0, {"algorithm": "x", "switch": 1}), TraceError,
             "'switch' must be true or false"),
        Case("Decision.key", lambda: Decision(0.0, {"algorithm": "x", "switch": True, "t": 1.0}), TraceError,
             "may not set 't'"),
        Case("Transition", lambda: Transition(FsmState.WAIT, "go", FsmState.END, guards=("ok", "")), FSMError,
             "guards must be a tuple of names"),
        Case("Hazard.name", lambda: Hazard("cooker on", ("on", "?d"), 1.0), ValueError, "must be an identifier"),
        Case("Hazard.fact", lambda: Hazard("h", ("not", "on", "?d"), 1.0), ValueError, "positive literal"),
        Case("Hazard.budget_s", lambda: Hazard("h", ("on", "?d"), math.inf), ValueError, "budget_s must be"),
        Case("Hazard.severity", lambda: Hazard("h", ("on", "?d"), 1.0, severity=-1.0), ValueError,
             "severity must be"),
        Case("People.roles", lambda: People("person", {"asleep": ()}), ValueError, r"unknown role\(s\) \['asleep'\]"),
        Case("People.safe", lambda: People("person", {"waiting": ()}, safe=("helped",)), ValueError,
             r"safe role\(s\) \['helped'\] are not declared"),
        Case("Binding.kind", lambda: Binding("lamp", ("on", "?d"), "?d"), ValueError, "Binding.kind must be one of"),
        Case("Binding.object", lambda: Binding("device", ("on", "?d"), "?x"), ValueError,
             "object '\\?x' is not one of its variables"),
        Case("Meaning", lambda: Meaning(hazards=(hazard, hazard)), ValueError, "duplicate hazard name"),
        Case("Command.flag", lambda: Command("start", 1), TypeError, "Command.flag must be a Flag"),  # type: ignore[arg-type]
        Case("Command.seq", lambda: Command(Flag.START, 0), ValueError, "Command.seq must be >= 1"),
        Case("CostParams.number", lambda: CostParams("t", cost=math.nan), ValueError,
             r"CostParams\.cost must be a number"),
        Case("CostParams.c_time", lambda: CostParams("t", c_time=-1), ValueError, "c_time must be >= 0"),
        Case("OscillationGuard.window_s", lambda: OscillationGuard(window_s=math.inf), ConfigError,
             "window_s must be a number"),
        Case("OscillationGuard.count", lambda: OscillationGuard(count=True), ConfigError,
             "count must be an integer >= 1"),
        Case("SkillStatus", lambda: SkillStatus(SkillState.FAILED), ValueError, "needs a reason"),
        Case("Stage.action", lambda: Stage(""), ValueError, "Stage.action must be a non-empty"),
        Case("StagePlan.goal", lambda: StagePlan((), Purpose.GEN_SUSP, goal=(("",),)), TypeError,
             "StagePlan.goal must be a tuple of literals"),
        Case("Stage.kind", lambda: Stage("go", kind="blocking"), TypeError,  # type: ignore[arg-type]
             "Stage.kind must be a StageKind"),
        Case("Stage.args", lambda: Stage("go", args=["a"]), TypeError, "Stage.args must be a tuple"),  # type: ignore[arg-type]
        Case("Stage.duration", lambda: Stage("go", duration=math.nan), ValueError, "Stage.duration must be"),
        Case("StagePlan.stages", lambda: StagePlan([Stage("go")], Purpose.UP_TSK), TypeError,  # type: ignore[arg-type]
             "StagePlan.stages must be a tuple"),
        Case("StagePlan.stage", lambda: StagePlan(("go",), Purpose.UP_TSK), TypeError,  # type: ignore[arg-type]
             "StagePlan.stages holds a str"),
        Case("StagePlan.purpose", lambda: StagePlan((), "upTsk"), TypeError,  # type: ignore[arg-type]
             "StagePlan.purpose must be a Purpose"),
        Case("StagePlan.sim_time", lambda: StagePlan((), Purpose.GEN_SUSP, sim_time=-0.5), ValueError,
             "sim_time must be >= 0"),
        Case("ArgSpec.name", lambda: ArgSpec("2nd"), ConfigError, "ArgSpec.name must be an identifier"),
        Case("ArgSpec.type", lambda: ArgSpec("n", type="list"), ConfigError, "type must be one of"),
        Case("Strategy.update", lambda: Strategy(update="derived"), ConfigError, "Strategy.update must be one of"),
        Case("Strategy.suspension", lambda: Strategy(suspension="never"), ConfigError,
             "Strategy.suspension must be one of"),
        Case("Strategy.policy", lambda: Strategy(policy="lax"), ConfigError, "Strategy.policy must be one of"),
        Case("Strategy.tree", lambda: Strategy(tree="cook:cooker"), ConfigError, "Strategy.tree must be a tree's name"),
        Case("MotionEstimate.unreachable", lambda: MotionEstimate(False, 3.0, 1.0, None), ValueError,
             "unreachable MotionEstimate must have time_s = inf"),
        Case("MotionEstimate.time_s", lambda: MotionEstimate(True, -1.0, 1.0, None), ValueError,
             "MotionEstimate.time_s must be >= 0"),
        Case("Estimate.source", lambda: Estimate(1.0, None, "plan"), TypeError,  # type: ignore[arg-type]
             "Estimate.source must be a Source"),
        Case("Estimate.c_time", lambda: Estimate(-1.0, None, Source.PLAN), ValueError, "c_time must be >= 0 or inf"),
        Case("Estimate.fit", lambda: Estimate(math.inf, None, Source.PLAN), ValueError,
             "does not fit source plan"),
        Case("FDOutcome.solved", lambda: FDOutcome(FDExit.SOLVED, 0, None, None, 0.0, 0.0), ValueError,
             "solved FDOutcome needs a plan"),
        Case("FDOutcome.unsolved", lambda: FDOutcome(FDExit.TIMEOUT, 23, (("a",),), None, 0.0, 0.0),
             ValueError, "exit timeout must not carry a plan"),
        Case("PlanResult.status", lambda: PlanResult("solved", (), 0.0, "fd", 0.0), TypeError,  # type: ignore[arg-type]
             "PlanResult.status must be a PlanStatus"),
        Case("PlanResult.plan", lambda: PlanResult(PlanStatus.SOLVED, None, 0.0, "fd", 0.0), ValueError,
             "solved PlanResult needs a plan"),
        Case("PlanResult.cost", lambda: PlanResult(PlanStatus.SOLVED, (), math.nan, "fd", 0.0), ValueError,
             "solved PlanResult needs a cost"),
        Case("PlanResult.unsolved", lambda: PlanResult(PlanStatus.UNSOLVABLE, (), None, "fd", 0.0), ValueError,
             "status unsolvable must not carry a plan"),
        Case("PlanResult.search", lambda: PlanResult(PlanStatus.SOLVED, (), 0.0, "fd", 0.0), ValueError,
             "solved PlanResult needs the search"),
        Case("PlanResult.optimal", lambda: PlanResult(PlanStatus.UNSOLVABLE, None, None, "fd", 0.0, optimal=True),
             ValueError, "status unsolvable cannot be optimal"),
        Case("PlanResult.failure", lambda: PlanResult(PlanStatus.ERROR, None, None, "fd", 0.0), ValueError,
             "carries a failure exactly when its status is error"),
        Case("PlanResult.steps", lambda: PlanResult(PlanStatus.SOLVED, ((),), 1.0, "fd", 0.0, search="x"), TypeError,
             "must hold non-empty tuples"),
        Case("PlanResult.wall_time_s", lambda: PlanResult(PlanStatus.ERROR, None, None, "fd", -0.1,
                                                          failure=Failure.ENGINE), ValueError,
             "wall_time_s must be >= 0"),
        Case("Attempt.search", lambda: Attempt("", FDExit.SOLVED, 1.0, 0.0, 0.0), ValueError,
             "needs the label of its search"),
        Case("Attempt.times", lambda: Attempt("lama-first", FDExit.SOLVED, 1.0, -1.0, 0.0), ValueError,
             "times must be >= 0"),
        Case("SearchRun.solved", lambda: SearchRun(FDExit.SOLVED, 0, (), None, 0.0), ValueError,
             "solved SearchRun needs a plan"),
        Case("SearchRun.over_budget", lambda: SearchRun(FDExit.OVER_BUDGET, 0, (FoundPlan((("a",),), 1.0, 0.0),),
                                                        None, 0.0), ValueError, "over its expansion budget"),
        Case("FilesAnswer.refused", lambda: FilesAnswer(solved, Reader.FAST_DOWNWARD), ValueError,
             "names unified-planning's refusal exactly when"),
        Case("FilesAnswer.validated_by_up", lambda: FilesAnswer(solved, Reader.FAST_DOWNWARD, "no", validated=True),
             ValueError, "cannot have validated a task UP's reader refused"),
        Case("FilesAnswer.no_plan", lambda: FilesAnswer(unsolvable, Reader.UNIFIED_PLANNING, validated=True),
             ValueError, "only a plan can be validated"),
        Case("FilesAnswer.rejected", lambda: FilesAnswer(solved, Reader.UNIFIED_PLANNING, validated=False),
             ValueError, "is an ERROR result"),
        Case("EngineSpec", lambda: EngineSpec("", "up-lpg", "up_lpg", "GPL", ""), ValueError,
             "needs a name and a factory name"),
        Case("TimedStep.start", lambda: TimedStep(-f1, "go", (), f0), ValueError, "start must be >= 0"),
        Case("TimedStep.duration", lambda: TimedStep(f0, "go", (), -f1), ValueError, "duration must be >= 0"),
        Case("EngineAttempt.outcome", lambda: EngineAttempt("lpg", "timeout"), TypeError,  # type: ignore[arg-type]
             "Attempt.outcome must be an Outcome"),
        Case("EngineAttempt.wall_time_s", lambda: EngineAttempt("lpg", EngineOutcome.TIMEOUT, wall_time_s=-1.0),
             ValueError, "Attempt.wall_time_s must be >= 0"),
        Case("TemporalResult.status", lambda: TemporalResult("solved", (), "lpg", (), 0.0),  # type: ignore[arg-type]
             TypeError, "TemporalResult.status must be a PlanStatus"),
        Case("TemporalResult.plan", lambda: TemporalResult(PlanStatus.SOLVED, None, "lpg", (), 0.0), ValueError,
             "status solved needs a plan"),
        Case("TemporalResult.order", lambda: TemporalResult(
            PlanStatus.SOLVED, (TimedStep(f2, "b", (), f0), TimedStep(f1, "a", (), f0)), "lpg", (), 0.0), ValueError,
             "must be in start-time order"),
        Case("TemporalResult.engine", lambda: TemporalResult(PlanStatus.SOLVED, (), "", (), 0.0), ValueError,
             "names the engine whose plan it is"),
        Case("TemporalResult.wall_time_s", lambda: TemporalResult(PlanStatus.UNSOLVABLE, None, "", (), -1.0),
             ValueError, "TemporalResult.wall_time_s must be >= 0"),
        Case("UnseenCondition.branch", lambda: UnseenCondition(-1, "x", ("clear", "?p"), Maker.NOTHING), ValueError,
             "index of"),
        Case("UnseenCondition.literal", lambda: UnseenCondition(0, "x", (), Maker.NOTHING), ValueError,
             "must be a literal"),
        Case("Point.exe", lambda: Point("dreamt", 0, "go(a)"), ValueError, "Point.exe must be one of"),
        Case("Point.after", lambda: Point("planned", -1, "go(a)"), ValueError, "counts the stages done"),
        Case("BranchRun.policy", lambda: BranchRun(point, 0, "x", "lenient"), ValueError,
             "BranchRun.policy must be one of"),
        Case("BranchRun.interruption_s", lambda: BranchRun(point, 0, "x", "conditional"), ValueError,
             "interruption_s is the interruption"),
        Case("BranchRun.tolerated", lambda: BranchRun(point, 0, "x", tolerated=(HazardOn("h", ("on", "d"), 1.0),)),
             ValueError, "only the conditional policy"),
        Case("Stretch.kind", lambda: Stretch(None, "cooker_on c", 0.0, 1.0, "ignored"), ValueError,
             "Stretch.kind: expected one of"),
        Case("Stretch.end", lambda: Stretch(None, "cooker_on c", 2.0, 1.0, "attended"), ValueError,
             "end 1.0 before start 2.0"),
        Case("Verdict.variants", lambda: Verdict("s", "ours", "1", "n", True, None, 3, None), ValueError,
             "held and variants go together"),
        Case("Verdict.held", lambda: Verdict("s", "ours", "1", "n", True, None, 4, 3), ValueError, "4 of 3 variants"),
        Case("TimedAction.kind", lambda: TimedAction(1.0, "explode", {}), ConfigError,
             r"TimedAction\.kind must be one of \['request', 'terminate', 'change', 'mode', 'world'\], got 'explode'"),
        Case("TimedAction.fields", lambda: TimedAction(1.0, "terminate", {"agent": "d1"}), ConfigError,
             r"TimedAction\('terminate'\)\.fields lacks 'reason' \(got \['agent'\]\)"),
        Case("RunOptions.level", lambda: RunOptions(suspension="never"), ValueError, "suspension: expected one of"),
        Case("RunOptions.seed", lambda: RunOptions(seed=-1), ValueError, "seed: expected an integer"),
        Case("RunOptions.tree", lambda: RunOptions(tree="cook:"), ValueError, "tree: expected NAME or TYPE:NAME"),
        Case("RunOptions.task_paths", lambda: RunOptions(task_paths="dir"), TypeError,  # type: ignore[arg-type]
             "task_paths: expected a sequence of folders"),
        Case("Translation", lambda: Translation(0), ValueError, "code 0 must carry SAS"),
        Case("DriveLimits", lambda: DriveLimits(accel=0.0), ValueError, r"DriveLimits\.accel must be > 0"),
        Case("TravelMatrix", lambda: TravelMatrix("w", 1, ("a", "b"), ((0.0, 0.0, 0.0),), z2, z2), ValueError,
             "2 labels need 2 poses"),
        Case("Outcome", lambda: Outcome("safe", "percent", "safe"), ValueError, "Outcome.kind: expected"),
        Case("Contrast", lambda: Contrast("weather", "a", "b"), ValueError, "Contrast.factor: expected one of"),
        Case("Perturbation.mode", lambda: Perturbation(mode="nearby"), ValueError, "mode: expected one of"),
        Case("Perturbation.during_s", lambda: Perturbation(during_s=0.0), ValueError,
             "during_s: expected a finite number > 0"),
        Case("Perturbation.rate", lambda: Perturbation(rate_per_min=-1.0), ValueError, "rate_per_min: expected"),
        Case("Perturbation.window", lambda: Perturbation(before_s=0.0, after_s=0.0), ValueError,
             "that make a window"),
        Case("Perturbation.kinds", lambda: Perturbation(kinds=("door", "door")), ValueError,
             "kinds: expected distinct kinds"),
        Case("Perturbation.stand_s", lambda: Perturbation(stand_s=(5.0, 1.0)), ValueError,
             r"stand_s: expected \[low, high\]"),
        Case("InterruptionGrid.interrupt", lambda: InterruptionGrid("requests[x]", 0.0, 10.0, 1.0), ValueError,
             "expected 'requests\\[N\\]'"),
        Case("InterruptionGrid.times", lambda: InterruptionGrid("requests[1]", 5.0, 5.0, 1.0), ValueError,
             "times: expected 0 <= start < stop"),
        Case("SweepStrategy.level", lambda: SweepStrategy(suspension="later"), ValueError,
             "suspension: expected one of"),
        Case("SweepStrategy.tree", lambda: SweepStrategy(tree="a:b:c"), ValueError, "tree: expected a tree's NAME"),
        Case("SweepStrategy.policy", lambda: SweepStrategy(policy="lax"), ValueError, "policy: expected one of"),
        Case("SweepStrategy.hazard_waiting", lambda: SweepStrategy(hazard_waiting="yes"), ValueError,  # type: ignore[arg-type]
             "hazard_waiting: expected true or false"),
        Case("SweepStrategy.scheduler", lambda: SweepStrategy(scheduler=""), ValueError,
             "scheduler: expected a scheduler name"),
        Case("Metric.name", lambda: Metric("a*b*", "s", Direction.LOWER, "m"), ValueError, "Metric: bad name"),
        Case("Metric.meaning", lambda: Metric("a.b", "s", Direction.LOWER, ""), ValueError,
             "a one-line meaning is required"),
        Case("RunRow.status", lambda: RunRow("a", 1, "s", "ok", {}, {}), ValueError,  # type: ignore[arg-type]
             "RunRow.status: expected a Status"),
        Case("RunRow.error", lambda: RunRow("a", 1, "s", Status.ERROR, {}, {}), ValueError,
             "status 'error' needs a message"),
        Case("SweepSpec.scenarios", lambda: SweepSpec((), (1,), (one,)), ValueError, "at least one scenario"),
        Case("SweepSpec.seeds", lambda: SweepSpec(("a",), (), (one,)), ValueError, "at least one seed"),
        Case("SweepSpec.strategies", lambda: SweepSpec(("a",), (1,), ()), ValueError, "at least one strategy"),
        Case("SweepSpec.variants", lambda: SweepSpec(("a",), (1,), (one,), variants={
            "b": InterruptionGrid("requests[1]", 0.0, 10.0, 1.0)}), ValueError, "'b' is not one of the scenarios"),
        Case("SweepSpec.duplicates", lambda: SweepSpec(("a",), (1, 1), (one,)), ValueError,
             r"seeds: duplicates in \[1, 1\]"),
        Case("SweepSpec.size", lambda: SweepSpec(("a",), tuple(range(MAX_JOBS + 1)), (one,)), ValueError,
             f"more than the {MAX_JOBS}"),
    ]


def _raised_at(build: Callable[[], object]) -> tuple[BaseException, tuple[str, int, str]]:
    """The exception ``build`` raises and where it was raised: (file relative to the root, line, function)."""
    try:
        build()
    except Exception as exc:  # every case must raise; the caller checks what
        frame = traceback.extract_tb(exc.__traceback__)[-1]
        return exc, (Path(frame.filename).resolve().relative_to(ROOT).as_posix(), frame.lineno or 0, frame.name)
    raise AssertionError("nothing was raised")


def test_each_check_fires_with_its_own_message() -> None:
    """One test over the table (built when it runs: collecting it imports nothing heavy)."""
    wrong = []
    for case in _cases():
        try:
            exc, (path, line, function) = _raised_at(case.build)
        except AssertionError:
            wrong.append(f"{case.id}: nothing was raised")
            continue
        if not isinstance(exc, case.error) or not re.search(case.match, str(exc)):
            wrong.append(f"{case.id}: {type(exc).__name__}: {exc} (expected {case.error.__name__} matching "
                         f"{case.match!r})")
        elif function != "__post_init__":
            wrong.append(f"{case.id}: raised in {function} ({path}:{line}), not by the dataclass's own check")
    assert not wrong, "\n".join(wrong)


def _post_init_raises() -> set[tuple[str, int]]:
    """(file, line) of every ``raise`` written in a ``__post_init__`` of the product's packages."""
    found = set()
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            for cls in ast.walk(tree):
                if not isinstance(cls, ast.ClassDef):
                    continue
                for fn in cls.body:
                    if isinstance(fn, ast.FunctionDef) and fn.name == "__post_init__":
                        rel = path.relative_to(ROOT).as_posix()
                        found |= {(rel, n.lineno) for n in ast.walk(fn) if isinstance(n, ast.Raise)}
    return found


def test_every_post_init_raise_has_a_case() -> None:
    written = _post_init_raises()
    assert len(written) > 60  # the scan itself works: there were 73 on 60ed0ea
    fired = {_raised_at(c.build)[1][:2] for c in _cases()}
    missing = sorted(written - fired)
    assert not missing, ("__post_init__ checks no case fires (add one to _cases in "
                         f"tests/test_post_init_checks.py): {missing}")
