"""TaBSA's baseline agents as its code defines them: ``tabsa-simple``, ``tabsa-simple2``, ``tabsa-distance``.

Read from RCPRG-ros-pkg/Smit-Sim, ``scripts/global_planner/my_agents.py`` (``SimpleAgent``,
``SimpleAgent2``, ``DistanceAgent``) and the simulator that feeds them (``my_system.py``,
``my_tasks.py``); re-written here, not copied.  Unlike our priority-first ``simple``,
``simple2`` and ``distance``, they ignore priority and deadlines.  Each decision:

1. a **non-preemptive** executing task is kept (``Task.preemptive``: in TaBSA only
   transport is preemptive; falls and pick-and-place run to the end once selected).
   Option ``non_preemptive``: the task types that behave so (default none);
2. ``tabsa-simple`` / ``tabsa-simple2`` only: with probability ``hesitance`` the executing
   task is kept.  The draw is a pure function of ``seed``, the time and the executing
   agent (never global random state), so the same day gives the same decisions, and a
   decision asked twice at one moment draws once, as TaBSA draws once a step;
3. otherwise every task (the executing one included) is scored and the best runs:
   the executing task wins ties, then the earliest request.  ``tabsa-simple`` scores the
   estimated duration, longest first; ``tabsa-simple2`` shortest first; ``tabsa-distance``
   **maximises** ``distance − ratio × estimated duration`` (metres − ratio × seconds).

**Estimates refresh at events, as TaBSA's simulator refreshes them** (``estimates =
"events"``): a task's estimated duration (its ``cTime``) and distance are re-read from
the reports when a request arrives or when the executing task changed since the last
decision, and are otherwise the values read then.  ``estimates = "reports"`` reads them
from every report instead (our variant, to see what the refresh rule does).

**Distance** (TaBSA: the path length from the robot to where the task begins): the
view carries neither the robot's pose nor a task's start, so the distance is measured
straight from the executing task's ``endPose`` (where the robot will be; the last one
seen when nothing executes) to the task's ``endPose``; 0 when either is unknown.  For a
fall the end is the start; for a transport or a pick-and-place it is not (an
approximation; ``docs/benchmark.md``).
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from typing import Any, ClassVar

from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView
from tasker.schedulers.checks import choice, integer, names, number

GRID = (0.0, 0.25, 0.5, 0.75, 1.0)
"""The values TaBSA sweeps hesitance and ratio over (Smit-Sim ``run_all_agents_100_days.sh``)."""
ESTIMATES = ("events", "reports")
_FIELD = {"duration": 0, "distance": 1}


def draw(seed: int, now: float, agent: str) -> float:
    """A uniform number in (0, 1], a pure function of its arguments (BLAKE2b of them)."""
    digest = hashlib.blake2b(f"{seed}|{now!r}|{agent}".encode(), digest_size=8).digest()
    return (int.from_bytes(digest, "big") + 1) / 2.0**64


class TabsaAgent(Scheduler):
    """What TaBSA's agents share: the executing task's protection, estimates refreshed at
    events, and the scan "keep the best so far unless another is strictly better"."""

    name = "tabsa-agent"
    preemptive = True
    reads_cost = False  # durations (cTime) and distances (endPose) only

    def __init__(self, *, non_preemptive: Sequence[str] = (), estimates: str = "events") -> None:
        self.non_preemptive = frozenset(names(self.name, "non_preemptive", non_preemptive))
        self.estimates = choice(self.name, "estimates", estimates, ESTIMATES)
        self._est: dict[str, tuple[float, float]] = {}  # agent -> (estimated duration s, distance m)
        self._last_exe: str | None = None
        self._here: tuple[float, ...] | None = None  # the robot's position as the view tells it
        self._seen: tuple[int, str | None, str, bool] | None = None  # (generation, exeDA, best, any): the last scan

    # -- what a subclass defines -------------------------------------------------------------------------
    def score(self, duration: float, distance: float) -> float:
        """Higher runs first."""
        raise NotImplementedError

    def hesitate(self, view: ScheduleView, exe: Candidate, record: dict[str, Any]) -> bool:
        """Keep the (preemptive) executing task without looking at the others?  TaBSA's
        ``DistanceAgent`` never does."""
        return False

    # -- the decision ------------------------------------------------------------------------------------
    def schedule(self, view: ScheduleView) -> Decision:
        exe = view.exe
        exe_id = exe.id if exe is not None else None
        seen, best = self._seen, None
        if seen is not None and view.generation is not None and seen[:2] == (view.generation, exe_id) \
                and self.estimates == "events" and exe_id == self._last_exe:
            # the same candidates and exeDA as at the last decision: nothing arrived, nothing to refresh
            if not seen[3]:
                return NO_CHANGE
            refreshed, best = False, seen[2]
            if exe is not None:
                self._here = self._exe_pose(exe)
        else:
            jobs = sorted([*view.candidates, *([exe] if exe is not None else [])], key=lambda c: c.order)
            if not view.candidates:
                self._seen = None if view.generation is None else (view.generation, exe_id, "", False)
                return NO_CHANGE
            refreshed = self.refresh(jobs, exe)
            best = exe_id if exe_id is not None else jobs[0].id
            best_score = self._score_of(best)
            for c in jobs:  # strictly better only: the executing task, then the earliest request, wins ties
                s = self._score_of(c.id)
                if s > best_score:
                    best, best_score = c.id, s
            self._seen = None if view.generation is None else (view.generation, exe_id, best, True)
        record: dict[str, Any] = {"algorithm": self.name, "exeDA": exe_id,
                                  "estimates": self.estimates, "refreshed": refreshed}
        if exe is not None and exe.task_type in self.non_preemptive:  # my_agents.py: not preemptive
            record.update(rule="non-preemptive", dac=None, switch=False)
            return Decision(None, record)
        if exe is not None and self.hesitate(view, exe, record):
            record.update(rule="hesitance", dac=None, switch=False)
            return Decision(None, record)
        switch = exe is None or best != exe_id
        record.update(rule=self.rule, dac=best, switch=switch)
        for role, who in (("dac", best), ("exeDA", exe_id)):
            if who is not None:
                record[f"score_{role}"] = self._score_of(who)
                for k in self.fields:
                    record[f"{k}_{role}"] = self._est[who][_FIELD[k]]
        return Decision(best if switch else None, record)

    rule: ClassVar[str] = ""
    fields: ClassVar[tuple[str, ...]] = ("duration",)
    """The estimates the score reads, recorded for the candidate and the executing task."""

    def _score(self, c: Candidate) -> float:
        return self._score_of(c.id)

    def _score_of(self, agent: str) -> float:
        duration, distance = self._est[agent]
        return self.score(duration, distance)

    def _exe_pose(self, exe: Candidate) -> tuple[float, ...] | None:
        pose = self.cost_params(exe, self.name).end_pose
        return tuple(pose) if pose is not None else self._here

    def refresh(self, jobs: Sequence[Candidate], exe: Candidate | None) -> bool:
        """TaBSA's ``System.update_jobs`` (my_system.py): every job's estimates are re-read when a
        job arrived or the executing one changed; True if they were."""
        exe_id = exe.id if exe is not None else None
        arrived = any(c.id not in self._est for c in jobs)
        changed = self._last_exe is not None and self._last_exe != exe_id
        self._last_exe = exe_id
        if exe is not None:
            self._here = self._exe_pose(exe)
        if self.estimates == "reports" or arrived or changed:
            here = self._here
            self._est = {c.id: (self.cost_params(c, self.name).c_time, self._distance(c, here)) for c in jobs}
            return True
        for gone in [a for a in self._est if a not in {c.id for c in jobs}]:
            del self._est[gone]
        return False

    def _distance(self, c: Candidate, here: tuple[float, ...] | None) -> float:
        pose = self.cost_params(c, self.name).end_pose
        if here is None or pose is None:
            return 0.0
        return math.hypot(pose[0] - here[0], pose[1] - here[1])


class TabsaSimple(TabsaAgent):
    """TaBSA's ``SimpleAgent``: the longest estimated duration runs; ``hesitance`` is the
    probability of keeping a preemptive executing task (my_agents.py ``SimpleAgent``)."""

    name = "tabsa-simple"
    rule = "longest"
    SWEEP = {"hesitance": GRID}

    def __init__(self, hesitance: float = 0.0, seed: int = 0, non_preemptive: Sequence[str] = (),
                 estimates: str = "events") -> None:
        super().__init__(non_preemptive=non_preemptive, estimates=estimates)
        self.hesitance = number(self.name, "hesitance", hesitance, low=0.0, high=1.0)  # a probability
        self.seed = integer(self.name, "seed", seed)

    def score(self, duration: float, distance: float) -> float:
        return duration

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (-self.cost_params(c, self.name).c_time, c.order)

    def hesitate(self, view: ScheduleView, exe: Candidate, record: dict[str, Any]) -> bool:
        """``random.random() <= hesitance`` in TaBSA; here a seeded draw in (0, 1], so that
        hesitance 0 never keeps and 1 always does."""
        u = draw(self.seed, view.now, exe.id)
        record.update(draw=u, hesitance=self.hesitance)
        return u <= self.hesitance


class TabsaSimple2(TabsaSimple):
    """TaBSA's ``SimpleAgent2``: the shortest estimated duration runs; hesitance as in ``tabsa-simple``."""

    name = "tabsa-simple2"
    rule = "shortest"

    def score(self, duration: float, distance: float) -> float:
        return -duration

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (self.cost_params(c, self.name).c_time, c.order)


class TabsaDistance(TabsaAgent):
    """TaBSA's ``DistanceAgent``: the highest ``distance − ratio × estimated duration`` runs
    (my_agents.py ``DistanceAgent``); no hesitance."""

    name = "tabsa-distance"
    rule = "distance - ratio * duration"
    fields = ("distance", "duration")
    SWEEP = {"ratio": GRID}

    def __init__(self, ratio: float = 0.0, non_preemptive: Sequence[str] = (), estimates: str = "events") -> None:
        super().__init__(non_preemptive=non_preemptive, estimates=estimates)
        self.ratio = number(self.name, "ratio", ratio, low=0.0, high=1.0)  # TaBSA's README: between 0 and 1

    def score(self, duration: float, distance: float) -> float:
        return distance - self.ratio * duration if self.ratio else distance
