"""Statistics over many runs: estimates with intervals, paired comparisons, Markdown tables."""
