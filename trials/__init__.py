"""Sea trials: trial definitions (:mod:`trials.runs.trial`), runs (:mod:`trials.runs.run`), logs,
metrics, figures and the ``mmg`` command line (:mod:`trials.cli`).

The everyday entry points are re-exported by the :mod:`mmg` facade
(``mmg.load_trial``, ``mmg.zigzag``, ``mmg.simulate``, ...).
"""

__all__: list[str] = []
