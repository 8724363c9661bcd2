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
    from experiments.sweep.spec import Job, SweepSpec

EXAMPLES = """\
examples:
  tasker results --workers 2                  # run what is missing (pilot, n seeds, control), write docs/results.md
  tasker results --pilot                      # only the pilot's 20 seeds; print the n it fixes
  tasker results --limit 60                   # 60 more runs, then say how long the rest takes
  tasker results --no-run --partial --markdown /tmp/interim.md   # an interim document from what is stored
  tasker results --replay carry 7 derived --out out/replay        # one run again, every output of tasker run
  tasker results --check                      # do docs/results.md's vouched-for traces still come out?"""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    ex = experiment_paths  # only its constants: the help must not load the experiment
    p = sub.add_parser("results", help="run the suspension-strategy experiment; regenerate docs/results.md",
                       description="Run the experiment declared in docs/results.md (static, planned and derived "
                                   "suspension over randomised, perturbed variants; a pilot fixes n) and write the "
                                   "document from the stored runs. Resumable: only missing runs are run.",
                       epilog=EXAMPLES)
    p.add_argument("--workers", type=positive_int, default=1, help="local worker processes (default 1)")
    p.add_argument("--limit", type=positive_int, default=None, metavar="N", help="start at most N runs in this call")
    p.add_argument("--pilot", action="store_true", help="run only the pilot and print the sizes it fixes")
    p.add_argument("--no-run", action="store_true", help="run nothing; write from what the databases hold")
    p.add_argument("--partial", action="store_true",
                   help="write the document even if the design is not complete (needs --markdown other than "
                        f"{ex.MARKDOWN}: the committed document is only replaced by a complete one)")
    p.add_argument("--db", default=ex.DB, help=f"perturbed arm's results database (default {ex.DB})")
    p.add_argument("--control-db", default=ex.CONTROL_DB, help=f"control arm's database (default {ex.CONTROL_DB})")
    p.add_argument("--markdown", default=ex.MARKDOWN, help=f"the document to write (default {ex.MARKDOWN})")
    p.add_argument("--replay", nargs=3, metavar=("SCENARIO", "SEED", "SUSPENSION"), default=None,
                   help="run one job of the perturbed arm again (with --control: of the control arm) with every "
                        "output into --out; SCENARIO as in the document (e.g. compound)")
    p.add_argument("--control", action="store_true", help="with --replay: the control arm's job")
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
    if args.partial and Path(args.markdown).resolve() == (ex.ROOT / experiment_paths.MARKDOWN).resolve():
        raise UsageError("--partial", f"an interim document may not replace {experiment_paths.MARKDOWN}: "
                                      "give --markdown PATH")
    writable_file(args.db, "--db")
    writable_file(args.control_db, "--control-db")
    if args.no_run:
        plan = ex.size(spec, args.db)
    else:
        plan, prog = ex.run(spec, db=args.db, control_db=args.control_db, workers=args.workers, limit=args.limit,
                            pilot_only=args.pilot, progress=show_progress(args))
        for name, s in (("pilot", prog.pilot), ("perturbed arm", prog.perturbed), ("control arm", prog.control)):
            if s is not None:
                note(args, f"{name}: {s.ran} run ({s.ok} ok, {s.errors} errors), {s.skipped} already stored")
    print("n per scenario (from the pilot): " + ", ".join(f"{Path(sc).stem} {n}" for sc, n in plan.n.items()))
    missing = _missing(spec, plan, args)
    if args.pilot:
        for size in plan.sizes:
            print(f"  {Path(size.scenario).stem:12} {size.contrast.name:18} {size.outcome.label:45} "
                  f"pilot pairs {size.pairs:3}  needs {'-' if size.required is None else size.required}")
        return EXIT_OK
    if missing and not args.partial:
        print(f"{missing} runs of the declared design are missing; {_eta(args, missing)}. {args.markdown} is written "
              "once they are in (run the same command again; --partial --markdown PATH for an interim document).")
        return EXIT_OK
    return _write(args, spec, plan, complete=not missing)


def _missing(spec: SweepSpec, plan: Plan, args: argparse.Namespace) -> int:
    from experiments.sweep import experiment as ex

    want = [*ex.perturbed_jobs(spec, plan.n), *ex.pilot_jobs(spec)]
    have = {r.key for r in ex.rows_of(args.db, want)}
    control = ex.control_jobs(spec)
    have_c = {r.key for r in ex.rows_of(args.control_db, control)}
    return len({j.key for j in want} - have) + len({j.key for j in control} - have_c)


def _eta(args: argparse.Namespace, missing: int) -> str:
    from experiments.sweep import experiment as ex

    walls = [r.wall for db in (args.db, args.control_db) if Path(db).is_file()
             for r in ex.rows_of(db, _all_jobs()) if r.wall]
    if not walls:
        return "no run time known yet to estimate them"
    per = sum(walls) / len(walls)
    return f"at {per:.1f} s a run on {args.workers} worker(s), about {per * missing / args.workers / 3600:.1f} h"


def _all_jobs() -> list[Job]:
    from experiments.sweep import experiment as ex

    spec = ex.load()
    return [*spec.jobs(), *ex.control_jobs(spec)]


def _write(args: argparse.Namespace, spec: SweepSpec, plan: Plan, *, complete: bool) -> int:
    from experiments.sweep import experiment as ex
    from experiments.sweep import provenance as pv
    from experiments.sweep.results_doc import render

    perturbed = ex.rows_of(args.db, ex.perturbed_jobs(spec, plan.n))
    control = ex.rows_of(args.control_db, ex.control_jobs(spec))
    picks = [(j, True) for j in pv.pick(ex.perturbed_jobs(spec, plan.n))]
    picks += [(j, False) for j in pv.pick(ex.control_jobs(spec))[:1]]
    note(args, f"vouching for {len(picks)} runs (running them again for their trace digests)")
    digests = tuple(pv.digest(ex.SPEC, j, perturbed=p) for j, p in picks)
    command = "tasker results" + (f" --workers {args.workers}" if args.workers != 1 else "")
    text = render(perturbed, control, plan, spec.scenarios, command, pv.Provenance(pv.commit(), digests))
    if not complete:
        text = ("> **Interim**: the declared design is not complete; these numbers are not the experiment's "
                "answer.\n\n" + text)
    Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
    Path(args.markdown).write_text(text, encoding="utf-8")
    print(f"wrote {args.markdown} ({len(perturbed)} perturbed and {len(control)} control runs)")
    return EXIT_OK


def _replay(args: argparse.Namespace, spec: SweepSpec) -> int:
    from experiments.run.runner import run_scenario
    from experiments.sweep import experiment as ex

    if args.out is None:
        raise UsageError("--out", "--replay needs --out DIR (where the run's outputs go)")
    scenario, seed_text, suspension = args.replay
    jobs = ex.control_jobs(spec) if args.control else spec.jobs()
    by_name = {Path(sc).stem: sc for sc in spec.scenarios}
    if scenario not in by_name:
        raise UsageError("--replay", f"no scenario {scenario!r} (scenarios: {', '.join(sorted(by_name))})")
    match = [j for j in jobs if j.scenario == by_name[scenario] and str(j.seed) == seed_text
             and j.strategy.suspension == suspension]
    if not match:
        raise UsageError("--replay", f"no job {scenario} seed {seed_text} suspension {suspension!r} in the "
                                     f"{'control' if args.control else 'perturbed'} arm (seeds "
                                     f"{min(j.seed for j in jobs)}..{max(j.seed for j in jobs)}; suspension static, "
                                     "planned or derived)")
    job = match[0]
    st = job.strategy
    run_scenario(job.source, job.options(), out=Path(args.out))
    print(f"wrote {args.out}/ ({scenario}, seed {seed_text}, {st.label}"
          f"{', control arm' if args.control else ''})")
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
