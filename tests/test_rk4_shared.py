"""The filters' RK4 step (:func:`ekf.kernels.rk4_step`, which takes the integrators' shared
:func:`mmg.rk4.rk4_step`) against the textbook tableau written out in the test (k1 at t, k2 and k3 at
t + dt/2, k4 at t + dt, weights 1, 2, 2, 1 over 6) on the model's own right-hand side
:func:`mmg.model.rhs`, the states the filter does not propagate held at 0; with and without a steady
wind, whose loads depend on the heading (which the paper filter holds at 0).  With the wind, the fast
transition Jacobian (:func:`ekf.kernels.jacobian_step`) must still be the complex-step reference's."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import mmg.effects as E
from ekf.kernels import jacobian_step, jacobian_step_reference, make_workspace, rk4_step
from mmg._jit import readonly
from mmg.model import DELTA_, N_, PSI_, R_, U_, V_, X_, Y_, rhs
from mmg.simulation import prepare
from trials.runs.trial import load_trial

REPO = Path(__file__).resolve().parents[1]
PAPER = readonly(np.array([U_, V_, R_, N_], dtype=np.int64))
LOG = readonly(np.array([X_, Y_, PSI_, N_, U_, V_, R_], dtype=np.int64))


def _textbook_step(x, d0, d1, dt, pk, slots):
    """Classical RK4 of the propagated slots, the others held at 0, the rudder linear over the step."""
    p, poly, axis, term = pk.args()[:4]
    coef = pk.hull_coef.astype(complex)

    def f(y, d):
        s = np.zeros(8, dtype=complex)
        s[slots] = y
        s[DELTA_] = d
        out = np.zeros(8, dtype=complex)
        rhs(s, d.real, p, poly, axis, term, coef, out)
        return out[slots]

    dm = 0.5 * (d0 + d1)
    k1 = f(x, d0)
    k2 = f(x + dt / 2 * k1, dm)
    k3 = f(x + dt / 2 * k2, dm)
    k4 = f(x + dt * k3, d1)
    return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


@pytest.fixture(scope="module", params=["calm", "steady wind"])
def packed(request):
    tr = load_trial(REPO / "configs" / "trials" / "zz20.yaml")
    pk, eq = prepare(tr.ship, tr.u0, tr.n0, tr.trim)
    if request.param == "steady wind":
        pk = E.Wind.pack(pk, {"scale": 1.0, "true_speed_mps": 25.0, "true_from_deg": 60.0}, tr.ship)
    return pk, eq.state()


@pytest.mark.parametrize("slots", [PAPER, LOG], ids=["paper", "raw-log"])
def test_filter_step_is_the_textbook_rk4(packed, slots):
    pk, x0 = packed
    rng = np.random.default_rng(5)
    idx = np.array([0, 1], dtype=np.int64)
    c0 = len(slots)
    ws = make_workspace(np.int64(c0 + 2), np.int64(c0), pk.hull_coef)
    for _ in range(10):
        x = np.array([x0[s] for s in slots], dtype=complex)
        x[[i for i, s in enumerate(slots) if s == V_]] = x0[U_] * rng.uniform(-0.1, 0.1)
        x[[i for i, s in enumerate(slots) if s == R_]] = rng.uniform(-0.01, 0.01)
        x[[i for i, s in enumerate(slots) if s == PSI_]] = rng.uniform(-3, 3)
        x = x + 1j * 1e-30 * rng.normal(size=len(x))          # a complex step rides along
        d0, d1 = rng.uniform(-0.5, 0.5, 2) + 1j * 1e-30 * rng.normal(size=2)
        z = np.r_[x, pk.hull_coef[idx]].astype(complex)
        rk4_step(z, d0, d1, 0.3, (slots, np.int64(c0), idx, np.int64(-1)), pk.args()[:4], ws)
        want = _textbook_step(x, d0, d1, 0.3, pk, slots)
        np.testing.assert_allclose(ws[7][:c0].real, want.real, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(ws[7][:c0].imag, want.imag, rtol=1e-10, atol=1e-45)
        assert np.any(ws[7][:c0].imag != 0)                        # the perturbation was carried


def test_the_fast_jacobian_carries_a_steady_wind(packed):
    pk, x0 = packed
    rng = np.random.default_rng(8)
    idx = np.array([0, 3, 5], dtype=np.int64)
    c0 = len(LOG) + 1                                # x, y, psi, n, u, v, r, then the timing offset
    nz = c0 + len(idx)
    ws, wr = make_workspace(np.int64(nz), np.int64(len(LOG)), pk.hull_coef), \
        make_workspace(np.int64(nz), np.int64(len(LOG)), pk.hull_coef)
    for _ in range(5):
        z = np.r_[0.0, 0.0, rng.uniform(-3, 3), x0[N_], x0[U_], x0[U_] * rng.uniform(-0.1, 0.1),
                  rng.uniform(-0.005, 0.005), 0.1, pk.hull_coef[idx]]
        rudder = (*rng.uniform(-0.5, 0.5, 2), *rng.uniform(-0.05, 0.05, 2))
        layout = (LOG, np.int64(c0), idx, np.int64(len(LOG)))
        jacobian_step(z, rudder, layout, 0.5, pk.args()[:4], ws)
        jacobian_step_reference(z, rudder, layout, 0.5, pk.args()[:4], wr)
        np.testing.assert_allclose(ws[8], wr[8], rtol=1e-13, atol=1e-12)
        np.testing.assert_allclose(ws[9], wr[9], rtol=1e-9, atol=1e-12)
