"""Trial definitions from YAML (the manoeuvre, the approach, the log to record), as a package of rooms
whose public names it re-exports: :mod:`.definition` the validated :class:`Trial`, its :class:`LogSpec` and
:class:`SensorBias`, :mod:`.load` the YAML schema, its reading and checks (:func:`load_trial`, :func:`trial_from_dict`; its
docstring describes the trial file and the manoeuvre kinds), :mod:`.approach` the check of the
approach revolutions, :mod:`.builders` trials made in Python
(:func:`make_trial`, :func:`zigzag`, :func:`turning`, :func:`stype`, :func:`schedule`, :func:`stopping`).
"""
from __future__ import annotations

from .definition import LogSpec, SensorBias, Trial, periodic_order
from .approach import APPROACH_RPM_TOLERANCE, CONSTANT_RPM_FACTOR_MAX, zero_thrust_advance_ratio
from .load import Side, MAX_SCHEDULE_BYTES, load_trial, MIN_DT, MIN_STEPS_PER_PERIOD, NOISE_MAX, trial_from_dict
from .builders import make_trial, zigzag, turning, stype, schedule, stopping, degrees

