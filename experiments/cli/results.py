"""``tasker results``: run the suspension-strategy experiment and regenerate ``docs/results.md``.

The steps (:mod:`experiments.sweep.experiment`) are resumable: each call adds only the runs the
databases do not hold.  The document is written once the declared design is complete (the
pilot, n seeds per scenario in the perturbed arm, the control arm); before that the command says
what is missing and how long it should take (``--partial`` writes an interim document elsewhere).
``--check`` re-runs the runs the committed document vouches for and fails when a trace changed.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from experiments.cli.args import EXIT_FAILED, EXIT_OK, UsageError, note, positive_int, show_progress, writable_file
from experiments.sweep import experiment_paths

if TYPE_CHECKING:
    from experiments.sweep.experiment import Plan
    from experiments.sweep.spec import SweepSpec

EXAMPLES = """\
examples:
  tasker results --workers 2                  # run what is missing (pilot, n seeds, three arms), write docs/results.md
  tasker results --pilot                      # only the pilot's 20 seeds; print the n it fixes
  tasker results --limit 60                   # 60 more runs, then say how long the rest takes
  tasker results --no-run --partial --markdown /tmp/interim.md   # an interim document from what is stored
  tasker results --no-run --partial --replace  # ... in place of docs/results.md (it says how much is in)
  tasker results --replay household 7 fallback --tree cook:cooker --out out/replay   # one run again, every output
  tasker results --check                      # do docs/results.md's vouched-for traces still come out?"""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    ex = experiment_paths  # only its constants: the help must not load the experiment
    p = sub.add_parser("results", help="run the suspension-strategy experiment; regenerate docs/results.md",
                       description="Run the experiment declared in docs/results.md (static, planned, derived and "
                                   "fallback suspension over randomised variants, in a targeted, an untargeted and "
                                   "a control arm; a pilot fixes n) and write the document from the stored runs. "
                                   "Resumable: only missing runs are run.",
                       epilog=EXAMPLES)
    p.add_argument("--workers", type=positive_int, default=1, help="local worker processes (default 1)")
    p.add_argument("--limit", type=positive_int, default=None, metavar="N", help="start at most N runs in this call")
    p.add_argument("--pilot", action="store_true", help="run only the pilot and print the sizes it fixes")
    p.add_argument("--no-run", action="store_true", help="run nothing; write from what the databases hold")
    p.add_argument("--partial", action="store_true",
                   help="write the document even if the design is not complete (needs --markdown other than "
                        f"{ex.MARKDOWN}, or --replace: the committed document is only replaced by a complete one "
                        "unless asked)")
    p.add_argument("--replace", action="store_true",
                   help=f"with --partial: replace {ex.MARKDOWN} with the interim document knowingly (it says so at "
                        "its top, with how many runs of the design are in)")
    p.add_argument("--results", default=ex.RESULTS, metavar="DIR",
                   help=f"the folder of the arms' results databases, ARM.db (default {ex.RESULTS})")
    p.add_argument("--markdown", default=ex.MARKDOWN, help=f"the document to write (default {ex.MARKDOWN})")
    p.add_argument("--replay", nargs=3, metavar=("SCENARIO", "SEED", "SUSPENSION"), default=None,
                   help="run one job again with every output into --out; SCENARIO as in the document (e.g. compound)")
    p.add_argument("--arm", choices=("targeted", "untargeted", "control"), default="targeted",
                   help="with --replay: the arm of the job (default targeted)")
    p.add_argument("--tree", default="default", help="with --replay: the cell's tree (default: default)")
    p.add_argument("--out", default=None, metavar="DIR", help="with --replay: where to write the run")
    p.add_argument("--check", action="store_true",
                   help="re-run the runs the document's provenance block vouches for; exit 1 if a trace changed")
    p.set_defaults(func=_results)


def _results(args: argparse.Namespace) -> int:
    from experiments.sweep import experiment as ex

    spec = ex.load()
    if args.check:
        return _check(args)
    if args.replay is not None:
        return _replay(args, spec)
    if args.replace and not args.partial:
        raise UsageError("--replace", "--replace only lets --partial write the committed document; a complete "
                                      "document is written without it")
    if (args.partial and not args.replace
            and Path(args.markdown).resolve() == (ex.ROOT / experiment_paths.MARKDOWN).resolve()):
        raise UsageError("--partial", f"an interim document may not replace {experiment_paths.MARKDOWN}: "
                                      "give --markdown PATH, or --replace to replace it knowingly")
    root = Path(args.results)
    for arm in ex.ARMS:
        writable_file(str(ex.db_of(arm, root)), "--results")
    if args.no_run:
        plan = ex.size(spec, ex.db_of("targeted", root))
    else:
        plan, prog = ex.run(spec, results=root, workers=args.workers, limit=args.limit, pilot_only=args.pilot,
                            progress=show_progress(args))
        for name, s in (("pilot", prog.pilot), *((f"{a} arm", prog.arms[a]) for a in ex.ARMS)):
            if s is not None:
                note(args, f"{name}: {s.ran} run ({s.ok} ok, {s.errors} errors), {s.skipped} already stored")
    print("n per scenario (from the pilot): " + ", ".join(f"{Path(sc).stem} {n}" for sc, n in plan.n.items()))
    missing = _missing(spec, plan, root)
    if args.pilot:
        for size in plan.sizes:
            print(f"  {size.scenario:40} {size.contrast.name:20} pilot pairs {size.pairs:3}  "
                  f"needs {'-' if size.required is None else size.required}")
        return EXIT_OK
    if missing and not args.partial:
        print(f"{missing} runs of the declared design are missing; {_eta(args, missing, root)}. {args.markdown} is "
              "written once they are in (run the same command again; --partial --markdown PATH for an interim "
              "document).")
        return EXIT_OK
    return _write(args, spec, plan, root, complete=not missing)


def _missing(spec: SweepSpec, plan: Plan, root: Path) -> int:
    return sum(want - have for want, have in _progress(spec, plan, root).values())


def _progress(spec: SweepSpec, plan: Plan, root: Path) -> dict[str, tuple[int, int]]:
    """Per arm, the runs the declared design asks for and how many of them are stored."""
    from experiments.sweep import experiment as ex

    out = {}
    for arm in ex.ARMS:
        want = ex.arm_jobs(spec, arm, plan.n) + (ex.pilot_jobs(spec) if arm == "targeted" else [])
        keys = {j.key for j in want}
        have = {r.key for r in ex.rows_of(ex.db_of(arm, root), want)} & keys
        out[arm] = (len(keys), len(have))
    return out


def _eta(args: argparse.Namespace, missing: int, root: Path) -> str:
    from experiments.sweep import experiment as ex

    spec = ex.load()
    walls = [r.wall for arm in ex.ARMS for r in ex.rows_of(ex.db_of(arm, root), ex.arm_jobs(spec, arm, None))
             if r.wall]
    if not walls:
        return "no run time known yet to estimate them"
    per = sum(walls) / len(walls)
    return f"at {per:.1f} s a run on {args.workers} worker(s), about {per * missing / args.workers / 3600:.1f} h"


def _write(args: argparse.Namespace, spec: SweepSpec, plan: Plan, root: Path, *, complete: bool) -> int:
    from experiments.sweep import experiment as ex
    from experiments.sweep import provenance as pv
    from experiments.sweep.results_doc import render

    arms = {arm: ex.by_cell(ex.rows_of(ex.db_of(arm, root), ex.arm_jobs(spec, arm, plan.n))) for arm in ex.ARMS}
    commit = pv.commit()
    picks = [(j, arm) for arm in ex.ARMS for j in pv.pick(ex.arm_jobs(spec, arm, plan.n), seed=f"{commit}|{arm}")
             if arm == "targeted" or j.scenario == spec.scenarios[0]]
    note(args, f"vouching for {len(picks)} runs (running them again for their trace digests)")
    digests = tuple(pv.digest(ex.SPEC, j, arm) for j, arm in picks)
    command = "tasker results" + (f" --workers {args.workers}" if args.workers != 1 else "")
    text = render(arms, plan, ex.cells(spec), command, pv.Provenance(commit, digests))
    if not complete:
        progress = _progress(spec, plan, root)
        done = ", ".join(f"{a} {have} of {want}" for a, (want, have) in progress.items())
        text = ("> **Interim**: the declared design is not complete (runs stored: " + done + "; the targeted "
                "arm's count includes the pilot). These numbers are not the experiment's answer: n was fixed by "
                "the pilot and stopping before it is not part of the declaration, so every verdict below is "
                "provisional and may change once the missing runs are in (`" + command + "` runs them and "
                "writes the complete document).\n\n" + text)
    Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
    Path(args.markdown).write_text(text, encoding="utf-8")
    print(f"wrote {args.markdown} (" + ", ".join(f"{len(arms[a])} {a}" for a in ex.ARMS) + " runs)")
    return EXIT_OK


def _replay(args: argparse.Namespace, spec: SweepSpec) -> int:
    from experiments.run.runner import run_scenario
    from experiments.sweep import experiment as ex

    if args.out is None:
        raise UsageError("--out", "--replay needs --out DIR (where the run's outputs go)")
    scenario, seed_text, suspension = args.replay
    jobs = ex.arm_spec(spec, args.arm).jobs()
    by_name = {Path(sc).stem: sc for sc in spec.scenarios}
    if scenario not in by_name:
        raise UsageError("--replay", f"no scenario {scenario!r} (scenarios: {', '.join(sorted(by_name))})")
    tree = None if args.tree == "default" else args.tree
    match = [j for j in jobs if j.scenario == by_name[scenario] and str(j.seed) == seed_text
             and j.strategy.suspension == suspension and j.strategy.tree == tree]
    if not match:
        trees = sorted({j.strategy.tree or "default" for j in jobs if j.scenario == by_name[scenario]})
        raise UsageError("--replay", f"no job {scenario} seed {seed_text} suspension {suspension!r} tree "
                                     f"{args.tree!r} in the {args.arm} arm (seeds {min(j.seed for j in jobs)}.."
                                     f"{max(j.seed for j in jobs)}; suspension static, planned, derived or fallback; "
                                     f"its trees: {', '.join(trees)})")
    job = match[0]
    run_scenario(job.source, job.options(), out=Path(args.out))
    print(f"wrote {args.out}/ ({scenario}, seed {seed_text}, {job.strategy.label}, {args.arm} arm)")
    return EXIT_OK


def _check(args: argparse.Namespace) -> int:
    from experiments.sweep import provenance as pv

    path = Path(args.markdown)
    if not path.is_file():
        raise UsageError("--markdown", f"{path}: no such document")
    try:
        prov = pv.parse(path.read_text(encoding="utf-8"))
    except ValueError as exc:
        raise UsageError("--markdown", f"{path}: {exc}") from None
    if prov is None:
        print(f"{path}: no provenance block (not generated by tasker results)", file=sys.stderr)
        return EXIT_FAILED
    changed = pv.verify(prov)
    for line in changed:
        print(f"{path}: changed: {line}", file=sys.stderr)
    if changed:
        print(f"{path} no longer describes this code: regenerate it with "
              f"'{shlex.join(['tasker', 'results'])}'", file=sys.stderr)
        return EXIT_FAILED
    print(f"{path}: the {len(prov.digests)} vouched-for runs give the same traces (generated on {prov.commit})")
    return EXIT_OK
