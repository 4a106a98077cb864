"""Measured records against the model.  Replay of a record against its own rudder and revolutions
(:mod:`.predict`, ``mmg predict``; its 90 % bands from the identified ship's uncertainty, :mod:`.bands`, the
ship drawn from its covariance by :mod:`.draws`), identification of a ship model from records and its
cross-validation (:mod:`.identify`, ``mmg identify``; whether its stated uncertainty holds from one group
of records to the next, :mod:`.foldspread`), the discrepancy workflow that names the
effect the model is missing (:mod:`.diagnose`, ``mmg diagnose``; the effects themselves, and where
to add one, are :mod:`mmg.effects`), and their figures (:mod:`.predict_plots`,
:mod:`.diagnose_plots`).  May import :mod:`mmg`, :mod:`ekf`, :mod:`trials.files` and
:mod:`trials.analysis` (not the simulated trials of :mod:`trials.runs`).
"""
