"""The papers reproduced.  The main job (:mod:`.reproduce`, ``mmg reproduce``: one report.md with the
straight run, Kijima's formulas, the trials' metrics, Artyszuk's tables, Rhee & Kim's Table 10 and
figures) and Artyszuk (2018) Tables 1-8 beside the paper's printed values (:mod:`.artyszuk`,
``mmg nomoto-paper``).  Rhee & Kim's Table 10 run is :mod:`trials.estimates.rhee_kim` (the Monte
Carlo reuses its trials).  May import :mod:`mmg`, :mod:`ekf` and every ``trials`` sub-package but
:mod:`trials.measured` and :mod:`trials.cli`.
"""
