"""Trial design: which trial tells most about the hull derivatives.  The derivative sensitivities of
Rhee & Kim eqs. (21)-(22) (:mod:`.sensitivity`), the Fisher information and Cramer-Rao bound of a
trial (:mod:`.fisher`), the search over trial families (:mod:`.design`), their charts
(:mod:`.sensitivity_plots`) and the reports of ``mmg sensitivity`` (:mod:`.sensitivity_report`).
May import :mod:`mmg`, :mod:`ekf`, :mod:`trials.files`, :mod:`trials.analysis`, :mod:`trials.runs`
and :mod:`trials.estimates` (the bounds are set beside the estimators' Monte Carlo and Table 10).
"""
