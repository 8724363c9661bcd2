"""Where the suspension-strategy experiment (:mod:`experiments.sweep.experiment`) keeps its two
results databases and its document, relative to the project root.  Apart, and importing nothing,
so that ``tasker --help`` can show them without loading the experiment's machinery."""

DB = "out/strategies.db"
CONTROL_DB = "out/strategies-control.db"
MARKDOWN = "docs/results.md"
