"""The one reading of a trace: :mod:`experiments.trace.timeline` turns ``trace.jsonl`` into per-agent
intervals and episodes; every metric, plot and page reads it.
"""
