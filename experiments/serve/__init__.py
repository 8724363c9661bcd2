"""``tasker serve``: the controller run live, against the wall clock, taking requests over HTTP.

The same loop as ``tasker run`` (:func:`experiments.run.runner.run_scenario`, through its ``live``
hook) steps the harmoniser, the agents, Fast Downward, OMPL and the MuJoCo robot, paced at
``--speed`` simulated seconds per wall second by :class:`experiments.serve.session.Session`,
which alone touches the loop.  What arrives over HTTP (:mod:`experiments.serve.app`) is read
as a scenario's actions are read (:mod:`experiments.serve.bodies`), queued for the session's
thread, and injected at a tick boundary; the session is saved as a scenario
(:mod:`experiments.serve.record`) that ``tasker run`` replays byte for byte.  The live page
(:mod:`experiments.serve.page`) is drawn by the run page's own world figure.  ``docs/serve.md``.
"""
