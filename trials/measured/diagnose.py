"""The discrepancy workflow (``mmg diagnose``): which effect is the model missing, how large, how
much closer it comes with it.

For the records given (every layout :func:`trials.files.logio.read_record` reads, the ship's length
checking the scale) and the ship config:

1. **Replay** each record against its measured rudder and revolutions (:mod:`mmg.replay`) in
   segments of ``segment_s`` (default 52 sqrt(L/g): 29 s for the 3 m model, 300 s at 325 m),
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
   (:func:`~trials.measured.diagnose_records.leading_straight_run`: rudder at its trim, no yaw, little
   wind) logs there a mean sway over ground that any hull leaves at (almost) zero through the water,
   so it is set by a heading bias (-u sin b) and a current's cross part alone, whatever the hull
   coefficients (:func:`ekf.identify.straight_run_residual`, one residual per record with its own
   standard error).  In the fit its weight is sqrt(tau_v), the v channel's correlation time: the fit
   counts each v row as if independent and dBIC counts it 1/tau_v times, so the straight run (a mean
   of v) keeps in the fit the weight against the v rows that dBIC gives it.  (The first form,
   sqrt(mean tau), over-weighted it on records whose u, v, r residuals are nearly white: on fresh
   family seed 18000 a 1 deg bias on a port turn fitted -0.93 deg at z 12.4 but at dBIC -1.3, the
   fit having traded the channels for the straight run.)  On a turning circle it is the one stretch where a
   heading bias does not trade with the hull terms (on turns of hulls that were not the model's a
   1-1.5 deg bias had sd 1.7-2.3 deg without it).  Its samples are also among the v rows; the
   straight run's own term is bounded by its hull-drift allowance, so the double count is small.

   An effect is **named** when dBIC > :data:`BIC_THRESHOLD` (20: twice Kass & Raftery's "very
   strong", calibrated on clean records by the bench) and its parameters differ from their neutral values by more than
   :data:`Z_THRESHOLD` standard errors (Gauss-Newton, inflated by sqrt(tau)) and its size clears
   the floor calibrated on ships that are not the model (:mod:`.decision`).  The best named
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
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace

import numpy as np

from mmg.errors import InputError
from mmg.model import pack
from mmg.parameters import MASS_NAMES, config_values
from mmg.ship import Ship

from .decision import (BIC_THRESHOLD, MAGNITUDE_UNITS, WEAK_BIC, Z_THRESHOLD, calibration, clears_floor, evidence_short, floor,
                       floor_parts, magnitude, mean_heading, over_floor, record_kind, residual_floor)
from .diagnose_records import Prepared, noise_level, prepare, synthetic_record, write_frt_csv  # noqa: F401
from .diagnose_report import fmt3, format_rms, format_values, round_header, size_with_unit
from .model_form import reclassify

__all__ = ["diagnose", "DiagnoseOptions", "Diagnosis", "straight_run_table", "straight_contradicts",
           "prepare", "synthetic_record", "write_frt_csv", "diagnose_each", "SHIP_FREE_TERMS", "MASS_FREE",
           "CONSTANTS_FREE", "TURN_CONSTANTS_FREE", "ZIGZAG_CONSTANTS_FREE", "TURN_HULL_TERMS", "DRIFT_FALL_MIN",
           "BIC_THRESHOLD", "Z_THRESHOLD", "CHANNELS"]

SHIP_FREE_TERMS = ("beta", "r", "v", "cos(beta)^2", "r|r|", "u^2")
"""Hull terms whose coefficients the diagnosis fits with every model (plus :data:`CONSTANTS_FREE`,
:data:`TURN_CONSTANTS_FREE` on turns, :data:`ZIGZAG_CONSTANTS_FREE` on zigzags, :data:`TURN_HULL_TERMS` on
turns to one side that need them,
:data:`MASS_FREE`)."""
TURN_HULL_TERMS = ("beta|beta|", "beta^2*r", "beta*r^2")
"""Hull terms it fits as well on turns to one side whose records need them (:func:`_drift_terms`): the
drift nonlinearities.  A 35 deg turn holds a drift of
10-15 deg for most of the record, where a real hull's side force and moment leave a polynomial
fitted for small drift (Kijima's) by more than its linear and r|r| terms can take up: on the
cross-flow members of the mismatch family the baseline left a 1.6-3 deg heading residual and a
10 m/s wind on a port turn was not identifiable (dBIC -12 to 11; 0 of 6 named over the calibration's
draws), with these terms freed 0.35-0.45 deg and the wind named (dBIC 46-76).  On a zigzag the
drift stays small and these terms would only trade with the linear ones."""
DRIFT_KIND = "turn_drift"
"""The kind of record set (:data:`~trials.measured.decision.KINDS`) of turns to one side (calibrated on
single turns) whose baseline freed the drift nonlinearities (:func:`_drift_terms`): its floors are
calibrated apart from those
of the turns that keep them at the config's (``"turn"``), since the ship's own mismatch lends the
candidates other sizes on the two baselines (fresh seed 27000: one set of floors over both
named shallow water on 2 of 20 clean Kijima turns)."""
SCREEN_NFEV = 6
"""Evaluation budget of a candidate's first (screening) fit; see :func:`diagnose`."""
UNEXPLAINED_FACTOR = 5.0
"""A residual RMS above this many times the channel's noise level is reported as unexplained."""
CHANNELS = ("u", "v", "r", "heading", "position")
"""Channels of ``rms_*``: u, v [m/s], r [deg/s], heading [deg], position [m] (RMS of the distance)."""
_COLS = ("u", "v", "r", "x", "y", "heading")


def _say(msg):
    print(msg, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------- statistics


def _tau(x: np.ndarray) -> float:
    """Integrated autocorrelation time (samples) of x: 1 + 2 sum rho_k over the initial positive run."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    n = len(x)
    if n < 8 or not np.any(x):
        return 1.0
    x = x - x.mean()
    f = np.fft.rfft(x, 2 * n)
    ac = np.fft.irfft(f * np.conj(f))[:n]
    if ac[0] <= 0:
        return 1.0
    rho = ac / ac[0]
    s = 0.0
    for k in range(1, n // 2):
        if rho[k] <= 0:
            break
        s += rho[k]
    return float(min(max(1.0 + 2.0 * s, 1.0), n / 4.0))


def _diffs(pred: np.ndarray, seg) -> np.ndarray:
    """Residual columns u, v, r, x, y, heading (replayed minus logged, SI) of what the record logs
    (:func:`ekf.identify.logged_residual`: a record with only the speed over ground has its u
    compared as that speed and no v)."""
    from ekf.identify import logged_residual

    return logged_residual(pred, seg)


def _rms(diffs: list, recs=None) -> dict:
    """Residual RMS per channel over the records (u, v [m/s], r [deg/s], heading [deg], position [m]); with
    ``recs`` (their :class:`Prepared`), v only over the records that log it, None when none does."""
    D = np.vstack(diffs)
    ok = np.isfinite(D).all(axis=1)
    D = D[ok] if ok.any() else np.zeros((1, 6))
    m = lambda a: float(np.sqrt(np.mean(a * a)))  # noqa: E731
    out = {"u": m(D[:, 0]), "v": m(D[:, 1]), "r": math.degrees(m(D[:, 2])), "heading": math.degrees(m(D[:, 5])),
           "position": float(np.sqrt(np.mean(D[:, 3] ** 2 + D[:, 4] ** 2)))}
    if recs is not None:
        v = [d[:, 1][np.isfinite(d).all(axis=1)] for d, r in zip(diffs, recs) if "v" not in r.absent]
        out["v"] = m(np.concatenate(v)) if v and sum(map(len, v)) else None
    return out


def absent_table(recs) -> list:
    """``[{"record", "channel", "column", "compared_instead"}]``: the residual channels each record does not log
    (:func:`trials.measured.diagnose_records.absent_channels`)."""
    return [{"record": r.name, "channel": c, **a} for r in recs for c, a in getattr(r, "absent", {}).items()]


# --------------------------------------------------------------------------- fitting


@dataclass
class _Model:
    effects: list
    free: list
    fit: object
    diffs: list          # per record (N, 6)
    straight: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """The straight-run residuals of the records that have one (:func:`ekf.identify.straight_run_residual`,
    unweighted: in their own standard errors)."""

    @property
    def theta(self):
        return self.fit.theta


CONSTANTS_FREE = ("w_P0",)
"""Propeller constants the diagnosis fits with every model: the wake w_P0 (the thrust)."""
TURN_CONSTANTS_FREE = ("epsilon",)
"""Rudder constants it fits as well on turns (:func:`~trials.measured.decision.record_kind` ``turn`` or
``turn_pair``): the rudder's inflow ratio epsilon (the rudder force, as epsilon^2).  In a 35 deg turn the
rudder's drag, (1 - t_R) F_N sin(delta), sets much of the speed lost; a rudder force 10-15 % off its
config leaves a residual in that speed loss and the drift that the resistance (u^2) and the wake cannot
take, and a candidate effect took it instead: on family member 31 of seed 5000 (rudder constants 9-14 %
off) a 10 m/s wind on a port turn was fitted at dBIC 19.5 and z 1.9 without epsilon, at dBIC 140 (z 10.5 on its loads)
(scale 1.08 for 1.10) with it.  On a zigzag the rudder force is what drives the response, and its size
trades with the freed linear hull terms (a Nomoto gain is their ratio): freeing it there too (variant 6
in ``docs/diagnose.md``) made a following 18 m/s wind on a 20/20 zigzag of the development set
not identifiable (correlation 0.997 with m_x, m_y, epsilon)."""
ZIGZAG_CONSTANTS_FREE = ("gamma_R_pos", "gamma_R_neg")
"""Rudder constants it fits as well on zigzags (:func:`~trials.measured.decision.record_kind`
``zigzag``): the flow-straightening coefficients gamma_R of the rudder's inflow angle for positive and
negative beta_R, each with its own prior (std 15 % of the config value, at least 0.05:
``rudder`` of :data:`ekf.identify.DIAGNOSIS_PRIOR_REL_STD`).  A real ship's two differ (the MMG
standard's KVLCC2: 0.395 and 0.640), and a difference the config does not have makes the rudder's
force asymmetric in a zigzag, where beta_R swings both ways: it is what the ship's own mismatch lends
a rudder offset there.  On the zigzags of fresh draws (family seeds 28000-31000, 140
clean or offset records) the round-1 offset's error was correlated -0.92 with the log of the member's
gamma_R_pos / gamma_R_neg, and three 1 deg offsets were fitted at 0.61-0.62 deg, under the zigzag floor that
asymmetry set (0.65 deg).  Freed, the two take the asymmetry: on family seed 32000 the 1 deg offsets
were fitted at 0.93-1.10 deg (0.87-1.39 without) and the clean zigzags' offsets fell from 0.08-0.53 to
0.02-0.26 deg.  The offset stays identifiable because it acts at every drift and the asymmetry only
with drift or yaw, but the two correlate (0.97-0.99 in that fit), so its standard error grows.  On a
turn to one side beta_R keeps one sign and only one of the two would be seen; it is not freed there."""
MASS_FREE = MASS_NAMES
"""Added masses and the added moment of inertia the diagnosis fits with every model (prior: the
config value, relative std from :data:`ekf.identify.DIAGNOSIS_PRIOR_REL_STD`, the diagnosis's policy
in the one table of prior widths): an added mass a few % off leaves a residual (surge speed loss in
the turn, sway and yaw lag) that an effect would otherwise take."""


LINEAR_TERMS = ("beta", "r", "v")
"""Hull terms whose coefficients take the ``hull`` (linear) width of
:data:`ekf.identify.DIAGNOSIS_PRIOR_REL_STD`."""
RESISTANCE_TERMS = ("cos(beta)^2", "u^2")
"""Hull terms that take its ``resistance`` width; every other freed hull term its ``hull_nonlinear``."""
MISMATCH_Z = 3.0
"""A fitted ship coefficient more than this many prior std from its config value is reported as
model-form mismatch (:attr:`Diagnosis.model_form_mismatch`) and not written to ``--out-ship``."""


def _baseline_prior(f, term):
    """``f`` (a :class:`ekf.identify.FreeParameter`) with the diagnosis's prior width
    (:data:`ekf.identify.DIAGNOSIS_PRIOR_REL_STD`, by the term's family) and, for a hull coefficient,
    its config sign kept as a bound (the signs that define the ship: a positive Y_beta, a negative N_r)."""
    from ekf.identify import DIAGNOSIS_PRIOR_REL_STD as P

    if f.kind == "hull":
        fam = "hull" if term in LINEAR_TERMS else "resistance" if term in RESISTANCE_TERMS else "hull_nonlinear"
        lo, hi = (0.0, np.inf) if f.prior > 0 else (-np.inf, 0.0) if f.prior < 0 else (f.lower, f.upper)
        return replace(f, sigma=max(P[fam] * abs(f.prior), P["hull_floor"]), lower=max(lo, f.lower),
                       upper=min(hi, f.upper))
    if f.kind == "w_P0":
        return replace(f, sigma=max(P["w_P0"] * abs(f.prior), 0.01))
    return f


def _ship_free(ship: Ship, packed, names=None, kind: str = "zigzag", drift: bool = False):
    """The ship's own parameters the diagnosis fits (``names``, or by default :data:`SHIP_FREE_TERMS`,
    :data:`CONSTANTS_FREE`, on a ``"zigzag"`` :data:`ZIGZAG_CONSTANTS_FREE`, on any other ``kind`` of
    record set :data:`TURN_CONSTANTS_FREE` and, with ``drift``, :data:`TURN_HULL_TERMS`, and
    :data:`MASS_FREE`) with the diagnosis's priors."""
    from ekf.identify import DIAGNOSIS_PRIOR_REL_STD, free_parameters

    if names is None:
        names = [n for n, t in zip(ship.hull.names, ship.hull.terms) if t in SHIP_FREE_TERMS] + list(CONSTANTS_FREE)
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
    terms = dict(zip(ship.hull.names, ship.hull.terms))
    return [_baseline_prior(f, terms.get(f.name)) for f in free]


def ship_fit_table(free, theta) -> list:
    """[{"name", "config", "fitted", "prior_std", "z"}] of the freed ship coefficients (added masses
    and moment in kg, kg m^2; hull coefficients primed), z their distance from the config in prior std."""
    return [{"name": f.name, "config": float(f"{f.prior:.5g}"), "fitted": float(f"{float(v):.5g}"),
             "prior_std": float(f"{f.sigma:.3g}"), "z": round((float(v) - f.prior) / f.sigma, 2) if f.sigma > 0 else 0.0}
            for f, v in zip(free, theta)]


def model_form_mismatch(free, theta) -> dict:
    """{coefficient: {"config", "fitted", "prior_std", "z"}} of the ship coefficients the fit took
    more than :data:`MISMATCH_Z` prior std from the config: the data ask for another model form (or
    an effect the candidates lack), not for these values."""
    return {r["name"]: {k: r[k] for k in ("config", "fitted", "prior_std", "z")}
            for r in ship_fit_table(free, theta) if abs(r["z"]) > MISMATCH_Z}


class _Fitter:
    def __init__(self, ship, packed, recs, scales, stride, max_nfev, ship_free):
        self.ship, self.packed, self.recs, self.scales = ship, packed, recs, scales
        self.stride, self.max_nfev, self.ship_free = stride, max_nfev, ship_free
        self.straight_weight = 1.0     # the round's sqrt(tau_v) (FitOptions.straight_weight; set by _search)

    def diffs(self, effects, free, theta):
        from ekf.identify import predict_logged

        return [_diffs(predict_logged(self.packed, r.seg, effects, free, theta, self.ship), r.seg)
                for r in self.recs]

    def straight(self, effects, free, theta) -> np.ndarray:
        """The records' straight-run residuals (:func:`ekf.identify.straight_run_residual`), unweighted."""
        from ekf.identify import straight_run_residual

        rows = [straight_run_residual(r.seg, list(effects) or None, free, theta, k) for k, r in enumerate(self.recs)]
        return np.array([a for a in rows if a is not None], float)

    def fit(self, effects, start_ship=None, start_eff=None, max_nfev=None, start=None) -> _Model:
        """Fit the ship terms and ``effects``' parameters; ``start`` (the whole vector) or
        ``start_ship`` and ``start_eff`` (a prefix of the effects' parameters) warm-start it."""
        from ekf.identify import effect_parameters, identify_segments

        free = list(self.ship_free) + effect_parameters(effects)
        if start is None:
            x_ship = [f.prior for f in self.ship_free] if start_ship is None else list(start_ship)
            eff_start = [f.prior if f.start is None else f.start for f in free[len(self.ship_free):]]
            if start_eff is not None:
                eff_start[:len(start_eff)] = list(start_eff)
            start = x_ship + eff_start
        x0 = np.array(start, float)
        fit = identify_segments(self.packed, [r.seg for r in self.recs], free, self.scales, stride=self.stride,
                                max_nfev=max_nfev or self.max_nfev, start=x0, effects=list(effects) or None,
                                ship=self.ship, straight_weight=self.straight_weight)
        return _Model(list(effects), free, fit, self.diffs(effects, free, fit.theta),
                      self.straight(effects, free, fit.theta))


def _stack(diffs, stride):
    D = np.vstack([d[::stride] for d in diffs])
    D[~np.isfinite(D)] = 0.0
    return D


def _scores(model_diffs, taus, stride):
    D = _stack(model_diffs, stride)
    N = D.shape[0]
    rss = np.maximum(np.sum(D * D, axis=0), 1e-300)
    neff = N / taus
    return rss, neff


def _delta_bic(before, after, k, taus, stride):
    """The channels' dBIC (module docstring) plus the change of the straight runs' chi-square: each is
    one mean with its own known standard error (:class:`ekf.identify.StraightRun`), so -2 ln L moves
    by the change of its square."""
    rss0, neff = _scores(before.diffs, taus, stride)
    rss1, _ = _scores(after.diffs, taus, stride)
    if len(before.straight) != len(after.straight):
        raise ValueError("the two models' straight runs differ in number (models of other records)")
    straight = float(np.sum(before.straight ** 2) - np.sum(after.straight ** 2))
    return float(np.sum(neff * np.log(rss0 / rss1)) - k * math.log(float(np.sum(neff)))) + straight


def _effect_index(model: _Model, effect, presence_only: bool = False) -> list:
    """Indices of ``effect``'s fitted parameters in ``model.free`` (only those that say it is there,
    :meth:`mmg.effects.Effect.presence_parameters`, with ``presence_only``)."""
    pres = effect.presence_parameters()
    return [i for i, f in enumerate(model.free) if f.kind == "effect" and f.name.split(".")[0] == effect.name
            and (not presence_only or f.name.split(".")[-1] in pres)]


def _effect_report(model: _Model, effect, inflate: float):
    idx = _effect_index(model, effect)
    th = model.fit.theta[idx]
    std = model.fit.std[idx] * inflate
    corr = np.nan_to_num(model.fit.corr[np.ix_(idx, idx)], nan=0.0)
    np.fill_diagonal(corr, 1.0)
    cov = corr * np.outer(std, std)
    vals, se = effect.report(th, cov)
    return vals, se, effect.presence_z(th, cov)


# --------------------------------------------------------------------------- description of what is left


def _describe(recs, diffs, noise, rms_after, L: float | None = None, kind: str | None = None) -> tuple[bool, str, dict]:
    """Unexplained flag, description and per-channel ratio residual / noise: a channel is unexplained
    when its residual is above :data:`UNEXPLAINED_FACTOR` times its noise *and* above what the ship's
    own mismatch leaves (:func:`trials.measured.decision.residual_floor`, with the ship length ``L``
    and the kind of record set, :func:`~trials.measured.decision.record_kind` when not given)."""
    D = np.vstack(diffs)
    M = np.vstack([r.seg.meas for r in recs])
    delta = np.concatenate([r.seg.inputs.delta for r in recs])
    ok = np.isfinite(D).all(axis=1)
    D, M, delta = D[ok], M[ok], delta[ok]
    names = ("u", "v", "r", "x", "y", "heading")
    ratio = {}
    for j, c in enumerate(names):
        ratio[c] = float(np.sqrt(np.mean(D[:, j] ** 2)) / max(noise[j], 1e-12))
    # position: the track's own growth within segments is not noise; judge u, v, r, heading
    U = float(np.median(np.hypot(M[:, 0], M[:, 1]))) if len(M) else 0.0
    rms = {c: float(np.sqrt(np.mean(D[:, names.index(c)] ** 2))) for c in ("u", "v", "r", "heading")}
    kind = kind or record_kind([r.seg.inputs.delta for r in recs])
    big = [c for c in ("u", "v", "r", "heading") if ratio[c] > UNEXPLAINED_FACTOR
           and (L is None or rms[c] > residual_floor(c, U, L, kind))]
    if not big:
        return False, "", ratio
    from .diagnose_report import channel_text

    parts = []
    psi = M[:, 5]
    for c in big:
        j = names.index(c)
        e = D[:, j] - D[:, j].mean()
        desc = [channel_text(c, float(np.sqrt(np.mean(D[:, j] ** 2))), float(noise[j]), float(D[:, j].mean()))]
        # earth-fixed: explained by cos/sin of heading; rudder: by delta
        A = np.column_stack([np.cos(psi), np.sin(psi), np.ones_like(psi)])
        r2_h = _r2(A, D[:, j])
        r2_d = _r2(np.column_stack([delta, np.abs(delta), np.ones_like(delta)]), D[:, j])
        r2_c = 1.0 - float(np.var(e)) / max(float(np.mean(D[:, j] ** 2)), 1e-300)
        desc.append(f"its constant part {r2_c:.0%} of the mean square")
        desc.append(f"correlated with heading (earth-fixed) R2 {r2_h:.2f}")
        desc.append(f"with rudder R2 {r2_d:.2f}")
        ws = [r.seg.context.channels.get("wind_speed_rel") if r.seg.context else None for r in recs]
        if all(w is not None for w in ws):
            wd = [r.seg.context.channels.get("wind_dir_rel") for r in recs]
            w = np.concatenate(ws)[ok]
            g = np.concatenate(wd)[ok]
            q = w * w
            r2_w = _r2(np.column_stack([q * np.cos(g), q * np.sin(g), q * np.sin(2 * g), np.ones_like(q)]), D[:, j])
            desc.append(f"with relative wind R2 {r2_w:.2f}")
        parts.append(", ".join(desc))
    return True, "; ".join(parts) + ": no candidate effect explains it", ratio


def _r2(A, y):
    y = np.asarray(y, float)
    if not np.any(y):
        return 0.0
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    res = y - A @ coef
    v = float(np.var(y))
    return float(max(0.0, 1.0 - np.var(res) / v)) if v > 0 else 0.0


# --------------------------------------------------------------------------- the workflow


@dataclass
class Diagnosis:
    """The result of :func:`diagnose` (see :meth:`to_json`)."""

    named: list
    parameters: dict
    standard_errors: dict
    rms_config: dict
    rms_before: dict
    rms_after: dict
    unexplained: bool
    unexplained_description: str
    candidates: list
    rounds: list
    ship_values: dict
    records: list
    pred_before: list
    pred_after: list
    seconds: float
    runs: list = field(default_factory=list)
    effects: list = field(default_factory=list)
    ship_fit_values: dict = field(default_factory=dict)
    """The ship's values as written to ``--out-ship``, by fit name in the fit's units (:mod:`mmg.parameters`;
    :attr:`ship_values` has them under the config's keys)."""
    intervals_95: dict = field(default_factory=dict)
    """{effect: {parameter: [lo, hi] or "any"}} (:func:`trials.measured.diagnose_report.effect_intervals`)."""
    evidence: dict = field(default_factory=dict)
    """{effect: {"delta_bic", "z", "false_alarm_probability"}} (:func:`~trials.measured.diagnose_report.effect_evidence`)."""
    not_identifiable: list = field(default_factory=list)
    """[{"effect", "confused_with", "correlation", "what_would_separate"}]: effects these records cannot separate."""
    identifiability: list = field(default_factory=list)
    """Every candidate's correlation with the rest, std and detection size (:mod:`trials.measured.identifiability`)."""
    model_form_mismatch: dict = field(default_factory=dict)
    """Ship coefficients the fit took far outside their priors (which, how far): :func:`model_form_mismatch`."""
    ship_fit: list = field(default_factory=list)
    """The freed ship coefficients: config, fitted, prior std, z (:func:`ship_fit_table`)."""
    baseline: str = "fitted"
    """"fitted", or "config (the fit replayed worse)" when the baseline fit was not kept."""
    straight_runs: list = field(default_factory=list)
    """The records' leading straight runs the fit used (:func:`straight_run_table`)."""
    absent_channels: list = field(default_factory=list)
    """Residual channels a record does not log and what was compared instead (:func:`absent_table`)."""
    model_form_effects: list = field(default_factory=list)
    """Effects the search named whose fit stands for a gap of the model's form, reported ``model_form_mismatch``
    instead (:func:`trials.measured.model_form.reclassify`): kept in the fitted model, not named."""

    @property
    def effect_status(self) -> dict:
        """{effect: "named", "model_form_mismatch" or "not_identifiable"} of the effects reported."""
        out = {x["effect"]: "not_identifiable" for x in self.not_identifiable or []}
        out.update({x["effect"]: x["status"] for x in self.model_form_effects})
        return {**out, **{e: "named" for e in self.named}}

    def summary_lines(self) -> list:
        """The console text (:func:`trials.measured.diagnose_report.summary_lines`)."""
        from .diagnose_report import summary_lines

        return summary_lines(self)

    def to_json(self) -> dict:
        out = {"named_effects": list(self.named), "parameters": self.parameters,
               "standard_errors": self.standard_errors, "intervals_95": self.intervals_95,
               "evidence": self.evidence, "not_identifiable": list(self.not_identifiable),
               "model_form_mismatch": self.model_form_mismatch, "baseline": self.baseline,
               "ship_fit": self.ship_fit,
               "rms_before": self.rms_before, "rms_after": self.rms_after, "rms_config": self.rms_config,
               "rms_units": {"u": "m/s", "v": "m/s", "r": "deg/s", "heading": "deg", "position": "m"},
               "unexplained": bool(self.unexplained), "unexplained_description": self.unexplained_description,
               "candidates": self.candidates, "rounds": self.rounds,
               "threshold": {"delta_bic": BIC_THRESHOLD, "z": Z_THRESHOLD},
               "ship_coefficients": self.ship_values,
               "files": [r.source for r in self.records], "names": [r.name for r in self.records],
               "seconds": round(self.seconds, 2),
               "identifiability": self.identifiability, "straight_runs": self.straight_runs,
               "absent_channels": self.absent_channels, "model_form_effects": self.model_form_effects,
               "effect_status": self.effect_status}
        if self.runs:
            out["runs"] = [dict(r.to_json(), name=r.records[0].name, file=r.records[0].source) for r in self.runs]
        return out


@dataclass(frozen=True)
class DiagnoseOptions:
    """How :func:`diagnose` searches (each field also a keyword argument of it).

    Attributes
    ----------
    wind : bool or None
        Wind loads in the model from the start: ``False`` (default: wind is then a candidate),
        ``True``, or ``None`` as the ship config says.
    candidates : list of str, optional
        Effect names to try (default: every registered effect).
    segment_s : float, optional
        Segment length [s] (default 52 sqrt(L/g)).
    stride : int, optional
        Use every ``stride``-th sample in the fits (default: samples 0.36 sqrt(L/g) apart, 0.2 s
        for the 3 m model, 2 s at 325 m; at least 1).
    max_nfev, screen_nfev : int
        Evaluation budgets of a fit: every candidate is first fitted (warm, from the current
        model) with ``screen_nfev``; one the budget stopped whose dBIC is positive or whose z
        clears the threshold is fitted on, up to ``max_nfev`` in all.
    per_run : bool
        With several records, also diagnose each alone (``runs``).
    ship_free : sequence of str, optional
        The ship's own parameters fitted with the effects (:func:`_ship_free`).
    say : callable, optional
        Where the progress lines go (nowhere when omitted).
    backend : str
        How the per-record diagnoses (``per_run``) are spread: ``"serial"`` (default), ``"loky"``
        (this machine's cores) or ``"dask"`` (the workers of ``client``): the same numbers either way
        (:func:`diagnose_each`).
    client : distributed.Client, optional
        The dask client for ``backend="dask"`` (default: the current one).
    n_jobs : int, optional
        Local workers of ``backend="loky"`` (default: every usable core).
    candidate_start : {"config", "current"}
        Where a candidate's fit starts the ship's own terms: ``"config"`` (default: the config's
        values, the priors' means, with the effects already named at their fitted values) or
        ``"current"`` (the model of the round before, e.g. the baseline fit).  A baseline without
        the effect bends the ship to mimic it (a 1 kn current on a zigzag: Y_rr 7 prior std out),
        and a fit started in that bend stays near it (the current then named at 0.32 m/s for 0.51).
    """

    wind: bool | None = False
    candidates: object = None
    segment_s: float | None = None
    stride: int | None = None
    max_nfev: int = 12
    per_run: bool = False
    ship_free: object = None
    say: object = None
    screen_nfev: int = SCREEN_NFEV
    backend: str = "serial"
    client: object = None
    n_jobs: int | None = None
    candidate_start: str = "config"


def _default_stride(recs, L: float) -> int:
    """Samples 0.36 sqrt(L/g) apart, at least every one."""
    dt = float(np.median(np.diff(recs[0].seg.inputs.t)))
    return max(1, int(round(0.36 * math.sqrt(L / 9.80665) / dt)))


def _candidates(recs, names, say):
    """(the effect classes to try, the log entries of those skipped and why)."""
    import mmg.effects as E

    cand, cand_log = [], []
    for nm in names:
        cls = E.get(nm, "--candidates")
        why = None
        if nm == "wind" and recs[0].seg.inputs.ext is not None:
            why = "wind loads are already in the model (ship config wind on)"
        for r in recs:
            why = why or cls.unavailable(r.seg.context)
            if why:
                why = f"{r.name}: {why}" if len(recs) > 1 and not why.startswith("wind loads") else why
                break
        if why:
            cand_log.append({"effect": nm, "skipped": why})
            say(f"candidate {nm} skipped: {why}")
        else:
            cand.append(cls)
    return cand, cand_log


def _scaled_rss(diffs, scales) -> float:
    """Sum of the squared residuals of every channel over its scale (the fit's cost without the prior)."""
    D = _stack(diffs, 1)
    sc = np.array([scales.u, scales.v, scales.r, scales.pos, scales.pos, scales.psi])
    return float(np.sum((D / sc) ** 2))


def _config_model(fitter, d_config) -> _Model:
    """The config as it is, as a :class:`_Model` (its standard errors the priors')."""
    from ekf.identify import IdentifyResult

    free = list(fitter.ship_free)
    th = np.array([f.prior for f in free])
    fit = IdentifyResult(free=free, theta=th, std=np.array([f.sigma for f in free]), corr=np.eye(len(free)),
                         cost_initial=math.nan, cost_final=math.nan, n_residuals=0, iterations=0,
                         message="the config as given (the fit replayed worse)")
    return _Model([], free, fit, d_config, fitter.straight([], free, th))


def _baseline(fitter, noise, say):
    """(the config's differences, the baseline fit, whether the fit was kept): fitted, every channel
    rescaled by the first fit's own residual (floored at the noise), fitted again; a fit that replays
    the records worse than the config as given (scaled residuals, no prior) is not kept: the config is."""
    from ekf.identify import Scales

    d_config = fitter.diffs([], [], [])
    base = fitter.fit([])
    D = _stack(base.diffs, 1)
    rm = np.sqrt(np.mean(D * D, axis=0))
    fl = np.maximum(rm, np.maximum(noise, 1e-9))
    fitter.scales = Scales(u=fl[0], v=fl[1], r=fl[2], psi=fl[5], pos=float(np.hypot(fl[3], fl[4])) / math.sqrt(2))
    base = fitter.fit([], start_ship=base.theta)
    kept = _scaled_rss(base.diffs, fitter.scales) <= _scaled_rss(d_config, fitter.scales)
    if not kept:
        say("baseline: the fitted ship replays worse than the config: the config is kept")
        base = _config_model(fitter, d_config)
    say(f"baseline (ship fitted, no effect): residual RMS {format_rms(_rms(base.diffs, fitter.recs))}")
    return d_config, base, kept


def _drift_terms(fitter, d_config, base, kept, o: DiagnoseOptions, say):
    """(baseline, kept) with the drift nonlinearities (:data:`TURN_HULL_TERMS`) freed where the records
    ask for them: their fit, started from the baseline, must lower the heading residual of the
    baseline fitted on by as many evaluations (the better of the two) by more than
    :data:`DRIFT_FALL_MIN`, and replay the records no worse than the config.

    A size test, not an evidence one.  On 48 clean family turns (``python bench/drift_gate.py --n
    48``, seed 1000) the fall parts the hull forms: 0.83-5.55 deg on every cross-flow member, at most
    0.054 deg on the Kijima ones but one (0.240).  A dBIC gate adds nothing there, and fails where an
    effect fills the residual: a 15 m/s wind on a cross-flow turn (fresh seed 28000) left a 8.5 deg
    heading residual that the drift terms lowered by 1.9 deg at dBIC -9, the terms stayed at the
    config's, and the wind was not named.  On a clean record of the ship that made it the six terms,
    nearly collinear, would wander on whatever the replay leaves (the main job's clean ST35 truth
    file: a fall of 0.0020 deg at dBIC 28; freed, N_bb 3.1 and Y_bbr 3.3 prior std off the config):
    the size test keeps them.  Called on turns to one side (record_kind ``"turn"``) whose records
    log their sway.  Where the terms are freed, ``fitter.ship_free`` takes them and ``fitter.kind``
    becomes :data:`DRIFT_KIND` (floors of their own); where not, both and the baseline are left as
    they were."""
    free0 = list(fitter.ship_free)
    ship, packed = fitter.ship, fitter.packed
    free1 = _ship_free(ship, packed, None, fitter.kind, drift=True)
    if len(free1) == len(free0):
        return base, kept
    ref = base
    polished = fitter.fit([], start=base.theta)
    if kept and _chi2(polished) < _chi2(base):
        ref = polished
    by_name = dict(zip([f.name for f in ref.free], ref.theta))
    fitter.ship_free = free1
    m = fitter.fit([], start=[by_name.get(f.name, f.prior) for f in free1])
    taus, _ = _taus(ref, o.stride)
    dbic = _delta_bic(ref, m, len(free1) - len(free0), taus, o.stride)
    better = _scaled_rss(m.diffs, fitter.scales) <= _scaled_rss(d_config, fitter.scales)
    fall = _rms(ref.diffs)["heading"] - _rms(m.diffs)["heading"]
    if better and fall > DRIFT_FALL_MIN:
        say(f"baseline: the drift terms freed (dBIC {fmt3(dbic)}, heading residual {fmt3(fall)} deg less): "
            f"residual RMS {format_rms(_rms(m.diffs, fitter.recs))}")
        fitter.kind = DRIFT_KIND
        return m, True
    fitter.ship_free = free0
    say(f"baseline: the drift terms kept at the config's (dBIC {fmt3(dbic)}, heading residual {fmt3(fall)} deg less)")
    return base, kept


DRIFT_FALL_MIN = 0.2192
"""The fall of the heading residual [deg] that freeing the drift terms must bring
(:func:`_drift_terms`): the heading residual the ship's own mismatch left on a clean zigzag, where the
drift stays small, as calibrated when the gate was chosen and ``turn_drift`` calibrated (then
``residual_floors.zigzag.heading`` of the packaged calibration then, 0.2192 deg).  A fall smaller
than what a ship that is not its model leaves where these terms play no part is not a drift the
config misses: on the main job's noiseless ST35 truth file, diagnosed with the ship that made it,
they took the heading residual from 0.0087 to 0.0067 deg at dBIC 28, and wandered 3.3 prior std
(``bench/drift_gate.py`` prints the falls).  A number of its own, not read from the zigzag floors in
use: those moved when the zigzag baseline freed gamma_R (:data:`ZIGZAG_CONSTANTS_FREE`),
and the turns' gate and the ``turn_drift`` floors calibrated with it must not move with them."""


def _covered(fitter, cand, say) -> tuple[list, list]:
    """(the candidates to fit, ``not_identifiable`` entries of those left out): a coefficient effect
    whose every changed coefficient (:meth:`mmg.effects.Effect.changed_coefficients`) the baseline
    frees is a change of the ship's own coefficients there, not something the records can tell from
    them, and is not fitted.  Shallow water on a turn whose drift terms are freed (:data:`DRIFT_KIND`):
    over 169 such candidate fits of the calibration and check draws of the ``turn_drift`` floors its dBIC never passed
    18.1 and its z never 1.73 (a name needs 20 and 3), and not fitting it takes a 3500 s turn from
    17.7 s to under the 15 s asked (``bench/bench_diagnose.py --timing-only``)."""
    free = {f.name for f in fitter.ship_free}
    keep, out = [], []
    for cls in cand:
        ch = cls.changed_coefficients(fitter.ship)
        if not ch or not set(ch) <= free:
            keep.append(cls)
            continue
        reason = f"a change of coefficients this fit frees, every one ({', '.join(ch)})"
        say(f"candidate {cls.name} not fitted: {reason}")
        out.append({"effect": cls.name, "confused_with": list(ch), "correlation": None,
                    "what_would_separate": f"{cls.measured_by}, or a zigzag diagnosed with these records",
                    "reason": reason,
                    "reason_kind": "coefficients"})
    return keep, out


def _taus(current, stride):
    """(correlation times [samples] of each channel's residual, the standard-error inflation)."""
    taus = np.array([np.median([_tau(d[::stride, j]) for d in current.diffs]) for j in range(6)])
    return taus, math.sqrt(float(np.mean(taus)))


def _try_candidate(fitter, current, cls, taus, inflate, ns, o: DiagnoseOptions):
    """(dBIC, clears the thresholds, cls, fit, values, standard errors, z, magnitude) of ``current``
    plus ``cls``: screened with ``screen_nfev``, a promising one the budget stopped fitted on to
    ``max_nfev``; named only above the calibrated floor of its magnitude (:mod:`.decision`)."""
    effs = current.effects + [cls]
    ship0 = None if o.candidate_start == "config" else current.theta[:ns]
    m = fitter.fit(effs, start_ship=ship0, start_eff=list(current.theta[ns:]), max_nfev=o.screen_nfev)
    k = len(cls.fit_parameters())
    dbic = _delta_bic(current, m, k, taus, o.stride)
    vals, se, z = _effect_report(m, cls, inflate)
    if m.fit.iterations >= o.screen_nfev and o.max_nfev > o.screen_nfev and (dbic > 0 or z > Z_THRESHOLD):
        m = fitter.fit(effs, start=m.theta, max_nfev=o.max_nfev - o.screen_nfev)
        dbic = _delta_bic(current, m, k, taus, o.stride)
        vals, se, z = _effect_report(m, cls, inflate)
    L = fitter.ship.particulars.L
    if ship0 is None and ns > 0 and _retry_from_current(fitter, cls, dbic, z, vals):
        m, dbic, vals, se, z = _nested_start(fitter, current, cls, taus, inflate, ns, o, (m, dbic, vals, se, z))
    mag = magnitude(cls.name, vals, L)
    ok = (dbic > BIC_THRESHOLD and z > Z_THRESHOLD and clears_floor(cls.name, vals, L, fitter.kind, fitter.heading)
          and not straight_contradicts(current.straight, m.straight))
    return dbic, ok, cls, m, vals, se, z, mag, _confounding(m, cls)


def _retry_from_current(fitter, cls, dbic: float, z: float, vals: dict) -> bool:
    """Whether a candidate fitted from the config's ship terms is fitted again from the model it is
    tested against (:func:`_nested_start`, the better kept): where that fit stopped short of it (dBIC
    below 0) though its precision and size would name it; on a turn whose baseline freed the drift
    nonlinearities (:data:`TURN_HULL_TERMS`, :data:`DRIFT_KIND`) wherever it falls short of the
    evidence to name it: from the config's values a budget of a few evaluations does not
    bring them and the effect's own parameters together (a 10 m/s wind on a cross-flow member's port
    turn: z 0.07 from the config, dBIC 76 and z 6.6 from the baseline fit)."""
    if fitter.kind == DRIFT_KIND:
        return dbic <= BIC_THRESHOLD
    L = fitter.ship.particulars.L
    return dbic < 0 and z > Z_THRESHOLD and clears_floor(cls.name, vals, L, fitter.kind, fitter.heading)


def straight_contradicts(before, after) -> bool:
    """Whether a model leaves some record's straight run (:class:`ekf.identify.StraightRun`) more than
    :data:`~trials.measured.decision.Z_THRESHOLD` of its standard errors off, and further off than the
    model it was tested against: the straight run reads a heading bias plus a current's cross part
    directly, so an effect whose fit it contradicts is asked for by the rest of the record (the
    ship's own mismatch on a turn), not by itself.  (Fresh family seed 21000: a 0.5 deg rudder offset
    on a port turn was named as a -0.56 deg heading bias, the straight run reading 0.06 +- 0.11 deg.)"""
    b, a = np.abs(np.asarray(before, float)), np.abs(np.asarray(after, float))
    return bool(len(a) and np.any((a > Z_THRESHOLD) & (a > b)))


def _nested_start(fitter, current, cls, taus, inflate, ns, o: DiagnoseOptions, first):
    """The better (by dBIC) of ``first`` = (fit, dBIC, values, se, z) and a fit started from ``current``
    itself with the effect at its neutral start.  ``current`` plus the effect holds ``current`` (the
    effect at neutral), so a dBIC below zero says the fit from the config's ship terms stopped short
    of it within its budget; a candidate whose precision and size would name it is then not judged on
    that unfinished fit (fresh family seed 18000: a 1 deg bias on a port turn, z 4.5 and over its
    floor, at dBIC -7 from the config's start)."""
    effs = current.effects + [cls]
    m = fitter.fit(effs, start_ship=current.theta[:ns], start_eff=list(current.theta[ns:]), max_nfev=o.max_nfev)
    dbic = _delta_bic(current, m, len(cls.fit_parameters()), taus, o.stride)
    if dbic <= first[1]:
        return first
    return (m, dbic, *_effect_report(m, cls, inflate))


def _confounding(model: _Model, effect) -> float:
    """R: the multiple correlation of the effect's presence parameters with every other fitted one
    (:func:`trials.measured.identifiability.block_confounding` of the fit's covariance); NaN where
    the covariance is not finite."""
    from .identifiability import block_confounding

    idx = _effect_index(model, effect, presence_only=True)
    std = np.asarray(model.fit.std, float)
    cov = np.nan_to_num(model.fit.corr, nan=0.0) * np.outer(std, std)
    np.fill_diagonal(cov, std * std)
    if not idx or not np.all(np.isfinite(cov)) or np.any(np.diag(cov) <= 0):
        return math.nan
    try:
        return float(block_confounding(cov, idx)["R"])
    except (np.linalg.LinAlgError, ValueError):
        return math.nan


def _parts(fitter, name: str, values: dict) -> dict:
    """``{"parts": {part: [size, floor]}}`` of a candidate judged by its parts (a current on a
    zigzag: :func:`~trials.measured.decision.floor_parts`), else ``{}``."""
    p = floor_parts(name, values, fitter.ship.particulars.L, fitter.kind, fitter.heading)
    return {"parts": {k: list(v) for k, v in p.items()}} if p else {}


def _search(fitter, base, cand, ns, o: DiagnoseOptions, say):
    """Forward selection from the baseline: each round tries every remaining candidate and names the
    best that clears the thresholds and holds beside its rival (:func:`_best_standing`).  Returns
    (final fit, named effects, the rounds' log)."""
    current, named, rounds, remaining = base, [], [], list(cand)
    lt = (fitter.ship.particulars.L, fitter.ship.particulars.T)
    while remaining:
        current = _polish(fitter, current, o)
        taus, inflate = _taus(current, o.stride)
        fitter.straight_weight = math.sqrt(taus[1])     # the v channel's: the straight run is a mean of v
        results, parts = [], []
        say(round_header(len(rounds) + 1, named))
        for cls in remaining:
            results.append(_try_candidate(fitter, current, cls, taus, inflate, ns, o))
            dbic, _, _, _, vals, _, z, mag, _ = results[-1]
            parts.append(_parts(fitter, cls.name, vals))
            pt = parts[-1].get("parts")
            sz = lambda x: size_with_unit(x, MAGNITUDE_UNITS.get(cls.name, ''), *lt)     # noqa: E731
            size = (", ".join(f"{k} {sz(abs(a))} (floor {sz(f)})" for k, (a, f) in pt.items()) if pt else
                    f"{sz(mag)} (floor {sz(floor(cls.name, fitter.kind))})")
            say(f"  {cls.name}: dBIC {fmt3(dbic)}, z {fmt3(z)}, {format_values(cls.name, vals)}, size {size}")
        rounds.append({"round": len(rounds) + 1, "model": [e.name for e in current.effects],
                       "tau_samples": {c: round(float(t), 1) for c, t in zip(_COLS, taus)},
                       "kind": fitter.kind, "heading_deg": round(math.degrees(fitter.heading), 2),
                       "candidates": [{"effect": c.name, "delta_bic": round(d, 2), "z": round(z, 2),
                                       "magnitude": float(f"{g:.4g}"), "floor": floor(c.name, fitter.kind),
                                       **pa, "R": round(rr, 4) if math.isfinite(rr) else None,
                                       "clears_threshold": bool(ok), "parameters": v, "standard_errors": s,
                                       **({"straight_z": [round(float(x), 2) for x in m.straight],
                                           "straight_contradicts": straight_contradicts(current.straight, m.straight)}
                                          if len(m.straight) else {})}
                                      for (d, ok, c, m, v, s, z, g, rr), pa in zip(results, parts)]})
        best = _best_standing(fitter, current, results, taus, inflate, ns, o, rounds[-1], say)
        if best is None:
            break
        named.append(best[2].name)
        current = best[3]
        remaining.remove(best[2])
    return current, named, rounds


def _polish(fitter, current, o: DiagnoseOptions):
    """On a turn whose baseline freed the drift terms (:data:`DRIFT_KIND`), ``current`` fitted on by
    another ``max_nfev`` evaluations from where it stopped (the
    better of the two kept): a candidate there is fitted again from ``current``
    (:func:`_retry_from_current`), and its dBIC must not count the further convergence of the ship's
    own terms that its longer fit reached as evidence for the effect.  (Calibration seed 1200: a
    0.25 m/s current on a cross-flow member's turn, named at 0.251 m/s in round 1, was joined in
    round 2 by a -1.14 deg heading bias at dBIC 39, the current pushed to 0.349 m/s, and a rudder
    offset and shallow water at dBIC 36 and 24 with z under 1: evidence of the longer fit alone.
    Against the null fitted on, the bias had dBIC 12 and z 1.8, and the current stayed 0.247 m/s.)"""
    if fitter.kind != DRIFT_KIND:
        return current
    m = fitter.fit(current.effects, start=current.theta, max_nfev=o.max_nfev)
    return m if _chi2(m) < _chi2(current) else current


def _chi2(model) -> float:
    """The fit's final cost (the scaled residuals' and the prior's)."""
    return float(model.fit.cost_final)


def _rival(results, r):
    """The candidate of the round's ``results`` that did not clear the naming tests though its dBIC
    cleared the threshold and is within :data:`~trials.measured.decision.WEAK_BIC` of ``r``'s or above
    (the most evidence of such), or None: the records hold as much evidence for it as for ``r``."""
    rivals = [x for x in results if not x[1] and x[0] > BIC_THRESHOLD and x[0] > r[0] - WEAK_BIC]
    return max(rivals, key=lambda x: x[0]) if rivals else None


def _best_standing(fitter, current, results, taus, inflate, ns, o: DiagnoseOptions, rnd: dict, say):
    """The round's candidate to name: the one with the most evidence among those that clear the tests
    and hold beside their rival (:func:`_rival`), or None.

    A candidate with as much evidence (dBIC) that a name could not be given to (its size within the
    ship's own mismatch, or its z short) may explain the same thing: on a turn, the straight run's
    drift is a heading bias or a current's cross part, and a current too small for its floor still
    drifts the circle.  The named one must then still clear dBIC, z and its floor with the rival in
    the model; else it is withheld (``rnd["withheld"]``, reported ``not_identifiable`` by
    :func:`withheld`).  (Fresh family seed 20000: 0.05-0.1 m/s currents on turns, fitted at dBIC
    111-152 but under the current's floor, were named as 0.56-1.08 deg heading biases.)"""
    for r in sorted((x for x in results if x[1]), key=lambda x: -x[0]):
        rival = _rival(results, r)
        if rival is None:
            return r
        with_rival = rival[3]
        cls = r[2]
        m = fitter.fit(with_rival.effects + [cls], start=np.concatenate([with_rival.theta,
                                                                         r[3].theta[len(current.theta):]]),
                       max_nfev=o.max_nfev)
        dbic = _delta_bic(with_rival, m, len(cls.fit_parameters()), taus, o.stride)
        stands, z, vals = _holds(fitter, m, cls, inflate)
        stands = stands and dbic > BIC_THRESHOLD and not straight_contradicts(with_rival.straight, m.straight)
        rnd.setdefault("withheld" if not stands else "beside_rival", []).append(
            {"effect": cls.name, "rival": rival[2].name, "delta_bic": round(dbic, 2), "z": round(z, 2),
             "parameters": vals})
        say(f"  {cls.name} beside {rival[2].name}: dBIC {fmt3(dbic)}, z {fmt3(z)}: "
            f"{'named' if stands else 'withheld (they explain the same evidence)'}")
        if stands:
            return r
    return None


def _holds(fitter, model: _Model, cls, inflate: float) -> tuple[bool, float, dict]:
    """(whether a named effect still clears z and its floor in ``model``, its z, its values)."""
    vals, _, z = _effect_report(model, cls, inflate)
    ok = z > Z_THRESHOLD and clears_floor(cls.name, vals, fitter.ship.particulars.L, fitter.kind, fitter.heading)
    return ok, z, vals


def _prune(fitter, current, named, rounds, ns: int, o: DiagnoseOptions, say):
    """The final check of forward selection: an effect named early can lose its evidence to one named
    after it (a heading bias on a zigzag is first taken for a cross current; once the bias is in, the
    current shrinks to nothing).  Every named effect must still clear z and its floor in the final
    joint fit; the weakest that does not is dropped (the rest refitted from where they were) and
    the check repeated.  Each drop is logged in the last round's ``dropped`` list."""
    while len(current.effects) > 1:
        _, inflate = _taus(current, o.stride)
        checks = [(cls, *_holds(fitter, current, cls, inflate)) for cls in current.effects]
        weak = [c for c in checks if not c[1]]
        if not weak:
            break
        cls, _, z, vals = min(weak, key=lambda c: c[2])
        keep = [e for e in current.effects if e is not cls]
        idx = set(_effect_index(current, cls))
        start = [v for i, v in enumerate(current.theta) if i not in idx]
        m = fitter.fit(keep, start=np.asarray(start), max_nfev=o.max_nfev)
        say(f"dropped {cls.name}: in the joint fit z {fmt3(z)}, {format_values(cls.name, vals)} "
            f"(no longer clears z or its floor)")
        if rounds:
            rounds[-1].setdefault("dropped", []).append({"effect": cls.name, "z": round(z, 2), "parameters": vals})
        current = m
        named = [n for n in named if n != cls.name]
    return current, named


def to_demote(table) -> list:
    """The named effects of an identifiability ``table`` (:func:`trials.measured.identifiability.assess`)
    that :func:`_demote` takes out: the statistics reason holds for them and their calibrated floor is
    above their detection size."""
    return [t["effect"] for t in table if t["named"] and t.get("reason_kind") == "statistics"
            and t.get("floor", 0.0) > t["detection_size"]]


def _demote(fitter, current, named, demote, rounds, o: DiagnoseOptions, say):
    """The model without the named effects in ``demote`` (refitted from where it was): names the records
    cannot separate from the ship's own coefficients (the statistics reason of
    :func:`trials.measured.identifiability.verdict`: its marginal sd could not have shown its detection
    size, and confounding is why) on a kind of record whose calibrated floor for it is above that size
    (the ship's own mismatch lends it more than matters), which the issue asks to be reported
    ``not_identifiable`` rather than named as a guess (fresh family seeds 19000 and 23000: a 1.5 deg
    rudder offset on a single port turn named at 6.0-7.0 deg, sd 1.0 deg, R 0.999 with the hull
    terms, floor 5.8 deg).  Without the floor condition a 18 m/s wind on a 20/20 zigzag of the
    development set (dev_29) was demoted: the wind is judged present on its loads, its scale alone
    trades with the shape factors.  Logged in the last round's ``demoted``."""
    drop = [cls for cls in current.effects if cls.name in demote]
    keep = [e for e in current.effects if e not in drop]
    idx = {i for cls in drop for i in _effect_index(current, cls)}
    start = np.asarray([v for i, v in enumerate(current.theta) if i not in idx])
    m = fitter.fit(keep, start=start, max_nfev=o.max_nfev)
    for cls in drop:
        say(f"demoted {cls.name}: these records cannot separate it from the ship's own coefficients")
        if rounds:
            rounds[-1].setdefault("demoted", []).append({"effect": cls.name})
    return m, [n for n in named if n not in demote]


def diagnose(ship: Ship, items, options: DiagnoseOptions | None = None, **kwargs) -> Diagnosis:
    """Diagnose the records ``items`` against ``ship`` (module docstring).

    Parameters
    ----------
    ship : Ship
    items : list of paths, TrialRecord or Prepared
    options : DiagnoseOptions, optional
        How to search; defaults when omitted.
    **kwargs
        Any :class:`DiagnoseOptions` field by name (``wind``, ``candidates``, ``segment_s``,
        ``stride``, ``max_nfev``, ``per_run``, ``ship_free``, ``say``, ``screen_nfev``), over
        ``options``.
    """
    import time

    from ekf.identify import Scales

    import mmg.effects as E

    t0 = time.perf_counter()
    o = DiagnoseOptions(**kwargs) if options is None else replace(options, **kwargs)
    say = o.say or (lambda m: None)
    calibration()                               # a bad calibration file: refused before any work
    recs = prepare(ship, items, wind=o.wind, segment_s=o.segment_s)
    if not recs:
        raise InputError("diagnose", "", "no record")
    L = ship.particulars.L
    packed = pack(ship)
    if o.stride is None:
        o = replace(o, stride=_default_stride(recs, L))
    U = float(np.median(np.concatenate([np.hypot(r.seg.meas[:, 0], r.seg.meas[:, 1]) for r in recs])))
    U = max(U, 0.05 * math.sqrt(9.80665 * L))
    noise = np.median(np.vstack([noise_level(r.seg.meas) for r in recs]), axis=0)
    cand, cand_log = _candidates(recs, list(o.candidates) if o.candidates is not None else E.names(), say)
    kind = record_kind([r.seg.inputs.delta for r in recs])
    sfree = _ship_free(ship, packed, o.ship_free, kind, drift=False)
    sc0 = Scales(u=0.05 * U, v=0.05 * U, r=0.05 * U / L, psi=math.radians(2.0), pos=0.05 * L)
    fitter = _Fitter(ship, packed, recs, sc0, o.stride, o.max_nfev, sfree)
    fitter.kind = kind
    fitter.heading = mean_heading([r.seg.meas[:, 5] for r in recs])
    d_config, base, kept = _baseline(fitter, noise, say)
    if o.ship_free is None and kind == "turn" and not any(r.seg.speed_only for r in recs):
        base, kept = _drift_terms(fitter, d_config, base, kept, o, say)
        sfree = fitter.ship_free
    cand, covered = _covered(fitter, cand, say)
    cand_log = cand_log + [{"effect": c["effect"], "skipped": c["reason"]} for c in covered]
    current, named, rounds = _search(fitter, base, cand, len(sfree), o, say)
    current, named = _prune(fitter, current, named, rounds, len(sfree), o, say)
    ni, table = _identifiability(fitter, current, named, cand, o, rounds)
    demote = to_demote(table)
    if demote:
        current, named = _demote(fitter, current, named, demote, rounds, o, say)
        ni, table = _identifiability(fitter, current, named, cand, o, rounds)
    res = _diagnosis(ship, recs, (d_config, base, fitter.kind), (current, named, rounds), (cand, cand_log), noise,
                     len(sfree), o.stride)
    res.not_identifiable, res.identifiability = ni + covered, table
    res.baseline = "fitted" if kept else "config (the fit replayed worse)"
    for ent in reclassify(res):                 # a named effect whose fit stands for the model's form
        say(f"{ent['effect']}: {ent['status']}, not named: {ent['reason']}")
    res.seconds = time.perf_counter() - t0
    if o.per_run and len(recs) > 1:
        res.runs = diagnose_each(ship, recs, o, progress=o.say is not None)
        res.seconds = time.perf_counter() - t0
    return res


def _diagnose_one(task) -> "Diagnosis":
    ship, rec, o = task
    return diagnose(ship, [rec], o)


def diagnose_each(ship: Ship, items, options: DiagnoseOptions | None = None, progress: bool = False) -> list:
    """Each record diagnosed alone, in record order, spread by ``options.backend`` (serial, this
    machine's cores, or a dask cluster: :func:`trials.files.sweep.run_sweep`, one progress line per
    record).  Every diagnosis is deterministic, so the backend does not change a number.

    Parameters
    ----------
    ship : Ship
    items : list of paths, TrialRecord or Prepared
    options : DiagnoseOptions, optional
        How each is diagnosed (``per_run``, ``say``, ``client`` are not passed on).
    progress : bool
        One line per finished record on stderr.

    Returns
    -------
    list of Diagnosis
    """
    from ..files.sweep import run_sweep

    o = options or DiagnoseOptions()
    recs = prepare(ship, items, wind=o.wind, segment_s=o.segment_s)
    each = replace(o, per_run=False, say=None, backend="serial", client=None)
    return run_sweep(_diagnose_one, [(ship, r, each) for r in recs], backend=o.backend, client=o.client,
                     n_jobs=o.n_jobs, labels=[r.name for r in recs], progress=progress)


def _identifiability(fitter, current, named, cand, o: DiagnoseOptions, rounds=()):
    """(not_identifiable entries, every candidate's figures): a candidate whose name was withheld beside
    its rival (:func:`withheld`), :func:`trials.measured.identifiability.assess`, a candidate of the last
    round whose dBIC and z cleared but whose size did not clear its calibrated floor
    (:func:`within_mismatch`), one with evidence short of a name (:func:`weak_evidence`), and a rival
    nothing else reports (:func:`rivals_withheld`); one entry per effect, none for a named one."""
    from .identifiability import assess

    _, inflate = _taus(current, o.stride)
    weak = weak_evidence(rounds)
    entries, table = assess(fitter, current, named, cand, inflate, o.segment_s, o.say, weak=weak)
    held = list({h["effect"]: h for h in withheld(rounds) if h["effect"] not in named}.values())   # the last round's
    entries = held + [e for e in entries if e["effect"] not in {h["effect"] for h in held}]
    have = {e["effect"] for e in entries}
    extra = within_mismatch(rounds, fitter.ship.particulars.L) + [
        {"effect": k, "confused_with": ["the ship's own coefficients"], "correlation": None,
         "what_would_separate": "a longer record, or one where the effect is larger", "reason": why,
         "reason_kind": "evidence"}
        for k, why in weak.items()] + rivals_withheld(rounds)   # those assess could not assess (a singular information)
    out = list(entries)
    have |= set(named)
    for e in extra:
        if e["effect"] not in have:
            out.append(e)
            have.add(e["effect"])
    return out, table


def withheld(rounds) -> list:
    """``not_identifiable`` entries (kind "rival") of the candidates whose name was withheld because a
    rival with as much evidence took theirs away (:func:`_best_standing`)."""
    return [_rival_entry(w["effect"], w["rival"], f"{w['rival']} explains the same evidence on these records: "
                         f"beside it {w['effect']} falls to dBIC {w['delta_bic']:.3g}, z {w['z']:.3g}")
            for rnd in rounds for w in rnd.get("withheld", [])]


def rivals_withheld(rounds) -> list:
    """``not_identifiable`` entries (kind "rival") of the rivals that took a withheld candidate's evidence
    (:func:`_best_standing`): used only where nothing else reports them."""
    return [_rival_entry(w["rival"], w["effect"], f"it explains the evidence {w['effect']} had (beside it "
                         f"{w['effect']} falls to dBIC {w['delta_bic']:.3g}, z {w['z']:.3g}), but did not clear "
                         "a name itself")
            for rnd in rounds for w in rnd.get("withheld", [])]


def _rival_entry(effect: str, other: str, reason: str) -> dict:
    return {"effect": effect, "confused_with": [other], "correlation": None,
            "what_would_separate": "a record where they act differently: the mirror turn or a zigzag, or a longer "
                                   "straight run", "reason": reason, "reason_kind": "rival"}


def weak_evidence(rounds) -> dict:
    """``{effect: reason}`` for the last round's candidates with some evidence that did not reach a
    name (:func:`~trials.measured.decision.evidence_short`) with a size over the calibrated floor
    (the size and precision tests a name needs pass; only the evidence falls short).  Such an effect
    may be there; dropping it silently would report a clean record.  How often a clean record of the
    calibration runs has one: ``bench/calibrate_diagnose.py`` prints it."""
    out = {}
    last = rounds[-1] if rounds else {"candidates": []}
    for c in last["candidates"]:
        if c.get("clears_threshold") or not evidence_short(c["delta_bic"], c["z"]) or not _over_floor(c):
            continue
        out[c["effect"]] = (f"at dBIC {c['delta_bic']:.3g} (a name needs {BIC_THRESHOLD:.3g}), z {c['z']:.3g}, "
                            f"{_size_text(c, MAGNITUDE_UNITS.get(c['effect'], ''))}: the record holds too little "
                            "evidence to tell it from the ship's own mismatch")
    return out


def _over_floor(c: dict) -> bool:
    """Whether a stored candidate's size cleared its floor: a part over its own floor where it was
    judged by its parts (:func:`_parts`), else its size over its floor (the rule of
    :func:`~trials.measured.decision.clears_floor`, on the figures the round kept)."""
    return over_floor(c["magnitude"], c.get("floor") or 0.0, c.get("parts"))


def _size_text(c: dict, unit: str) -> str:
    """A stored candidate's size against its floor(s), in ``unit``: its parts along and across the
    heading each with its floor where it was judged by them, else its size and floor."""
    if c.get("parts"):
        sizes = ", ".join(f"{k} {abs(v[0]):.3g} (floor {v[1]:.3g})" for k, v in c["parts"].items())
        return f"its parts along and across the heading, {sizes} {unit}"
    return f"size {c['magnitude']:.3g} {unit} (floor {c.get('floor') or 0.0:.3g} {unit})"


def within_mismatch(rounds, L: float) -> list:
    """``not_identifiable`` entries of the last round's candidates that the evidence and precision
    tests passed but the calibrated floor stopped: an effect of that size is there in the statistics,
    and the ship's own mismatch (:mod:`.decision`) could lend it as much."""
    out = []
    last = rounds[-1] if rounds else {"candidates": []}
    for c in last["candidates"]:
        if c["delta_bic"] > BIC_THRESHOLD and c["z"] > Z_THRESHOLD and not c["clears_threshold"]:
            unit = MAGNITUDE_UNITS.get(c["effect"], "")
            if c.get("straight_contradicts") and _over_floor(c):
                z = max(abs(x) for x in c["straight_z"])
                out.append({"effect": c["effect"], "confused_with": ["the ship's own coefficients"],
                            "correlation": None, "what_would_separate": "a ship model closer to this ship",
                            "reason": (f"at dBIC {c['delta_bic']:.3g}, z {c['z']:.3g}, {_size_text(c, unit)}, but its fit "
                                       f"leaves the record's straight run {z:.3g} sd off: the straight run reads it "
                                       "directly, so the rest of the record asks for it, not the effect"),
                            "reason_kind": "straight_run"})
                continue
            out.append({"effect": c["effect"], "confused_with": ["the ship's own coefficients"], "correlation": None,
                        "what_would_separate": "a ship model closer to this ship (e.g. identified on other "
                                               "records) or a larger effect",
                        "reason": _within_reason(c, unit), "reason_kind": "floor"})
    return out


def _within_reason(c: dict, unit: str) -> str:
    """Why a candidate that cleared dBIC and z was not named: its size (or parts) and floor(s)."""
    return (f"at dBIC {c['delta_bic']:.3g}, z {c['z']:.3g}, {_size_text(c, unit)}, within what the ship's own "
            "mismatch lends it (calibrated)")


def straight_run_table(recs, before: _Model, after: _Model) -> list:
    """[{"record", "samples", "seconds", "logged_drift_deg", "sd_deg", "z_before", "z_after"}] of the
    records that open with a straight run (:class:`ekf.identify.StraightRun`): its length, the drift
    angle over ground it logs, atan2(-v, u) in the logged heading's axes (a heading bias b reads as b,
    a current as its cross part over the speed), that angle's standard error, and its residual in
    those standard errors before and after the named effects."""
    out, k = [], 0
    for r in recs:
        st = r.seg.straight
        if st is None:
            continue
        m = np.asarray(r.seg.meas[:st.n], float)
        t = np.asarray(r.seg.inputs.t, float)
        U = float(np.mean(np.hypot(m[:, 0], m[:, 1])))
        zb = float(before.straight[k]) if k < len(before.straight) else math.nan
        za = float(after.straight[k]) if k < len(after.straight) else math.nan
        out.append({"record": r.name, "samples": int(st.n), "seconds": float(f"{t[st.n - 1] - t[0]:.3g}"),
                    "logged_drift_deg": float(f"{math.degrees(float(np.mean(np.arctan2(-m[:, 1], m[:, 0])))):.3g}"),
                    "sd_deg": float(f"{math.degrees(st.sigma / U):.3g}"),
                    "z_before": round(zb, 2), "z_after": round(za, 2)})
        k += 1
    return out


def _diagnosis(ship, recs, baseline, search, cands, noise, ns: int, stride: int) -> Diagnosis:
    """The :class:`Diagnosis`: baseline = (the config's differences, the baseline fit, the kind of record
    set the floors were read for), search = (final
    fit, named effects, rounds) of :func:`_search`, cands = (candidates, log) of :func:`_candidates`;
    the named effects' values with standard errors inflated by the residuals' correlation, what is left."""
    d_config, base, kind = baseline
    current, named, rounds = search
    cand, cand_log = cands
    _, inflate = _taus(current, stride)
    from .diagnose_report import effect_estimate, effect_evidence, effect_intervals

    params, ses, ivs = {}, {}, {}
    for cls in current.effects:
        v, s, _ = _effect_report(current, cls, inflate)
        params[cls.name] = v
        ses[cls.name] = s
        ivs[cls.name] = effect_intervals(cls, *effect_estimate(current, cls, inflate))
    cand_log = cand_log + [{"effect": c.name, "named": c.name in named} for c in cand]
    unexpl, desc, _ = _describe(recs, current.diffs, noise, None, ship.particulars.L, kind)
    mfm = model_form_mismatch(current.free[:ns], current.theta[:ns])
    th_out = [f.prior if f.name in mfm else v for f, v in zip(current.free[:ns], current.theta[:ns])]
    fit_vals = {f.name: float(v) for f, v in zip(current.free[:ns], th_out)}   # mismatched: the config's, not written as fitted
    ship_vals = config_values(ship, fit_vals)
    return Diagnosis(named=named, parameters=params, standard_errors=ses, rms_config=_rms(d_config, recs),
                     rms_before=_rms(base.diffs, recs), rms_after=_rms(current.diffs, recs), unexplained=unexpl,
                     unexplained_description=desc, candidates=cand_log, rounds=rounds, ship_values=ship_vals,
                     ship_fit_values=fit_vals, records=recs, pred_before=[r.seg.meas + d for r, d in zip(recs, base.diffs)],
                     pred_after=[r.seg.meas + d for r, d in zip(recs, current.diffs)],
                     seconds=0.0, effects=current.effects, intervals_95=ivs, evidence=effect_evidence(named, rounds),
                     model_form_mismatch=mfm, ship_fit=ship_fit_table(current.free[:ns], current.theta[:ns]),
                     straight_runs=straight_run_table(recs, base, current), absent_channels=absent_table(recs))
