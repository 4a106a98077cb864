"""The naming decision of ``mmg diagnose``: the thresholds an effect's fit must clear to be named
(:func:`trials.measured.diagnose.diagnose`); a module of its own so that the report and the
identifiability check read them without importing the workflow."""
from __future__ import annotations

__all__ = ["BIC_THRESHOLD", "Z_THRESHOLD"]

BIC_THRESHOLD = 20.0
"""dBIC an effect must exceed to be named.  Kass & Raftery (1995) call > 10 very strong evidence
for independent samples; with the tau-corrected counts the largest candidate dBIC on 20 clean
perturbed record pairs (bench/bench_diagnose.py, seeds 0-19) was 15.4, 10.9, 9.5, 7.6, ... (2 of 20
above 10), so the threshold is set at 20 and the false-alarm rate checked on fresh seeds."""
Z_THRESHOLD = 3.0
"""|parameter - neutral| / standard error an effect's fit must exceed to be named."""
