"""The baseline of the diagnosis and its priors: which of the ship's own parameters are fitted with every
model (:func:`_ship_free`, the term families below), their prior widths (:func:`_baseline_prior`), and the
baseline fit with no effect (:func:`fit_baseline`: :func:`_baseline`, then on turns to one side
:func:`_drift_terms`)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from mmg.terms import is_resistance
from mmg.parameters import LINEAR_TERMS, MASS_NAMES, parameter  # noqa: F401 (LINEAR_TERMS: in __all__)
from mmg.ship import Ship

from .fit import _config_model
from .rules import module_rule, rule
from .report import fmt3, format_rms
from .statistics import _chi2, _delta_bic, _rms, _scaled_rss, _stack, _taus

__all__ = ["SHIP_FREE_TERMS", "TURN_HULL_TERMS", "DRIFT_KIND", "CONSTANTS_FREE", "TURN_CONSTANTS_FREE",
           "ZIGZAG_CONSTANTS_FREE", "MASS_FREE", "LINEAR_TERMS", "DRIFT_FALL_MIN",
           "fit_baseline"]


SHIP_FREE_TERMS = ("beta", "r", "v", "cos(beta)^2", "r|r|", "u^2", "r^3")
"""Hull terms whose coefficients the diagnosis fits with every model (with the straight-ahead resistance
whatever its term, :func:`mmg.terms.is_resistance`, e.g. the MMG standard method's X_0 on ``1``; ``r^3`` is
that form's pure-yaw nonlinearity, Kijima's ``r|r|``; plus :data:`CONSTANTS_FREE`,
:data:`TURN_CONSTANTS_FREE` on turns, :data:`ZIGZAG_CONSTANTS_FREE` on zigzags, :data:`TURN_HULL_TERMS` on
turns to one side that need them,
:data:`MASS_FREE`)."""


TURN_HULL_TERMS = ("beta|beta|", "beta^2*r", "beta*r^2")
"""Hull terms it fits as well on turns to one side whose records need them (:func:`_drift_terms`): the
drift nonlinearities.  A 35 deg turn holds a drift of 10-15 deg for most of the record, where a real hull's
side force and moment leave a polynomial fitted for small drift (Kijima's) by more than its linear and r|r|
terms can take up; the residual they leave would otherwise be taken by a candidate effect.  On a zigzag the
drift stays small and these terms would only trade with the linear ones."""


DRIFT_KIND = "turn_drift"
"""The kind of record set (:data:`~trials.measured.diagnose.decision.KINDS`) of turns to one side (calibrated on
single turns) whose baseline freed the drift nonlinearities (:func:`_drift_terms`): its floors are
calibrated apart from those of the turns that keep them at the config's (``"turn"``), since the ship's own
mismatch lends the candidates other sizes on the two baselines."""


CONSTANTS_FREE = ("w_P0",)
"""Propeller constants the diagnosis fits with every model: the wake w_P0 (the thrust)."""


TURN_CONSTANTS_FREE = ("epsilon",)
"""Rudder constants it fits as well on turns (:func:`~trials.measured.diagnose.decision.record_kind` ``turn`` or
``turn_pair``): the rudder's inflow ratio epsilon (the rudder force, as epsilon^2).  In a 35 deg turn the
rudder's drag, (1 - t_R) F_N sin(delta), sets much of the speed lost; a rudder force 10-15 % off its
config leaves a residual in that speed loss and the drift that the resistance (u^2) and the wake cannot
take, and a candidate effect would take it instead.  On a zigzag the rudder force is what drives the
response, and its size trades with the freed linear hull terms (a Nomoto gain is their ratio): it is not
freed there."""


ZIGZAG_CONSTANTS_FREE = ("gamma_R_pos", "gamma_R_neg")
"""Rudder constants it fits as well on zigzags (:func:`~trials.measured.diagnose.decision.record_kind`
``zigzag``): the flow-straightening coefficients gamma_R of the rudder's inflow angle for positive and
negative beta_R, each with its own prior (std 15 % of the config value, at least 0.05:
``rudder`` of :data:`ekf.identify.DIAGNOSIS_PRIOR_REL_STD`).  A real ship's two differ (the MMG
standard's KVLCC2: 0.395 and 0.640), and a difference the config does not have makes the rudder's
force asymmetric in a zigzag, where beta_R swings both ways: it is what the ship's own mismatch lends
a rudder offset there.  The offset stays identifiable because it acts at every drift and the asymmetry
only with drift or yaw, but the two correlate, so its standard error grows.  On a turn to one side beta_R
keeps one sign and only one of the two would be seen; it is not freed there."""


MASS_FREE = MASS_NAMES
"""Added masses and the added moment of inertia the diagnosis fits with every model (prior: the
config value, relative std from :data:`ekf.identify.DIAGNOSIS_PRIOR_REL_STD`, the diagnosis's policy
in the one table of prior widths): an added mass a few % off leaves a residual (surge speed loss in
the turn, sway and yaw lag) that an effect would otherwise take."""


def _baseline_prior(f, entry):
    """``f`` (a :class:`ekf.identify.FreeParameter`) with the diagnosis's prior of its parameter-table
    ``entry`` (:class:`mmg.parameters.ShipParameter`): the width of its ``diagnosis_family`` in
    :data:`ekf.identify.DIAGNOSIS_PRIOR_REL_STD` (floored at its ``diagnosis_floor``) and, where it
    ``keeps_sign``, its config sign as a bound; ``f`` as it is for an entry without a diagnosis family."""
    from ekf.identify import DIAGNOSIS_PRIOR_REL_STD as P

    if not entry.diagnosis_family:
        return f
    sigma = max(P[entry.diagnosis_family] * abs(f.prior), entry.diagnosis_floor)
    if not entry.keeps_sign:
        return replace(f, sigma=sigma)
    lo, hi = (0.0, np.inf) if f.prior > 0 else (-np.inf, 0.0) if f.prior < 0 else (f.lower, f.upper)
    return replace(f, sigma=sigma, lower=max(lo, f.lower), upper=min(hi, f.upper))


def _ship_free(ship: Ship, packed, names=None, kind: str = "zigzag", drift: bool = False):
    """The ship's own parameters the diagnosis fits (``names``, or by default :data:`SHIP_FREE_TERMS`,
    :data:`CONSTANTS_FREE`, on a ``"zigzag"`` :data:`ZIGZAG_CONSTANTS_FREE`, on any other ``kind`` of
    record set :data:`TURN_CONSTANTS_FREE` and, with ``drift``, :data:`TURN_HULL_TERMS`, and
    :data:`MASS_FREE`) with the diagnosis's priors."""
    from ekf.identify import DIAGNOSIS_PRIOR_REL_STD, free_parameters

    if names is None:
        names = [n for n, a, t in zip(ship.hull.names, ship.hull.axes, ship.hull.terms)
                 if t in SHIP_FREE_TERMS or is_resistance(n, t, a)] + list(CONSTANTS_FREE)
        if kind == "zigzag":
            names += list(ZIGZAG_CONSTANTS_FREE)
        else:
            names += [n for n, t in zip(ship.hull.names, ship.hull.terms) if t in TURN_HULL_TERMS and drift]
            names += list(TURN_CONSTANTS_FREE)
        mass = list(MASS_FREE)
    else:
        mass = [n for n in names if n in MASS_FREE]
        names = [n for n in names if n not in MASS_FREE]
    free = free_parameters(packed, ship.hull.names, names + mass, priors=DIAGNOSIS_PRIOR_REL_STD,
                           hull_terms=ship.hull.terms)
    return [_baseline_prior(f, parameter(f.name, ship.hull.names, ship.hull.terms)) for f in free]


def _baseline(fitter, noise, say):
    """(the config's differences, the baseline fit, whether the fit was kept, the fitter with the
    residual scales of the fits that follow): fitted, every channel rescaled by the first fit's own
    residual (floored at the noise), fitted again; a fit that replays the records worse than the config
    as given (scaled residuals, no prior) is not kept: the config is."""
    from ekf.identify import Scales

    d_config = fitter.diffs([], [], [])
    base = fitter.fit([])
    D = _stack(base.diffs, 1)
    rm = np.sqrt(np.mean(D * D, axis=0))
    fl = np.maximum(rm, np.maximum(noise, 1e-9))
    fitter = replace(fitter, scales=Scales(u=fl[0], v=fl[1], r=fl[2], psi=fl[5],
                                           pos=float(np.hypot(fl[3], fl[4])) / math.sqrt(2)))
    base = fitter.fit([], start_ship=base.theta)
    kept = _scaled_rss(base.diffs, fitter.scales) <= _scaled_rss(d_config, fitter.scales)
    if not kept:
        say("baseline: the fitted ship replays worse than the config: the config is kept")
        base = _config_model(fitter, d_config)
    say(f"baseline (ship fitted, no effect): residual RMS {format_rms(_rms(base.diffs, fitter.recs))}")
    return d_config, base, kept, fitter


def _drift_terms(fitter, d_config, base, kept, o, say):
    """(baseline, kept, fitter) with the drift nonlinearities (:data:`TURN_HULL_TERMS`) freed where the records
    ask for them: their fit, started from the baseline, must lower the heading residual of the
    baseline fitted on by as many evaluations (the better of the two) by more than
    :data:`DRIFT_FALL_MIN`, and replay the records no worse than the config.

    A size test, not an evidence one: the fall parts hull forms whose drift forces the config's
    polynomial misses from those it holds (``python bench/drift_gate.py`` prints the falls; the gate's
    source is in ``configs/calibration/diagnose_rules.yaml``), where a dBIC gate fails whenever an effect
    fills the residual, and on a clean record of the ship that made it the six nearly collinear terms
    would wander on whatever the replay leaves.  Called on turns to one side (record_kind ``"turn"``) whose records
    log their sway.  Where the terms are freed, the fitter returned frees them too and is of kind
    :data:`DRIFT_KIND` (floors of their own); where not, the fitter and the baseline are returned as
    they came."""
    free0 = list(fitter.ship_free)
    ship, packed = fitter.ship, fitter.packed
    free1 = _ship_free(ship, packed, None, fitter.kind, drift=True)
    if len(free1) == len(free0):
        return base, kept, fitter
    ref = base
    polished = fitter.fit([], start=base.theta)
    if kept and _chi2(polished) < _chi2(base):
        ref = polished
    by_name = dict(zip([f.name for f in ref.free], ref.theta))
    drift = replace(fitter, ship_free=free1)
    m = drift.fit([], start=[by_name.get(f.name, f.prior) for f in free1])
    taus, _ = _taus(ref, o.stride)
    dbic = _delta_bic(ref, m, len(free1) - len(free0), taus, o.stride)
    better = _scaled_rss(m.diffs, fitter.scales) <= _scaled_rss(d_config, fitter.scales)
    fall = _rms(ref.diffs)["heading"] - _rms(m.diffs)["heading"]
    if better and fall > rule("drift_fall_min"):
        say(f"baseline: the drift terms freed (dBIC {fmt3(dbic)}, heading residual {fmt3(fall)} deg less): "
            f"residual RMS {format_rms(_rms(m.diffs, fitter.recs))}")
        return m, True, replace(drift, kind=DRIFT_KIND)
    say(f"baseline: the drift terms kept at the config's (dBIC {fmt3(dbic)}, heading residual {fmt3(fall)} deg less)")
    return base, kept, fitter


def fit_baseline(fitter, noise, o, say):
    """(the config's differences, the baseline fit, whether the fit was kept, the fitter of what follows):
    :func:`_baseline`, then on turns to one side whose records all log their sway and whose ship's own
    parameters are the default ones (``o.ship_free`` None), :func:`_drift_terms`."""
    d_config, base, kept, fitter = _baseline(fitter, noise, say)
    if o.ship_free is None and fitter.kind == "turn" and not any(r.seg.speed_only for r in fitter.recs):
        base, kept, fitter = _drift_terms(fitter, d_config, base, kept, o, say)
    return d_config, base, kept, fitter


_RULES = {"DRIFT_FALL_MIN": "drift_fall_min"}
"""The module's name of a number of the diagnosis rules (:mod:`.rules`), read-only: ``DRIFT_FALL_MIN``, the
fall of the heading residual [deg] that freeing the drift terms must bring (:func:`_drift_terms`), the
heading residual the ship's own mismatch leaves on a clean zigzag, where the drift stays small and these terms
play no part.  A smaller fall is not a drift the config misses.  It is a number of its own, not the zigzag
residual floor in use: the ``turn_drift`` floors were calibrated with this gate."""
__getattr__ = module_rule(__name__, _RULES)
