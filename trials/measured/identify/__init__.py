"""Identify a ship model from measured records (``mmg identify``) and cross-validate it: the package
re-exports its rooms' public names.  :mod:`.fit` holds the fit (the training records, the free set and
its priors, the start states, the stages, :func:`identify`, the folds and :func:`cross_validate`; its
docstring describes the method), :mod:`.covariance` the covariance and run-to-run spread written with
the fit, :mod:`.report` ``ship.yaml``, ``report.md`` and the JSON summaries (:func:`write_identification`).
"""
from __future__ import annotations

from .fit import (identify, IdentifyOptions, cross_validate, cv_folds, load_runs, Identification, ship_with_values,
                  DEFAULT_FREE, DEFAULT_WEIGHTING, DEFAULT_MAX_NFEV, stage_description, start_noise,
                  DEFAULT_INITIAL_STATE, INITIAL_STATES, fold_of, manoeuvre_class, goes_astern, ASTERN_SHARE,
                  FOLD_ASSIGNMENTS, _bounded_wind, _free_names, same_run_groups, with_fitted_wind, with_ship_effects,
                  replay_fitted, fitted_run, without_fit_sections)
from .covariance import (fit_covariance, identification_covariance, run_covariance, COVARIANCE_METHOD, run_spread,
                         START_UNITS, model_form)
from .report import write_identification, ship_yaml, fold_spread_json, identification_summary, free_parameter_text

__all__ = ["identify", "IdentifyOptions",
           "cross_validate", "cv_folds", "write_identification", "load_runs", "ship_yaml", "Identification",
           "fit_covariance", "ship_with_values",
           "DEFAULT_FREE", "DEFAULT_WEIGHTING", "DEFAULT_MAX_NFEV",
           "stage_description", "identification_covariance", "run_covariance", "fold_spread_json",
           "COVARIANCE_METHOD", "identification_summary", "start_noise", "DEFAULT_INITIAL_STATE", "run_spread",
           "START_UNITS", "free_parameter_text", "model_form", "replay_fitted", "fitted_run", "without_fit_sections",
           "INITIAL_STATES", "fold_of", "manoeuvre_class", "goes_astern", "ASTERN_SHARE", "FOLD_ASSIGNMENTS"]
