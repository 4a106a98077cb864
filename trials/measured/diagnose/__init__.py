"""The discrepancy workflow (``mmg diagnose``): which effect is the model missing, how large, how
much closer it comes with it.

For the records given (every layout :func:`trials.files.logio.read_record` reads, the ship's length
checking the scale) and the ship config:

1. **Replay** each record against its measured rudder and revolutions (:mod:`mmg.replay`) in
   segments of ``segment_s`` (default ``segment_length`` of the diagnosis rules, :mod:`.rules`, times
   sqrt(L/g)),
   each restarting from the measured state, and form the residuals of u, v, r, heading and the
   track (x, y) in the record's own (logged) quantities.  ``rms_config`` is this with the
   config as it is.
2. **Baseline**: fit the ship coefficients the records inform (:data:`SHIP_FREE_TERMS`: the
   resistance, the linear sway/yaw derivatives and the yaw damping r|r| term, the wake
   w_P0, :data:`CONSTANTS_FREE`, on turns the rudder's inflow ratio epsilon,
   :data:`TURN_CONSTANTS_FREE`, on zigzags the rudder's flow straightening for either sign of its
   inflow angle, :data:`ZIGZAG_CONSTANTS_FREE`, and the added masses and moment, :data:`MASS_FREE`; :func:`ekf.identify.identify_segments`
   with its prior) with no effect: constants of the
   config that are merely a bit off (added mass, wake, hull) are absorbed here, so they do not
   pass for an effect.  On turns to one side whose records log their sway, the drift
   nonlinearities (:data:`TURN_HULL_TERMS`) as well where they lower the heading residual by more
   than :data:`DRIFT_FALL_MIN` (:func:`_drift_terms`); such a record set is then of kind
   :data:`DRIFT_KIND`, with floors of its own.  ``rms_before`` is this model's residual.
3. **Candidates**: each registered effect (:mod:`mmg.effects`) not yet in the model and
   applicable to every record (a wind candidate needs the relative-wind channels, non-zero, and a
   ship wind section; otherwise it is skipped with that reason) is fitted together with the same
   ship coefficients; a coefficient effect whose every changed coefficient the baseline frees
   (shallow water on :data:`DRIFT_KIND`) is not, and is reported ``not_identifiable``
   (:func:`_covered`).  Score: the Bayesian information criterion with per-channel unknown noise
   variances and an effective sample count per channel, N_eff = N / tau, tau the integrated
   autocorrelation time of the current model's residual in that channel (the residuals of a
   10 Hz record are far from independent; BIC with the raw N would name an effect for every
   smooth misfit):

       dBIC = sum_c N_eff,c ln(RSS_c,before / RSS_c,with) - k ln(sum_c N_eff,c) + (chi2_straight,before - chi2_straight,with)

   The last term is the **straight run's**: a record that opens with a steady straight run
   (:func:`~trials.measured.diagnose.records.leading_straight_run`: rudder at its trim, no yaw, little
   wind) logs there a mean sway over ground that any hull leaves at (almost) zero through the water,
   so it is set by a heading bias (-u sin b) and a current's cross part alone, whatever the hull
   coefficients (:func:`ekf.identify.straight_run_residual`, one residual per record with its own
   standard error).  In the fit its weight is sqrt(tau_v), the v channel's correlation time: the fit
   counts each v row as if independent and dBIC counts it 1/tau_v times, so the straight run (a mean
   of v) keeps in the fit the weight against the v rows that dBIC gives it.  On a turning circle it is the
   one stretch where a heading bias does not trade with the hull terms.  Its samples are also among the v rows; the
   straight run's own term is bounded by its hull-drift allowance, so the double count is small.

   An effect is **named** when dBIC > :data:`BIC_THRESHOLD` and its parameters differ from their neutral values by more than
   :data:`Z_THRESHOLD` standard errors (Gauss-Newton, inflated by sqrt(tau)) and its size clears
   the floor calibrated on ships that are not the model (:mod:`.decision`); these numbers, and the
   package's other tuned ones, are read from ``configs/calibration/diagnose_rules.yaml`` (:mod:`.rules`),
   each with its meaning and source.  The best named
   candidate is added and the search repeats over the rest until none clears the threshold.
   **Final check** (:func:`_prune`): every named effect must still clear z and its floor in the
   final joint fit; one that lost its evidence to an effect named after it is dropped.
4. **Report**: ``rms_after`` with the named effects; each effect's parameters and standard
   errors; ``unexplained`` when a channel's residual stays above :data:`UNEXPLAINED_FACTOR` times
   its noise level (estimated from the record's own second differences) and
   ``unexplained_description`` saying which channel and what it correlates with (heading: an
   earth-fixed cause; rudder; relative wind; body-fixed constant).
   A named effect whose fit stands for a gap of the model's form (a shape parameter on its bound, a
   value the measured channels do not allow) is reported ``model_form_mismatch`` instead
   (:mod:`.model_form`).

Residual frames.  FRT-DS-ESSO u, v are GNSS velocities over ground resolved in the logged
heading; the replay's hydrodynamics need the velocity through the water.  Every replay (its
start and each segment restart) therefore begins from the *model* state of the logged one
(:meth:`mmg.effects.EffectSet.to_model`: minus the candidate current, heading minus the candidate
bias) and its states are mapped back to logged ones (:meth:`~mmg.effects.EffectSet.to_logged`)
before the residuals are formed: u, v compare over-ground velocities, positions are over ground
on both sides.  Without a current the model takes the logged over-ground u, v as through the
water, which is exactly the discrepancy a current leaves.

The package's modules, in the order a diagnosis passes through them:

* :mod:`.rules`: the tuned numbers (thresholds, gates, budgets, windows), read from their file;
* :mod:`.records`: the records read, checked and segmented (:func:`prepare`), and synthetic ones;
* :mod:`.options`: how the search runs (:class:`DiagnoseOptions`);
* :mod:`.statistics`: residuals, their RMS and correlation time, dBIC, an effect's fitted values;
* :mod:`.fit`: the fit of the ship's own parameters and the effects (:class:`_Fitter`, :class:`_Model`);
* :mod:`.baseline`: the ship's own parameters, their priors and the baseline fit (step 2);
* :mod:`.search`: the candidates and forward selection over them (step 3);
* the decision: :mod:`.decision` (thresholds, floors, kinds of record set), :mod:`.calibration`
  (how the floors are calibrated), :mod:`.identifiability` and :mod:`.verdicts` (what was not named, and
  why);
* :mod:`.result`: :class:`Diagnosis` (step 4); :mod:`.report` its text, :mod:`.plots` its figures;
* :mod:`.api`: :func:`diagnose` and :func:`diagnose_each`, the steps in order.
"""
from __future__ import annotations

from .api import diagnose, diagnose_each
from .baseline import (CONSTANTS_FREE, DRIFT_KIND, MASS_FREE, SHIP_FREE_TERMS,  # noqa: F401
                       TURN_CONSTANTS_FREE, TURN_HULL_TERMS, ZIGZAG_CONSTANTS_FREE, _ship_free)
from .fit import _Model  # noqa: F401
from .options import DiagnoseOptions  # noqa: F401
from .records import (Manoeuvre, Prepared, RecordNoise, noise_level, prepare, synthetic_record,  # noqa: F401
                      write_frt_csv)
from .rules import module_rule
from .result import (CHANNELS, Diagnosis, absent_table, model_form_mismatch, ship_fit_table,  # noqa: F401
                     straight_run_table, _describe)
from .search import _covered, _rival, straight_contradicts  # noqa: F401
from .statistics import _delta_bic, _effect_report, _tau  # noqa: F401
from .verdicts import _demote, absorbed, rivals_withheld, to_demote, weak_evidence, withheld, within_mismatch  # noqa: F401

__all__ = ["diagnose", "DiagnoseOptions", "Diagnosis", "straight_run_table", "straight_contradicts",
           "prepare", "synthetic_record", "Manoeuvre", "RecordNoise", "write_frt_csv",
           "diagnose_each", "SHIP_FREE_TERMS", "MASS_FREE",
           "CONSTANTS_FREE", "TURN_CONSTANTS_FREE", "ZIGZAG_CONSTANTS_FREE", "TURN_HULL_TERMS", "DRIFT_FALL_MIN",
           "BIC_THRESHOLD", "Z_THRESHOLD", "CHANNELS"]

_RULES = {"BIC_THRESHOLD": "bic_threshold", "Z_THRESHOLD": "z_threshold", "DRIFT_FALL_MIN": "drift_fall_min",
          "SCREEN_NFEV": "screen_nfev"}
"""The package's names of numbers of the diagnosis rules (:mod:`.rules`), read-only (their meanings: the
modules that use them, :mod:`.decision`, :mod:`.baseline`, :mod:`.options`)."""

__getattr__ = module_rule(__name__, _RULES)
