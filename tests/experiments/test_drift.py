"""The drift guard: the committed documents generated from runs still describe this code.

Each such document ends with a provenance block (the commit it was generated on and the trace
digests of a few of its runs, :mod:`experiments.sweep.provenance`).  Those runs are run again
here; a trace that differs means the code now says something else than the document, and the
document must be regenerated (``tasker results``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.sweep import provenance as pv

ROOT = Path(__file__).resolve().parents[2]
GENERATED = ("docs/results.md",)


@pytest.mark.slow
@pytest.mark.parametrize("doc", GENERATED)
def test_a_generated_document_still_describes_this_code(doc: str) -> None:
    prov = pv.parse((ROOT / doc).read_text(encoding="utf-8"))
    assert prov is not None, f"{doc} has no provenance block: regenerate it ('tasker results')"
    assert prov.digests, f"{doc} vouches for no run"
    changed = pv.verify(prov)
    assert not changed, (f"{doc} (generated on {prov.commit}) no longer describes this code; regenerate it "
                         f"('tasker results'). Traces that changed: {changed}")
