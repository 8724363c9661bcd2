"""The docs name what exists: files, ``tasker``'s flags, schedulers and strategies.

Read: ``README.md`` and ``docs/*.md``.  What they may name comes from the code itself — the
``tasker`` command's parsers (:func:`experiments.cli.build_parser`), the scheduler registry
(:func:`tasker.schedulers.names`, entry points included), the strategy levels of
:mod:`tasker.task` (``UPDATES``, ``SUSPENSIONS``, ``POLICIES``), the day protocols' registry —
never from a list typed here, so a scheduler or a strategy added to the code (``fallback``)
is expected of the docs at once.  What is checked:

* **files**: a path under a project folder (``experiments/sweep/spec.py``, ``docs/cli.md``,
  ``tests/…::test``) exists; a bare ``name.py`` is a file of the project (a user's own file is
  written ``my_….py``); in a table row whose first cell is a project folder (the README's
  tour), a ``.py``/``.md`` file or a folder the row names is inside it; a Markdown link leads
  to a file;
* **flags**: every ``--flag`` of a ``tasker CMD …`` command (in a code block or a code span, and
  in a row of ``docs/cli.md``'s table of commands) is an option of ``CMD``; any other
  ``--flag`` is an option of some ``tasker`` command, or of the script the line runs, or one
  of pytest's;
* **choices**: ``--flag a|b|c`` lists every choice the code has, and only those (for
  ``--suspension``, ``--update``, ``--policy``: the strategy levels); a single value after a
  flag with choices is one of them; a scenario or sweep key ``update``/``suspension``/
  ``policy`` holds levels that exist, and a comment explaining such a key names every level;
* **schedulers**: a name after ``--scheduler``/``--schedulers``, in ``scheduler = "…"`` or
  ``scheduler=…`` is registered; a list the doc marks ``<!-- checked: every scheduler -->``
  names exactly the registered schedulers; a day protocol after ``--protocol`` is registered.

``test_the_checks_catch_the_drift_issue_39_found`` feeds each check the drift issue 39 found
(``sweepspec.py``, a ``--suspension`` list without ``derived``, …), so none passes vacuously.
"""

from __future__ import annotations

import argparse
import functools
import re
import shlex
import subprocess
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ("README.md", *sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md")))
PROJECT_DIRS = ("tasker", "domains", "planners", "robot", "experiments", "tests", "benchmarks", "docs", ".ci")
PYTEST_FLAGS = frozenset({"-m", "-k", "-x", "-q", "-p", "--durations", "--collect-only"})
"""The pytest options the docs may show (pytest is not ours: its own parser is not read here)."""
MARK = "<!-- checked: every scheduler -->"


@dataclass(frozen=True)
class Problem:
    """Something a doc names that does not exist (or a list that misses something)."""

    doc: str
    line: int
    what: str

    def __str__(self) -> str:
        return f"{self.doc}:{self.line}: {self.what}"


# ----------------------------------------------------------------------------------------- what exists


@functools.cache
def _options() -> dict[str, frozenset[str]]:
    """Every ``tasker`` subcommand and its options (and ``""``: the top level's)."""
    from experiments.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    out = {"": frozenset(o for a in parser._actions for o in a.option_strings)}
    out.update({name: frozenset(o for a in p._actions for o in a.option_strings) for name, p in sub.choices.items()})
    return out


@functools.cache
def _choices() -> dict[str, frozenset[str]]:
    """The values a flag takes: the strategy levels of the model, else the choices of its parsers."""
    from experiments.cli import build_parser
    from tasker.harmoniser import Mode
    from tasker.task import POLICIES, SUSPENSIONS, UPDATES

    out: dict[str, set[str]] = {}
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    for p in sub.choices.values():
        for a in p._actions:
            if a.choices is not None and not isinstance(a, argparse._SubParsersAction):
                for o in a.option_strings:
                    out.setdefault(o, set()).update(str(c) for c in a.choices)
    out.update({"--suspension": set(SUSPENSIONS), "--update": set(UPDATES), "--policy": set(POLICIES),
                "--mode": {m.value for m in Mode}})
    return {k: frozenset(v) for k, v in out.items()}


@functools.cache
def _levels() -> dict[str, frozenset[str]]:
    """The levels of a strategy key (a scenario's ``[settings]``, a sweep spec, ``--strategies``)."""
    from tasker.task import POLICIES, SUSPENSIONS, UPDATES

    return {"update": frozenset(UPDATES), "suspension": frozenset(SUSPENSIONS), "policy": frozenset(POLICIES)}


@functools.cache
def _schedulers() -> frozenset[str]:
    from tasker import schedulers

    return frozenset(schedulers.names())


@functools.cache
def _protocols() -> frozenset[str]:
    from experiments.days import pipeline

    return frozenset(pipeline.names())


@functools.cache
def _project_files() -> frozenset[str]:
    """Every file git knows in the checkout (what a reader of the docs can open)."""
    done = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True)
    return frozenset(done.stdout.splitlines())


def _exists(rel: str) -> bool:
    rel = rel.rstrip("/")
    return rel in _project_files() or any(f.startswith(rel + "/") for f in _project_files())


# ----------------------------------------------------------------------------------------- reading a doc


def _lines(text: str) -> Iterator[tuple[int, str, bool]]:
    """(line number, line, inside a fenced code block) of a Markdown text; fence lines are left out."""
    fenced = False
    for n, line in enumerate(text.splitlines(), start=1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        yield n, line, fenced


def _spans(line: str) -> list[str]:
    """The code spans of a line (single backticks)."""
    return re.findall(r"`([^`]+)`", line)


def _commands(text: str) -> Iterator[tuple[int, str]]:
    """(line, command text) of every ``tasker …`` command: a fenced line (joined over ``\\``
    continuations, its ``#`` comment dropped) or a code span that starts with ``tasker ``."""
    pending: tuple[int, str] | None = None
    for n, line, fenced in _lines(text):
        if fenced:
            if pending is not None:
                start, head = pending
                line, n = head + " " + line.strip(), start
                pending = None
            stripped = line.strip().removeprefix("$ ")
            if stripped.endswith("\\"):
                pending = (n, stripped[:-1])
                continue
            if stripped.startswith("tasker ") or stripped.startswith("python -m experiments.cli "):
                yield n, re.sub(r"\s#.*$", "", stripped)
        else:
            for span in _spans(line):
                if span.startswith("tasker "):
                    yield n, span


def _words(command: str) -> list[str]:
    """A command's words, usage brackets and ellipses dropped (``[--workers N]…`` is ``--workers N``)."""
    command = command.replace("python -m experiments.cli ", "tasker ", 1).replace("\\|", "|")
    try:
        words = shlex.split(command)
    except ValueError:
        words = command.split()
    return [w.strip("[]…,;") for w in words if w.strip("[]…,;")]


def _flag(word: str) -> str | None:
    m = re.fullmatch(r"(--?[a-zA-Z][\w-]*)(=.*)?", word)
    return m.group(1) if m else None


def _placeholder(word: str) -> bool:
    """``NAME``, ``N``, ``SCHEDULER``, ``X``…: a value the reader fills in."""
    return bool(re.fullmatch(r"[A-Z][A-Z0-9_]*|\.\.\.|…|\{.*\}|<.*>", word))


# ----------------------------------------------------------------------------------------- the checks


def check_files(doc: str, text: str) -> list[Problem]:
    out = []
    for n, line, _ in _lines(text):
        row = re.match(r"\|\s*`([a-z_]+)/`\s*\|", line)  # a tour row: | `experiments/` | … |
        folder = row.group(1) if row and row.group(1) in PROJECT_DIRS else None
        for span in _spans(line):
            for word in span.split():
                word = word.split("::")[0].rstrip(".,;:)")
                word = re.sub(r":\d+$", "", word)  # file:line
                if any(c in word for c in "*{}<>$") or word.startswith(("-", "/", "~", "http")):
                    continue
                top = word.split("/")[0]
                if top in PROJECT_DIRS and "/" in word:
                    if not _exists(word):
                        out.append(Problem(doc, n, f"`{word}` does not exist"))
                elif folder and re.fullmatch(r"[\w/]+\.(py|md)|[a-z_]+/", word):
                    if not _exists(f"{folder}/{word}"):
                        out.append(Problem(doc, n, f"`{word}` is not in {folder}/ (this row's folder)"))
                elif re.fullmatch(r"[\w.-]+\.py", word) and not word.startswith("my_"):
                    if not any(Path(f).name == word for f in _project_files()):
                        out.append(Problem(doc, n, f"`{word}` is no file of the project"))
        for target in re.findall(r"\]\(([^)#\s]+)[^)]*\)", line):  # Markdown links to files
            if not target.startswith(("http:", "https:", "mailto:")):
                rel = (Path(doc).parent / target).as_posix()
                if not _exists(rel.removeprefix("./")):
                    out.append(Problem(doc, n, f"link to {target}, which does not exist"))
    return out


def _values(words: list[str], i: int) -> list[str]:
    """The values after the flag at ``words[i]`` (its ``=value`` or the words up to the next flag)."""
    if "=" in words[i]:
        return [words[i].split("=", 1)[1]]
    out = []
    for w in words[i + 1:]:
        if w.startswith("-"):
            break
        out.append(w.rstrip(":"))  # `--protocol tabsa-original`: (a sentence goes on)
    return out


def _check_values(doc: str, n: int, flag: str, values: list[str], out: list[Problem]) -> None:
    """The values written after ``flag``: alternatives ``a|b`` complete, scheduler and protocol names registered."""
    if not values or _placeholder(values[0]):
        return
    first = values[0]
    if flag in _choices():
        allowed = _choices()[flag]
        if "|" in first:
            written = set(first.split("|"))
            if written != allowed:
                missing, extra = sorted(allowed - written), sorted(written - allowed)
                out.append(Problem(doc, n, f"{flag} {first}: " + "; ".join(
                    part for part in (f"leaves out {missing}" if missing else "",
                                      f"names {extra}, not a choice" if extra else "") if part)))
        elif first not in allowed and not first.startswith(("$", "\"")):
            out.append(Problem(doc, n, f"{flag} {first}: not one of {sorted(allowed)}"))
    elif flag in ("--scheduler", "--schedulers"):
        for v in values if flag == "--schedulers" else values[:1]:
            name = v.split(":")[0]
            if not _placeholder(name) and name not in _schedulers():
                out.append(Problem(doc, n, f"{flag} {v}: no scheduler {name!r} is registered"))
    elif flag == "--protocol" and not first.endswith(".toml") and first not in _protocols():
        out.append(Problem(doc, n, f"--protocol {first}: no day protocol {first!r} is registered"))
    elif flag == "--strategies":
        for v in values:
            _check_label(doc, n, v, out)


def _check_label(doc: str, n: int, label: str, out: list[Problem]) -> None:
    """A strategy label (``update=planned,suspension=static``): each factor's level exists."""
    for part in label.split(","):
        key, _, value = part.partition("=")
        if key in _levels() and not _placeholder(value) and value not in _levels()[key]:
            out.append(Problem(doc, n, f"{part}: {key} is one of {sorted(_levels()[key])}"))
        elif key == "scheduler" and value and not _placeholder(value) and value not in _schedulers():
            out.append(Problem(doc, n, f"{part}: no scheduler {value!r} is registered"))


@functools.cache
def _script_flags(script: str) -> frozenset[str]:
    path = ROOT / script
    return frozenset(re.findall(r"--[a-z][\w-]*", path.read_text(encoding="utf-8"))) if path.is_file() else frozenset()


def check_flags(doc: str, text: str) -> list[Problem]:
    out: list[Problem] = []
    options = _options()
    everywhere = frozenset().union(*options.values())
    for n, command in _commands(text):
        words = _words(command)
        sub = next((w for w in words[1:] if not w.startswith("-")), "")
        if sub not in options:
            sub = ""  # `tasker --help`, or a table line such as `tasker plan (small, cold cache)`
        for i, w in enumerate(words[1:], start=1):
            flag = _flag(w)
            if flag is None:
                continue
            if flag not in options[sub] and flag not in options[""]:
                out.append(Problem(doc, n, f"`tasker {sub}` has no option {flag}"))
            else:
                _check_values(doc, n, flag, _values(words, i), out)
    cli_table = doc == "docs/cli.md"
    for n, line, fenced in _lines(text):
        if fenced:
            script = re.search(r"python (?:-m )?(\S+\.py|pytest)\b", line)
            for flag in re.findall(r"(?<![\w-])(--[a-z][\w-]*)", line.split(" #")[0]):
                if line.strip().startswith(("tasker ", "python -m experiments.cli")):
                    continue  # a command: checked above
                known = (_script_flags(script.group(1)) if script and script.group(1) != "pytest"
                         else PYTEST_FLAGS if script else everywhere)
                if flag not in known and flag not in everywhere:
                    out.append(Problem(doc, n, f"{flag}: no such option of {script.group(1) if script else 'tasker'}"))
            continue
        row = re.match(r"\|\s*`([a-z]+)[ `]", line) if cli_table else None
        row_sub = row.group(1) if row and row.group(1) in options else None
        for span in _spans(line):
            if span.startswith(("tasker ", "python ")) or "-->" in span:  # a command; an FSM row `a --ev--> b`
                continue
            words = _words(span)
            for i, w in enumerate(words):
                flag = _flag(w)
                if flag is None or not flag.startswith("--"):
                    continue
                if row_sub is not None and flag not in options[row_sub] | options[""]:
                    out.append(Problem(doc, n, f"`tasker {row_sub}` (this row) has no option {flag}"))
                elif flag not in everywhere and flag not in PYTEST_FLAGS and not any(
                        flag in _script_flags(f) for f in _project_files() if f.startswith("benchmarks/")):
                    out.append(Problem(doc, n, f"{flag}: no tasker command (nor benchmark script) has it"))
                else:
                    _check_values(doc, n, flag, _values(words, i), out)
    return out


def check_settings(doc: str, text: str) -> list[Problem]:
    """Strategy keys and scheduler names written as TOML (scenarios, sweep specs) or as labels."""
    out: list[Problem] = []
    for n, line, fenced in _lines(text):
        if fenced:
            m = re.match(r"\s*(update|suspension|policy|scheduler)\s*=\s*([^#]*?)\s*(?:#\s*(.*))?$", line)
            if m:
                key, value, comment = m.group(1), m.group(2), m.group(3) or ""
                allowed = _schedulers() if key == "scheduler" else _levels()[key]
                for v in re.findall(r'"([^"]*)"', value):
                    if v not in allowed:
                        out.append(Problem(doc, n, f'{key} = "{v}": not one of {sorted(allowed)}'))
                said = set(re.findall(r"[a-z]+", comment))
                if key != "scheduler" and said & _levels()[key]:  # a comment that lists the levels lists them all
                    missing = sorted(_levels()[key] - said)
                    if missing:
                        out.append(Problem(doc, n, f"the comment on {key} leaves out {missing}"))
        for span in _spans(line):
            if re.fullmatch(r"[a-z_]+=[\w-]+(,[a-z_]+=[\w-]+)*", span):
                _check_label(doc, n, span, out)
            for name in re.findall(r'schedulers\.create\("([^"]+)"', span if not fenced else line):
                if name not in _schedulers():
                    out.append(Problem(doc, n, f'schedulers.create("{name}"): not registered'))
    return out


def check_marked_lists(doc: str, text: str) -> list[Problem]:
    """A block marked :data:`MARK` names exactly the registered schedulers (the block: the lines up to
    a blank line or the next list item)."""
    out: list[Problem] = []
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if MARK not in line:
            continue
        block = [line.split(MARK, 1)[1]]
        for nxt in lines[i + 1:]:
            if not nxt.strip() or re.match(r"\s*([-*]|\d+\.)\s", nxt):
                break
            block.append(nxt)
        named = {s for s in _spans(" ".join(block)) if re.fullmatch(r"[a-z][a-z0-9]*(-[a-z0-9]+)*", s)}
        missing, extra = sorted(_schedulers() - named), sorted(named - _schedulers())
        if missing:
            out.append(Problem(doc, i + 1, f"the list of every scheduler leaves out {missing}"))
        if extra:
            out.append(Problem(doc, i + 1, f"the list of every scheduler names {extra}, which are not registered"))
    return out


CHECKS = (check_files, check_flags, check_settings, check_marked_lists)


# ----------------------------------------------------------------------------------------- the tests


@pytest.mark.parametrize("doc", DOCS)
def test_a_doc_names_only_what_exists(doc: str) -> None:
    text = (ROOT / doc).read_text(encoding="utf-8")
    problems = [p for check in CHECKS for p in check(doc, text)]
    assert not problems, "\n".join(map(str, problems))


def test_the_strategy_levels_the_docs_are_held_to_are_the_command_lines_too() -> None:
    """The docs are checked against tasker.task's levels; the CLI's choices and the sweep's levels
    (typed again in experiments/) must be the same, or a doc could be right and the command refuse it."""
    from experiments.cli import build_parser
    from experiments.inputs import strategy

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    run = {o: set(a.choices) for a in sub.choices["run"]._actions if a.choices for o in a.option_strings}
    for flag, key in (("--suspension", "suspension"), ("--update", "update"), ("--policy", "policy")):
        assert run[flag] == set(_levels()[key]), flag
    assert set(strategy.SUSPENSION_VALUES) == set(_levels()["suspension"])
    assert set(strategy.STRATEGY_VALUES) == set(_levels()["update"])
    assert set(strategy.POLICY_VALUES) == set(_levels()["policy"])


def test_the_registrys_lists_are_marked_for_checking() -> None:
    """The README's list of the scheduler registry, and docs/model.md's of the indexed ones, are
    checked as complete: they carry the mark."""
    for doc in ("README.md", "docs/model.md"):
        assert MARK in (ROOT / doc).read_text(encoding="utf-8"), doc


def test_model_md_says_which_schedulers_pick_from_the_index() -> None:
    """docs/model.md's marked list splits the registry at "do;": those before it are the indexed ones."""
    from tasker import schedulers

    text = (ROOT / "docs" / "model.md").read_text(encoding="utf-8")
    block = text.split(MARK, 1)[1].split(" do;", 1)[0]
    said = {s for s in _spans(block.replace("\n", " ")) if re.fullmatch(r"[a-z][a-z0-9-]*", s)}
    assert said == {n for n in schedulers.names() if schedulers.create(n).indexed}


@pytest.mark.parametrize(("text", "found"), [
    ("| `experiments/` | sweeps (`strategy.py`, `sweepspec.py`, `sweep.py`) |", ["`strategy.py` is not in",
                                                                              "`sweepspec.py` is not in",
                                                                              "`sweep.py` is not in"]),
    ("see `experiments/sweep/sweep.py` and `sweepspec.py`", ["does not exist", "no file of the project"]),
    ("| `docs/` | `model.md`, `nowhere.md` | and [the page](docs/gone.md)", ["`nowhere.md` is not in docs/",
                                                                           "link to docs/gone.md"]),
    ("`--seed N`, `--suspension static|planned`, `--mode IT|CT`", ["--suspension static|planned: leaves out"]),
    ("`--update static|planned|derived`", ["names ['derived'], not a choice"]),
    ("```bash\ntasker run paper --suspension derivd --fast\n```", ["not one of", "has no option --fast"]),
    ("```bash\ntasker day --protocol tabsa-longest --schedulers alg2 edf-2 \\\n    --out out/x\n```",
     ["no day protocol 'tabsa-longest'", "no scheduler 'edf-2'"]),
    ("`tasker fsm guide_human --strategy planned\\|static --format mermaid\\|svg`", ["--format mermaid|svg"]),
    ("| `explain RUN_DIR` | the plan (`--at T`, `--json`) |", ["`tasker explain` (this row) has no option --json"]),
    ("```toml\nsuspension = \"planned\"     # genSusp: planned (PDDL) or static (eq. 47 tree)\n```",
     ["the comment on suspension leaves out ['derived', 'fallback']"]),
    ("```toml\nscheduler = \"alg3\"\nsuspension = [\"static\", \"later\"]\n```", ["alg3", "later"]),
    ("strategies `update=static,suspension=sometimes` and `scheduler=fifo2`", ["suspension is one of",
                                                                              "no scheduler 'fifo2'"]),
    (f"{MARK}\nSchedulers: `alg2`, `fifo` and `bogus`.", ["leaves out", "names ['bogus']"]),
])
def test_the_checks_catch_the_drift_issue_39_found(text: str, found: list[str], tmp_path: Path) -> None:
    doc = "docs/cli.md" if text.startswith("| `explain") else "docs/example.md"
    problems = "\n".join(str(p) for check in CHECKS for p in check(doc, text))
    for fragment in found:
        assert fragment in problems, f"{fragment!r} not in:\n{problems}"


def test_good_text_passes_the_checks() -> None:
    """The other side: what exists raises nothing (the checks are not merely strict)."""
    from tasker import schedulers
    from tasker.task import SUSPENSIONS, UPDATES

    every = ", ".join(f"`{n}`" for n in schedulers.names())
    text = (f"{MARK}\nSchedulers: {every}.\n\n"
            f"`--suspension {'|'.join(SUSPENSIONS)}`, `--update {'|'.join(UPDATES)}`, see "
            "`experiments/sweep/spec.py`, `docs/cli.md`, `tests/tasker/test_trace.py::test_encoding_is_canonical`\n\n"
            "| `experiments/` | sweeps (`inputs/strategy.py`, `sweep/spec.py`, `sweep/`) |\n\n"
            "```bash\ntasker day --protocol tabsa --schedulers alg2 lookahead:horizon=3 \\\n"
            "    --strategies suspension=static suspension=derived --out out/day\n```\n")
    problems = [str(p) for check in CHECKS for p in check("docs/example.md", text)]
    assert problems == []
