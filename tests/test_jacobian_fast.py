"""The fast transition Jacobian: tangent-linear RK4 with analytic hull-coefficient columns.

:func:`ekf.kernels.jacobian_step` must give the F of the brute-force complex step
(:func:`ekf.kernels.jacobian_step_reference`, one complex RK4 step per column) to rounding, for
both filter layouts and for both ships (the Esso Osaka's Kijima terms in beta with x_G = 0 and a
constant-power engine; the KVLCC2's MMG-2015 terms in v' with x_G != 0 and a constant-rpm
engine), and the filters built on it must give the estimates of the previous implementation.
Timings are in ``bench/bench_ekf.py``, not here.
"""
from __future__ import annotations

import functools
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import ekf.filter as ekf_filter
import ekf.log_filter as ekf_log_filter
from ekf.data import estimable_names, hull_slots
from ekf.estimate import P0_for, R_for, initial_state, load_config
from ekf.kernels import jacobian_step, jacobian_step_reference, make_workspace
from mmg._jit import readonly
from mmg.model import N_, PSI_, R_, U_, V_, X_, Y_, inverse_mass, rhs, rhs_hull_jacobian
from mmg.simulation import prepare
from trials.estimates.estimation import data_from_trial
from trials.runs.trial import load_trial

REPO = Path(__file__).resolve().parents[1]
TRIALS = {"esso_osaka": REPO / "configs" / "trials" / "zz20.yaml",
          "kvlcc2": REPO / "configs" / "trials" / "kvlcc2_zz20.yaml"}
CONFIGS = {"esso_osaka": None, "kvlcc2": REPO / "configs" / "estimation" / "kvlcc2_l7.yaml"}
# read-only, as the filters' own (global) slot arrays are: the same compiled specialisation
PAPER = dict(slots=readonly(np.array([U_, V_, R_, N_], dtype=np.int64)), c0=4, itau=-1)
LOG = dict(slots=readonly(np.array([X_, Y_, PSI_, N_, U_, V_, R_], dtype=np.int64)), c0=8, itau=7)


@pytest.fixture(scope="module", params=sorted(TRIALS))
def ship(request):
    tr = load_trial(TRIALS[request.param])
    pk, eq = prepare(tr.ship, tr.u0, tr.n0, tr.trim)
    names = estimable_names(tr.ship)
    return request.param, tr, pk, eq.state(), hull_slots(tr.ship, names)


def _random_state(rng, layout, x0, L, values):
    u = x0[U_] * rng.uniform(0.5, 1.1)
    v = x0[U_] * rng.uniform(-0.15, 0.15)
    r = x0[U_] / L * rng.uniform(-0.6, 0.6)
    n = x0[N_] * rng.uniform(0.8, 1.1)
    c = values * rng.uniform(0.8, 1.2, len(values))
    if layout is PAPER:
        return np.r_[u, v, r, n, c]
    return np.r_[rng.uniform(-1e3, 1e3, 2), rng.uniform(-np.pi, np.pi), n, u, v, r, rng.uniform(-0.3, 0.3), c]


def _assert_same_F(F, Fref, tol):
    """|F - Fref| within tol of sqrt(row scale x column scale) (the states and coefficients differ by
    orders of magnitude), and within tol relative to each entry that is not itself negligible."""
    A = np.abs(Fref - np.eye(len(Fref)))
    row = A.max(axis=1, keepdims=True)
    colm = A.max(axis=0, keepdims=True)
    scale = np.sqrt(np.maximum(row, 1e-300) * np.maximum(colm, 1e-300))
    err = np.abs(F - Fref)
    assert np.all(err <= tol * scale + 1e-300), float(np.max(err / scale))
    big = A > 1e-8 * row
    assert np.all(err[big] <= 10 * tol * np.abs(Fref[big])), float(np.max(err[big] / np.abs(Fref[big])))


@pytest.mark.parametrize("layout", [PAPER, LOG], ids=["paper", "raw-log"])
def test_jacobian_equals_complex_step_reference(ship, layout):
    name, tr, pk, x0, idx = ship
    rng = np.random.default_rng(13)
    nz = layout["c0"] + len(idx)
    ns = len(layout["slots"])
    values = pk.hull_coef[idx]
    for _ in range(25):
        z = _random_state(rng, layout, x0, tr.ship.particulars.L, values)
        d0, d1 = rng.uniform(-0.6, 0.6, 2)
        g0, g1 = rng.uniform(-0.05, 0.05, 2)
        ws, wr = make_workspace(nz, ns, pk.hull_coef), make_workspace(nz, ns, pk.hull_coef)
        for w, f in ((ws, jacobian_step), (wr, jacobian_step_reference)):
            f(z, (d0, d1, g0, g1), (layout["slots"], layout["c0"], idx, layout["itau"]), 0.1, pk.args()[:4], w)
        np.testing.assert_allclose(ws[8], wr[8], rtol=1e-14, atol=1e-14 * np.abs(wr[8]).max())
        _assert_same_F(ws[9], wr[9], 1e-12)
        assert np.array_equal(ws[9][ns:], np.eye(nz)[ns:])


def test_hull_jacobian_is_the_complex_step_of_rhs(ship):
    """d rhs / d c: analytic (the hull forces are linear in the coefficients) = complex step of rhs."""
    name, tr, pk, x0, idx = ship
    rng = np.random.default_rng(3)
    p, poly, ha, ht, hc = pk.args()
    for _ in range(10):
        x = np.zeros(8)
        x[U_] = x0[U_] * rng.uniform(0.5, 1.1)
        x[V_] = x0[U_] * rng.uniform(-0.15, 0.15)
        x[R_] = x0[U_] / tr.ship.particulars.L * rng.uniform(-0.6, 0.6)
        x[N_] = x0[N_]
        x[PSI_] = rng.uniform(-3, 3)
        x[6] = rng.uniform(-0.6, 0.6)
        B = np.empty((3, len(idx)))
        rhs_hull_jacobian(x, p, ha, ht, idx, inverse_mass(p, np.empty(8)), B)
        out = np.empty(8, dtype=complex)
        for j, i in enumerate(idx):
            c = hc.astype(complex)
            c[i] += 1e-30j
            rhs(x.astype(complex), x[6], p, poly, ha, ht, c, out)
            d = out.imag / 1e-30
            np.testing.assert_allclose(B[:, j], d[[U_, V_, R_]], rtol=1e-13, atol=1e-13 * np.abs(d).max())
            assert np.all(np.delete(d, [U_, V_, R_]) == 0.0)


def _rel(a, b):
    """Largest difference per state, relative to that state's largest magnitude."""
    return float(np.max(np.abs(a - b).max(axis=0) / np.abs(b).max(axis=0)))


@pytest.mark.parametrize("which", ["esso_osaka", "kvlcc2"])
def test_run_filter_estimates_match_previous_path(which, monkeypatch):
    cfg = load_config(CONFIGS[which])
    tr = load_trial(TRIALS[which])
    if which == "esso_osaka":
        tr = replace(tr, duration=600.0)
    data = data_from_trial(tr, cfg)
    m = data.meas
    args = (data.packed, data.slots, m.t, m.z(), m.delta, initial_state(data, cfg),
            P0_for(cfg, data.names, data.reference), R_for(cfg, data.name))
    new = ekf_filter.run_filter(*args, trial=data.name, names=data.names)
    with monkeypatch.context() as mp:
        mp.setattr(ekf_filter, "filter_kernel", functools.partial(ekf_filter.filter_kernel, reference=True))
        old = ekf_filter.run_filter(*args, trial=data.name, names=data.names)
    assert new.z.shape == old.z.shape and len(m.t) > 4000
    assert _rel(new.z, old.z) < 1e-9
    for n in data.names:
        assert new.final[n] == pytest.approx(old.final[n], rel=1e-9, abs=0), n
    d = np.sqrt(np.diag(old.P))
    assert np.max(np.abs(new.P - old.P) / np.outer(d, d)) < 1e-9


def test_log_filter_estimates_match_previous_path(monkeypatch):
    cfg = load_config()
    data = data_from_trial(TRIALS["esso_osaka"], cfg, seed=1000)
    new = ekf_log_filter.run_log_filter(data, data.record, cfg, duration=600.0, passes=1)
    with monkeypatch.context() as mp:
        mp.setattr(ekf_log_filter, "log_filter_kernel",
                   functools.partial(ekf_log_filter.log_filter_kernel, reference=True))
        old = ekf_log_filter.run_log_filter(data, data.record, cfg, duration=600.0, passes=1)
    # Not 1e-9 as the paper filter: this filter's first pass (wide prior, a sample every 5 s,
    # Q = 0) amplifies rounding ~1e8-fold - only reordering the Joseph update's sums moves its
    # estimates by 3e-9, the Jacobian's rounding by 1e-8 (~1e-6 of their standard deviations)
    nd = ekf_log_filter.ND
    assert _rel(new.z[:, nd:], old.z[:, nd:]) < 1e-7
    assert _rel(new.z[:, :ekf_log_filter.TAU], old.z[:, :ekf_log_filter.TAU]) < 1e-7
    np.testing.assert_allclose(new.nis, old.nis, rtol=1e-6)
