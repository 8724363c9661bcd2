"""Support for the model's users, kept apart from the model: reading user files, the disk cache, CLI checks.

Nothing here is the TaskER model; the model (``tasker`` proper) uses only the did-you-mean
helper of :mod:`tasker.support.reader`.  Standard library only, like the whole package.
"""
