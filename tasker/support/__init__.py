"""Support for the model's users, kept apart from the model: reading user files and the disk cache.

Nothing here is the TaskER model; the model (``tasker`` proper) uses only the did-you-mean
helper of :mod:`tasker.support.reader`.  Standard library only, like the whole package.
The command line lives in :mod:`experiments.cli`.
"""
