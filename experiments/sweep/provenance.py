"""What a generated document was made with: the commit, and the trace digests of a few of its runs.

A document generated from runs (``docs/results.md``) ends with a provenance block: the commit
of the code that ran (``-dirty`` when the working tree had changes) and, for a few of the
runs it reports, the SHA-256 of the run's trace.  :func:`verify` runs those jobs again with
the code as it is now and says which traces differ: a test does this in CI, so a change of
behaviour that would change what the committed document says fails until the document is
regenerated (``tasker results``).  The block is an HTML comment holding JSON (read back by
:func:`parse`) followed by a short visible table.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import subprocess
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from experiments.analysis.tables import markdown_table
from experiments.sweep.spec import Job, SweepSpec, load_spec

BEGIN = "<!-- provenance "
END = " -->"
ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Digest:
    """One run a document vouches for and its trace's SHA-256: a job of a sweep spec (``spec`` its
    path from the project's root; ``perturbed``: with the spec's ``[perturbation]``, else the control
    arm without it), or, with ``spec`` empty, a plain ``tasker run`` of ``scenario`` (a shipped name
    or a path from the root; ``seed`` -1 for the scenario's own; ``strategy`` a label or empty for the
    scenario's own settings)."""

    spec: str
    perturbed: bool
    scenario: str
    seed: int
    strategy: str
    sha256: str

    def to_json(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class Provenance:
    """The commit a document was generated on, and its digests."""

    commit: str
    digests: tuple[Digest, ...]


def commit(root: Path = ROOT) -> str:
    """The checkout's commit (short), ``-dirty`` if its tracked files changed; ``unknown`` outside git."""
    try:
        head = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=root, capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("-dirty" if dirty else "")


def arm(spec: SweepSpec, perturbed: bool) -> SweepSpec:
    """The spec as run for one arm: as written (perturbed) or without its ``[perturbation]`` (control)."""
    return spec if perturbed else dataclasses.replace(spec, perturbation=None)


def find_job(spec: SweepSpec, scenario: str, seed: int, strategy: str) -> Job:
    for job in spec.jobs():
        if (job.scenario, job.seed, job.strategy.label) == (scenario, seed, strategy):
            return job
    raise KeyError(f"no job ({scenario}, seed {seed}, {strategy}) in the spec {spec.name!r}")


def trace_digest(job: Job) -> str:
    """Run ``job`` (no pictures) into a temporary folder; the SHA-256 of its ``trace.jsonl``."""
    from experiments.run.runner import run_scenario

    with tempfile.TemporaryDirectory(prefix="tasker-provenance-") as tmp:
        out = Path(tmp) / "run"
        run_scenario(job.source, job.options(), out=out, pictures=False)
        return hashlib.sha256((out / "trace.jsonl").read_bytes()).hexdigest()


def digest(spec_path: str, job: Job, perturbed: bool) -> Digest:
    return Digest(spec_path, perturbed, job.scenario, job.seed, job.strategy.label, trace_digest(job))


def run_digest(scenario: str, *, seed: int | None = None, strategy: str = "", root: Path = ROOT) -> Digest:
    """The digest of a plain run of ``scenario`` (as ``tasker run`` runs it: not randomised)."""
    from experiments.inputs.strategy import Strategy
    from experiments.run.options import RunOptions
    from experiments.run.runner import run_scenario

    st = Strategy.parse(strategy) if strategy else Strategy()
    source = scenario if not scenario.endswith(".toml") else str(root / scenario)
    with tempfile.TemporaryDirectory(prefix="tasker-provenance-") as tmp:
        out = Path(tmp) / "run"
        run_scenario(source, RunOptions.of(st, seed=seed), out=out, pictures=False)
        sha = hashlib.sha256((out / "trace.jsonl").read_bytes()).hexdigest()
    return Digest("", False, scenario, -1 if seed is None else seed, strategy, sha)


def render(p: Provenance) -> list[str]:
    """The block: a comment with the JSON, then a visible section."""
    data = {"commit": p.commit, "digests": [d.to_json() for d in p.digests]}
    body = [[Path(d.scenario).stem, "tasker run" if not d.spec else "perturbed" if d.perturbed else "control",
             "its own" if d.seed < 0 else str(d.seed), d.strategy or "its own settings", f"`{d.sha256[:16]}`"]
            for d in p.digests]
    return ["## Provenance", "",
            f"Generated on commit `{p.commit}`. The traces of these runs, run again with the code beside this "
            "document, must have the digests below (`tests/experiments/test_drift.py` checks them in CI; "
            "regenerate the document when they change):", "",
            *markdown_table(["scenario", "arm", "seed", "strategy", "trace SHA-256 (first 16)"], body), "",
            BEGIN + json.dumps(data, sort_keys=True) + END]


def parse(text: str) -> Provenance | None:
    """The provenance block of a document (None if it has none); ValueError if it is damaged."""
    start = text.rfind(BEGIN)
    if start < 0:
        return None
    end = text.find(END, start + len(BEGIN))
    if end < 0:
        raise ValueError("the provenance block is not closed (expected ' -->')")
    try:
        data = json.loads(text[start + len(BEGIN):end])
        return Provenance(str(data["commit"]), tuple(Digest(**d) for d in data["digests"]))
    except (ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"the provenance block is not the JSON tasker writes: {exc}") from None


def verify(p: Provenance, root: Path = ROOT) -> list[str]:
    """Each digest of ``p`` whose job, run now, gives another trace: ``"scenario seed strategy: old → new"``."""
    specs: dict[str, SweepSpec] = {}
    changed = []
    for d in p.digests:
        if not d.spec:
            now = run_digest(d.scenario, seed=None if d.seed < 0 else d.seed, strategy=d.strategy, root=root).sha256
        else:
            if d.spec not in specs:
                specs[d.spec] = load_spec(root / d.spec)
            now = trace_digest(find_job(arm(specs[d.spec], d.perturbed), d.scenario, d.seed, d.strategy))
        if now != d.sha256:
            where = "tasker run" if not d.spec else "perturbed" if d.perturbed else "control"
            changed.append(f"{Path(d.scenario).stem} seed {d.seed} {d.strategy or 'its own settings'} "
                           f"({where}): {d.sha256[:12]} → {now[:12]}")
    return changed


def pick(jobs: Sequence[Job], per_scenario: int = 1) -> list[Job]:
    """A few jobs to vouch for: per scenario, ``per_scenario`` jobs of its first seed, the strategies
    taken in turn across scenarios (so every strategy appears)."""
    out: list[Job] = []
    scenarios = list(dict.fromkeys(j.scenario for j in jobs))
    strategies = list(dict.fromkeys(j.strategy.label for j in jobs))
    for i, sc in enumerate(scenarios):
        mine = [j for j in jobs if j.scenario == sc]
        first = min(j.seed for j in mine)
        for k in range(per_scenario):
            label = strategies[(i + k) % len(strategies)]
            out += [j for j in mine if j.seed == first and j.strategy.label == label][:1]
    return out
