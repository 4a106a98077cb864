"""Central-difference Jacobian, the one numerical derivative the straight-run solver and the Nomoto
fits share (each had its own copy)."""
from __future__ import annotations

import numpy as np

__all__ = ["central_jacobian"]


def central_jacobian(fun, x, floor: float, f0=None) -> np.ndarray:
    """Jacobian of the vector function ``fun`` at ``x`` by central differences.

    Parameters
    ----------
    fun : callable
        ``fun(x) -> array`` of length m.
    x : ndarray
        The point (n,).
    floor : float
        Step of component j: ``1e-6 * max(|x_j|, floor)`` (the floor keeps the step finite at 0).
    f0 : ndarray, optional
        ``fun(x)`` when already known (only its length is used).

    Returns
    -------
    ndarray (m, n)
    """
    x = np.asarray(x, float)
    m = len(fun(x) if f0 is None else f0)
    J = np.empty((m, len(x)))
    for j in range(len(x)):
        h = 1e-6 * max(abs(x[j]), floor)
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        J[:, j] = (np.asarray(fun(xp)) - np.asarray(fun(xm))) / (2 * h)
    return J
