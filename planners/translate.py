"""Fast Downward's translator in this process, and what one process reuses across its calls.

:func:`translate` turns a PDDL domain and problem (text) into Fast Downward's SAS task
(text, as its translator writes ``output.sas``).  Two paths give byte-identical output:

* **reuse** (the default): the pipeline of the installed ``fast_downward.translate``
  package called step by step — its s-expression reader, ``parse_task``, ``normalize``,
  ``pddl_to_sas``, ``SASTask.output`` — on text in memory, with the domain read once
  per process (below), the options built once, and no temporary files;
* **reference** (``reuse=False``): the package's own ``main()`` on files, exactly as its
  command line runs it.  Tests compare the two on every bundled domain's problems.

**The domain, parsed once per process.**  Every problem of a task type shares its domain,
and parsing it into the translator's objects is about a tenth of a translation.  The
package has no entry point that takes a parsed domain, and its later steps mutate the
objects they are given (``normalize`` rewrites actions), so a parsed domain cannot be
handed out twice.  What is kept, per domain text, is (1) the s-expression reading, which
no step mutates (:func:`domain_sexp`, shared with :mod:`planners.schema`) and (2) a pickle
of what ``parsing_functions.parse_domain_pddl`` returned for it; each call unpickles a fresh
copy.  ``parse_domain_pddl`` is a pure function of the s-expressions and of the option
``keep_no_ops`` (ours never changes), so the copy equals what it would build again.

**The one monkeypatch.**  To give ``parse_task`` that copy, :func:`_parse_task` replaces
``parsing_functions.parse_domain_pddl`` for the length of one ``parse_task`` call, under
:data:`TRANSLATE_LOCK`, and restores it in ``finally``.  It relies on two facts about the
library, both tested (``tests/planners/test_translate.py``), so an upgrade that breaks them
fails there, not silently: ``parse_task`` looks ``parse_domain_pddl`` up as a module
global and calls it once, and the reuse path's output is byte for byte the reference's.
Should a call find ``parse_task`` not calling it exactly once, that call lets
``parse_task`` parse everything itself, with a ``RuntimeWarning``: slower, still exact.

The translator keeps its options in a module global (``options.options``) and prints to
``sys.stdout``, so every call holds :data:`TRANSLATE_LOCK` while it runs.
"""

from __future__ import annotations

import contextlib
import functools
import io
import os
import pickle
import tempfile
import threading
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

TRANSLATE_LOCK = threading.Lock()
"""Held by every use of the translator package: its options are a module global, and it prints."""

OK, OUT_OF_MEMORY, INPUT_ERROR = 0, 20, 30
"""Exit codes of a translation, as Fast Downward's driver reports them."""

_OPTIONS = ["domain.pddl", "problem.pddl"]
"""The translator's options: its defaults (the file names are not read on the reuse path)."""


@dataclass(frozen=True, slots=True)
class Translation:
    """One translation: ``code`` 0 (``sas`` is the SAS task), 20 out of memory, 30 bad input."""

    code: int
    message: str = ""
    sas: str = ""

    def __post_init__(self) -> None:
        if (self.code == OK) != bool(self.sas):
            raise ValueError(f"a Translation with code {self.code} must {'' if self.code == OK else 'not '}carry SAS")


def translate(domain: str, problem: str, *, reuse: bool = True) -> Translation:
    """The SAS task of a PDDL domain and problem; never raises for bad input (see ``code``)."""
    run = _translate_reusing if reuse else _translate_reference
    with TRANSLATE_LOCK, contextlib.redirect_stdout(io.StringIO()):
        try:
            return Translation(OK, sas=run(domain, problem))
        except MemoryError:
            return Translation(OUT_OF_MEMORY, "translator ran out of memory")
        except SystemExit as exc:  # the translator reports input errors this way
            return Translation(INPUT_ERROR, f"translator: {exc}")
        except Exception as exc:  # noqa: BLE001 - any translator failure is an input error for us
            return Translation(INPUT_ERROR, f"translator: {type(exc).__name__}: {exc}")


@functools.lru_cache(maxsize=32)
def domain_sexp(text: str) -> list[Any]:
    """The translator's s-expression reading of a domain (memoised; no step mutates it).

    Raises the reader's ``ParseError`` on malformed text.
    """
    from fast_downward.translate.pddl_parser import lisp_parser

    return lisp_parser.parse_nested_list(io.StringIO(text, newline=None))


@functools.lru_cache(maxsize=32)
def _parsed_domain(text: str) -> bytes:
    """A pickle of ``parse_domain_pddl``'s ten results for the domain (under our options)."""
    from fast_downward.translate.pddl_parser import parsing_functions

    parsed = tuple(parsing_functions.parse_domain_pddl(parsing_functions.Context(), domain_sexp(text)))
    return pickle.dumps(parsed, protocol=pickle.HIGHEST_PROTOCOL)


def _translate_reusing(domain: str, problem: str) -> str:
    from fast_downward.translate import main, normalize
    from fast_downward.translate import options as translate_options
    from fast_downward.translate.pddl_parser import lisp_parser

    translate_options.options = _options()
    task = _parse_task(domain, lisp_parser.parse_nested_list(io.StringIO(problem, newline=None)))
    normalize.normalize(task)
    out = io.StringIO()
    main.pddl_to_sas(task).output(out)
    return out.getvalue()


def _parse_task(domain: str, problem_sexp: list[Any]) -> Any:
    """``parse_task`` with the domain's parse unpickled instead of built again (see the module doc)."""
    from fast_downward.translate.pddl_parser import parsing_functions

    parsed = _parsed_domain(domain)
    original = parsing_functions.parse_domain_pddl
    calls = 0

    def remembered(context: Any, domain_pddl: Any) -> Iterator[Any]:
        nonlocal calls
        calls += 1
        return iter(pickle.loads(parsed))

    parsing_functions.parse_domain_pddl = remembered
    try:
        task = parsing_functions.parse_task(domain_sexp(domain), problem_sexp)
    finally:
        parsing_functions.parse_domain_pddl = original
    if calls == 1:
        return task
    # the library changed under us: its parse_task no longer reads the domain this way, so
    # let it parse everything itself (exact, only slower); tests/planners/test_translate.py fails
    warnings.warn(f"fast_downward.translate's parse_task called parse_domain_pddl {calls} times, not once: "
                  "planners.translate parses the domain on every call", RuntimeWarning, stacklevel=2)
    return parsing_functions.parse_task(domain_sexp(domain), problem_sexp)


@functools.cache
def _options() -> Any:
    from fast_downward.translate import options as translate_options

    return translate_options.parse_args(_OPTIONS)


def _translate_reference(domain: str, problem: str) -> str:
    from fast_downward.translate import main
    from fast_downward.translate import options as translate_options

    with tempfile.TemporaryDirectory(prefix="tasker-translate-") as tmp:
        dom, prob, sas = (os.path.join(tmp, n) for n in ("domain.pddl", "problem.pddl", "output.sas"))
        Path(dom).write_text(domain)
        Path(prob).write_text(problem)
        translate_options.set_options([dom, prob, "--sas-file", sas])
        main.main()
        return Path(sas).read_text()

