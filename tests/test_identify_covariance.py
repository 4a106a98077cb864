"""mmg identify's start states and written covariance: each record's replay starts
from a fitted state, not its one noisy first sample, and the covariance written into ship.yaml keeps the
prior at its stated std (the data's information alone scaled by their residual variance)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

import mmg
from ekf.identify import FreeParameter, _result
from mmg.model import pack
from mmg.replay import ReplayInputs, replay
from trials.measured.identify import Identification, identification_covariance, identify
from trials.measured.predict import MeasuredRun

SHIP = "esso_osaka_3m"
NOISE = np.array([0.004, 0.004, 0.004, 0.0, 0.0, 0.004])
"""Std of the noise added to every sample: u, v [m/s], r [rad/s], x, y [m], psi [rad]."""


def _records(ship, n_rec=3, duration=40.0, dt=0.1):
    """Clean replays of ``ship`` (zigzag-like rudders from a moving start) and the same with white noise."""
    pk = pack(ship)
    clean, noisy = [], []
    for k in range(n_rec):
        t = np.arange(0.0, duration + 1e-9, dt)
        delta = np.radians(10.0 + 5 * k) * np.sign(np.sin(2 * np.pi * t / (20.0 + 5 * k)))
        inp = ReplayInputs(t=t, delta=np.convolve(delta, np.ones(5) / 5, mode="same"), n=np.full_like(t, 10.0))
        s = replay(pk, inp, [0.4, 0.01 * (k - 1), 0.02 * (1 - k), 0.0, 0.0, 0.3 * k])
        rng = np.random.default_rng(100 + k)
        clean.append(s)
        noisy.append(MeasuredRun(name=f"rec{k}", source=f"rec{k}", meas=s + rng.normal(0.0, NOISE, s.shape),
                                 inputs=inp))
    return clean, noisy


def test_each_records_start_state_is_fitted_well_below_the_noise_of_its_first_sample():
    """The known ship's records with noise of known std: the start state the fit replays from is within a
    fraction of the noise of the true state, while the raw first sample is off by the noise itself."""
    ship = mmg.load_ship(SHIP)
    clean, runs = _records(ship)
    ident = identify(ship, runs, free=["kappa"], segment_s=(np.inf,), say=lambda m: None, max_nfev=8)
    v = {f.name: float(x) for f, x in zip(ident.fit.free, ident.fit.theta)}
    raw, fitted = [], []
    for s, run in zip(clean, runs):
        for j, nm in ((0, "u"), (1, "v"), (2, "r"), (5, "psi")):
            raw.append((run.meas[0, j] - s[0, j]) / NOISE[j])
            fitted.append((run.meas[0, j] + v[f"start.{nm}[{run.name}]"] - s[0, j]) / NOISE[j])
    raw, fitted = np.sqrt(np.mean(np.square(raw))), np.sqrt(np.mean(np.square(fitted)))
    assert 0.5 < raw < 2.0                               # the first samples carry the noise (in its std's units)
    assert fitted < 0.35 and fitted < 0.3 * raw
    old = identify(ship, runs, free=["kappa"], segment_s=(np.inf,), say=lambda m: None, max_nfev=8,
                   initial_state="sample")
    assert [f.name for f in old.fit.free] == ["kappa"]   # the raw first sample: nothing fitted for the start


def _linear_fit(A, y, prior, sig, rows=None):
    """A linear least squares with a prior solved by hand, returned as ekf.identify's result of it: the data
    rows A theta - y, then the prior's (theta - prior) / sig; ``rows``: each record's data rows."""
    n = A.shape[1]
    J = np.vstack([A, np.diag(1.0 / sig)])
    theta = np.linalg.solve(J.T @ J, A.T @ y + prior / sig ** 2)
    fun = np.concatenate([A @ theta - y, (theta - prior) / sig])
    free = [FreeParameter(f"p{i}", "hull", i, float(prior[i]), float(sig[i])) for i in range(n)]
    sol = SimpleNamespace(jac=J, fun=fun, x=theta, cost=0.5 * float(fun @ fun), nfev=1, message="", status=1)
    return _result(free, sol, 0.5 * float(fun @ fun), rows), theta


def test_the_written_covariance_keeps_the_prior_at_its_stated_std():
    """y = 2 theta_0 + noise of std 0.01 (200 samples), theta_1 not in the data, each with a prior std of 0.5:
    the written covariance gives theta_1 its prior std 0.5 (not 0.5 s, s the residual std, as the fit's own
    Gauss-Newton covariance does) and theta_0 the variance 1 / (sum a^2 / s_d^2 + 1 / 0.5^2), s_d^2 the data
    residuals' sum of squares over N - n."""
    rng = np.random.default_rng(7)
    N = 200
    A = np.column_stack([np.full(N, 2.0), np.zeros(N)])
    y = 2.0 * 0.3 + rng.normal(0.0, 0.01, N)
    sig = np.array([0.5, 0.5])
    fit, theta = _linear_fit(A, y, np.zeros(2), sig)
    ident = Identification(ship=None, initial=None, fit=fit, runs=[], segment_s=np.inf, tau=1.0)
    c = identification_covariance(ident)
    got = np.asarray(c["matrix"])
    rd = y - 2.0 * theta[0]
    sd2 = float(rd @ rd) / (N - 2)
    assert np.isclose(np.sqrt(got[1, 1]), 0.5, rtol=1e-9)            # the prior's std, as stated
    assert np.isclose(got[0, 0], 1.0 / (4.0 * N / sd2 + 1.0 / 0.25), rtol=1e-9)
    assert abs(got[0, 1]) < 1e-15
    assert fit.std[1] < 0.05                                         # the fit's own: 0.5 s, shrunk by s ~ 0.01
    tau = Identification(ship=None, initial=None, fit=fit, runs=[], segment_s=np.inf, tau=4.0)
    got4 = np.asarray(identification_covariance(tau)["matrix"])     # correlated residuals: N / 4 independent
    assert np.isclose(got4[0, 0], 1.0 / (4.0 * N / (4.0 * sd2) + 1.0 / 0.25), rtol=1e-9)
    assert np.isclose(np.sqrt(got4[1, 1]), 0.5, rtol=1e-9)
    assert "(inflated)" in identification_covariance(tau)["source"] and "not inflated" in c["source"]


def test_a_channel_without_noise_gets_no_start_offset():
    """Smoothed channels (no noise in their second difference: the FRT records' u, v, r) leave the start as
    logged: an offset whose prior std (twice the noise) is under 1 % of its residual scale is not fitted."""
    ship = mmg.load_ship(SHIP)
    clean, runs = _records(ship, n_rec=1, duration=20.0)
    m = runs[0].meas.copy()
    m[:, :3] = clean[0][:, :3]                          # u, v, r without noise; the heading noisy
    run = MeasuredRun(name="smooth", source="smooth", meas=m, inputs=runs[0].inputs)
    ident = identify(ship, [run], free=["kappa"], segment_s=(np.inf,), say=lambda m: None, max_nfev=2)
    assert [f.name for f in ident.fit.free if f.kind == "start"] == ["start.psi[smooth]"]


def test_cli_initial_state_choices_are_the_fits():
    """``mmg identify --initial-state`` offers exactly what :func:`identify` accepts (the parser does not
    import the fitting module, for the start-up time)."""
    import argparse

    from trials.cli.identify import add_parser
    from trials.measured.identify import INITIAL_STATES

    ap = argparse.ArgumentParser()
    add_parser(ap.add_subparsers())
    sub = next(a for a in ap._subparsers._group_actions[0].choices.values())
    act = next(a for a in sub._actions if a.dest == "initial_state")
    assert set(act.choices) == set(INITIAL_STATES)
