"""Experiments: scenario files, runs, sweeps, metrics, plots, and the ``tasker`` command line."""
