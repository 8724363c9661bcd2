"""Reading temporal PDDL (2.1) with unified-planning's reader, as PlanSys2 and ROSPlan write it.

A domain is *temporal* when it has a ``(:durative-action`` or declares ``:durative-actions``
(a ROSPlan domain may declare it and have only instantaneous actions: the engines here plan
those too).  Such a domain goes to :mod:`planners.temporal`; every other one to the classical
path, unchanged.

PlanSys2's domain template writes empty blocks — ``(:functions )`` with only a comment
inside — which UP's reader refuses ("Expected '('").  :func:`tolerant` blanks an empty
``:functions``, ``:predicates`` or ``:constants`` block out (spaces in place of its characters,
its newlines kept), so every line and column an error names is still the file's own.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

from planners.checks import PddlError, check_depth, check_problem_domain
from tasker.errors import TaskerError

if TYPE_CHECKING:
    import unified_planning as up

_COMMENT = re.compile(r";[^\n]*")
_DURATIVE = re.compile(r"\(\s*:durative-action\b|:durative-actions\b", re.IGNORECASE)
_EMPTY_BLOCK = re.compile(r"\(\s*:(?:functions|predicates|constants)(?:\s|;[^\n]*)*\)", re.IGNORECASE)


def is_temporal(domain_text: str) -> bool:
    """Whether the domain is PDDL 2.1 temporal: a durative action, or the requirement declared."""
    return _DURATIVE.search(_COMMENT.sub("", domain_text)) is not None


def tolerant(text: str) -> str:
    """``text`` with PlanSys2's empty blocks blanked out, lines and columns unchanged."""
    return _EMPTY_BLOCK.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)


def parse(domain_text: str, problem_text: str | None, domain_file: str | Path,
          problem_file: str | Path = "<problem>") -> up.model.Problem:
    """UP's model of a temporal domain (and problem); a fault is a :class:`PddlError` naming the
    file (the domain's when the domain alone is at fault), the line and the column."""
    from planners.checks import parse_domain

    domain_text = tolerant(domain_text)
    try:
        model = parse_domain(domain_text, domain_file)  # blames the domain for the domain's faults
    except TaskerError:
        raise
    except Exception as exc:  # noqa: BLE001 - the reader's own failure (an assertion) on this input
        raise _failed(domain_file, exc) from None
    if problem_text is None:
        return model
    check_depth(problem_text, problem_file)
    check_problem_domain(domain_text, problem_text, problem_file)
    problem_text = tolerant(problem_text)
    constants = {o.name.lower(): o.type.name for o in model.all_objects}
    if constants:  # PlanSys2's problems may declare a domain constant again (POPF accepts it; UP does not)
        problem_text = without_constants(problem_text, constants)
    return _parse_problem(domain_text, problem_text, problem_file)


def without_constants(problem_text: str, constants: dict[str, str]) -> str:
    """``problem_text`` with the ``:objects`` entries that declare a domain constant again, with
    its own type, blanked out (spaces; lines and columns kept).  Another type stays, for UP's
    reader to refuse."""
    code = _COMMENT.sub(lambda c: " " * len(c.group(0)), problem_text)  # positions kept
    m = re.search(r"\(\s*:objects\b", code, re.IGNORECASE)
    if m is None:
        return problem_text
    depth, end = 0, None
    for i in range(m.start(), len(code)):
        if code[i] == "(":
            depth += 1
        elif code[i] == ")":
            depth -= 1
            if depth == 0:
                end = i
                break
    if end is None:
        return problem_text
    tokens = [(t.group(0).lower(), t.start(), t.end()) for t in re.finditer(r"[^\s()]+", code[:end])
              if t.start() >= m.end()]
    out = list(problem_text)
    group: list[tuple[str, int, int]] = []
    k = 0
    while k < len(tokens):
        if tokens[k][0] == "-" and k + 1 < len(tokens):
            typ = tokens[k + 1]
            again = [t for t in group if constants.get(t[0]) == typ[0]]
            spans = again + ([tokens[k], typ] if again and len(again) == len(group) else [])
            for _, a, b in spans:
                out[a:b] = " " * (b - a)
            group, k = [], k + 2
            continue
        group.append(tokens[k])
        k += 1
    return "".join(out)


def _failed(file: str | Path, exc: BaseException) -> PddlError:
    """A failure of UP's reader that is none of its syntax or semantic errors (an ``assert`` inside
    it, e.g. on a contingent problem): bad input it cannot read, said as such."""
    said = " ".join(str(exc).split())
    return PddlError(file, f"unified-planning's PDDL reader cannot read it ({type(exc).__name__}"
                           f"{': ' + said if said else ''}); is it PDDL 2.1 (durative actions, no contingency)?")


def _parse_problem(domain_text: str, problem_text: str, problem_file: str | Path) -> up.model.Problem:
    import pyparsing
    import unified_planning as up
    from unified_planning.io import PDDLReader

    from planners.checks import _lenient_names, _located  # one reader's error wording for both paths

    try:
        with _lenient_names():
            return PDDLReader().parse_problem_string(domain_text, problem_text)
    except (pyparsing.ParseBaseException, SyntaxError, up.exceptions.UPException, KeyError, ValueError) as exc:
        raise _located(problem_file, exc) from None
    except RecursionError:
        raise PddlError(problem_file, "nested too deep for the PDDL reader (write it flatter)") from None
    except Exception as exc:  # noqa: BLE001 - the reader's own failure (an assertion) on this input
        raise _failed(problem_file, exc) from None
