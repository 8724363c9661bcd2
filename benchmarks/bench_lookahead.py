"""Benchmark of the look-ahead scheduler: decision time against queue length, and its anytime quality.

    python benchmarks/bench_lookahead.py

1. One ``pf_schedule`` decision of ``lookahead`` (default node budget) with an executing
   task and 1, 2, 4, 8, 12, 16, 32 and 64 waiting candidates, against Alg. 2's decision
   on the same view, measured in the same run: the ratio is lookahead / alg2.  The view's
   ``reqSP`` answers from straight-line travel at 0.5 m/s, like a synthetic day task.
2. Anytime quality: on queues of 6 to 9, the objective the default budget reaches over
   the optimum (the same search with an unlimited budget).  1.000 means optimal.
3. Long queues (12, 16 and 24 jobs, 5 queues each), where neither search can prove its
   order optimal: the objective of ``lookahead`` at its default node budget and of
   ``lookahead-cpsat`` (:mod:`planners.cpsat`, OR-Tools CP-SAT) at its default time
   limit, over the best order known (the better of CP-SAT with 10x its limit and the
   branch and bound with 100x its budget), and the wall time of one search of each.
4. The other schedulers' decision on the views of part 1, against Alg. 2's, measured in the
   same run (ratio = scheduler / alg2): ``edf``, ``wspt``, ``atc`` and TaBSA's agents (every
   scheduler of the day tables besides the look-ahead and Alg. 2).  TaBSA's
   agents keep state (estimates read at events, the request table), so each timed
   decision is a fresh scheduler's first: every estimate read and, for
   ``tabsa-scheduler``, the table of slots built — their dearest decision.
"""

from __future__ import annotations

import math
import random
import statistics
import time

from planners.cpsat import LookAheadCpSat, solve_cpsat
from tasker import schedulers
from tasker.messages import CompletionCost, CostParams, SPRequest
from tasker.schedulers.base import Candidate, Scheduler, ScheduleView
from tasker.schedulers.lookahead import LookAhead, solve

SPEED = 0.5
SIZES = (1, 2, 4, 8, 12, 16, 32, 64)
OTHERS = ("edf", "wspt", "atc", "tabsa-simple", "tabsa-simple2", "tabsa-distance", "tabsa-scheduler")


def make_view(n: int, seed: int = 0) -> ScheduleView:
    """An executing task and ``n`` candidates of three types at random sites of a 10 x 8 m flat."""
    rng = random.Random(seed)
    kinds = (("transport", 1.0, 1), ("pick_place", 2.0, 2), ("fall", 10.0, 3))

    def one(k: int) -> Candidate:
        kind, w, prio = kinds[rng.randrange(3)]
        work = rng.uniform(30, 300)
        site = (rng.uniform(0, 10), rng.uniform(0, 8))
        return Candidate(f"d{k}", kind, CostParams(kind, cost=w * work, cps=w, c_time=work, end_pose=site,
                                                   deadline=rng.uniform(100, 3600), priority=prio), float(k), k)

    jobs = [one(k) for k in range(1, n + 2)]
    by = {c.id: c for c in jobs}

    def req_sp(agent: str, req: SPRequest) -> CompletionCost:
        p = by[agent].params
        assert isinstance(p, CostParams) and p.end_pose is not None
        x, y = req.args["pose"]
        travel = math.hypot(x - p.end_pose[0], y - p.end_pose[1]) / SPEED
        return CompletionCost(p.cost + p.cps * travel, p.cps)

    return ScheduleView(1000.0, jobs[0], jobs[1:], req_sp)


def decision_time(s: Scheduler, view: ScheduleView, repeats: int) -> float:
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        s.schedule(view)
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


def first_decision_time(name: str, view: ScheduleView, repeats: int) -> float:
    """Median seconds of a fresh scheduler's first decision (made outside the timing)."""
    samples = []
    for _ in range(repeats):
        s = schedulers.create(name)
        t0 = time.perf_counter()
        s.schedule(view)
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


def others() -> None:
    alg2 = schedulers.create("alg2")
    print("4. other schedulers: decision time (median ms) and ratio to alg2 on the same view")
    print(f"{'queue':>6} {'alg2 ms':>9} " + " ".join(f"{n:>22}" for n in OTHERS))
    for n in SIZES:
        view = make_view(n)
        repeats = 200 if n <= 16 else 50
        t_alg2 = decision_time(alg2, view, repeats)
        cells = []
        for name in OTHERS:
            t = first_decision_time(name, view, repeats)
            cells.append(f"{t * 1e3:>12.3f} ({t / t_alg2:>6.1f})")
        print(f"{n:>6} {t_alg2 * 1e3:>9.3f} " + " ".join(f"{c:>22}" for c in cells))


def main() -> None:
    look, alg2 = schedulers.create("lookahead"), schedulers.create("alg2")
    assert isinstance(look, LookAhead)
    print(f"1. decision time (median), node budget {look.node_budget}")
    print(f"{'queue':>6} {'alg2 ms':>9} {'lookahead ms':>13} {'ratio':>8} {'nodes':>6}  rule")
    for n in SIZES:
        view = make_view(n)
        repeats = 200 if n <= 16 else 20
        t_alg2 = decision_time(alg2, view, repeats)
        t_look = decision_time(look, view, repeats)
        rec = look.schedule(view).record or {}
        print(f"{n:>6} {t_alg2 * 1e3:>9.3f} {t_look * 1e3:>13.3f} {t_look / t_alg2:>8.0f} {rec.get('nodes'):>6}  "
              f"{rec.get('rule')}")
    print("2. anytime quality: objective at the default budget / optimum (mean over 10 queues each)")
    for n in (6, 7, 8, 9):
        gaps, exact_share = [], 0
        for seed in range(10):
            prob, _ = look.problem(make_view(n - 1, seed))
            _, opt, _, _ = solve(prob, node_budget=10**8)
            _, got, _, exact = solve(prob, node_budget=look.node_budget)
            gaps.append(got / opt if opt > 0 else 1.0)
            exact_share += exact
        print(f"{n:>6} jobs: {statistics.mean(gaps):.4f} (worst {max(gaps):.4f}); "
              f"search complete within budget in {exact_share}/10")
    cpsat = LookAheadCpSat()
    print(f"3. long queues: objective / best order known (mean, worst of 5 queues), median ms per search; "
          f"lookahead node budget {look.node_budget}, lookahead-cpsat time limit {cpsat.time_limit}")
    print(f"{'jobs':>6} {'lookahead':>18} {'ms':>7} {'lookahead-cpsat':>18} {'ms':>7}")
    for n in (12, 16, 24):
        bb, cp, t_bb, t_cp = [], [], [], []
        for seed in range(5):
            prob, _ = look.problem(make_view(n - 1, seed))
            t0 = time.perf_counter()
            v_bb = solve(prob, node_budget=look.node_budget)[1]
            t1 = time.perf_counter()
            v_cp = solve_cpsat(prob, cpsat.time_limit)[1]
            t2 = time.perf_counter()
            best = min(v_bb, v_cp, solve_cpsat(prob, 10 * cpsat.time_limit)[1],
                       solve(prob, node_budget=100 * look.node_budget)[1])
            bb.append(v_bb / best)
            cp.append(v_cp / best)
            t_bb.append(t1 - t0)
            t_cp.append(t2 - t1)
        print(f"{n:>6} {statistics.mean(bb):>8.3f} ({max(bb):.3f}) {statistics.median(t_bb) * 1e3:>7.1f} "
              f"{statistics.mean(cp):>8.3f} ({max(cp):.3f}) {statistics.median(t_cp) * 1e3:>7.1f}")
    others()


if __name__ == "__main__":
    main()
