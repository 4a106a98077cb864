"""Standard manoeuvre metrics (IMO MSC.137(76) definitions) from time histories, as a package of rooms
whose public names it re-exports: :mod:`.manoeuvres` the turning, zigzag and stopping metrics and their
executes (its docstring gives the definitions), :mod:`.imo` the IMO standard's criteria, :mod:`.records`
the metrics of a record (:func:`record_metrics`, what ``mmg metrics`` runs).
"""
from __future__ import annotations

from .manoeuvres import (HEADING_JUMP, HOLD_TOL, MIN_HOLD_S, MIN_MANOEUVRE_RUDDER, PEAK_WINDOW_S, fit_circle,
                         corrected_heading, Hold, rudder_holds, execute_time, turning_metrics, zigzag_switches,
                         zigzag_metrics, zigzag_problem, STOPPED_FRACTION, stopping_metrics)
from .imo import (IMO_STANDARD, ADVANCE_LIMIT_L, TACTICAL_DIAMETER_LIMIT_L, INITIAL_TURNING_LIMIT_L,
                  ZZ20_FIRST_OVERSHOOT_LIMIT_DEG, STOPPING_LIMIT_L, STOPPING_LIMIT_LARGE_L, zz10_overshoot_limits,
                  imo_criteria)
from .records import MIN_TURN_DIAMETER_L, check_turning_diameters, TRIAL_DEFINED, fill_from_trial, record_metrics

