"""Differentiator: smoothed signal and its first two derivatives from one regression spline.

Turns a recorded heading (or yaw rate) into omega' and eps' for the point
methods.  Imports nothing from the other :mod:`trials.analysis.nomoto` modules.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from scipy.interpolate import make_lsq_spline

from mmg.errors import InputError

__all__ = ["smooth_derivatives"]


def _lsq_spline(x, y, per_knot: int, k: int = 5):
    """Least-squares spline of degree k with uniform knots every ``per_knot`` samples; (spline, GCV)."""
    n = len(x)
    nint = max(1, int(round((n - 1) / per_knot)))
    inner = np.linspace(x[0], x[-1], nint + 1)[1:-1]
    t = np.r_[[x[0]] * (k + 1), inner, [x[-1]] * (k + 1)]
    spl = make_lsq_spline(x, y, t, k=k)
    p = len(t) - k - 1
    rss = float(np.sum((spl(x) - y) ** 2))
    return spl, n * rss / max(n - p, 1) ** 2


def smooth_derivatives(x, y, per_knot: Optional[int] = None):
    """Smoothed signal and its first two derivatives from one quintic regression spline.

    The signal is fitted by least squares with a quintic B-spline on uniform
    knots, the knot spacing (in samples) picked by generalised cross-validation
    from 2, 3, 4, 6, ... 128 samples per knot interval (those leaving at least
    two intervals); derivatives are the
    spline's analytic derivatives.  Why this and not Savitzky-Golay or a
    penalised cubic smoothing spline:

    * one smooth curve is differentiated, so omega' and eps' are exactly the
      derivatives of the smoothed heading (the consistency Artyszuk obtained
      with his Bezier fit and that eq. (15) needs); a Savitzky-Golay filter
      gives each sample its own local polynomial, so the derivatives are not
      those of any single curve, and it must be truncated at the record's ends;
    * quintic, so eps' (the second derivative) is still a smooth cubic, and the
      ends are free (a natural cubic smoothing spline, e.g. scipy's
      ``make_smoothing_spline``, forces the second derivative to zero at both
      ends, which is wrong for eps' at the end of a zigzag record);
    * the only tuning, the knot spacing, is chosen by GCV from the data, so the
      same code serves noise-free simulations (dense knots, near interpolation)
      and noisy trial records (wider knots).

    Parameters
    ----------
    x : ndarray
        Abscissa (e.g. s' or t), strictly increasing.
    y : ndarray
        Signal at ``x`` (e.g. heading [rad]).
    per_knot : int, optional
        Fixed samples per knot interval (skip GCV).

    Returns
    -------
    y_s, dy, d2y : ndarray
        Smoothed signal, dy/dx, d2y/dx2 at ``x``.

    Raises
    ------
    InputError
        No candidate knot spacing gives a spline (too few or irregular samples).
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    cands = [per_knot] if per_knot else [m for m in (2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128)
                                         if (len(x) - 1) / m >= 2] or [max(1, (len(x) - 1) // 2)]
    best = None
    for m in cands:
        try:
            spl, g = _lsq_spline(x, y, m)
        except (ValueError, np.linalg.LinAlgError):
            continue
        if best is None or g < best[1]:
            best = (spl, g)
    if best is None:
        raise InputError("differentiator", "", "cannot fit a spline to the signal (too few or irregular samples)")
    spl = best[0]
    return spl(x), spl.derivative(1)(x), spl.derivative(2)(x)


