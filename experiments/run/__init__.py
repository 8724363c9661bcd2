"""One pipeline: a scenario and a strategy become a run folder (trace, metrics, pictures)."""
