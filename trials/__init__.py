"""Sea trials, records and the ``mmg`` command: the top layer, over the physics (:mod:`mmg`) and
the estimators (:mod:`ekf`), in sub-packages by concept.  Which folder for what:

========================  =================================================================================
:mod:`trials.files`       records in and out: the record every reader returns, the log formats (project
                          logs, truth files, FRT-DS-ESSO), channel and unit checks, a record against its
                          ship, the rudder rebuilt from a log header, staged outputs, track/history figures
:mod:`trials.analysis`    what a record shows: IMO metrics (turning, zigzag overshoots), Nomoto K, T
:mod:`trials.runs`        trial definitions from YAML, a trial simulated with its log, parallel sweeps
:mod:`trials.measured`    measured records against the model: replay (predict), identify, diagnose
:mod:`trials.estimates`   estimation from logs and trials (EKF, output error), Table 10, Monte Carlo
:mod:`trials.planning`    trial design: sensitivities, Fisher information and Cramer-Rao bounds, search
:mod:`trials.papers`      the papers reproduced: the main job (``mmg reproduce``), Artyszuk's tables
:mod:`trials.imo`         the IMO manoeuvring standards (MSC.137(76)) on a ship, with their uncertainty
                          (``mmg imo``, ``mmg.imo``); above runs and measured
:mod:`trials.cli`         the ``mmg`` command, one module per subcommand; the numba cache warm-up
========================  =================================================================================

Each sub-package imports only from those listed above it (with :mod:`trials.measured` beside, not
above, :mod:`trials.runs`: it needs no simulated trial); its ``__init__`` says exactly which, and
``tests/test_layers.py`` checks it.  The physics itself (hull forces, effects such as wind or
current, the rudder law) is in :mod:`mmg`; the estimators' numerics in :mod:`ekf`.

The everyday entry points are re-exported by the :mod:`mmg` facade
(``mmg.load_trial``, ``mmg.zigzag``, ``mmg.simulate``, ...).
"""

__all__: list[str] = []
