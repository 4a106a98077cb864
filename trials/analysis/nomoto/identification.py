"""All identifications on one zigzag record, and the heading RMS that scores each model.

:func:`identify` is the top of the package (what ``mmg nomoto`` runs): it
converts the record (:func:`~trials.analysis.nomoto.zigzag.zigzag_data`) and runs the
classical, four-point, least-squares and (optionally) output-error methods.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from trials.analysis.nomoto.classical import ClassicalResult, classical_first_order
from trials.analysis.nomoto.fourpoint import FourPointResult, four_point
from trials.analysis.nomoto.least_squares import FitResult, fit_least_squares
from trials.analysis.nomoto.models import NomotoModel
from trials.analysis.nomoto.output_error import fit_output_error
from trials.analysis.nomoto.points import ZigzagPoints
from trials.analysis.nomoto.response import simulate_response
from trials.analysis.nomoto.zigzag import ZigzagData, zigzag_data
from trials.files.records import TrialRecord

__all__ = ["heading_rms", "fit_problem", "NomotoIdentification", "identify"]


def heading_rms(model: NomotoModel, z: ZigzagData, delta_bias: float = 0.0) -> float:
    """RMS [rad] of (simulated - recorded) heading over the zigzag, from the execute state.

    The model is driven by the recorded rudder from psi = 0, omega' = omega_e,
    eps' = eps_e at the execute (:func:`~trials.analysis.nomoto.response.simulate_response`)
    and compared with the smoothed heading increment ``z.psi``.

    Parameters
    ----------
    model : NomotoModel
        Model to simulate.
    z : ZigzagData
        The record.
    delta_bias : float
        Neutral rudder angle [rad].

    Returns
    -------
    float
        RMS [rad]; NaN when a parameter is NaN, T1 = 0, or T2 = 0 in a
        second-order model (such models are not simulated).
    """
    if not np.all(np.isfinite([model.K, model.T1, model.T2, model.T3])) or model.T1 == 0 or \
            (model.order == 2 and model.T2 == 0):
        return float("nan")
    psi = simulate_response(model, z.s, z.delta + z.delta_e, 0.0, z.omega_e, z.eps_e, delta_bias)
    return float(np.sqrt(np.mean((psi - z.psi) ** 2)))


def fit_problem(model: NomotoModel, rms_deg: float, psi_rms_deg: float) -> str:
    """Why a fitted model is unusable, in plain words ('' when it is usable).

    A fit is unusable when a parameter of its order is not finite (T1, T2 not
    real), when K or a time constant T1 (T2 in a second-order model) is not
    positive (not the model of a directionally stable ship: a zigzag fit that
    returns it has failed, not found such a ship), or when its heading replay
    is not finite (diverged) or further from the record than no turn at all
    (replay RMS above the recorded heading's own RMS about zero).

    Parameters
    ----------
    model : NomotoModel
        The fitted model.
    rms_deg : float
        RMS [deg] of its heading replay against the record (:func:`heading_rms`).
    psi_rms_deg : float
        RMS [deg] of the recorded heading increment about zero.

    Returns
    -------
    str
        The reasons, joined by '; ' ('' when none).
    """
    names = ("K", "T1") if model.order == 1 else ("K", "T1", "T2", "T3")
    vals = {n: float(getattr(model, n)) for n in names}
    reasons = []
    bad = [n for n, v in vals.items() if not np.isfinite(v)]
    if bad:
        reasons.append(f"{', '.join(bad)} not real")
    neg = [f"{n} = {v:.3g}" for n, v in vals.items() if n != "T3" and np.isfinite(v) and v <= 0]
    if neg:
        reasons.append(f"{', '.join(neg)} not positive (non-physical)")
    if not bad:
        if not np.isfinite(rms_deg):
            reasons.append("heading replay diverged (not finite)")
        elif rms_deg > psi_rms_deg:
            reasons.append(f"heading replay RMS {rms_deg:.3g} deg exceeds the recorded heading's own RMS "
                           f"{psi_rms_deg:.3g} deg (worse than no turn)")
    return "; ".join(reasons)


@dataclass(frozen=True)
class NomotoIdentification:
    """Everything identified from one zigzag record.

    Attributes
    ----------
    zigzag : ZigzagData
        The dimensionless record and its characteristic points.
    points : ZigzagPoints
        CR1, OS1, CR2, OS2 used by the four-point method.
    classical : ClassicalResult
        First-order K, T (eqs. 10-12).
    four_point : FourPointResult
        Four-point K, T1, T2, T3 and determinants.
    least_squares : FitResult
        Eq. (15), integrated twice, over all samples (:func:`fit_least_squares`).
    output_error : FitResult or None
        Heading-history fit, None when not run.
    rms : dict
        Heading RMS [deg] of each model against the record, keys "first_order",
        "four_point", "least_squares" (:func:`heading_rms`) and "output_error"
        (the fit's own residual, from its fitted state at the execute).
    problems : dict
        Same keys: why that fit is unusable ('' when usable, :func:`fit_problem`).
    """

    zigzag: ZigzagData
    points: ZigzagPoints
    classical: ClassicalResult
    four_point: FourPointResult
    least_squares: FitResult
    output_error: Optional[FitResult]
    rms: dict = field(default_factory=dict)
    problems: dict = field(default_factory=dict)

    def usable(self, key: str) -> bool:
        """Whether the fit ``key`` (a key of :attr:`rms`) is usable."""
        return not self.problems.get(key, "")

    def fits(self) -> dict:
        """{key: (label, NomotoModel, delta_bias [rad])} of the fits run, in report order."""
        out = {"first_order": ("1st order (Nomoto, eq. 10/12)", self.classical.model, 0.0),
               "four_point": ("2nd order four-point", self.four_point.model, 0.0),
               "least_squares": ("2nd order least squares", self.least_squares.model, self.least_squares.delta_bias)}
        if self.output_error is not None:
            out["output_error"] = ("2nd order output error", self.output_error.model, self.output_error.delta_bias)
        return out

    def dimensional(self, key: str) -> dict:
        """The fit ``key`` in seconds: K [1/s] = K' U/L, T1, T2, T3 [s] = T' L/U."""
        m = self.fits()[key][1]
        z = self.zigzag
        d = {"K_per_s": m.K * z.U / z.L, "T1_s": m.T1 * z.L / z.U}
        if m.order == 2:
            d.update(T2_s=m.T2 * z.L / z.U, T3_s=m.T3 * z.L / z.U)
        return {k: (float(v) if np.isfinite(v) else None) for k, v in d.items()}

    def to_dict(self) -> dict:
        """JSON-ready dict with the keys the CLI promises."""
        z = self.zigzag
        d = {
            "record": z.name, "L_m": z.L, "U_m_per_s": z.U, "t_execute_s": z.t_execute,
            "first_execute_to": "starboard" if z.sign > 0 else "port",
            "delta0_deg": float(np.degrees(z.delta0)), "yaw_rate": z.yaw_rate_source,
            "first_order": self.classical.to_dict(),
            "second_order_four_point": self.four_point.to_dict(),
            "second_order_least_squares": self.least_squares.to_dict(),
            "second_order_output_error": None if self.output_error is None else self.output_error.to_dict(),
            "points": self.points.to_dict(),
            "heading_rms_deg": {k: (None if not np.isfinite(v) else float(v)) for k, v in self.rms.items()},
            "parameter_units": "K, T1, T2, T3 dimensionless (K' = K L/U, T' = T U/L); in seconds under 'dimensional'",
        }
        keys = {"first_order": "first_order", "four_point": "second_order_four_point",
                "least_squares": "second_order_least_squares", "output_error": "second_order_output_error"}
        for k in self.fits():
            d[keys[k]].update(usable=self.usable(k), unusable_because=self.problems.get(k, ""),
                              dimensional=self.dimensional(k))
        return d

    def to_pandas(self):
        """Summary table: one row per method with K, T/T1, T2, T3 [-], heading RMS [deg] and ``usable``."""
        import pandas as pd

        rows = []
        for key, (label, m, _) in self.fits().items():
            first = key == "first_order"
            rows.append({"method": label, "K": m.K, "T1": m.T1, "T2": np.nan if first else m.T2,
                         "T3": np.nan if first else m.T3, "rms_deg": self.rms.get(key, np.nan),
                         "usable": self.usable(key)})
        return pd.DataFrame(rows)


def identify(record: TrialRecord, L: float, U: Optional[float] = None, output_error: bool = True,
             per_knot: Optional[int] = None) -> NomotoIdentification:
    """Run all identifications on a zigzag record.

    Parameters
    ----------
    record : TrialRecord
        Zigzag record (t, psi, delta; r and speed optional).
    L : float
        Ship length [m].
    U : float, optional
        Speed [m/s] for s'; default approach speed.
    output_error : bool
        Also run the (slower) output-error fit.
    per_knot : int, optional
        Samples per knot interval of the differentiator (None: chosen by GCV).

    Returns
    -------
    NomotoIdentification
        The zigzag, its four points, every method's result and heading RMS.

    Raises
    ------
    InputError
        Not a zigzag, too short, NaN, missing channels.
    """
    z = zigzag_data(record, L, U, per_knot)
    pts = z.points(2)
    cl = classical_first_order(z)
    fp = four_point(pts)
    ls = fit_least_squares(z)
    oe = fit_output_error(z) if output_error else None
    rms = {"first_order": heading_rms(cl.model, z), "four_point": heading_rms(fp.model, z),
           "least_squares": heading_rms(ls.model, z, ls.delta_bias)}
    if oe is not None:
        rms["output_error"] = oe.rms  # from its own fitted state at the execute
    rms = {k: float(np.degrees(v)) for k, v in rms.items()}
    ident = NomotoIdentification(z, pts, cl, fp, ls, oe, rms)      # its fits(), to judge them
    psi_rms = float(np.degrees(np.sqrt(np.mean(z.psi ** 2))))
    problems = {k: fit_problem(m, rms[k], psi_rms) for k, (_, m, _) in ident.fits().items()}
    return NomotoIdentification(z, pts, cl, fp, ls, oe, rms, problems)
