"""Day protocols (TaBSA-like): seeded days of requests, run per scheduler, and their table; shipped
protocols in ``protocols/``.
"""
