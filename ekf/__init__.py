"""Estimators of MMG hull coefficients from sea-trial data: the state-augmented EKF of Rhee & Kim
(1999), the EKF on the raw log, and the joint output-error fit.

They work on arrays and the physics model (:mod:`mmg`) and know no file format: the trials
layer (:mod:`trials.estimates.estimation`) builds their input, a :class:`TrialData`, from a log file or
a simulated trial.  The coefficients they free are named from the ship's hull table
(:func:`estimable_names`).

Names are imported on first use (``import ekf`` is cheap).
"""
from __future__ import annotations

from importlib import import_module as _import_module

_LAZY = {
    "TrialData": ("ekf.data", "TrialData"),
    "RecordInfo": ("ekf.data", "RecordInfo"),
    "estimable_names": ("ekf.data", "estimable_names"),
    "hull_slots": ("ekf.data", "hull_slots"),
    "PAPER_DERIVATIVES": ("ekf.data", "PAPER_DERIVATIVES"),
    "AugmentedEKF": ("ekf.filterpy_ekf", "AugmentedEKF"),
    "FilterResult": ("ekf.filter", "FilterResult"),
    "FilterDivergence": ("ekf.filter", "FilterDivergence"),
    "run_filter": ("ekf.filter", "run_filter"),
    "Estimate": ("ekf.estimate", "Estimate"),
    "estimate": ("ekf.estimate", "estimate"),
    "joint_estimate": ("ekf.estimate", "joint_estimate"),
    "load_config": ("ekf.estimate", "load_config"),
    "free_run": ("ekf.estimate", "free_run"),
    "FreeRun": ("ekf.estimate", "FreeRun"),
    "run_log_filter": ("ekf.log_filter", "run_log_filter"),
    "LogFilterResult": ("ekf.log_filter", "LogFilterResult"),
    "refine": ("ekf.output_error", "refine"),
    "OEResult": ("ekf.output_error", "OEResult"),
    "OEEstimate": ("ekf.output_error", "OEEstimate"),
    "Measurements": ("ekf.preprocess", "Measurements"),
    "recover": ("ekf.preprocess", "recover"),
}

__all__ = list(_LAZY)


def __getattr__(name: str):
    try:
        module, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'ekf' has no attribute {name!r}") from None
    value = getattr(_import_module(module), attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
