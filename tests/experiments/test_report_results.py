"""docs/results.md from the stored runs (experiments.sweep.factorial): per scenario, paired, Holm over the
tests shown, failures counted apart, a factor with no effect said so, deterministic."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from experiments.analysis.stats import holm
from experiments.inputs.strategy import Strategy
from experiments.metrics.store import ResultStore, RunRow, Status
from experiments.sweep import factorial as results

STRATEGIES = [Strategy(update="planned", suspension=s, policy=p, hazard_waiting=h).label
              for s, p, h in itertools.product(("static", "planned"), ("strict", "conditional"), (False, True))]


def _metrics(scenario: str, seed: int, label: str) -> dict[str, object]:
    """``hh``: planned leaves the cooker on 10 s longer than static under the conditional policy in seed 2
    only; time to help is 5 s shorter with planned everywhere.  ``cr``: no hazard at all (constant 0).
    hazard_waiting changes nothing (as when it is a no-op)."""
    f = dict(Strategy.parse(label).items())
    planned = f["suspension"] == "planned"
    unattended = 0.0
    if scenario == "hh":
        unattended = 20.0 + seed + (10.0 if planned and f["policy"] == "conditional" and seed == 2 else 0.0)
    return {"safety": {"unattended_s": unattended, "budget_overruns": int(unattended > 30),
                       "hazards": {"cooker_on": {"unattended_s": unattended}}},
            "people": {"time_to_help_s": {"mean": 40.0 + seed - (5.0 if planned else 0.0)}, "not_helped": 0},
            "totals": {"failed": 0, "unfinished": 0},
            "calibration": {"estimates": {"error_s": {"mean": 1.0 + seed}, "compared": 2, "underestimated": 1},
                            "interruptions": {"error_s": {"mean": -2.0}, "compared": 1, "underestimated": 0,
                                              "censored": 0}}}


@pytest.fixture
def rows() -> list[RunRow]:
    out = [RunRow(sc, seed, st, Status.OK, {"tasker_version": "9.9"}, _metrics(sc, seed, st))
           for sc in ("hh", "cr") for seed in (1, 2, 3, 4) for st in STRATEGIES]
    out.append(RunRow("cr", 5, STRATEGIES[0], Status.ERROR, {}, {}, error="PlanningFailed: no plan"))
    return out


def test_holm_family_is_exactly_the_tests_shown(rows: list[RunRow]) -> None:
    pairs, every, constant = results.tested_pairs(rows)
    assert {p.metric for p in pairs} <= set(results.TESTED)
    assert "safety.unattended_s" not in {p.metric for p in pairs if p.scenario == "cr"} or \
        "safety.unattended_s" not in constant
    expected = holm([p.p for p in pairs])
    assert [p.p_holm for p in pairs] == pytest.approx(expected, nan_ok=True)
    assert len(every) > len(pairs)  # the report's own family is larger


def test_document_is_deterministic_and_says_what_the_runs_show(rows: list[RunRow]) -> None:
    text = results.render(rows, "python -m experiments.sweep.factorial --seeds 4")
    assert text == results.render(list(reversed(rows)), "python -m experiments.sweep.factorial --seeds 4")
    assert text.startswith("# Static versus planned suspension: results")
    assert "python -m experiments.sweep.factorial --seeds 4" in text
    assert results.DECLARATION.rstrip() in text
    # the seed where planned was less safe is named, with the hazard that grew
    assert "| hh | conditional/off | 2 | 22 | 32 | cooker_on |" in text
    assert "| hh | conditional/on | 2 | 22 | 32 | cooker_on |" in text
    assert "planned never left hazards unattended longer than static here" in text  # cr
    # time to help: planned better by 5 s in every seed of hh
    assert "-5 ± 0 (n 4), 4/0/0" in text
    # hazard_waiting identical in every pair
    assert "Hazard-aware waiting changed nothing in these runs" in text
    assert "the harmoniser made 0 securing decisions" in text
    # the errored run is counted as infeasible, apart from the ok runs
    assert "| cr | static/strict/off | 4 | 1 | 0 |" in text


def test_a_person_planned_left_unhelped_is_named_with_the_reasons(rows: list[RunRow]) -> None:
    label = Strategy(update="planned", suspension="planned", policy="strict", hazard_waiting=False).label
    worse = [RunRow(r.scenario, r.seed, r.strategy, r.status, r.record,
                    {**r.metrics, "people": {"time_to_help_s": {"mean": None}, "not_helped": 1},
                     "totals": {"failed": 1, "unfinished": 0, "failure_reasons": ["d2: stuck in the doorway"]}})
             if (r.scenario, r.seed, r.strategy) == ("cr", 3, label) else r for r in rows]
    assert [(sc, seed) for sc, _, seed, *_ in results.worse_outcomes(worse)] == [("cr", 3)]
    text = results.render(worse, "cmd")
    assert "| cr | strict/off | 3 | 0 / 0 | 1 / 1 | d2: stuck in the doorway |" in text
    assert "planned left more people never helped, or failed more tasks, than static in 1 of 16" in text


def test_notes_are_included_verbatim_after_the_findings(rows: list[RunRow]) -> None:
    text = results.render(rows, "cmd", notes="## Reading the traces (by hand)\n\n* a note\n")
    assert text.index("## What it shows") < text.index("* a note") < text.index("## Primary outcome per cell")


def test_a_factor_with_an_effect_is_not_called_a_no_op(rows: list[RunRow]) -> None:
    changed = [RunRow(r.scenario, r.seed, r.strategy, r.status, r.record,
                      {**r.metrics, "people": {"time_to_help_s": {"mean": 50.0 + r.seed}, "not_helped": 0}})
               if r.status is Status.OK and "hazard_waiting=on" in r.strategy else r for r in rows]
    text = results.render(changed, "cmd")
    assert "Hazard-aware waiting changed nothing" not in text
    assert "### hazard waiting — hh" in text


def test_main_reports_what_the_database_holds(rows: list[RunRow], tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    spec = tmp_path / "s.toml"
    spec.write_text('scenarios = ["paper"]\nseeds = 2\n[factors]\nsuspension = ["static", "planned"]\n',
                    encoding="utf-8")
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        for seed in (0, 1):
            for st in ("suspension=static", "suspension=planned"):
                store.add(RunRow("paper", seed, st, Status.OK, {}, {"safety": {"unattended_s": float(seed)},
                                                                    "people": {"time_to_help_s": {"mean": 3.0}}}))
        store.add(RunRow("paper", 7, "suspension=static", Status.OK, {}, {}))  # not a job of the spec
    md = tmp_path / "results.md"
    code = results.main(["--spec", str(spec), "--db", str(db), "--out", str(tmp_path / "rep"), "--markdown", str(md),
                         "--no-run"])
    assert code == 0
    text = md.read_text(encoding="utf-8")
    assert "4 runs (4 ok)" in text and "--no-run" not in text.split("```")[1]
    assert results.main(["--spec", str(spec), "--db", str(db), "--seeds", "3", "--no-run"]) == 2


def test_the_shipped_factorial_spec_is_the_declared_design() -> None:
    from experiments.sweep.spec import load_spec

    spec = load_spec(Path(results.ROOT) / results.SPEC)
    assert {Strategy.parse(s.label) for s in spec.strategies} == {Strategy.parse(s) for s in STRATEGIES}
    assert [Path(s).stem for s in spec.scenarios] == ["household", "carry", "paper", "compound"]
    assert set(spec.variants) == set(spec.scenarios)  # every scenario has its interruption grid
    for grid in spec.variants.values():  # the first three seeds put the interruption in every stratum
        assert sorted(grid.stratum(seed) for seed in spec.seeds[:3]) == \
            sorted(grid.stratum(k) for k in range(grid.strata))


def test_replay_refuses_a_job_the_spec_does_not_have(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = str(Path(results.ROOT) / results.SPEC)
    assert results.main(["--spec", spec, "--replay", "kitchen", "1", "planned/strict/off", "--out",
                         str(tmp_path)]) == 2
    assert "no scenario 'kitchen'" in capsys.readouterr().err
    assert results.main(["--spec", spec, "--replay", "carry", "1", "planned/strict/of", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "no job carry seed 1 cell 'planned/strict/of'" in err and "planned/strict/off" in err
    assert not any(tmp_path.iterdir())
