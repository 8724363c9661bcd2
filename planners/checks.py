"""Load and check PDDL before anything runs: errors name the file, the line and the fault.

unified-planning's ``PDDLReader`` does the reading (it is built on pyparsing): a syntax
error is a ``pyparsing.ParseBaseException`` carrying ``lineno``/``col``, a semantic
one (unknown predicate, wrong arity, undefined type or object, missing goal) a
``SyntaxError`` whose message holds ``line: N, col M``.  The domain is read alone
first, so an error is blamed on the right file.  Requirements that Fast Downward
cannot handle are refused from the domain's ``:requirements`` and from the problem
kind UP computes.

unified-planning and pyparsing are imported by the checks that use them, not by this
module: its exceptions are raised by code (task loading from remembered checks,
:mod:`planners.problem`) that must not pay for them.
"""

from __future__ import annotations

import contextlib
import io
import re
import threading
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from tasker.errors import DefinitionError as DefinitionError  # defined there; re-exported here
from tasker.errors import PddlError as PddlError
from tasker.support import reader

if TYPE_CHECKING:
    import unified_planning as up
    from unified_planning.io.pddl_reader import PDDLGrammar

SUPPORTED_REQUIREMENTS = frozenset({
    ":strips", ":typing", ":negative-preconditions", ":disjunctive-preconditions", ":equality",
    ":existential-preconditions", ":universal-preconditions", ":quantified-preconditions",
    ":conditional-effects", ":adl", ":action-costs",
})
"""PDDL requirements the classical planners here (Fast Downward) accept."""

# Numbers read from PDDL are Real to UP; integral ones are fine for Fast Downward.
_TOLERATED_FEATURES = frozenset({"REAL_NUMBERS_IN_ACTIONS_COST", "UNDEFINED_INITIAL_NUMERIC"})
_LINE_RE = re.compile(r"line:?\s*(\d+),\s*col:?\s*(\d+)")
_SPAN_RE = re.compile(
    r"[\s.,]*(?:Error from|found at|from|From)?\s*line:?\s*\d+,\s*col:?\s*\d+\s*to\s*line:?\s*\d+,\s*col:?\s*\d+\.?"
)
_WRAPPED_RE = re.compile(r"UP\w+Error\('(.*)'\)")
_grammar: PDDLGrammar | None = None
_names_lock = threading.Lock()


@contextlib.contextmanager
def _lenient_names() -> Iterator[None]:
    """PDDL keeps types and objects in separate namespaces (an object ``robot`` of type
    ``robot`` is fine); UP refuses that unless ``error_used_name`` is off while reading."""
    from unified_planning.environment import get_environment

    env = get_environment()
    with _names_lock, warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*already defined.*")
        warnings.filterwarnings("ignore", message=".*'parseString' deprecated.*")  # inside UP's reader
        old, env.error_used_name = env.error_used_name, False
        try:
            yield
        finally:
            env.error_used_name = old


def _read(path: str | Path) -> str:
    """The file's text; a non-UTF-8 byte is named with its line (:func:`tasker.support.reader.read_text`)."""
    p = Path(path)
    if not p.is_file():
        raise PddlError(p, "no such file")
    try:
        return reader.read_text(p)
    except reader.InputError as exc:
        raise PddlError(p, exc.message, exc.line) from None


def _located(file: str | Path, exc: BaseException) -> PddlError:
    """Turn a reader exception into a :class:`PddlError` with the line when there is one."""
    import pyparsing

    if isinstance(exc, pyparsing.ParseBaseException):
        return PddlError(file, f"syntax error: {exc.msg}", exc.lineno, exc.col)
    text = str(exc).strip()
    m = _LINE_RE.search(text)
    reason = _SPAN_RE.sub("", text)
    reason = _WRAPPED_RE.sub(r"\1", reason)
    reason = reason.replace("Not able to handle:", "unknown predicate or invalid expression:")
    reason = reason.replace("Found invalid expression:", "unknown object or invalid expression:")
    reason = re.sub(r"\s+", " ", reason).strip(" .,:")
    line, col = (int(m.group(1)), int(m.group(2))) if m else (None, None)
    return PddlError(file, reason or type(exc).__name__, line, col)


def declared_requirements(domain_text: str, file: str | Path = "<domain>") -> tuple[str, ...]:
    """The ``:requirements`` a domain declares, read with UP's own PDDL grammar."""
    import pyparsing
    from unified_planning.io.pddl_reader import PDDLGrammar
    from unified_planning.io.utils import parse_string

    global _grammar
    if _grammar is None:
        _grammar = PDDLGrammar()
    try:
        res = parse_string(_grammar.domain, domain_text.replace("\t", " ").lower(), parse_all=True)
    except pyparsing.ParseBaseException as exc:
        raise _located(file, exc) from None
    return tuple(str(f) for f in res.get("features", []) if str(f) != ":requirements")


def _nested(domain_text: str) -> list[object] | None:
    """The domain as Fast Downward's s-expression reader sees it (lower case, no comments),
    or ``None`` when it cannot read it (unbalanced parentheses, no token at all)."""
    from fast_downward.translate.pddl_parser import lisp_parser
    from fast_downward.translate.pddl_parser.parse_error import ParseError

    try:
        nested: list[object] = lisp_parser.parse_nested_list(io.StringIO(domain_text))
    except (ParseError, StopIteration, RecursionError):  # StopIteration: no token at all
        return None
    return nested


def _supported_at_a_glance(domain_text: str) -> bool:
    """Whether Fast Downward's s-expression reader (a few ms, no grammar) finds the domain's
    ``:requirements`` all supported.  When it does, unified-planning's grammar would read them
    the same way, and any syntax error elsewhere is reported by :func:`parse_domain`, which
    reads the whole text with that grammar next; otherwise the grammar decides (and words it)."""
    nested = _nested(domain_text)
    if nested is None:
        return False
    blocks = [b for b in nested if isinstance(b, list) and b and b[0] == ":requirements"]
    return len(blocks) <= 1 and all(len(b) > 1 for b in blocks) and all(
        isinstance(r, str) and r in SUPPORTED_REQUIREMENTS for b in blocks for r in b[1:])


def check_requirements(domain_text: str, file: str | Path) -> None:
    """Refuse a domain that declares a requirement Fast Downward cannot handle."""
    if _supported_at_a_glance(domain_text):
        return
    bad = [r for r in declared_requirements(domain_text, file) if r not in SUPPORTED_REQUIREMENTS]
    if bad:
        line = next((i for i, s in enumerate(domain_text.splitlines(), 1) if bad[0] in s.lower()), None)
        raise PddlError(file, f"unsupported requirement(s) {' '.join(bad)}; supported: "
                              f"{' '.join(sorted(SUPPORTED_REQUIREMENTS))}", line)


_INSTEAD = {
    "either": "(either ...) types: unified-planning's PDDL reader cannot read them, so a task folder cannot use "
              "them (tasker plan reads them with Fast Downward's translator): declare a common supertype instead, "
              "e.g. (:types item robot - carriable), and use it",
    "derived": ":derived predicates: unified-planning's PDDL reader cannot read them, so a task folder cannot use "
               "them (tasker plan reads them with Fast Downward's translator): compute the predicate in task.py's "
               "extra_facts (as domains/doors.py does for free_passage), or write its condition into the "
               "actions' preconditions",
}
_CONSTRUCT_RE = {"either": re.compile(r"-\s*(\(\s*either\b)", re.IGNORECASE),
                 "derived": re.compile(r"(\(\s*:derived\b|:derived-predicates\b)", re.IGNORECASE)}


def _uses_either(node: object) -> bool:
    """Whether ``- (either ...)`` is a type anywhere in Fast Downward's nested list."""
    if not isinstance(node, list):
        return False
    pairs = zip(node, node[1:], strict=False)
    if any(prev == "-" and isinstance(x, list) and x[:1] == ["either"] for prev, x in pairs):
        return True
    return any(_uses_either(x) for x in node)


def check_constructs(domain_text: str, file: str | Path) -> None:
    """Refuse ``(either ...)`` types and ``:derived`` predicates plainly, with their line:
    unified-planning's reader would call them "syntax error: Expected ')'" somewhere else.
    Fast Downward's s-expression reader finds them; the line is that of the first occurrence
    outside comments."""
    nested = _nested(domain_text)
    if nested is None:
        return  # unbalanced: unified-planning's grammar words the syntax error
    derived = any(isinstance(b, list) and b[:1] == [":derived"] for b in nested) or any(
        isinstance(b, list) and b[:1] == [":requirements"] and ":derived-predicates" in b for b in nested)
    for what in [w for w, found in (("either", _uses_either(nested)), ("derived", derived)) if found]:
        code = "\n".join(s.split(";", 1)[0] for s in domain_text.splitlines())
        m = _CONSTRUCT_RE[what].search(code)
        at = m.start(1) if m else 0
        line, col = (code.count("\n", 0, at) + 1, at - code.rfind("\n", 0, at)) if m else (None, None)
        raise PddlError(file, _INSTEAD[what], line, col, reader_only=True)


def check_repeated_parameters(domain_text: str, file: str | Path) -> None:
    """Refuse a predicate that names one parameter twice (logistics00's ``(in ?obj ?obj)``), which PDDL
    allows: unified-planning's reader keeps one of them and then calls every use of the predicate
    "arity 1 but 2 parameters were passed", at the use.  Read from Fast Downward's s-expression reader."""
    nested = _nested(domain_text)
    if nested is None:
        return
    for block in nested:
        if not (isinstance(block, list) and block[:1] == [":predicates"]):
            continue
        for pred in block[1:]:
            if not (isinstance(pred, list) and pred and isinstance(pred[0], str)):
                continue
            names = [x for x in pred[1:] if isinstance(x, str) and x.startswith("?")]
            twice = next((n for k, n in enumerate(names) if n in names[:k]), None)
            if twice is not None:
                code = _COMMENT.sub("", domain_text)
                m = re.search(rf"\(\s*{re.escape(pred[0])}\s+{re.escape(twice)}\b", code, re.IGNORECASE)
                line = code.count("\n", 0, m.start()) + 1 if m else None
                raise PddlError(file, f"predicate {pred[0]} names parameter {twice} twice: unified-planning's reader "
                                      f"keeps one, and every use of {pred[0]} then has an argument too many; give "
                                      f"each parameter its own name, e.g. ({pred[0]} {twice} {twice}2)", line,
                                reader_only=True)


_GLUED = re.compile(r"[A-Za-z0-9_\-]\?[A-Za-z]")


def check_glued_variables(text: str, file: str | Path) -> None:
    """Refuse a name glued to a variable (zenotravel's ``(aircraft?a)``): PDDL's names cannot hold ``?``,
    so it reads as ``(aircraft ?a)``, and Fast Downward's reader splits it so; unified-planning's takes
    it for one unknown name.  The line and the spaced form are named."""
    code = _COMMENT.sub("", text)
    m = _GLUED.search(code)
    if m:
        start = max(code.rfind("(", 0, m.start()), code.rfind(" ", 0, m.start()), code.rfind("\t", 0, m.start())) + 1
        line, col = code.count("\n", 0, start) + 1, start - code.rfind("\n", 0, start)
        word = re.match(r"[^\s()]*", code[start:])
        glued = word.group(0) if word else m.group(0)
        raise PddlError(file, f"{glued}: a name and a variable without a space between them, which unified-planning's "
                              f"reader takes for one name; write {glued.replace('?', ' ?', 1)}", line, col,
                        reader_only=True)


_COST_INIT = re.compile(r"\(\s*=\s*\(\s*total-cost\s*\)", re.IGNORECASE)
_INIT = re.compile(r"\(\s*:init\b", re.IGNORECASE)


def check_kind(problem: up.model.Problem, file: str | Path, domain_text: str = "", problem_text: str = "") -> None:
    """Refuse a problem whose UP problem kind needs features the planner lacks.  Action costs whose
    problem does not set ``(= (total-cost) 0)`` (which PDDL lets it omit: FD assumes 0) are named
    as such, not in UP's words for numeric planning."""
    from planners.kind import supported_kind

    supported = set(supported_kind().features)
    extra = sorted(set(problem.kind.features) - supported - _TOLERATED_FEATURES)
    if not extra:
        return
    code = _COMMENT.sub("", problem_text)
    if "INCREASE_EFFECTS" in extra and re.search(r"\(\s*total-cost\s*\)", _COMMENT.sub("", domain_text),
                                                   re.IGNORECASE) and not _COST_INIT.search(code):
        m = _INIT.search(code)
        raise PddlError(file, "the problem's :init does not set (= (total-cost) 0): unified-planning's reader takes "
                              "(increase (total-cost) ...) for action costs only when it does (Fast Downward assumes "
                              "0); add (= (total-cost) 0) to :init",
                        code.count("\n", 0, m.start()) + 1 if m else None, reader_only=True)
    raise PddlError(file, f"unsupported PDDL features for a classical planner: {', '.join(extra)}")


@dataclass(frozen=True, slots=True)
class CheckedDomain:
    """A domain that passed the checks (now, or in a process that remembered it: :mod:`planners.cache`).

    Only its file and text: what task types need of it is :class:`planners.problem.DomainModel`.
    """

    path: Path
    text: str


MAX_PDDL_DEPTH = 32
"""Parentheses within each other at most this deep: a task's domain needs about 8 (an effect's
``when`` inside ``forall`` inside ``and``); unified-planning's reader runs out of Python's recursion
at about 50."""

_COMMENT = re.compile(r";[^\n]*")


def check_depth(text: str, file: str | Path) -> None:
    """Refuse PDDL nested deeper than :data:`MAX_PDDL_DEPTH` (a very deep goal), with its line: the
    readers (unified-planning's, Fast Downward's) recurse once a level and would crash on it."""
    depth = 0
    for n, line in enumerate(_COMMENT.sub("", text).split("\n"), start=1):
        for ch in line:
            if ch == "(":
                depth += 1
                if depth > MAX_PDDL_DEPTH:
                    raise PddlError(file, f"parentheses nested more than {MAX_PDDL_DEPTH} deep: the PDDL readers "
                                          "cannot read it (write the goal or condition flatter)", n)
            elif ch == ")":
                depth -= 1


def _types_line(text: str) -> int | None:
    m = re.search(r"\(\s*:types\b", _COMMENT.sub("", text), re.IGNORECASE)
    return text.count("\n", 0, m.start()) + 1 if m else None


def check_types(domain_text: str, file: str | Path) -> None:
    """Refuse a cycle of types (``a - b`` and ``b - a``): each reader follows the parents up and
    never gets to ``object``.  Read from Fast Downward's s-expression reader."""
    nested = _nested(domain_text)
    if nested is None:
        return
    parent: dict[str, str] = {}
    for block in nested:
        if isinstance(block, list) and block[:1] == [":types"]:
            pending: list[str] = []
            items = block[1:]
            i = 0
            while i < len(items):
                tok = items[i]
                if tok == "-" and i + 1 < len(items) and isinstance(items[i + 1], str):
                    for name in pending:
                        parent.setdefault(name, items[i + 1])
                    pending, i = [], i + 2
                    continue
                if isinstance(tok, str):
                    pending.append(tok)
                i += 1
    for start in parent:
        seen = [start]
        node = start
        while node in parent:
            node = parent[node]
            if node in seen:
                cycle = seen[seen.index(node):] + [node]
                raise PddlError(file, f"the types form a cycle: {' - '.join(cycle)} (each type's parent must lead "
                                      "to object)", _types_line(domain_text))
            seen.append(node)


def _domain_name(text: str) -> tuple[str, int] | None:
    """The name a PDDL text gives its domain (``(domain NAME)`` or a problem's ``(:domain NAME)``), and its line."""
    code = _COMMENT.sub("", text)
    m = re.search(r"\(\s*:?domain\s+([^\s()]+)", code, re.IGNORECASE)
    return (m.group(1).lower(), code.count("\n", 0, m.start()) + 1) if m else None


def check_problem_domain(domain_text: str, problem_text: str, file: str | Path) -> None:
    """A problem names its domain (``(:domain NAME)``): one naming another was planned silently."""
    mine, theirs = _domain_name(domain_text), _domain_name(problem_text)
    if mine and theirs and mine[0] != theirs[0]:
        raise PddlError(file, f"the problem is for domain {theirs[0]!r}, but the domain given is {mine[0]!r} "
                              "(give the problem's own domain, or correct its (:domain ...))", theirs[1])


def load_domain(path: str | Path) -> CheckedDomain:
    """Read and check a ``domain.pddl``; raise :class:`PddlError` naming the file and line."""
    text = _read(path)
    check_depth(text, path)
    check_types(text, path)
    check_constructs(text, path)
    check_repeated_parameters(text, path)
    check_glued_variables(text, path)
    check_requirements(text, path)
    check_numeric(parse_domain(text, path), text, path)
    return CheckedDomain(Path(path), text)


def check_numeric(domain: up.model.Problem, text: str, file: str | Path) -> None:
    """Refuse numeric fluents in conditions and effects other than ``total-cost``'s: the classical
    planner cannot handle them (its parser would say "Undefined predicate Got: decrease")."""
    fve = domain.environment.free_vars_extractor
    for a in domain.actions:
        used = [("an effect on", e.fluent) for e in getattr(a, "effects", ())
                if not e.fluent.type.is_bool_type() and e.fluent.fluent().name != "total-cost"]
        used += [("a condition on", f) for c in getattr(a, "preconditions", ()) for f in fve.get(c)
                 if not f.type.is_bool_type()]
        if used:
            what, fluent = used[0]
            name = fluent.fluent().name
            lines = text.splitlines()
            start = next((i for i, s in enumerate(lines) if re.search(rf"\(:action\s+{re.escape(a.name)}\b", s,
                                                                       re.IGNORECASE)), 0)
            line = next((i + 1 for i in range(start, len(lines)) if f"({name}" in lines[i].lower()), None)
            raise PddlError(file, f"action {a.name}: {what} the numeric fluent {name}: unsupported PDDL features "
                                  "(numeric fluents are supported only as action costs: (increase (total-cost) "
                                  "...) by a constant or a fluent fixed in the problem such as travel-time)", line)


def remembered_domain(path: str | Path) -> CheckedDomain:
    """A ``domain.pddl`` whose checks passed before with this exact content (the caller
    knows it from :mod:`planners.cache`): read, not checked again."""
    return CheckedDomain(Path(path), _read(path))


def parse_domain(text: str, file: str | Path = "<domain>") -> up.model.Problem:
    """UP's domain-only model of ``text``; raise :class:`PddlError` naming ``file`` and the line."""
    import pyparsing
    import unified_planning as up
    from unified_planning.io import PDDLReader

    check_depth(text, file)
    try:
        with _lenient_names():
            return PDDLReader().parse_problem_string(text)
    except (pyparsing.ParseBaseException, SyntaxError, up.exceptions.UPException, KeyError, ValueError) as exc:
        raise _located(file, exc) from None
    except RecursionError:  # deeper than unified-planning's reader manages, though within check_depth
        raise PddlError(file, "nested too deep for the PDDL reader (write it flatter)") from None


def load_problem_text(
    domain: CheckedDomain, problem_text: str, problem_file: str | Path = "<problem>"
) -> up.model.Problem:
    """Parse a problem against a checked domain; check its goal and problem kind."""
    import pyparsing
    import unified_planning as up
    from unified_planning.io import PDDLReader

    check_depth(problem_text, problem_file)
    check_problem_domain(domain.text, problem_text, problem_file)
    check_glued_variables(problem_text, problem_file)
    try:
        with _lenient_names():
            problem = PDDLReader().parse_problem_string(domain.text, problem_text)
    except (pyparsing.ParseBaseException, SyntaxError, up.exceptions.UPException, KeyError, ValueError) as exc:
        raise _located(problem_file, exc) from None
    except RecursionError:
        raise PddlError(problem_file, "nested too deep for the PDDL reader (write it flatter)") from None
    check_kind(problem, problem_file, domain.text, problem_text)
    return problem


def load_problem(domain_path: str | Path, problem_path: str | Path) -> tuple[CheckedDomain, str, up.model.Problem]:
    """Load and check a domain/problem pair; return the domain, the problem text and UP's model."""
    domain = load_domain(domain_path)
    text = _read(problem_path)
    return domain, text, load_problem_text(domain, text, problem_path)
