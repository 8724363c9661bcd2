"""Sweeps: scenarios x seeds x strategies in parallel, resumable, with their report; shipped sweep
specs in ``specs/``.
"""
