"""Estimation from sea-trial logs and simulated trials.  Logs and trials turned into the estimators'
input, and their reports (:mod:`.estimation`, ``mmg estimate``, ``mmg.estimate``), Rhee & Kim's
Table 10 reproduced with the augmented EKF (:mod:`.rhee_kim`), and the Monte Carlo of the three
estimators over log-noise seeds (:mod:`.montecarlo`, ``mmg montecarlo``, ``log-filter``,
``output-error``).  The estimators themselves are :mod:`ekf`.  May import :mod:`mmg`, :mod:`ekf`,
:mod:`trials.files`, :mod:`trials.analysis` and :mod:`trials.runs`.
"""
