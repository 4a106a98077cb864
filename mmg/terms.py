"""Named hull-force terms: the hull model is a sum of coefficients times these terms.

A hull force component (X_H', Y_H' or N_H', all primed, see :mod:`mmg.nondim`)
is ``sum_i c_i * term_i(beta, v', r')``.  The Kijima (1990) form used for the
Esso Osaka writes its terms in the drift angle beta = atan(-v/u) and r' = rL/U;
the MMG standard method (Yasukawa & Yoshimura 2015) used for KVLCC2 writes them
in v' = v/U and r'.  Both draw from the one registry below, so the simulator,
the estimator (whose Jacobian with respect to a coefficient *is* the term's
value) and later model extensions share the same definitions.

Each term is a key (the expression as written in the configs) and an integer id
used inside compiled code.  ``|x|`` is the absolute value: ``beta|beta|`` is the
odd quadratic Kijima uses.

The low-speed cross-flow model (Yoshimura & Nomoto 1978; Yoshimura 2009, used by the Osaka group
for the 3 m Esso Osaka) writes the hull's sway force and yaw moment as linear terms
``Y_v v'|u'| + Y_r r'|u'|`` (``"v*cos(beta)"``, ``"r*cos(beta)"``: cos(beta) = |u|/U is |u'|)
plus the cross-flow drag of the hull's strips, integrated over x' = x/L in [-1/2, 1/2]:
``"int(|v+x*r|*(v+x*r))"`` is :func:`crossflow_Y` and ``"int(x*|v+x*r|*(v+x*r))"`` is
:func:`crossflow_N` of (v', r'); the sway force of a uniform drag coefficient C_D is then
-C_D times the first, the yaw moment -C_D times the second.  Both stay bounded (quadratic)
at any drift angle, 90 deg included, where the Kijima polynomials in beta are extrapolated.
"""
from __future__ import annotations

import numpy as np
from ._jit import njit

from ._inlining import hot_loops_only

TERMS: dict[str, int] = {
    "1": 0,
    "beta": 1,
    "r": 2,
    "beta|beta|": 3,
    "r|r|": 4,
    "beta^2*r": 5,
    "beta*r^2": 6,
    "r*sin(beta)": 7,
    "cos(beta)^2": 8,
    "v": 9,
    "v^2": 10,
    "v*r": 11,
    "r^2": 12,
    "v^4": 13,
    "v^3": 14,
    "v^2*r": 15,
    "v*r^2": 16,
    "r^3": 17,
    "v|v|": 18,
    "v*cos(beta)": 19,
    "r*cos(beta)": 20,
    "int(|v+x*r|*(v+x*r))": 21,
    "int(x*|v+x*r|*(v+x*r))": 22,
}
"""Term expression -> integer id (beta [rad], v = v', r = r', all dimensionless)."""

AXES = {"X": 0, "Y": 1, "N": 2}


@njit(cache=True, error_model="numpy")
def sabs(x):
    """|x| written so that complex-step differentiation stays analytic (sign from the real part)."""
    return x if x.real >= 0.0 else -x


@njit(cache=True, error_model="numpy")
def crossflow_Y(a, b):
    """Cross-flow sway integral F(a, b) = integral over x in [-1/2, 1/2] of |a + b x| (a + b x) dx.

    With a = v', b = r' it is the primed sway force of strips of unit drag coefficient across
    the hull (sign: the force is -C_D F).  Closed form, written without a division by b when
    the local cross-flow w(x) = a + b x keeps its sign along the hull (|a| >= |b|/2, b = 0
    included): F = s (a^2 + b^2/12), s the sign of a.  When w changes sign along the hull,
    F = (w_+^2 |w_+| - w_-^2 |w_-|) / (3 b) with w_+- = a +- b/2 (the two terms add, so no
    cancellation; |b| > 2 |a| >= 0 keeps b away from 0).  ``sabs`` keeps complex steps analytic.

    Parameters
    ----------
    a, b : float or complex
        v' and r' (dimensionless), real or complex.

    Returns
    -------
    float or complex
    """
    if sabs(a).real >= 0.5 * sabs(b).real:
        s = 1.0 if a.real >= 0.0 else -1.0
        return s * (a * a + b * b / 12.0)
    wp = a + 0.5 * b
    wm = a - 0.5 * b
    return (wp * wp * sabs(wp) - wm * wm * sabs(wm)) / (3.0 * b)


@njit(cache=True, error_model="numpy")
def crossflow_N(a, b):
    """Cross-flow yaw integral G(a, b) = integral over x in [-1/2, 1/2] of x |a + b x| (a + b x) dx.

    The primed yaw moment of unit-drag strips is -C_D G (see :func:`crossflow_Y`).  Closed form:
    G = s a b / 6 when a + b x keeps its sign s along the hull (|a| >= |b|/2); otherwise, from
    x = (w - a)/b, G = [(w_+^3 |w_+| - w_-^3 |w_-|)/4 - a (w_+^2 |w_+| - w_-^2 |w_-|)/3] / b^2,
    w_+- = a +- b/2.  Pure yaw (a = 0) gives b|b|/32, pure drift (b = 0) gives 0.

    Parameters
    ----------
    a, b : float or complex
        v' and r' (dimensionless), real or complex.

    Returns
    -------
    float or complex
    """
    if sabs(a).real >= 0.5 * sabs(b).real or b.real * b.real == 0.0:     # b^2 underflowing: G ~ 0 either way
        s = 1.0 if a.real >= 0.0 else -1.0
        return s * a * b / 6.0
    wp = a + 0.5 * b
    wm = a - 0.5 * b
    cub = wp * wp * sabs(wp) - wm * wm * sabs(wm)
    qua = wp * wp * wp * sabs(wp) - wm * wm * wm * sabs(wm)
    return (0.25 * qua - a * cub / 3.0) / (b * b)


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def term_value(tid, beta, vp, rp):
    """Value of term ``tid`` at drift angle beta [rad], v' and r' (dimensionless)."""
    if tid == 0:
        return 1.0 + 0.0 * beta
    if tid == 1:
        return beta
    if tid == 2:
        return rp
    if tid == 3:
        return beta * sabs(beta)
    if tid == 4:
        return rp * sabs(rp)
    if tid == 5:
        return beta * beta * rp
    if tid == 6:
        return beta * rp * rp
    if tid == 7:
        return rp * np.sin(beta)
    if tid == 8:
        c = np.cos(beta)
        return c * c
    if tid == 9:
        return vp
    if tid == 10:
        return vp * vp
    if tid == 11:
        return vp * rp
    if tid == 12:
        return rp * rp
    if tid == 13:
        return vp * vp * vp * vp
    if tid == 14:
        return vp * vp * vp
    if tid == 15:
        return vp * vp * rp
    if tid == 16:
        return vp * rp * rp
    if tid == 17:
        return rp * rp * rp
    if tid == 18:
        return vp * sabs(vp)
    if tid == 19:
        return vp * np.cos(beta)
    if tid == 20:
        return rp * np.cos(beta)
    if tid == 21:
        return crossflow_Y(vp, rp)
    if tid == 22:
        return crossflow_N(vp, rp)
    return 0.0 * beta


V_PARITY = (1, -1, 1, -1, 1, 1, -1, -1, 1, -1, 1, -1, 1, 1, -1, 1, -1, 1, -1, -1, 1, -1, 1)
"""Parity of each term (indexed by id, :data:`TERMS`) in the sway velocity: 1 where term(-beta, -v', r') =
term(beta, v', r') (even), -1 where it is minus that (odd); beta = atan(-v/u) is odd in v.
:func:`mmg.model.astern_factor` reads it: going astern a term changes sign or not by its parity.  A test
holds it against the terms themselves (``tests/test_astern_hull.py``)."""


def term_id(key: str) -> int:
    """Integer id of a term expression; KeyError lists the known ones."""
    try:
        return TERMS[key]
    except KeyError:
        raise KeyError(f"unknown hull term {key!r}; known terms: {', '.join(TERMS)}") from None


_LATEX = {"Y_beta": r"$Y'_\beta$", "Y_r": r"$Y'_r$", "Y_bb": r"$Y'_{\beta|\beta|}$", "Y_rr": r"$Y'_{r|r|}$",
          "Y_bbr": r"$Y'_{\beta\beta r}$", "Y_brr": r"$Y'_{\beta rr}$", "N_beta": r"$N'_\beta$", "N_r": r"$N'_r$",
          "N_bb": r"$N'_{\beta|\beta|}$", "N_rr": r"$N'_{r|r|}$", "N_bbr": r"$N'_{\beta\beta r}$",
          "N_brr": r"$N'_{\beta rr}$"}


def latex_label(name: str) -> str:
    """Matplotlib label of a hull coefficient: ``"Y_bb"`` -> ``$Y'_{\beta|\beta|}$`` (Kijima names),
    ``"N_vvr"`` -> ``$N'_{vvr}$`` (any other ``AXIS_sub`` name)."""
    if name in _LATEX:
        return _LATEX[name]
    axis, _, sub = name.partition("_")
    sub = sub.replace("beta", "\\beta ").strip()
    return f"${axis}'_{{{sub}}}$" if sub else f"${axis}'$"


def is_resistance(name: str, term: str, axis: str | None = None) -> bool:
    """Whether hull coefficient ``name`` (of equation ``axis``, default the name's first letter) with term
    ``term`` is a straight-ahead resistance: a surge (X) term not zero at beta = v' = r' = 0, e.g. ``X_uu``
    (``cos(beta)^2``) of the Kijima form, ``X_0`` (``1``) of the MMG standard method; it stays negative."""
    if (axis or name[:1]) != "X" or not term:
        return False
    return float(term_value(term_id(term), 0.0, 0.0, 0.0)) != 0.0
