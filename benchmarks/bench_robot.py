"""Benchmark of the robot layer: cost queries against a fresh OMPL query, and MuJoCo speed.

Run ``python benchmarks/bench_robot.py``.  In one run it measures, in the paper's
apartment, over random reachable pose pairs:

* our :class:`robot.motion.MotionEstimator` (roadmap grown once, result cache off so
  every query is really planned) against a fresh OMPL ``RRTConnect`` + ``simplify``
  query on the same 2-D checker, printing the speed and path-length ratios;
* the real-time factor of a navigation in MuJoCo (TIAGo, 50 Hz controller).

Targets: ours <= 2 ms median after warm-up, >= 3x faster, paths <= 5 % longer;
navigation >= 50x real time.
"""

from __future__ import annotations

import gc
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from robot.motion import BasePlanner, DriveLimits, MotionEstimator  # noqa: E402
from robot.roadmap import ompl_setup, path_length  # noqa: E402
from robot.scene import Scene  # noqa: E402
from robot.sim import Simulation  # noqa: E402
from robot.spec import load_world  # noqa: E402
from robot.tiago import robot_dimensions  # noqa: E402
from tasker.stage import Stage  # noqa: E402


class FreshRRTConnect:
    """The baseline: a new OMPL SimpleSetup + RRTConnect + simplifySolution per query."""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene

    def plan(self, a: tuple[float, float], b: tuple[float, float]) -> list[tuple[float, float]] | None:
        from ompl import geometric as og

        setup = ompl_setup(self.scene, 0.005)  # ~7 cm, as in the probes; the same checker as ours
        space = setup.getStateSpace()
        setup.setPlanner(og.RRTConnect(setup.getSpaceInformation()))
        s, g = space.allocState(), space.allocState()
        s[0], s[1], g[0], g[1] = a[0], a[1], b[0], b[1]
        setup.setStartAndGoalStates(s, g)
        if not setup.solve(1.0) or not setup.haveExactSolutionPath():
            return None
        setup.simplifySolution(0.0)
        path = og.PathGeometric(setup.getSolutionPath())
        return [(st[0], st[1]) for st in path.getStates()]


def pose_pairs(scene: Scene, planner: BasePlanner, n: int, seed: int = 0) -> list[tuple[tuple, tuple]]:
    rng = np.random.default_rng(seed)
    pairs: list[tuple[tuple, tuple]] = []
    while len(pairs) < n:
        a = (float(rng.uniform(scene.xmin, scene.xmax)), float(rng.uniform(scene.ymin, scene.ymax)),
             float(rng.uniform(-math.pi, math.pi)))
        b = (float(rng.uniform(scene.xmin, scene.xmax)), float(rng.uniform(scene.ymin, scene.ymax)),
             float(rng.uniform(-math.pi, math.pi)))
        if scene.static_free(a[0], a[1]) and scene.static_free(b[0], b[1]) and planner.plan(a[:2], b[:2]):
            pairs.append((a, b))
    return pairs


def bench_queries(n: int = 60) -> None:
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_WARN)
    spec = load_world("paper")
    scene = Scene(spec, robot_dimensions()[2])
    t = time.perf_counter()
    planner = BasePlanner(spec, scene, cache_size=0)
    build = time.perf_counter() - t
    ours = MotionEstimator(planner, DriveLimits.of(spec.robot))
    base = FreshRRTConnect(scene)
    pairs = pose_pairs(scene, planner, n)
    for a, b in pairs[:5]:  # warm-up
        ours.estimate(a, b)
        base.plan(a[:2], b[:2])
    t_ours, t_base, ratios = [], [], []
    for a, b in pairs:
        gc.collect()  # a collection triggered by one planner must not land in the other's timing
        gc.disable()
        t = time.perf_counter()
        est = ours.estimate(a, b)
        t_ours.append(time.perf_counter() - t)
        t = time.perf_counter()
        ref = base.plan(a[:2], b[:2])
        t_base.append(time.perf_counter() - t)
        gc.enable()
        if ref is not None and est.reachable:
            ratios.append(est.distance_m / max(path_length(ref), 1e-9))
    mo, mb = statistics.median(t_ours) * 1e3, statistics.median(t_base) * 1e3
    print(f"roadmap: {planner.roadmap.stats.nodes} nodes, {planner.roadmap.stats.edges} edges, "
          f"built once in {build:.2f} s")
    print(f"cost query, {len(pairs)} random pose pairs (paper apartment, people left out):")
    print(f"  ours (roadmap, cache off)      median {mo:6.2f} ms  p90 {np.percentile(t_ours, 90) * 1e3:6.2f} ms"
          f"   target <= 2 ms: {'OK' if mo <= 2 else 'MISS'}")
    print(f"  fresh RRTConnect + simplify    median {mb:6.2f} ms  p90 {np.percentile(t_base, 90) * 1e3:6.2f} ms")
    print(f"  speed-up (median ratio)        {mb / mo:6.1f}x   target >= 3x: {'OK' if mb / mo >= 3 else 'MISS'}")
    med, worst = statistics.median(ratios), max(ratios)
    print(f"  path length ours/RRTConnect    median {med:.3f}  mean {statistics.mean(ratios):.3f}  "
          f"max {worst:.3f}   target <= 1.05: {'OK' if med <= 1.05 else 'MISS'}")
    cached = MotionEstimator(BasePlanner(spec, scene), ours.limits)
    for a, b in pairs:
        cached.estimate(a, b)
    t = time.perf_counter()
    for a, b in pairs:
        cached.estimate(a, b)
    print(f"  ours, repeated query (cache hit) {(time.perf_counter() - t) / len(pairs) * 1e6:6.1f} us")
    del base


def bench_navigation() -> None:
    sim = Simulation("paper")
    total_sim = total_wall = 0.0
    now = 0.0
    for place in ("kitchen", "bedroom", "stove", "bathroom"):
        stage = Stage("navigate", ("robot", place), skill="navigate", data={"to": place})
        t = time.perf_counter()
        sim.begin("bench", stage, now)
        start = now
        while sim.poll("bench", stage, now).state.value == "running" and now - start < 200:
            now += 0.1
        total_wall += time.perf_counter() - t
        total_sim += now - start
    rtf = total_sim / total_wall
    print(f"navigation in MuJoCo (TIAGo, 50 Hz control, 500 Hz physics, people scripted): "
          f"{total_sim:.1f} s simulated in {total_wall:.2f} s wall = {rtf:.0f}x real time   "
          f"target >= 50x: {'OK' if rtf >= 50 else 'MISS'}")


if __name__ == "__main__":
    bench_queries()
    bench_navigation()
