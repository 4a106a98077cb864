"""Trial definitions and runs.  A trial from its YAML (:mod:`.trial`: the ship, the approach, the
manoeuvre, the log to record, the effects of the trial), simulated with its log,
metrics and figures (:mod:`.run`, ``mmg simulate``, ``mmg.simulate``); many independent
simulations run in parallel through :mod:`trials.files.sweep`.  May import :mod:`mmg`, :mod:`trials.files` and
:mod:`trials.analysis`.
"""
