"""Reading and checking the files a user writes: scenarios (robot and synthetic), their requests and
fields, the strategy factors of a run.  The lowest layer of ``experiments``.
"""
