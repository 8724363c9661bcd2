"""Metrics: what a run, a day or a path measured (from the timeline), the registry that says what each
metric means and which way is better, and the results store.
"""
