"""Where the suspension-strategy experiment (:mod:`experiments.sweep.experiment`) keeps its results
databases (one per arm, ``RESULTS/ARM.db``) and its document, relative to the project root.  Apart,
and importing nothing, so that ``tasker --help`` can show them without loading the experiment's
machinery."""

RESULTS = "out/results"
MARKDOWN = "docs/results.md"
