"""One definition of each effect: the estimators take an effect parameter's prior from its
:class:`mmg.effects.Parameter`, the ship coefficients' prior widths come from one table, the replay's
measured-wind loads are the ``wind`` effect's, and one function turns model states into a logged record (trial runs and the
diagnosis's synthetic records alike)."""
import math

import numpy as np
import pytest

import mmg
import mmg.effects as E
from mmg.model import pack


@pytest.fixture(scope="module")
def ship():
    return mmg.load_ship("esso_osaka_3m")


def test_freed_rudder_offset_and_wind_scale_take_the_effects_priors(ship):
    """``mmg identify --free rudder_offset wind_scale``: prior width, bounds and start are the effects'
    own (before: 0.05 rad within +-10 deg, and 1 +- 0.5 within [0, 3], numbers of their own)."""
    from ekf.identify import free_parameters

    off, wind = free_parameters(pack(ship), ship.hull.names, ["rudder_offset", "wind_scale"])
    q = E.RudderOffset.parameters[0]
    assert off.sigma == pytest.approx(math.radians(q.sigma))
    assert (off.lower, off.upper) == pytest.approx((math.radians(q.lower), math.radians(q.upper)))
    w = E.Wind.fit_parameters()[0]
    assert (wind.prior, wind.sigma, wind.lower, wind.upper, wind.start) == (w.default, w.sigma, w.lower, w.upper,
                                                                           w.start)
    # the wind effect's named scale and its fit parameter are one Parameter (range and width)
    named = E.Wind.parameters[0]
    assert (named.lower, named.upper, named.sigma) == (w.lower, w.upper, w.sigma)


def test_coefficient_prior_widths_are_one_table(ship):
    """Identification and diagnosis read the ship coefficients' prior widths from one table per family
    (ekf.identify.PRIOR_REL_STD) and the diagnosis's named policy beside it (added masses narrower)."""
    from ekf.identify import DIAGNOSIS_PRIOR_REL_STD, PRIOR_REL_STD, free_parameters
    from trials.measured.diagnose import MASS_FREE, _ship_free

    pk = pack(ship)
    ident = {f.name: f for f in free_parameters(pk, ship.hull.names, ["N_r", *MASS_FREE])}
    diag = {f.name: f for f in _ship_free(ship, pk, kind="turn")}
    for nm in MASS_FREE:
        assert ident[nm].sigma == pytest.approx(PRIOR_REL_STD["mass"] * ident[nm].prior)
        assert diag[nm].sigma == pytest.approx(DIAGNOSIS_PRIOR_REL_STD["mass"] * diag[nm].prior)
    assert ident["N_r"].sigma == pytest.approx(max(PRIOR_REL_STD["hull"] * abs(ident["N_r"].prior), 0.01))
    P = DIAGNOSIS_PRIOR_REL_STD
    assert diag["N_r"].sigma == pytest.approx(max(P["hull"] * abs(diag["N_r"].prior), P["hull_floor"]))
    assert diag["N_rr"].sigma == pytest.approx(max(P["hull_nonlinear"] * abs(diag["N_rr"].prior), P["hull_floor"]))
    assert diag["X_uu"].sigma == pytest.approx(max(P["resistance"] * abs(diag["X_uu"].prior), P["hull_floor"]))
    assert diag["w_P0"].sigma == pytest.approx(P["w_P0"] * diag["w_P0"].prior)
    assert diag["epsilon"].prior == pytest.approx(ship.rudder.epsilon)     # the rudder's inflow ratio, 10 %
    assert diag["epsilon"].sigma == pytest.approx(0.10 * ship.rudder.epsilon)
    assert "epsilon" not in {f.name for f in _ship_free(ship, pk, kind="zigzag")}   # on turns only
    assert diag["N_r"].upper == 0.0 and diag["Y_beta"].lower == 0.0        # the signs that define the ship


def test_replay_wind_loads_are_the_wind_effects(ship, monkeypatch):
    """trials.measured.predict's measured-wind loads are mmg.effects.Wind.external (no second copy): a
    changed effect changes the replay's loads."""
    from trials.measured.predict import measured_run
    from trials.files.records import TrialRecord

    t = np.arange(0.0, 20.0, 0.1)
    one = np.ones_like(t)
    rec = TrialRecord(t=t, name="r", source="r", u=0.5 * one, v=0 * one, r=0 * one, x=0.5 * t, y=0 * one,
                      psi=0 * one, U=0.5 * one, delta=0 * one, n=10 * one, wind_speed_rel=1.5 + 0.1 * np.sin(t),
                      wind_dir_rel=np.mod(0.3 * t, 2 * np.pi))
    base = measured_run(ship, rec, wind=True).inputs.ext
    assert base is not None and np.abs(base).max() > 0
    orig = E.Wind.external.__func__
    monkeypatch.setattr(E.Wind, "external", classmethod(lambda cls, v, ctx: 3.0 * orig(cls, v, ctx)))
    np.testing.assert_allclose(measured_run(ship, rec, wind=True).inputs.ext, 3.0 * base, rtol=1e-12)


def test_one_record_generator(ship, monkeypatch):
    """TrialRun.record and trials.measured.diagnose.synthetic_record both log through trials.files.records.logged_record."""
    import trials.files.records as R
    from trials.measured.diagnose import Manoeuvre, synthetic_record

    calls = []
    real = R.logged_record

    def spy(*a, **k):
        calls.append(k.get("name"))
        return real(*a, **k)

    monkeypatch.setattr(R, "logged_record", spy)
    rec = synthetic_record(ship, Manoeuvre("turning", duration=20.0), {"rudder_offset": {"offset_deg": 1.0}}, name="syn")
    run = mmg.simulate(mmg.load_trial("zz20"))
    log = run.record()
    assert calls == ["syn", run.trial.name]
    assert len(rec.t) > 10 and len(log.t) > 10


def _load_cov(theta, load_var):
    """The covariance of (scale, sway_factor, yaw_factor) when the fit knows the three loads (surge
    scale, sway scale*sway_factor, yaw scale*yaw_factor) independently with variances ``load_var``:
    the loads' Jacobian inverted by hand."""
    s, a, b = theta[:3]
    Ginv = np.array([[1.0, 0.0, 0.0], [-a / s, 1.0 / s, 0.0], [-b / s, 0.0, 1.0 / s]])
    cov = np.eye(len(theta)) * 0.01                     # yaw_sin (4th): known on its own, not a load's presence
    cov[:3, :3] = Ginv @ np.diag(load_var) @ Ginv.T
    return cov


def test_wind_presence_is_judged_on_its_three_loads():
    """A wind whose surge load the fit cannot tell from the resistance (sd 2) but whose sway and yaw
    loads it knows to 0.1: present at many standard errors, though its scale alone is 0.5 sd from 0;
    loads of 0.1, 0.05, 0.05 with the same sds: not shown."""
    from scipy.stats import chi2, norm

    from mmg.effects import get
    from mmg.effects.base import Effect

    W = get("wind")
    var = np.array([4.0, 0.01, 0.01])
    th = np.array([1.0, 1.0, 1.0, 0.0])
    cov = _load_cov(th, var)
    x = 1.0 / 4.0 + 1.0 / 0.01 + 1.0 / 0.01                       # the loads' Wald statistic, 3 dof
    assert W.presence_z(th, cov) == pytest.approx(norm.isf(0.5 * chi2.sf(x, 3)), rel=1e-6)
    assert W.presence_z(th, cov) > 10.0
    assert Effect.presence_z.__func__(W, th, cov) == pytest.approx(0.5, rel=1e-6)   # the scale alone
    small = np.array([0.1, 0.5, 0.5, 0.0])                         # loads 0.1, 0.05, 0.05
    assert W.presence_z(small, _load_cov(small, var)) < 3.0
