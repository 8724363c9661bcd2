"""The suspension-strategy experiment: its declared families per cell, the pilot's sizes, the hypotheses,
the document, the provenance block and the drift check, seeds chosen on the command line."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.analysis.family import BINARY, Contrast, Outcome, pilot_sizes, run_family
from experiments.analysis.stats import holm
from experiments.inputs.strategy import Strategy
from experiments.metrics.store import RunRow, Status
from experiments.sweep import experiment as ex
from experiments.sweep import provenance as pv
from experiments.sweep.results_doc import render
from experiments.sweep.spec import Job, SweepSpec, load_spec, select_seeds

ROOT = Path(__file__).resolve().parents[2]
SUSPENSIONS = ("static", "planned", "derived", "fallback")


def _label(suspension: str, tree: str | None = None) -> str:
    return Strategy(update="planned", suspension=suspension, policy="strict", hazard_waiting=False, tree=tree).label


def _metrics(scenario: str, seed: int, suspension: str, tree: str | None) -> dict[str, object]:
    """``hh``, default tree: static and derived unsafe in every third seed, planned and fallback never;
    ``hh`` with ``cook:cooker``: every strategy alike; ``cr``: identical everywhere."""
    unsafe = scenario == "hh" and tree is None and seed % 3 == 0 and suspension in ("static", "derived")
    return {"suspensions": {"all_safe": not unsafe, "count": 1, "unsafe": int(unsafe), "goal_unmet": int(unsafe)},
            "safety": {"unattended_s": 40.0 + seed - (10.0 if not unsafe else 0.0)},
            "carried": {"seconds": 0.0}, "people": {"time_to_help_s": {"mean": 30.0 + seed}},
            "totals": {"failed": 0, "static_fallbacks": 0},
            "switching": {"schedule": "d1 d2 d1" if seed % 2 else "d1 d2"},
            "run": {"targeted_changes": 1}, "gensusp_wall_s": [0.02] if suspension != "static" else []}


def _rows(seeds: range, cells: tuple[tuple[str, str | None], ...] = (("hh", None), ("hh", "cook:cooker"),
                                                                      ("cr", None))) -> list[RunRow]:
    return [RunRow(sc, seed, _label(s, tree), Status.OK, {}, _metrics(sc, seed, s, tree))
            for sc, tree in cells for seed in seeds for s in SUSPENSIONS]


CELLS = ["hh [default]", "hh [cook:cooker]", "cr [default]"]


def test_a_run_is_read_in_its_cell_and_pairs_within_it() -> None:
    rows = ex.by_cell(_rows(range(1, 4)))
    assert sorted({r.scenario for r in rows}) == sorted(CELLS)
    assert {Strategy.parse(r.strategy).tree for r in rows} == {None}
    assert ex.cell("hh", None) == "hh [default]" and ex.scenario_of("hh [cook:cooker]") == "hh"


def test_the_family_is_every_cell_and_contrast_holm_adjusted_together_whatever_the_data() -> None:
    rows = ex.by_cell(_rows(range(1, 31), cells=(("hh", None),)))  # the other cells declared, never run
    tests = run_family(rows, CELLS, ex.CONTRASTS, ex.OUTCOMES)
    assert len(tests) == len(CELLS) * len(ex.CONTRASTS)
    assert [t.p_holm for t in tests] == pytest.approx(holm([t.effect.p for t in tests]))
    by = {(t.scenario, t.contrast.treatment): t for t in tests}
    planned = by[("hh [default]", "planned")]
    assert (planned.effect.informative, planned.effect.estimate) == (10, pytest.approx(10 / 30))
    assert planned.verdict == "treatment better" and by[("hh [default]", "derived")].verdict == "identical"
    assert by[("cr [default]", "planned")].effect.n == 0 and by[("cr [default]", "planned")].p_holm == 1.0


def test_a_contrast_pairs_only_runs_that_differ_in_its_factor() -> None:
    c = Contrast("suspension", "static", "fallback")
    assert c.partner(_label("fallback", "cook:cooker")) == _label("static", "cook:cooker")  # the tree held
    assert c.partner(_label("planned")) is None
    with pytest.raises(ValueError, match="Contrast.factor"):
        Contrast("colour", "a", "b")
    with pytest.raises(ValueError, match="Outcome.kind"):
        Outcome("x", "ordinal", "x")


def test_the_pilot_sizes_each_cells_tests_and_n_per_scenario_is_clamped() -> None:
    rows = ex.by_cell(_rows(range(1, 21)))
    sizes = pilot_sizes(rows, CELLS, ex.CONTRASTS, ex.OUTCOMES, family_size=len(CELLS) * len(ex.CONTRASTS))
    by = {(s.scenario, s.contrast.treatment): s for s in sizes}
    assert by[("hh [default]", "planned")].discordant == pytest.approx(6 / 20)
    assert by[("hh [default]", "planned")].required is not None
    assert by[("cr [default]", "planned")].required is None  # nothing to size: no discordant pair
    n = ex.fixed_n(sizes, ["hh", "cr"])
    assert n["cr"] == ex.MIN_N and ex.MIN_N <= n["hh"] <= ex.MAX_N
    assert by[("hh [default]", "planned")].outcome.kind == BINARY


@pytest.mark.slow
def test_the_document_is_deterministic_declares_first_answers_per_cell_and_ends_with_its_provenance() -> None:
    targeted = ex.by_cell(_rows(range(1, 31)))
    arms = {"targeted": targeted, "untargeted": ex.by_cell(_rows(range(1, 7), cells=(("cr", None),))),
            "control": []}
    plan = ex.Plan(tuple(pilot_sizes(targeted, CELLS, ex.CONTRASTS, ex.OUTCOMES)), {"hh": 30, "cr": 30})
    prov = pv.Provenance("abc123", (pv.Digest(ex.SPEC, "targeted", "hh", 1, _label("static"), "f" * 64),))
    text = render(arms, plan, CELLS, "tasker results", prov)
    shuffled = {a: list(reversed(rows)) for a, rows in arms.items()}
    assert text == render(shuffled, plan, CELLS, "tasker results", prov)
    assert ex.DECLARATION.strip() in text and text.index(ex.DECLARATION.strip()) < text.index("## The pilot")
    assert "* **hh [default]**: **helps**: planned" in text and "* **cr [default]**: no Holm-significant" in text
    assert pv.parse(text) == prov and "abc123" in text
    h1 = next(line for line in text.splitlines() if line.startswith("| H1 |"))
    assert "| 90 | 0.111 [" in h1 and "**supported**" in h1  # pooled over three cells: 10 of 90 pairs
    h2 = next(line for line in text.splitlines() if line.startswith("| H2 | untargeted |"))
    assert "**supported**" in h2  # identical pairs: the interval is [0, 0]
    assert "## genSusp's planner wall time, cold caches" in text and "| planned | 90 | 20.0 | 20.0 |" in text


@pytest.mark.slow
def test_the_hypotheses_can_fail() -> None:
    weak = ex.by_cell(_rows(range(1, 61), cells=(("cr", None),)))
    for r in weak:  # static unsafe in 3 of 60 seeds, planned never: 0.05 < 0.10
        if _label("static") == r.strategy and r.seed % 20 == 0:
            r.metrics["suspensions"]["all_safe"] = False  # type: ignore[index]
    control = ex.by_cell(_rows(range(1, 61), cells=(("hh", None),)))  # planned safer by 0.33 without perturbing
    text = render({"targeted": weak, "untargeted": [], "control": control}, ex.Plan((), {"cr": 60}),
                  ["cr [default]", "hh [default]"], "tasker results", None)
    h1 = next(line for line in text.splitlines() if line.startswith("| H1 |"))
    assert "| 60 | 0.05 [" in h1 and "**not supported**" in h1
    h2 = {line.split("|")[2].strip(): line for line in text.splitlines() if line.startswith("| H2 |")}
    assert "**not supported**" in h2["control"]  # a difference of 0.33: outside ± 0.03
    # no pairs at all (an interim document before the arm ran): nothing shown equivalent, and said so
    assert "untested: no pairs yet" in h2["untargeted"] and "**supported**" not in h2["untargeted"]
    untargeted = text[text.index("## The untargeted arm's family"):]
    assert "| cr [default] | planned vs static | 0 | 0 | – [–, –] | 1.000 | 1.000 | no pairs |" in untargeted


def test_a_damaged_provenance_block_is_named() -> None:
    assert pv.parse("# no block here\n") is None
    with pytest.raises(ValueError, match="not closed"):
        pv.parse("x <!-- provenance {")
    with pytest.raises(ValueError, match="not the JSON tasker writes"):
        pv.parse("x <!-- provenance {\"commit\": 1} -->")


def test_verify_names_each_run_whose_trace_changed_in_its_arm(monkeypatch: pytest.MonkeyPatch) -> None:
    spec = ex.load()
    job = spec.jobs()[0]
    prov = pv.Provenance("c", tuple(pv.Digest(ex.SPEC, arm, job.scenario, job.seed, job.strategy.label, sha * 64)
                                    for arm, sha in (("targeted", "a"), ("untargeted", "b"), ("control", "b"))))
    seen: list[Job] = []

    def fake(j: Job) -> str:
        seen.append(j)
        return "b" * 64

    monkeypatch.setattr(pv, "trace_digest", fake)
    changed = pv.verify(prov)
    assert len(changed) == 1 and "targeted" in changed[0] and "aaaaaaaaaaaa → bbbbbbbbbbbb" in changed[0]
    assert [j.perturbation.mode if j.perturbation else None for j in seen] == ["targeted", "untargeted", None]


def test_the_drift_guard_picks_a_random_sample_not_the_first_seed() -> None:
    spec = ex.load()
    jobs = ex.arm_jobs(spec, "targeted", {sc: 60 for sc in spec.scenarios})
    picked = pv.pick(jobs, seed="abc")
    assert picked == pv.pick(jobs, seed="abc") and picked != pv.pick(jobs, seed="abd")
    assert len(picked) == len(spec.scenarios) and len({j.scenario for j in picked}) == len(spec.scenarios)
    assert any(j.seed != 1 for j in picked)


def test_the_shipped_spec_is_the_declared_design() -> None:
    spec = ex.load()
    assert {st.suspension for st in spec.strategies} == set(SUSPENSIONS)
    assert {(st.update, st.policy, st.hazard_waiting) for st in spec.strategies} == {("planned", "strict", False)}
    assert spec.perturbation is not None and spec.perturbation.mode == "targeted" and spec.cold
    assert (spec.perturbation.before_s, spec.perturbation.during_s) == (20.0, 8.0)
    assert len(spec.seeds) >= ex.MAX_N and set(spec.variants) == set(spec.scenarios)
    cells = ex.cells(spec)
    assert len(cells) >= 6 and all(len(spec.trees[sc]) >= 1 for sc in spec.scenarios)
    for arm, mode in (("untargeted", "untargeted"), ("control", None)):
        jobs = ex.arm_jobs(spec, arm)
        assert {j.perturbation.mode if j.perturbation else None for j in jobs} == {mode}
        assert {j.seed for j in jobs} == set(range(1, ex.OTHER_SEEDS + 1))
    assert len(ex.pilot_jobs(spec)) == len(cells) * len(SUSPENSIONS) * ex.PILOT_SEEDS
    assert all(j.options().cold for j in ex.pilot_jobs(spec)[:3])


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


def test_a_spec_runs_each_strategy_with_each_tree_of_a_scenario(tmp_path: Path) -> None:
    p = tmp_path / "t.toml"
    p.write_text('scenarios = ["household"]\nseeds = 2\nstrategies = ["suspension=static", "suspension=planned"]\n'
                 '[variants.household]\ninterrupt = "requests[2]"\ntimes = { start = 0, stop = 180, step = 60 }\n'
                 'trees = ["default", "cook:cooker"]\n')
    spec = load_spec(p)
    assert [(j.seed, j.strategy.suspension, j.strategy.tree) for j in spec.jobs()] == [
        (s, susp, tree) for s in (0, 1) for tree in (None, "cook:cooker") for susp in ("static", "planned")]
    p.write_text(p.read_text().replace('"cook:cooker"', '"cook:"'))
    with pytest.raises(Exception, match=r"trees\[1\].*TYPE:NAME"):
        load_spec(p)


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
    assert main(["results", "--no-run", "--replace"]) == 2
    assert "--replace only lets --partial" in capsys.readouterr().err
    assert main(["results", "--replay", "nowhere", "1", "derived", "--out", "/tmp/x"]) == 2
    assert "no scenario 'nowhere'" in capsys.readouterr().err
    assert main(["results", "--replay", "household", "1", "fallback", "--tree", "x:y", "--out", "/tmp/x"]) == 2
    assert "its trees: cook:cooker, default" in capsys.readouterr().err


def test_a_plain_run_is_vouched_for_by_its_scenario(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[tuple[str, object, str]] = []

    def fake(scenario: str, *, seed: int | None = None, strategy: str = "", root: Path = ROOT) -> pv.Digest:
        calls.append((scenario, seed, strategy))
        return pv.Digest("", "", scenario, -1, strategy, "c" * 64)

    monkeypatch.setattr(pv, "run_digest", fake)
    prov = pv.Provenance("c", (pv.Digest("", "", "paper", -1, "", "c" * 64),))
    assert pv.verify(prov) == [] and calls == [("paper", None, "")]
    assert "| paper | tasker run | its own | its own settings |" in "\n".join(pv.render(prov))


def test_the_progress_of_an_empty_store_is_every_run_missing(tmp_path: Path) -> None:
    from experiments.cli.results import _missing, _progress
    from experiments.sweep import experiment as ex

    spec = ex.load()
    plan = ex.size(spec, ex.db_of("targeted", tmp_path))
    progress = _progress(spec, plan, tmp_path)
    assert set(progress) == set(ex.ARMS)
    assert all(have == 0 and want > 0 for want, have in progress.values())
    assert _missing(spec, plan, tmp_path) == sum(want for want, _ in progress.values())
    assert progress["targeted"][0] >= len({j.key for j in ex.pilot_jobs(spec)})
