"""Ships that are not their model: the mismatch family that ``mmg diagnose``'s naming is calibrated on.

A real ship differs from its predicted model: its hull derivatives, rudder and propeller constants,
added masses and wind loads are all off by a few to a few tens of per cent, and its hull may not
even follow the model's form.  This module draws such ships from a config (:func:`mismatch_ship`,
:func:`mismatch_family`) and simulates full-scale trials of them with hidden effects
(:func:`trial_records`) the way the independent development set ``../shared/data/diagnose-dev/`` was
made: 10 kn approach at constant propeller revolutions, 35 deg turns to starboard and port, 10/10,
15/15 and 20/20 zigzags of nine reversals and a 60 s tail, 1 s samples, uniform log noise of the
set's half-widths; the wider trials users run (:data:`WIDE_TRIALS`: zigzags port first, turns
of 15 to 35 deg to either hand, at any approach speed); for a model-scale config (``froude_scale`` > 1,
e.g. ``kvlcc2_l7``) the same full-scale trial Froude-scaled to the model.

Every factor is ``1 + u`` with ``u`` uniform in ``[-h, h]`` (a random sign and size), ``h`` the
relative half-width of :class:`MismatchSpec`.  A fraction of the family has its hull's nonlinear
part in another form: the low-speed cross-flow form (:func:`mmg.terms.crossflow_Y`,
:func:`mmg.terms.crossflow_N`), its coefficients fitted by least squares to the config's nonlinear
sway forces and yaw moments (Kijima's terms in beta, or the MMG standard method's cubic terms in
v') over the operating range and then perturbed like the others.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from mmg.parameters import LINEAR_TERMS
from mmg.ship import Ship
from mmg.units import KNOT

__all__ = ["DEV_NOISE_HALF_WIDTHS", "DEV_TRIALS", "HULL_LINEAR_TERMS", "RUDDER_CONSTANTS", "TRIALS", "MismatchSpec",
           "TrialConditions", "WIDE_TRIALS", "crossflow_fit", "froude_scaled", "mismatch_family", "mismatch_member",
           "mismatch_ship", "trial_hand", "trial_records"]

HULL_LINEAR_TERMS = LINEAR_TERMS
"""Hull terms counted as linear (:data:`mmg.parameters.LINEAR_TERMS`); with them the straight-ahead resistance
(:func:`mmg.terms.is_resistance`: ``X_uu``'s ``cos(beta)^2``, ``X_0``'s ``1``).  The rest, but the other constants ``"1"``, are nonlinear."""

RUDDER_CONSTANTS = ("f_alpha", "epsilon", "kappa", "t_R", "a_H", "x_H_prime", "gamma_R_pos", "gamma_R_neg")
"""The rudder constants the family moves (the geometry, A_R, H_R, eta, x_R', l_R', is kept)."""

DEV_NOISE_HALF_WIDTHS = (0.02, 0.02, 0.0002, 0.5, 0.5, math.radians(0.05))
"""Uniform log-noise half-widths of the development set (u, v [m/s], r [rad/s], x, y [m], psi [rad])."""


TRIALS = {
    "turn35": {"kind": "turning", "rudder_deg": 35.0},
    "turn35p": {"kind": "turning", "rudder_deg": -35.0},
    "zz10": {"kind": "zigzag", "rudder_deg": 10.0, "heading_deg": 10.0},
    "zz15": {"kind": "zigzag", "rudder_deg": 15.0, "heading_deg": 15.0},
    "zz20": {"kind": "zigzag", "rudder_deg": 20.0, "heading_deg": 20.0},
}
"""The development set's trials: 35 deg turns (starboard, port) and zigzags (starboard first).

The wider family's trials are added below: zigzags port first (``zz10p``, ``zz15p``, ``zz20p``) and
turns of 15 to 30 deg to either hand (``turn15`` ... ``turn30p``; a trailing ``p``: to port)."""

TRIALS.update({f"zz{a}p": {"kind": "zigzag", "rudder_deg": -float(a), "heading_deg": float(a)} for a in (10, 15, 20)})
TRIALS.update({f"turn{a}{h}": {"kind": "turning", "rudder_deg": s * float(a)}
               for a in (15, 20, 25, 30) for h, s in (("", 1.0), ("p", -1.0))})

DEV_TRIALS = ("turn35", "turn35p", "zz10", "zz15", "zz20")
"""The development set's trials (the default of the mismatch bench)."""

WIDE_TRIALS = tuple(TRIALS)
"""Every trial of :data:`TRIALS`: either hand first, zigzags 10/10 to 20/20, turns 15 to 35 deg."""


@dataclass(frozen=True)
class MismatchSpec:
    """Relative half-widths of the uniform, random-sign factors a family member is drawn with.

    Attributes
    ----------
    hull_linear : float
        Hull terms of :data:`HULL_LINEAR_TERMS` (``beta``, ``r``, ``v``) and the resistance
        (``X_uu``'s ``cos(beta)^2``, ``X_0``'s ``1``).
    hull_nonlinear : float
        Every other hull term but the sway and yaw constants ``"1"`` (``beta|beta|``, ``r|r|``,
        ``beta^2*r``, ``v^3``, ``r*sin(beta)``, ``v^2``, the cross-flow drags, ...).
    rudder : float
        The rudder constants of :data:`RUDDER_CONSTANTS`.
    propeller : float
        The wake fraction's and the thrust deduction's first coefficients, the K_T curve as a whole.
    added_mass : float
        m_x', m_y', J_z'.
    wind : float
        The surge, sway and yaw wind loads, each on its own (ships with a ``wind`` section).
    crossflow_fraction : float
        Probability that a member's hull nonlinear part is of the cross-flow form.
    wind_curve : str
        The shape of the members' wind loads (:data:`trials.measured.wind_curves.WIND_CURVES`):
        ``"fujiwara"``, the model's own regression with the ``wind`` factors; ``"harmonic"``, every
        member's loads on a loaded tanker's measured curve
        (:data:`trials.measured.wind_curves.TANKER_LOADED`), each coefficient times its own factor of
        half-width ``wind``; ``"mixed"``: half of the members (at random places) so.
    beta_max_deg, r_max : float
        The operating range the cross-flow form is fitted over: |beta| <= beta_max_deg, |r'| <= r_max.
    """

    hull_linear: float = 0.10
    hull_nonlinear: float = 0.25
    rudder: float = 0.15
    propeller: float = 0.15
    added_mass: float = 0.10
    wind: float = 0.30
    crossflow_fraction: float = 0.25
    wind_curve: str = "fujiwara"
    beta_max_deg: float = 25.0
    r_max: float = 0.8


def _factor(rng: np.random.Generator, h: float) -> float:
    """1 + u, u uniform in [-h, h]."""
    return float(1.0 + rng.uniform(-h, h))


def _is_linear(name: str, axis: str, term: str) -> bool:
    """Whether a hull term takes the linear half-width: a :data:`HULL_LINEAR_TERMS` term or the resistance."""
    from mmg.terms import is_resistance

    return term in HULL_LINEAR_TERMS or is_resistance(name, term, axis)


def _nonlinear_sway_yaw(hull) -> list:
    """(name, axis, term, value) of the hull's nonlinear sway and yaw terms (neither linear nor constant)."""
    return [(n, a, t, v) for n, a, t, v in zip(hull.names, hull.axes, hull.terms, hull.values)
            if a in ("Y", "N") and t != "1" and not _is_linear(n, a, t)]


def crossflow_fit(ship: Ship, beta_max_deg: float = 25.0, r_max: float = 0.8) -> dict:
    """The cross-flow form of a hull's nonlinear sway force and yaw moment.

    Least squares over a grid of |beta| <= ``beta_max_deg``, |r'| <= ``r_max`` (v' = -sin beta):
    Y_nl ~ Y_CD F(v', r') + Y_rr r'|r'|, N_nl ~ N_CD G(v', r') + N_CDY F(v', r') with F, G the
    cross-flow integrals (:func:`mmg.terms.crossflow_Y`, :func:`mmg.terms.crossflow_N`).  One drag
    term per axis leaves 60 % of the yaw moment's nonlinear part unexplained on the Esso Osaka
    set; the second terms (a sway drag with an arm, and the pure-yaw side force) bring it to about
    35 % (the Kijima couplings beta^2 r, beta r^2 have no cross-flow counterpart).

    Parameters
    ----------
    ship : Ship
        A ship whose hull has nonlinear sway and yaw terms: Kijima's (``beta|beta|``, ``r|r|``,
        ``beta^2*r``, ``beta*r^2``), the MMG standard method's (``v^3``, ``v^2*r``, ``v*r^2``,
        ``r^3``) or any other of :data:`mmg.terms.TERMS`.
    beta_max_deg, r_max : float
        The operating range.

    Returns
    -------
    dict
        ``{"Y": [(name, term, value), ...], "N": [...], "rms_fraction": {"Y": .., "N": ..}}``: the
        fitted terms and the residual's rms as a fraction of the config's nonlinear part's.
    """
    from mmg.terms import crossflow_N, crossflow_Y, term_id, term_value

    b, r = (g.ravel() for g in np.meshgrid(np.radians(np.linspace(-beta_max_deg, beta_max_deg, 41)),
                                           np.linspace(-r_max, r_max, 33)))
    v = -np.sin(b)
    nonlinear = _nonlinear_sway_yaw(ship.hull)
    cols = {t: np.array([term_value(term_id(t), x, y, z) for x, y, z in zip(b, v, r)], float)
            for t in {t for _, _, t, _ in nonlinear}}
    F = np.array([crossflow_Y(x, y) for x, y in zip(v, r)])
    G = np.array([crossflow_N(x, y) for x, y in zip(v, r)])
    basis = {"Y": [("Y_CD", "int(|v+x*r|*(v+x*r))", F), ("Y_rr", "r|r|", r * np.abs(r))],
             "N": [("N_CD", "int(x*|v+x*r|*(v+x*r))", G), ("N_CDY", "int(|v+x*r|*(v+x*r))", F)]}
    out, frac = {}, {}
    for ax in ("Y", "N"):
        target = sum((val * cols[term] for _, a, term, val in nonlinear if a == ax), np.zeros_like(b))
        A = np.column_stack([col for _, _, col in basis[ax]])
        c, *_ = np.linalg.lstsq(A, target, rcond=None)
        frac[ax] = float(np.sqrt(np.mean((target - A @ c) ** 2)) / max(np.sqrt(np.mean(target ** 2)), 1e-12))
        out[ax] = [(name, term, float(ci)) for (name, term, _), ci in zip(basis[ax], c)]
    out["rms_fraction"] = frac
    return out


def _hull(ship: Ship, rng, spec: MismatchSpec, crossflow: bool):
    """The member's hull and its factors (name -> factor)."""
    from mmg.ship import HullModel

    h = ship.hull
    rows = list(zip(h.names, h.axes, h.terms, h.values))
    if crossflow:
        fit = crossflow_fit(ship, spec.beta_max_deg, spec.r_max)
        gone = {row[0] for row in _nonlinear_sway_yaw(h)}
        rows = [row for row in rows if row[0] not in gone]
        rows += [(name, ax, term, val) for ax in ("Y", "N") for name, term, val in fit[ax]]
    factors = {}
    for name, axis, term, _ in rows:
        linear = _is_linear(name, axis, term)
        if term != "1" or linear:
            factors[name] = _factor(rng, spec.hull_linear if linear else spec.hull_nonlinear)
    hull = HullModel(names=tuple(r[0] for r in rows), axes=tuple(r[1] for r in rows), terms=tuple(r[2] for r in rows),
                     values=tuple(r[3] * factors.get(r[0], 1.0) for r in rows), astern=h.astern)
    return hull, factors


def mismatch_member(ship: Ship, rng: np.random.Generator, spec: MismatchSpec = MismatchSpec(),
                    crossflow: bool | None = None) -> tuple[Ship, dict]:
    """One ship of the family and the factors it was drawn with.

    Parameters
    ----------
    ship : Ship
        The config (the model that diagnoses).
    rng : numpy.random.Generator
    spec : MismatchSpec
    crossflow : bool, optional
        Whether the hull's nonlinear part is of the cross-flow form; drawn with probability
        ``spec.crossflow_fraction`` when None.

    Returns
    -------
    (Ship, dict)
        The member and ``{"hull_form": "kijima" | "config" | "crossflow", "hull": {name: factor}, "rudder":
        {...}, "propeller": {"w_P0": .., "t_P": .., "K_T": ..}, "mass": {"m_x_prime": .., ...},
        "wind": {"surge": .., "sway": .., "yaw": ..}}`` (``hull_form``: the config's own form,
        ``kijima`` where it is Kijima's in beta, else ``config``; a cross-flow member's hull factors
        are on its fitted cross-flow values, :func:`crossflow_fit`).
    """
    cf = rng.uniform() < spec.crossflow_fraction           # drawn always: the same stream either way
    crossflow = bool(cf if crossflow is None else crossflow)
    hull, fh = _hull(ship, rng, spec, crossflow)
    fr = {k: _factor(rng, spec.rudder) for k in RUDDER_CONSTANTS}
    fp = {k: _factor(rng, spec.propeller) for k in ("w_P0", "t_P", "K_T")}
    fm = {k: _factor(rng, spec.added_mass) for k in ("m_x_prime", "m_y_prime", "J_z_prime")}
    pr = ship.propeller
    first = lambda c, f: (c[0] * f,) + tuple(c[1:])  # noqa: E731
    out = replace(ship, name=f"{ship.name} (mismatch member)", hull=hull,
                  rudder=replace(ship.rudder, **{k: getattr(ship.rudder, k) * f for k, f in fr.items()}),
                  propeller=replace(pr, w_P0=first(pr.w_P0, fp["w_P0"]), t_P=first(pr.t_P, fp["t_P"]),
                                    K_T=tuple(c * fp["K_T"] for c in pr.K_T)),
                  mass=replace(ship.mass, **{k: getattr(ship.mass, k) * f for k, f in fm.items()}))
    own = "kijima" if any("beta" in t for t in ship.hull.terms) else "config"
    factors = {"hull_form": "crossflow" if crossflow else own, "hull": fh, "rudder": fr, "propeller": fp,
               "mass": fm}
    if ship.wind is not None:
        fw = {k: _factor(rng, spec.wind) for k in ("surge", "sway", "yaw")}
        w = ship.wind
        out = replace(out, wind=replace(w, scale=w.scale * fw["surge"], sway_factor=w.sway_factor * fw["sway"] / fw["surge"],
                                        yaw_factor=w.yaw_factor * fw["yaw"] / fw["surge"]))
        factors["wind"] = fw
    return out, factors


def mismatch_ship(ship: Ship, rng: np.random.Generator, spec: MismatchSpec = MismatchSpec()) -> Ship:
    """One ship of the family (:func:`mismatch_member` without its factors)."""
    return mismatch_member(ship, rng, spec)[0]


def mismatch_family(ship: Ship, n: int, seed: int, spec: MismatchSpec = MismatchSpec()) -> list:
    """``n`` members drawn from ``seed``: a list of (Ship, factors) (:func:`mismatch_member`).

    Exactly ``round(n * spec.crossflow_fraction)`` of them, at random places, have the cross-flow hull.
    With ``spec.wind_curve`` other than ``"fujiwara"``, the members whose wind loads follow another
    curve (all, or half at random places) carry it as ``factors["wind_curve"]``
    (:meth:`~trials.measured.wind_curves.HarmonicWindCurve.to_dict`), drawn from a stream of its own
    after the members, so the members themselves are those of the ``"fujiwara"`` family of the seed."""
    from .wind_curves import TANKER_LOADED, WIND_CURVES

    if spec.wind_curve not in WIND_CURVES:
        raise ValueError(f"MismatchSpec.wind_curve {spec.wind_curve!r}: one of {WIND_CURVES}")
    rng = np.random.default_rng(seed)
    cross = set(rng.permutation(n)[:round(n * spec.crossflow_fraction)].tolist())
    family = [mismatch_member(ship, rng, spec, crossflow=i in cross) for i in range(n)]
    if spec.wind_curve == "fujiwara" or ship.wind is None:
        return family
    crng = np.random.default_rng([seed, 1])
    other = set(range(n)) if spec.wind_curve == "harmonic" else set(crng.permutation(n)[:n // 2].tolist())
    for i, (member, factors) in enumerate(family):
        curve = TANKER_LOADED.drawn(crng, spec.wind)
        if i in other:
            factors["wind_curve"] = curve.to_dict()
    return family


def trial_hand(kind: str) -> str:
    """``"starboard"`` or ``"port"``: the hand of a :data:`TRIALS` trial's first rudder."""
    return "port" if TRIALS[kind]["rudder_deg"] < 0 else "starboard"


def _zigzag_end(rec, t_execute: float, reversals: int, tail: float) -> float:
    """The time of the ``reversals``-th rudder reversal after the execute, plus ``tail`` [s]."""
    d = np.asarray(rec.delta)
    after = rec.t > t_execute + 1.0
    s = np.sign(d - np.median(d[rec.t <= t_execute]) if (rec.t <= t_execute).any() else d)
    flips = np.flatnonzero(after[1:] & (s[1:] != s[:-1]) & (s[1:] != 0)) + 1
    if len(flips) < reversals:
        return float(rec.t[-1])
    return float(rec.t[flips[reversals - 1]]) + tail


def froude_scaled(effects: dict, true_wind, noise, lam: float):
    """Full-scale effects, true wind and noise half-widths at the scale of a 1/``lam`` model.

    Froude similarity: speeds (a current's ``speed_mps``, the true wind's) and u, v go as
    1/sqrt(lam), r as sqrt(lam), x, y as 1/lam; angles (offsets, biases, directions, psi) and
    ratios (T/H, wind-load factors) are the same at both scales.

    Returns
    -------
    (dict, (float, float), tuple)
    """
    k = 1.0 / math.sqrt(lam)
    eff = {e: dict(v) for e, v in (effects or {}).items()}
    if "current" in eff and "speed_mps" in eff["current"]:
        eff["current"]["speed_mps"] = eff["current"]["speed_mps"] * k
    du, dv, dr, dx, dy, dpsi = noise
    return eff, (true_wind[0] * k, true_wind[1]), (du * k, dv * k, dr / k, dx / lam, dy / lam, dpsi)


@dataclass(frozen=True)
class TrialConditions:
    """The conditions a trial of :func:`trial_records` is sailed in, at full scale.

    Attributes
    ----------
    effects : dict or None
        ``{effect: {parameter: value}}`` (mmg.effects); a ``wind`` entry gets the steady ``true_wind`` and
        the truth ship's own wind-load factors (its ``wind`` section), so the wind acts through the member's
        loads, not the config's.
    true_wind : (float, float)
        True wind speed [m/s] and the direction it comes from [rad, clockwise from north].
    speed_kn : float
        Approach speed [kn].
    """

    effects: dict | None = None
    true_wind: tuple = (0.0, 0.0)
    speed_kn: float = 10.0


def trial_records(ship: Ship, truth: Ship, kind: str, conditions=None, seed: int = 0,
                  noise=DEV_NOISE_HALF_WIDTHS, name: str | None = None, wind_curve=None):
    """A full-scale trial of ``truth`` logged as the development set's are.

    10 s straight run at heading 0, then the execute; a turn runs 1500 s after it, a zigzag to its
    ninth reversal plus 60 s (simulated for 4000 s, longer below 10 kn in proportion); constant propeller
    revolutions (the approach's, at the conditions' ``speed_kn``); 1 s samples; uniform noise of half-widths
    ``noise`` (u, v, r, x, y, psi).  For a model-scale ``ship`` (``ship.froude_scale`` = lambda > 1) the trial
    is the full-scale one Froude-scaled: the conditions and ``noise`` are given at full scale and taken to the
    model by :func:`froude_scaled`, the times (execute, length, tail, sampling) by 1/sqrt(lambda); the
    record's ``meta["effects"]`` holds the model-scale effects.

    Parameters
    ----------
    ship : Ship
        The config (for :func:`~trials.measured.diagnose.records.synthetic_record`'s record).
    truth : Ship
        The ship that sails (a family member).
    kind : str
        A key of :data:`TRIALS`.
    conditions : TrialConditions or dict, optional
        The effects, true wind and approach speed; a dict: the effects alone, in calm air at 10 kn.
    seed : int
        Noise seed.
    noise : sequence of 6 floats
        Uniform half-widths, full scale.
    name : str, optional
    wind_curve : dict, optional
        A member's ``factors["wind_curve"]`` (:func:`mismatch_family`): its wind loads follow that
        curve (:class:`~trials.measured.wind_curves.HarmonicWindCurve`, on ``truth``'s wind geometry)
        in the logged states instead of ``truth``'s regression (which still acts in the closed-loop run
        that makes a zigzag's rudder history).

    Returns
    -------
    trials.files.records.TrialRecord
    """
    from .diagnose.records import Manoeuvre, RecordNoise, synthetic_record

    c = conditions if isinstance(conditions, TrialConditions) else TrialConditions(conditions)
    tr = TRIALS[kind]
    lam = ship.froude_scale
    eff, true_wind, noise = froude_scaled(c.effects, c.true_wind, noise, lam)
    ts = 1.0 / math.sqrt(lam)                              # model time / full-scale time
    if "wind" in eff:
        if truth.wind is None:
            raise ValueError("a wind effect needs the truth ship's wind section")
        eff["wind"] = {**truth.wind.values(), **eff["wind"], "true_speed_mps": float(true_wind[0]),
                       "true_from_deg": math.degrees(true_wind[1])}
    rpm = replace(truth, engine=replace(truth.engine, mode="constant_rpm"))
    loads = None
    if wind_curve is not None and "wind" in eff:
        from .wind_curves import HarmonicWindCurve

        curve, geometry = HarmonicWindCurve.from_dict(wind_curve), truth.wind.particulars()
        loads = lambda V, g: curve.loads(V, g, geometry)  # noqa: E731
    te = 10.0 * ts
    zig = tr["kind"] == "zigzag"
    man = Manoeuvre(tr["kind"], rudder_deg=tr["rudder_deg"], speed=c.speed_kn * KNOT * ts,
                    duration=(4000.0 * max(1.0, 10.0 / c.speed_kn) if zig else 10.0 + 1500.0) * ts, dt=ts,
                    heading_deg=tr.get("heading_deg"), t_execute=te)
    rec = synthetic_record(ship, man, eff, truth_ship=rpm, true_wind=true_wind,
                           noise=RecordNoise(noise, "uniform", seed), name=name or kind, wind_loads=loads)
    if zig:
        rec = rec.slice_time(-math.inf, _zigzag_end(rec, te, 9, 60.0 * ts) + 1e-9 * ts)
    return replace(rec, meta={**rec.meta, "trial": kind, "effects": eff})
