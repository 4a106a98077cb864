"""The statistics of the diagnosis: residuals of a replay (:func:`_diffs`), their RMS per channel
(:func:`_rms`), the correlation time of a residual (:func:`_tau`), the evidence of one model over another
(:func:`_delta_bic`) and an effect's fitted values with their standard errors (:func:`_effect_report`)."""
from __future__ import annotations

import math

import numpy as np

__all__ = ["_tau", "_rms", "_delta_bic", "_effect_report"]


_COLS = ("u", "v", "r", "x", "y", "heading")


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


def _effect_index(model, effect, presence_only: bool = False) -> list:
    """Indices of ``effect``'s fitted parameters in ``model.free`` (only those that say it is there,
    :meth:`mmg.effects.Effect.presence_parameters`, with ``presence_only``)."""
    pres = effect.presence_parameters()
    return [i for i, f in enumerate(model.free) if f.kind == "effect" and f.name.split(".")[0] == effect.name
            and (not presence_only or f.name.split(".")[-1] in pres)]


def _effect_report(model, effect, inflate: float):
    """(values, standard errors, presence z) of ``effect`` in the fitted ``model`` (a
    :class:`~trials.measured.diagnose.fit._Model`), its standard errors inflated by ``inflate``
    (:meth:`mmg.effects.Effect.report`, :meth:`~mmg.effects.Effect.presence_z`)."""
    idx = _effect_index(model, effect)
    th = model.fit.theta[idx]
    std = model.fit.std[idx] * inflate
    corr = np.nan_to_num(model.fit.corr[np.ix_(idx, idx)], nan=0.0)
    np.fill_diagonal(corr, 1.0)
    cov = corr * np.outer(std, std)
    vals, se = effect.report(th, cov)
    return vals, se, effect.presence_z(th, cov)


def _r2(A, y):
    y = np.asarray(y, float)
    if not np.any(y):
        return 0.0
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    res = y - A @ coef
    v = float(np.var(y))
    return float(max(0.0, 1.0 - np.var(res) / v)) if v > 0 else 0.0


def _scaled_rss(diffs, scales) -> float:
    """Sum of the squared residuals of every channel over its scale (the fit's cost without the prior)."""
    D = _stack(diffs, 1)
    sc = np.array([scales.u, scales.v, scales.r, scales.pos, scales.pos, scales.psi])
    return float(np.sum((D / sc) ** 2))


def _taus(current, stride):
    """(correlation times [samples] of each channel's residual, the standard-error inflation)."""
    taus = np.array([np.median([_tau(d[::stride, j]) for d in current.diffs]) for j in range(6)])
    return taus, math.sqrt(float(np.mean(taus)))



def _chi2(model) -> float:
    """The fit's final cost (the scaled residuals' and the prior's)."""
    return float(model.fit.cost_final)
