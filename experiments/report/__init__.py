"""What a person reads: plots, HTML pages of a run and of a sweep, and ``explain``."""
