"""The fit of the ship's own parameters and a set of effects to the records: :class:`_Fitter` (what is
fitted, on what, with which residual scales; frozen: a changed fit is a new one made with
:func:`dataclasses.replace`) and the fitted model it returns, :class:`_Model`."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .statistics import _diffs

__all__ = ["_Fitter", "_Model"]


@dataclass(frozen=True, eq=False)
class _Model:
    """A fitted model: its effects, the parameters fitted (ship's own first, then the effects'), the fit
    (:class:`ekf.identify.IdentifyResult`), the residuals per record (N, 6) and the straight runs'."""

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


@dataclass(frozen=True, eq=False)
class _Fitter:
    """What a fit is made of: the ship (and its packed form), the records (:class:`~.records.Prepared`),
    the residual scales (:class:`ekf.identify.Scales`), the sample stride and evaluation budget, the
    ship's own parameters fitted with every model (:func:`~.baseline._ship_free`), the kind of record
    set whose floors judge a name (:func:`~.decision.record_kind`), the records' mean heading [rad], the
    straight runs' weight in the fit (:attr:`ekf.identify.FitOptions.straight_weight`: sqrt(tau_v)
    of the round's model, 1 before the search), and the records' typical speed U [m/s]
    (:func:`~.decision.typical_speed`; a floor in a fraction of U needs it, 0 where not known)."""

    ship: object
    packed: object
    recs: list
    scales: object
    stride: int
    max_nfev: int
    ship_free: list
    kind: str
    heading: float
    straight_weight: float = 1.0
    speed: float = 0.0

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


def _config_model(fitter, d_config) -> _Model:
    """The config as it is, as a :class:`_Model` (its standard errors the priors')."""
    from ekf.identify import IdentifyResult

    free = list(fitter.ship_free)
    th = np.array([f.prior for f in free])
    fit = IdentifyResult(free=free, theta=th, std=np.array([f.sigma for f in free]), corr=np.eye(len(free)),
                         cost_initial=math.nan, cost_final=math.nan, n_residuals=0, iterations=0,
                         message="the config as given (the fit replayed worse)")
    return _Model([], free, fit, d_config, fitter.straight([], free, th))
