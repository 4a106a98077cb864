"""From a model-scale ship to the full-scale one (``mmg imo --scale-to``): Froude scaling with the scale effects.

Froude scaling at lambda = L_S / L_M (equal Froude number, so the model's speed is U_S / sqrt(lambda)):
non-dimensional (primed) coefficients are unchanged, lengths scale as lambda, times as sqrt(lambda),
forces as (rho_S / rho_M) lambda^3.  What does not follow Froude's law (the viscous part) is corrected
here, each correction with a stated relative uncertainty (:class:`ScaleEffects`).

What comes from where
---------------------
*From the model* (identified, or the model config's own): every hull coefficient in primed form (the hull
form, its terms and values; the resistance coefficient corrected by the friction line below), the
straight-run wake ``w_P0`` (scaled by the ITTC-1978 wake formula below), the rudder inflow ratio
``epsilon`` (corrected for the wake scaling), the slipstream share ``kappa``, the flow-straightening
``gamma_R_pos``, ``gamma_R_neg`` and lever ``l_R_prime``, and the added masses ``m_x_prime``,
``m_y_prime``, ``J_z_prime`` (primed).  A fitted ``rudder_offset`` (the model rudder's zero error), the
wind scale and shape factors (the model's superstructure and the pond's wind, not the ship's), and the
propeller walk astern ``Y_P_astern`` (a property of the model's own screw, its handedness and its stern
run; the full-scale config's value, 0 unless given, stands) are not transferred: sampled values of them
are dropped.

*From the full-scale config*: particulars (L, B, T, S, x_G, rho), mass and inertia (m', I_zG'),
propeller (D, P, K_T, K_Q, the thrust deduction t_P(u), the speed dependence of w_P0(u)), engine,
steering gear, rudder geometry and interaction constants (A_R, H_R, f_alpha, eta, t_R, a_H, x_H', x_R'),
wind.  The propeller loading is therefore the ship's: the full-scale propeller and engine find their
own self-propulsion point in the simulation; only ``kappa`` (how much of the slipstream reaches the
rudder) carries over from the heavier-loaded model.

Scale effects (the 3 m config's header, configs/ships/esso_osaka_3m.yaml, lists them)
-------------------------------------------------------------------------------------
* Friction line: C_F = 0.075 / (log10 Re - 2)^2 (ITTC-1957 model-ship correlation line), Re = U L / nu
  at the model's and the ship's speed; the resistance coefficient (the X coefficient whose term is not
  zero at beta = r' = 0: X_uu of the Kijima form, X_0 of others) becomes
  X_S' = X_M' + (1 + k) (C_FM - C_FS) S / (L T) (ITTC 7.5-02-03-01.4, 1978 ITTC Performance Prediction
  Method, 2.4.1; the form factor 1 + k = 1.2 of the 3 m config's header).  The roughness and
  correlation allowances are not added (the full-scale Rhee & Kim resistance the header inverted has none);
  they are part of the stated uncertainty.
* Wake: w_S = (t + 0.04) + (w_M - t - 0.04) ((1 + k) C_FS + dC_F) / ((1 + k) C_FM) (ITTC 7.5-02-03-01.4,
  2.4.3; 0.04 for the rudder's share of the wake, dC_F = 0.0004 the roughness allowance, t the thrust
  deduction at the model's speed); the full-scale w_P0(u) keeps its speed dependence, its constant term
  moved so that w_P0(U_S) = w_S.
* Rudder inflow: epsilon = (1 - w_R) / (1 - w_P); the rudder's wake w_R = 1 - epsilon_M (1 - w_M) is
  scaled by the same formula as the propeller's, so epsilon_S = (1 - w_RS) / (1 - w_S).
* Propeller loading: the full-scale propeller and engine (above); ``kappa`` transfers with its
  uncertainty.  Free-running models without a skin-friction correction run heavier loaded, which is
  why their rudder is more effective (Ueno, Suzuki & Tsukada, Ocean Engineering 145 (2017) 124-137,
  "Rudder effectiveness and speed correction in practice at tank test").

Each correction is multiplied by (1 + xi), xi ~ N(0, s) with the relative std s of :class:`ScaleEffects`
(friction and wake: on the correction; epsilon and kappa: on the transferred value), sampled together
with the identified covariance (:func:`full_scale_draws`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from mmg.errors import InputError
from mmg.ship import Ship

__all__ = ["ScaleEffects", "Scaling", "ittc57_cf", "kinematic_viscosity", "check_similar", "scaling",
           "resistance_coefficient", "SIMILARITY_TOLERANCE", "TRANSFERRED", "EFFECTS"]

SIMILARITY_TOLERANCE = 0.03
"""Largest relative difference of B/L, T/L and C_b between a model and the ship it is scaled to: beyond
it the two are not the same hull form (the 3 m Esso Osaka and the ship agree within 0.5 %)."""
TRANSFERRED = ("epsilon", "kappa", "gamma_R_pos", "gamma_R_neg", "l_R_prime")
"""Rudder constants taken from the model (flow quantities identify may free); the rest of the rudder is the ship's."""
EFFECTS = ("friction", "wake", "epsilon", "kappa")
"""The scale-effect corrections, in the order of a draw's columns (:func:`full_scale_draws`)."""

NU_FRESH = 1.1386e-6
"""Kinematic viscosity of fresh water at 15 deg C [m^2/s] (ITTC 7.5-02-01-03, 2011)."""
NU_SEA = 1.1892e-6
"""Kinematic viscosity of sea water at 15 deg C, salinity 3.5 % [m^2/s] (ITTC 7.5-02-01-03, 2011)."""


def kinematic_viscosity(rho: float) -> float:
    """nu [m^2/s] at 15 deg C of fresh water (``rho`` below 1012 kg/m^3) or of sea water."""
    return NU_FRESH if rho < 1012.0 else NU_SEA


def ittc57_cf(re) -> np.ndarray | float:
    """ITTC-1957 model-ship correlation line C_F = 0.075 / (log10 Re - 2)^2."""
    return 0.075 / (np.log10(re) - 2.0) ** 2


@dataclass(frozen=True)
class ScaleEffects:
    """The scale-effect corrections' constants and their relative standard deviations.

    Attributes
    ----------
    form_factor : float
        1 + k (the 3 m config's header: 1.2, within Prohaska's 1.1-1.4 for full-bodied tankers).
    delta_CF : float
        Roughness allowance in the ITTC-1978 wake formula (0.0004, ITTC-1978's fixed value).
    friction_rel_std : float
        0.2 of the resistance correction: 1 + k between 1.1 and 1.4 moves it by -8 % to +17 %, other
        friction lines (Hughes, Grigson) by 5-10 % at Re ~ 1e6, the left-out allowances dC_F = 0.0004
        by 11 % (a reasoned figure, not a measured one).
    wake_rel_std : float
        0.3 of the wake correction: wake-scaling methods (ITTC-1978, Sasajima-Tanaka, Yazaki) differ by
        0.03-0.05 for full ships where the correction is ~0.13, and the Osaka identification of this
        model found w_P0 = 0.614 against the formula's 0.452 (reasoned).
    epsilon_rel_std : float
        0.1 of epsilon: no full-scale rudder-inflow measurement of this hull; the model's larger wake
        and heavier loading change the rudder's inflow by tens of per cent (Ueno et al. 2017), most of
        which the wake scaling and the ship's own propeller take up (reasoned).
    kappa_rel_std : float
        0.15 of kappa: the slipstream share at the model's heavier loading carried to the ship's (reasoned).
    """

    form_factor: float = 1.2
    delta_CF: float = 0.0004
    friction_rel_std: float = 0.2
    wake_rel_std: float = 0.3
    epsilon_rel_std: float = 0.1
    kappa_rel_std: float = 0.15

    def stds(self) -> np.ndarray:
        """The relative stds in the order of :data:`EFFECTS`."""
        return np.array([self.friction_rel_std, self.wake_rel_std, self.epsilon_rel_std, self.kappa_rel_std])


def _ratios(s: Ship) -> np.ndarray:
    pa = s.particulars
    return np.array([pa.B / pa.L, pa.T / pa.L, pa.C_b])


def check_similar(model: Ship, full: Ship) -> float:
    """lambda = L_S / L_M after checking that ``model`` is a smaller model of ``full``'s hull form.

    Raises
    ------
    mmg.errors.InputError
        B/L, T/L or C_b differing by more than :data:`SIMILARITY_TOLERANCE`, or a "model" not smaller.
    """
    a, b = _ratios(model), _ratios(full)
    rel = np.abs(a - b) / np.abs(b)
    if np.any(rel > SIMILARITY_TOLERANCE):
        k = int(np.argmax(rel))
        what = ("B/L", "T/L", "C_b")[k]
        raise InputError("--scale-to", full.name, f"not the hull form of {model.name}: {what} {b[k]:.4g} against "
                                                  f"{a[k]:.4g} ({100 * rel[k]:.1f} % apart, at most "
                                                  f"{100 * SIMILARITY_TOLERANCE:g} %)")
    lam = full.particulars.L / model.particulars.L
    if lam <= 1.0:
        raise InputError("--scale-to", full.name, f"L = {full.particulars.L:g} m is not larger than the "
                                                  f"model's {model.particulars.L:g} m")
    return lam


def resistance_coefficient(ship: Ship) -> str:
    """The hull's resistance coefficient: its one X coefficient whose term is not zero at beta = r' = 0."""
    names = list(ship.hull.resistance_names())
    if len(names) != 1:
        raise InputError("hull", ship.name, f"expected one resistance coefficient (an X term not zero at "
                                            f"beta = r' = 0), found {names or 'none'}")
    return names[0]


def _poly(c, u: float) -> float:
    return float(sum(a * u ** k for k, a in enumerate(c)))


@dataclass(frozen=True)
class Scaling:
    """Froude scaling of one model to one full-scale ship at the ship's approach speed ``u_ship`` [m/s].

    Build it with :func:`scaling`.  ``base`` is the full-scale ship with the model's hull form (the
    values are written in by :meth:`values`); ``re_*``, ``cf_*`` the Reynolds numbers and ITTC-1957
    friction coefficients, ``t_model`` the model's thrust deduction at ``u_model``.
    """

    model_name: str
    base: Ship
    lam: float
    u_ship: float
    u_model: float
    re_model: float
    re_ship: float
    cf_model: float
    cf_ship: float
    t_model: float
    resistance: str
    effects: ScaleEffects

    @property
    def wake_ratio(self) -> float:
        """((1 + k) C_FS + dC_F) / ((1 + k) C_FM): the viscous wake's model-to-ship ratio (ITTC-1978)."""
        k1, e = self.effects.form_factor, self.effects
        return (k1 * self.cf_ship + e.delta_CF) / (k1 * self.cf_model)

    def wake_to_ship(self, w_model: float) -> float:
        """ITTC-1978: w_S = (t + 0.04) + (w_M - t - 0.04) ((1 + k) C_FS + dC_F) / ((1 + k) C_FM)."""
        a = self.t_model + 0.04
        return a + (w_model - a) * self.wake_ratio

    def resistance_correction(self, model: Ship) -> float:
        """(1 + k) (C_FM - C_FS) S / (L T): added to the model's primed resistance coefficient (negative)."""
        pa = model.particulars
        return self.effects.form_factor * (self.cf_model - self.cf_ship) * pa.S_wetted / (pa.L * pa.T)

    def corrections(self, model: Ship) -> dict:
        """The nominal scale-effect figures of ``model`` (for the report): model and ship values of the
        resistance coefficient, the wake at the approach and epsilon."""
        v = self.values(model)
        w_m = _poly(model.propeller.w_P0, self.u_model)
        return {"friction": (self.resistance, model.hull.value(self.resistance), v[self.resistance]),
                "wake": ("w_P0 at the approach", w_m, self.wake_to_ship(w_m)),
                "epsilon": ("epsilon", model.rudder.epsilon, v["epsilon"]),
                "kappa": ("kappa", model.rudder.kappa, v["kappa"])}

    def values(self, model: Ship, xi=None) -> dict:
        """The full-scale values of the transferred parameters (by their ``mmg identify`` names, SI) from
        ``model`` (its config's or identified values), each scale-effect correction times (1 + xi)
        (``xi`` in the order of :data:`EFFECTS`; zeros when None)."""
        from mmg.parameters import CONSTANTS, MASS_NAMES

        xf, xw, xe, xk = (0.0, 0.0, 0.0, 0.0) if xi is None else (float(x) for x in xi)
        out = dict(model.hull.as_dict())
        out[self.resistance] += self.resistance_correction(model) * (1.0 + xf)
        w_m = _poly(model.propeller.w_P0, self.u_model)
        w_s = w_m + (self.wake_to_ship(w_m) - w_m) * (1.0 + xw)
        full_w = self.base.propeller.w_P0
        out["w_P0"] = full_w[0] + w_s - _poly(full_w, self.u_ship)
        r = model.rudder
        w_rs = self.wake_to_ship(1.0 - r.epsilon * (1.0 - w_m))
        out["epsilon"] = (1.0 - w_rs) / (1.0 - self.wake_to_ship(w_m)) * (1.0 + xe)
        out["kappa"] = r.kappa * (1.0 + xk)
        out.update({k: getattr(r, k) for k in TRANSFERRED if k not in ("epsilon", "kappa")})
        for name in MASS_NAMES:                   # primed: the model's value at the ship's scale
            entry = CONSTANTS[name]
            out[name] = getattr(model.mass, entry.config_key) * entry.config_scale(self.base)
        return out

    def ship(self, model: Ship, xi=None) -> Ship:
        """The full-scale ship of ``model`` (:meth:`values` written into :attr:`base`)."""
        from ..measured.identify import ship_with_values

        return ship_with_values(self.base, self.values(model, xi))


def scaling(model: Ship, full: Ship, u_ship: float, effects: ScaleEffects | None = None) -> Scaling:
    """The :class:`Scaling` of ``model`` to ``full`` at the full-scale approach speed ``u_ship`` [m/s].

    Raises
    ------
    mmg.errors.InputError
        Not the same hull form, or a model not smaller than the ship (:func:`check_similar`); a hull
        without one resistance coefficient, or one the friction correction makes zero or positive (a
        model resistance below the model's friction alone: no straight run at full scale).
    """
    e = effects or ScaleEffects()
    lam = check_similar(model, full)
    u_m = u_ship / math.sqrt(lam)
    pm, ps = model.particulars, full.particulars
    re_m = u_m * pm.L / kinematic_viscosity(pm.rho)
    re_s = u_ship * ps.L / kinematic_viscosity(ps.rho)
    name = resistance_coefficient(model)
    sc0 = model.hull.value(name)
    dx = e.form_factor * (ittc57_cf(re_m) - ittc57_cf(re_s)) * pm.S_wetted / (pm.L * pm.T)
    if sc0 + dx >= 0.0:
        raise InputError("--scale-to", full.name, f"{model.name}'s resistance coefficient {name} = {sc0:.4g} is "
                                                  f"smaller than the model's friction alone: with the friction-line "
                                                  f"correction {dx:+.4g} the ship would have none ({sc0 + dx:+.4g}); an "
                                                  f"identification that traded {name} against w_P0 (both set the "
                                                  f"straight run at constant revolutions) cannot be scaled: fix them "
                                                  f"(mmg identify --free without {name}, w_P0)")
    base = replace(full, hull=model.hull, name=f"{full.name} (scaled from {model.name})", covariance=None,
                   source=f"{full.source}; hull and constants Froude-scaled from {model.name} (trials.imo.scaling)")
    return Scaling(model.name, base, lam, u_ship, u_m, re_m, re_s, float(ittc57_cf(re_m)), float(ittc57_cf(re_s)),
                   _poly(model.propeller.t_P, u_m), name, e)


def full_scale_draws(sc: Scaling, model: Ship, names, rows, xi) -> tuple[list[str], np.ndarray]:
    """Full-scale parameter samples from model-scale ones: each row of ``rows`` (columns ``names``, the
    model's sampled parameters) written into ``model``, then scaled with that row's scale-effect factors
    ``xi`` (N x :data:`EFFECTS`).  Returns (full-scale names, N x names array) for
    :func:`trials.imo.sampling.run_samples`."""
    from ..measured.identify import ship_with_values

    out = []
    for row, x in zip(np.atleast_2d(rows), np.atleast_2d(xi)):
        m = ship_with_values(model, dict(zip(names, (float(v) for v in row)))) if len(names) else model
        out.append(sc.values(m, x))
    keys = list(out[0])
    return keys, np.array([[o[k] for k in keys] for o in out], dtype=float)
