"""Exact heading response of a linear Nomoto model to a sampled rudder history.

The model is written in state-space form and propagated with matrix
exponentials under a first-order hold on the rudder (exact for a
piecewise-linear rudder), so stiff models (tiny T2) and complex T1, T2 are no
problem.  Used by the output-error fit and to score models against records.
"""
from __future__ import annotations

import numpy as np
from scipy import linalg

from trials.analysis.nomoto.models import NomotoModel

__all__ = ["simulate_response"]


def _state_space(model: NomotoModel):
    """State space (A, B, b1) of a model: dx/ds' = A x + B delta.

    Second order: state (psi, omega', q) with q = eps' - b1 delta, which removes
    ddelta/ds' from the input, b1 = K T3 / (T1 T2).  First order: state
    (psi, omega') and b1 is None.
    """
    K, T1, T2, T3 = model.K, model.T1, model.T2, model.T3
    if model.order == 1:
        A = np.array([[0.0, 1.0], [0.0, -1.0 / T1]])
        B = np.array([0.0, K / T1])
        return A, B, None
    return _state_space_x(K, T1 * T2, T1 + T2, T3)


def _state_space_x(K, x1, x2, T3):
    """State space (A, B, b1) of eq. (13) from K, x1 = T1 T2, x2 = T1 + T2, T3 (valid for complex T1, T2 too)."""
    a0, a1 = 1.0 / x1, x2 / x1
    b1, b0 = K * T3 / x1, K / x1
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, -a0, -a1]])
    B = np.array([0.0, b1, b0 - a1 * b1])
    return A, B, b1


def simulate_response(model: NomotoModel, s, delta, psi0: float = 0.0, omega0: float = 0.0,
                      eps0: float = 0.0, delta_bias: float = 0.0) -> np.ndarray:
    """Heading response [rad] of a Nomoto model to a sampled rudder history.

    The rudder is taken as piecewise linear between samples (first-order hold),
    which is exact for a trapezoidal rudder; the linear ODE is then propagated
    exactly with matrix exponentials, so stiff models (tiny T2) are no problem.

    Parameters
    ----------
    model : NomotoModel or tuple
        Model, or a tuple (K, x1, x2, T3) with x1 = T1 T2, x2 = T1 + T2 (eq. 16),
        which also covers complex T1, T2.
    s : ndarray
        Dimensionless distances [-], increasing.  Non-uniform steps are allowed
        (a matrix exponential is computed per distinct step, steps equal to
        12 decimals sharing one).
    delta : ndarray
        Rudder [rad] at ``s``.
    psi0, omega0, eps0 : float
        Initial heading [rad], omega' [-] and eps' [-] at ``s[0]`` (eps0 unused for
        a first-order model).
    delta_bias : float
        Neutral rudder angle [rad] (the rudder that keeps the ship straight); the
        model is driven by ``delta - delta_bias``.

    Returns
    -------
    ndarray
        Heading psi [rad] at ``s``.
    """
    s = np.asarray(s, float)
    u = np.asarray(delta, float) - delta_bias
    A, B, b1 = _state_space_x(*model) if isinstance(model, tuple) else _state_space(model)
    n = A.shape[0]
    x = np.array([psi0, omega0] + ([] if b1 is None else [eps0 - b1 * u[0]]), float)
    out = np.empty((len(s), n))
    out[0] = x
    h = np.diff(s)
    cache = {}
    for k, hk in enumerate(h):
        key = round(float(hk), 12)
        if key not in cache:
            M = np.zeros((n + 2, n + 2))
            M[:n, :n] = A * hk
            M[:n, n] = B * hk
            M[n, n + 1] = 1.0
            E = linalg.expm(M)
            cache[key] = (E[:n, :n], E[:n, n], E[:n, n + 1])
        Phi, G0, G1 = cache[key]
        x = Phi @ x + G0 * u[k] + G1 * (u[k + 1] - u[k])
        out[k + 1] = x
    return out[:, 0]


