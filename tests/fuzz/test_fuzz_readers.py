"""Fuzzing every reader of a user's file: random and mutated text is a value or a TaskerError.

The seeds are the shipped files (scenarios, a sweep spec, a world, a day protocol, the task-folder
template, a domain); each example mutates one (:func:`tests.fuzz.conftest.mutated`) and reads it
with the reader every command uses.  Anything but a :class:`~tasker.errors.TaskerError` would be
a traceback and exit 3 on the command line; an example that runs for seconds is a hang.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tasker.errors import TaskerError
from tasker.support import reader
from tests.fuzz.conftest import bounded, examples, mutated

ROOT = Path(__file__).resolve().parents[2]
SEEDS = {
    "synthetic": ROOT / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml",
    "robot": ROOT / "experiments" / "inputs" / "scenarios" / "paper.toml",
    "spec": ROOT / "experiments" / "sweep" / "specs" / "factorial.toml",
    "world": ROOT / "robot" / "worlds" / "flat.toml",
    "protocol": ROOT / "experiments" / "days" / "protocols" / "tabsa_short.toml",
    "task": ROOT / "planners" / "template" / "task.toml",
    "domain": ROOT / "domains" / "cook" / "domain.pddl",
}


def _reads_cleanly(fn: Callable[[], Any], seconds: float = 10.0) -> None:
    """``fn()`` returns, or raises a TaskerError with a message; nothing else, never for long."""
    with bounded(seconds), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # doubtful input warns: a fact, not a fault
        try:
            fn()
        except TaskerError as exc:
            assert str(exc).strip(), "an error without a message"


@pytest.fixture(scope="module")
def scratch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


@pytest.mark.slow
@examples(300)
@given(st.text(max_size=300) | st.binary(max_size=300).map(lambda b: b.decode("latin-1")))
def test_random_text_is_toml_or_a_clean_error(text: str) -> None:
    _reads_cleanly(lambda: reader.loads(text, "f.toml"))


@pytest.mark.slow
@examples(300)
@given(st.text(alphabet="[]{}\",:0123456789.eE-+ aZ\\ntrueflsn", max_size=300))
def test_random_text_is_json_or_a_clean_error(text: str) -> None:
    _reads_cleanly(lambda: reader.parse_json(text, "f.json"))


def _write(scratch: Path, name: str, data: bytes) -> Path:
    p = scratch / name
    p.write_bytes(data)
    return p


@pytest.mark.slow
@examples(120)
@given(mutated(SEEDS["synthetic"].read_bytes()))
def test_a_mutated_synthetic_scenario(scratch: Path, data: bytes) -> None:
    from experiments.inputs import synthetic

    p = _write(scratch, "synthetic.toml", data)
    _reads_cleanly(lambda: synthetic.build(synthetic.load(p), seed=1))


@pytest.fixture(scope="module")
def robot_loaded() -> None:
    """The first robot scenario loads the robot's model (seconds, cold): not part of any example."""
    from experiments.inputs import scenario as scenarios

    scenarios.load(SEEDS["robot"])


@examples(15)
@given(mutated(SEEDS["robot"].read_bytes()))
def test_a_mutated_robot_scenario(scratch: Path, robot_loaded: None, data: bytes) -> None:
    from experiments.inputs import scenario as scenarios

    p = _write(scratch, "robot.toml", data)
    _reads_cleanly(lambda: scenarios.load(p) if scenarios.kind_of(p) == "robot" else None, seconds=30.0)


@examples(40)
@given(mutated(SEEDS["spec"].read_bytes()))
def test_a_mutated_sweep_spec(scratch: Path, data: bytes) -> None:
    from experiments.sweep.spec import load_spec

    (scratch / "scenarios").mkdir(exist_ok=True)
    compound = SEEDS["spec"].parent / "scenarios" / "compound.toml"
    (scratch / "scenarios" / "compound.toml").write_bytes(compound.read_bytes())
    p = _write(scratch, "spec.toml", data)
    _reads_cleanly(lambda: load_spec(p))


@examples(40)
@given(mutated(SEEDS["world"].read_bytes()))
def test_a_mutated_world(scratch: Path, data: bytes) -> None:
    from robot.spec import load_world

    p = _write(scratch, "world.toml", data)
    _reads_cleanly(lambda: load_world(p))


@examples(40)
@given(mutated(SEEDS["protocol"].read_bytes()))
def test_a_mutated_day_protocol(scratch: Path, data: bytes) -> None:
    from experiments.days import protocol

    p = _write(scratch, "protocol.toml", data)
    _reads_cleanly(lambda: protocol.load(p))


@examples(100)
@given(mutated(SEEDS["task"].read_bytes().replace(b"__TASK__", b"fuzzed").replace(b"__DIR__", b"fuzzed")))
def test_a_mutated_task_toml(scratch: Path, data: bytes) -> None:
    from planners.taskspec import read_task_toml

    p = _write(scratch, "task.toml", data)
    _reads_cleanly(lambda: read_task_toml(p))


@pytest.mark.slow
@examples(20)
@given(mutated(SEEDS["domain"].read_bytes()))
def test_a_mutated_domain(scratch: Path, data: bytes) -> None:
    from planners.checks import load_domain

    p = _write(scratch, "domain.pddl", data)
    _reads_cleanly(lambda: load_domain(p), seconds=20.0)


@pytest.mark.slow
@examples(200)
@given(st.text(alphabet="() ;-?:abcdefxyz\n", max_size=400))
def test_random_pddl_text_passes_the_cheap_checks_or_is_refused(text: str) -> None:
    from planners.checks import check_depth, check_types

    _reads_cleanly(lambda: (check_depth(text, "d.pddl"), check_types(text, "d.pddl")))


@examples(25)
@given(kind=st.sampled_from(["synthetic", "spec", "world", "protocol"]), data=st.data())
def test_tasker_check_on_a_mutated_file_never_ends_in_an_internal_error(
        scratch: Path, kind: str, data: st.DataObject, capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.cli import main

    p = _write(scratch, f"check-{kind}.toml", data.draw(mutated(SEEDS[kind].read_bytes())))
    with bounded(30.0), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        status = main(["check", str(p), "-q"])
    err = capsys.readouterr().err
    assert status in (0, 1) and "internal error" not in err, err
