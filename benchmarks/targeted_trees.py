"""How each task folder's trees fare under a targeted perturbation (issue 36, item 6's folders).

    python benchmarks/targeted_trees.py [--seeds 1-10] [--only FOLDER ...]

For every task folder with two trees (guide_human and human_fell in the ``paper`` scenario,
water_plants and hot_pot in their own scenarios), every tree and every suspension strategy
(static, planned, derived, fallback), each seed is run as a randomised variant of the scenario
with its interruption placed by the grid below and one targeted change aimed at the tree's
branch (``Perturbation(mode="targeted")``, ``experiments/run/targeting.py``).  Printed per
folder, tree and strategy: the runs, how many met a targeted change (a ``world`` event whose note
starts "perturbation (targeted"), how many of those aimed at an agent of the folder's task type,
the folder's suspensions that were safe (``metrics["suspensions"]["episodes"]``, the goal-based
judge) and the runs whose every suspension was safe (``metrics["suspensions"]["all_safe"]``).

Every number is of simulated runs: the output does not depend on the host (no wall times).  The
paper and water_plants grids are those of ``experiments/sweep/specs/strategies.toml`` (the
water_plants one widened to its task's length since it puts the can away, see below); hot_pot's
spans its task's stages the same way.  Strategies are never tuned here: the trees are the
folders' own.
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from experiments.inputs.perturbation import NOTE, Perturbation  # noqa: E402
from experiments.inputs.scenario import InterruptionGrid  # noqa: E402
from experiments.run.options import RunOptions  # noqa: E402
from experiments.run.runner import RunResult, run_scenario  # noqa: E402
from tasker import events as ev  # noqa: E402
from tasker.errors import RunAborted  # noqa: E402

SPECS = ROOT / "experiments" / "sweep" / "specs"
STRATEGIES = ("static", "planned", "derived", "fallback")
TARGETED = f"{NOTE} (targeted"
# strategies.toml's [perturbation], in the targeted mode
PERTURBATION = Perturbation(rate_per_min=3.0, before_s=20.0, after_s=60.0, mode="targeted")


@dataclass(frozen=True)
class Folder:
    """A task folder, the scenario it runs in, the grid that places its interruption, its trees."""

    name: str
    scenario: str
    grid: InterruptionGrid
    trees: tuple[str | None, ...]
    paths: tuple[str, ...] = ()


PAPER = InterruptionGrid("requests[2]", 10.0, 130.0, 40.0)  # strategies.toml [variants.paper]
FOLDERS = (
    Folder("guide_human", "paper", PAPER, (None, "guide_human:arrive")),
    Folder("human_fell", "paper", PAPER, (None, "human_fell:help_first")),
    # water_plants alone runs 0-178 s now that it puts the can away on its shelf: four strata over it
    Folder("water_plants", str(SPECS / "scenarios" / "water_plants.toml"),
           InterruptionGrid("requests[1]", 0.0, 180.0, 45.0), (None, "water_plants:can_first"),
           (str(SPECS / "tasks" / "water_plants"),)),
    # hot_pot alone runs 0-91 s (the pot held from 34.5 s): four strata over it
    Folder("hot_pot", str(SPECS / "scenarios" / "hot_pot.toml"),
           InterruptionGrid("requests[1]", 0.0, 92.0, 23.0), (None, "hot_pot:stove"),
           (str(SPECS / "tasks" / "hot_pot"),)),
)


@dataclass
class Tally:
    runs: int = 0
    aborted: int = 0
    targeted: int = 0
    at_folder: int = 0
    episodes: int = 0
    safe: int = 0
    all_safe: int = 0
    kinds: Counter[str] | None = None


def _kind(note: str) -> str:
    why = note.split("): ", 1)[-1]
    if why.startswith("someone put"):
        return "place"
    if why.startswith("door"):
        return "door"
    return "device" if why.startswith("someone switched") else "?"


def _one(folder: Folder, tree: str | None, strategy: str, seed: int, memo: dict[Any, Any]) -> dict[str, Any]:
    key = (folder.scenario, tree, strategy, seed)
    if key in memo:  # guide_human and human_fell share the paper scenario's default-tree runs
        return memo[key]
    opts = RunOptions(seed=seed, suspension=strategy, tree=tree, randomize=True, interruption=folder.grid,
                      perturbation=PERTURBATION, task_paths=folder.paths)
    try:
        result = run_scenario(folder.scenario, opts, pictures=False)
        aborted = False
    except RunAborted as exc:  # a run never dies of one task; an abort is counted, its partial trace read
        assert isinstance(exc.result, RunResult)
        result, aborted = exc.result, True
    types = {e.agent: e.task_type for e in result.trace.typed if isinstance(e, ev.TaskRequested)}
    notes = [e.note for e in result.trace.typed if isinstance(e, ev.WorldChanged) and e.note.startswith(TARGETED)]
    susp = result.metrics.get("suspensions", {})
    memo[key] = out = {"aborted": aborted, "notes": notes, "types": types, "episodes": susp.get("episodes", []),
                       "all_safe": bool(susp.get("all_safe"))}
    return out


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", default="1-10", help="A-B (inclusive)")
    ap.add_argument("--only", nargs="*", default=None, help="folders to run (default: all)")
    args = ap.parse_args(argv)
    lo, _, hi = args.seeds.partition("-")
    seeds = range(int(lo), int(hi or lo) + 1)
    memo: dict[Any, Any] = {}
    print(f"seeds {seeds.start}-{seeds.stop - 1}, targeted perturbation {PERTURBATION.to_json()}")
    print(f"{'folder':<13} {'tree':<11} {'strategy':<9} {'runs':>4} {'targeted':>8} {'at type':>7} "
          f"{'safe/susp':>9} {'all_safe':>8}  kinds")
    for folder in FOLDERS:
        if args.only and folder.name not in args.only:
            continue
        for tree in folder.trees:
            for strategy in STRATEGIES:
                t = Tally(kinds=Counter())
                for seed in seeds:
                    r = _one(folder, tree, strategy, seed, memo)
                    t.runs += 1
                    t.aborted += r["aborted"]
                    if r["notes"]:
                        t.targeted += 1
                        note = r["notes"][0]
                        assert t.kinds is not None
                        t.kinds[_kind(note)] += 1
                        aimed = next((a for a in r["types"] if f"{a}'s" in note), None)
                        t.at_folder += r["types"].get(aimed) == folder.name
                    mine = [e for e in r["episodes"] if e["task_type"] == folder.name]
                    t.episodes += len(mine)
                    t.safe += sum(1 for e in mine if e["safe"])
                    t.all_safe += r["all_safe"]
                name = (tree or "default").rpartition(":")[2]
                kinds = ", ".join(f"{k} {n}" for k, n in sorted((t.kinds or {}).items())) or "-"
                aborted = f"  ({t.aborted} aborted)" if t.aborted else ""
                print(f"{folder.name:<13} {name:<11} {strategy:<9} {t.runs:>4} {t.targeted:>8} {t.at_folder:>7} "
                      f"{f'{t.safe}/{t.episodes}':>9} {t.all_safe:>8}  {kinds}{aborted}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
