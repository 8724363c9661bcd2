"""The suspension-strategy experiment: its declared family, the pilot's sizes, the document, the provenance
block and the drift check, seeds chosen on the command line."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.analysis.family import BINARY, SECONDS, Contrast, Outcome, pilot_sizes, run_family
from experiments.analysis.stats import holm
from experiments.inputs.strategy import Strategy
from experiments.metrics.store import RunRow, Status
from experiments.sweep import experiment as ex
from experiments.sweep import provenance as pv
from experiments.sweep.results_doc import render
from experiments.sweep.spec import Job, SweepSpec, load_spec, select_seeds

ROOT = Path(__file__).resolve().parents[2]
LABELS = {s: Strategy(update="planned", suspension=s, policy="strict", hazard_waiting=False).label
          for s in ("static", "planned", "derived")}


def _metrics(scenario: str, seed: int, suspension: str) -> dict[str, object]:
    """``hh``: static's suspension is unsafe in every third seed, derived's never, planned's like static's;
    derived leaves the hazard 20 s less (every seed), planned the same as static.  ``cr``: identical."""
    unsafe = scenario == "hh" and seed % 3 == 0 and suspension != "derived"
    hazard = 40.0 + seed - (20.0 if scenario == "hh" and suspension == "derived" else 0.0)
    return {"suspensions": {"all_safe": not unsafe, "count": 1, "unsafe": int(unsafe), "inapplicable_stages": 0},
            "safety": {"unattended_alive_s": hazard, "after_end_s": 0.0, "unowned_s": 3.0},
            "people": {"time_to_help_s": {"mean": 30.0 + seed}},
            "totals": {"failed": 0, "unfinished": 0, "static_fallbacks": 0},
            "decisions": {"cost_compared": 2, "margins": {"-0.1": 1, "+0.2": 1},
                          "hysteresis_flips": {"0.85": 1, "0.9": 0, "0.95": 0, "1": 1}}}


def _rows(seeds: range, scenarios: tuple[str, ...] = ("hh", "cr")) -> list[RunRow]:
    return [RunRow(sc, seed, LABELS[s], Status.OK, {}, _metrics(sc, seed, s))
            for sc in scenarios for seed in seeds for s in LABELS]


def test_the_family_is_the_declared_tests_holm_adjusted_together_whatever_the_data() -> None:
    rows = _rows(range(1, 31), scenarios=("hh",))  # 'cr' declared but never run
    tests = run_family(rows, ["hh", "cr"], ex.CONTRASTS, ex.OUTCOMES)
    assert len(tests) == 2 * len(ex.CONTRASTS) * len(ex.OUTCOMES)
    assert [t.p_holm for t in tests] == pytest.approx(holm([t.effect.p for t in tests]))
    by = {(t.scenario, t.contrast.treatment, t.outcome.kind): t for t in tests}
    safe = by[("hh", "derived", BINARY)]
    assert (safe.effect.informative, safe.effect.estimate) == (10, pytest.approx(10 / 30))
    assert safe.verdict == "treatment better"  # all_safe: higher is better
    hazard = by[("hh", "derived", SECONDS)]
    assert hazard.effect.estimate == pytest.approx(-20.0) and hazard.verdict == "treatment better"
    assert by[("hh", "planned", SECONDS)].verdict == "identical"
    assert by[("cr", "derived", BINARY)].effect.n == 0 and by[("cr", "derived", BINARY)].p_holm == 1.0


def test_too_few_informative_pairs_give_no_verdict() -> None:
    rows = _rows(range(1, 13), scenarios=("hh",))  # 4 discordant pairs
    t = next(t for t in run_family(rows, ["hh"], ex.CONTRASTS[:1], ex.OUTCOMES[:1]))
    assert t.effect.informative == 4 and t.verdict == "too few pairs"


def test_a_contrast_pairs_only_runs_that_differ_in_its_factor() -> None:
    c = Contrast("suspension", "static", "derived")
    assert c.partner(LABELS["derived"]) == LABELS["static"]
    assert c.partner(LABELS["planned"]) is None
    with pytest.raises(ValueError, match="Contrast.factor"):
        Contrast("colour", "a", "b")
    with pytest.raises(ValueError, match="Outcome.kind"):
        Outcome("x", "ordinal", "x")


def test_the_pilot_sizes_each_test_and_n_is_clamped() -> None:
    sizes = pilot_sizes(_rows(range(1, 21)), ["hh", "cr"], ex.CONTRASTS, ex.OUTCOMES)
    by = {(s.scenario, s.contrast.treatment, s.outcome.kind): s for s in sizes}
    binary = by[("hh", "derived", BINARY)]
    assert binary.pairs == 20 and binary.discordant == pytest.approx(6 / 20) and binary.required is not None
    assert by[("cr", "derived", BINARY)].required is None  # nothing to size: no discordant pair
    assert by[("hh", "derived", SECONDS)].required is None  # a constant difference: no spread
    n = ex.fixed_n(sizes, ["hh", "cr"])
    assert n["cr"] == ex.MIN_N and ex.MIN_N <= n["hh"] <= ex.MAX_N


@pytest.mark.slow
def test_the_document_is_deterministic_declares_first_and_ends_with_its_provenance() -> None:
    rows = _rows(range(1, 31))
    plan = ex.Plan(tuple(pilot_sizes(rows, ["hh", "cr"], ex.CONTRASTS, ex.OUTCOMES)), {"hh": 30, "cr": 30})
    prov = pv.Provenance("abc123", (pv.Digest(ex.SPEC, True, "hh", 1, LABELS["static"], "f" * 64),))
    text = render(rows, rows[:6], plan, ["hh", "cr"], "tasker results", prov)
    assert text == render(list(reversed(rows)), list(reversed(rows[:6])), plan, ["hh", "cr"], "tasker results",
                          prov)
    assert ex.DECLARATION.strip() in text
    assert text.index(ex.DECLARATION.strip()) < text.index("## The pilot")
    assert "* **hh**: **helps**" in text and "* **cr**: no Holm-significant difference" in text
    assert pv.parse(text) == prov
    assert "abc123" in text


def test_a_damaged_provenance_block_is_named() -> None:
    assert pv.parse("# no block here\n") is None
    with pytest.raises(ValueError, match="not closed"):
        pv.parse("x <!-- provenance {")
    with pytest.raises(ValueError, match="not the JSON tasker writes"):
        pv.parse("x <!-- provenance {\"commit\": 1} -->")


def test_verify_names_each_run_whose_trace_changed(monkeypatch: pytest.MonkeyPatch) -> None:
    spec = ex.load()
    job = spec.jobs()[0]
    prov = pv.Provenance("c", (pv.Digest(ex.SPEC, True, job.scenario, job.seed, job.strategy.label, "a" * 64),
                               pv.Digest(ex.SPEC, False, job.scenario, job.seed, job.strategy.label, "b" * 64)))
    seen: list[Job] = []

    def fake(j: Job) -> str:
        seen.append(j)
        return "b" * 64

    monkeypatch.setattr(pv, "trace_digest", fake)
    changed = pv.verify(prov)
    assert len(changed) == 1 and "perturbed" in changed[0] and "aaaaaaaaaaaa → bbbbbbbbbbbb" in changed[0]
    assert seen[0].perturbation is not None and seen[1].perturbation is None


def test_the_shipped_spec_is_the_declared_design() -> None:
    spec = ex.load()
    assert {st.suspension for st in spec.strategies} == {"static", "planned", "derived"}
    assert {(st.update, st.policy, st.hazard_waiting) for st in spec.strategies} == {("planned", "strict", False)}
    assert spec.perturbation is not None and spec.perturbation.rate_per_min == 3.0
    assert (spec.perturbation.before_s, spec.perturbation.after_s) == (20.0, 60.0)
    assert len(spec.seeds) >= ex.MAX_N and set(spec.variants) == set(spec.scenarios)
    control = ex.control_jobs(spec)
    assert {j.perturbation for j in control} == {None} and {j.seed for j in control} == set(range(1, 31))
    assert len(ex.pilot_jobs(spec)) == len(spec.scenarios) * 3 * ex.PILOT_SEEDS


def _spec(tmp_path: Path, extra: str = "") -> Path:
    p = tmp_path / "s.toml"
    p.write_text('scenarios = ["synthetic_demo"]\nseeds = 10\nseed_start = 1\nstrategies = ["update=static"]\n'
                 + extra)
    return p


def test_seeds_are_chosen_from_the_spec_with_clear_errors(tmp_path: Path) -> None:
    spec = load_spec(_spec(tmp_path))
    assert select_seeds(spec, "2-4,7").seeds == (2, 3, 4, 7)
    assert select_seeds(spec, "5").seeds == (5,)
    for text, message in (("1-x", "expected seeds as A-B"), ("5-2", "high < low"), ("11", "not a seed of the spec")):
        with pytest.raises(ValueError, match=message):
            select_seeds(spec, text)


def test_a_spec_names_its_task_folders_relative_to_itself(tmp_path: Path) -> None:
    (tmp_path / "tasks").mkdir()
    spec: SweepSpec = load_spec(_spec(tmp_path, 'paths = ["tasks"]\n'))
    assert spec.task_paths == (str((tmp_path / "tasks").resolve()),)
    with pytest.raises(Exception, match=r"paths\[0\].*no such folder"):
        load_spec(_spec(tmp_path, 'paths = ["nowhere"]\n'))


@pytest.mark.slow
def test_sweep_runs_a_limit_and_says_how_long_the_rest_takes(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.cli import main

    spec = _spec(tmp_path)
    db = tmp_path / "r.db"
    assert main(["sweep", str(spec), "--db", str(db), "--seeds", "1-3", "--limit", "2", "--workers", "1", "-q"]) == 0
    out = capsys.readouterr().out
    assert "2 run (2 ok" in out and "1 jobs not run yet" in out and "about" in out
    assert main(["sweep", str(spec), "--db", str(db), "--seeds", "12"]) == 2
    assert "--seeds" in capsys.readouterr().err


def test_results_refuses_an_interim_document_in_place_of_the_committed_one(
        capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.cli import main

    assert main(["results", "--no-run", "--partial"]) == 2
    assert "interim document may not replace" in capsys.readouterr().err
    assert main(["results", "--replay", "nowhere", "1", "derived", "--out", "/tmp/x"]) == 2
    assert "no scenario 'nowhere'" in capsys.readouterr().err


def test_margins_and_flips_are_summed_per_cell() -> None:
    rows = _rows(range(1, 4), scenarios=("hh",))
    plan = ex.Plan((), {"hh": 3})
    text = render(rows, [], plan, ["hh"], "tasker results", None)
    line = next(s for s in text.splitlines() if s.startswith("| hh | static | 6 |"))
    assert line.split("|")[4].strip() == "3" and "-0.1:3 +0.2:3" in line  # |margin| < 0.1: the -0.1 bin
    assert line.rstrip(" |").endswith("3 | 0 | 0 | 3")


def test_a_plain_run_is_vouched_for_by_its_scenario(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[tuple[str, object, str]] = []

    def fake(scenario: str, *, seed: int | None = None, strategy: str = "", root: Path = ROOT) -> pv.Digest:
        calls.append((scenario, seed, strategy))
        return pv.Digest("", False, scenario, -1, strategy, "c" * 64)

    monkeypatch.setattr(pv, "run_digest", fake)
    prov = pv.Provenance("c", (pv.Digest("", False, "paper", -1, "", "c" * 64),))
    assert pv.verify(prov) == [] and calls == [("paper", None, "")]
    assert "| paper | tasker run | its own | its own settings |" in "\n".join(pv.render(prov))
