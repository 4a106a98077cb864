"""The mismatch family's other wind-load curve (trials.measured.wind_curves) and its use in the family."""
import math

import numpy as np
import pytest

import mmg
from trials.measured.mismatch import MismatchSpec, TrialConditions, mismatch_family, trial_records
from trials.measured.wind_curves import TANKER_LOADED, HarmonicWindCurve

SIMPLE = HarmonicWindCurve(a=(0.1, -0.8, 0.05, -0.02), b=(-0.7, 0.05, -0.02), c=(0.13, -0.06, 0.03))


@pytest.mark.parametrize("curve", [SIMPLE, TANKER_LOADED, TANKER_LOADED.drawn(np.random.default_rng(3), 0.3)])
def test_symmetry_cx_even_cy_cn_odd(curve):
    g = np.random.default_rng(0).uniform(-math.pi, math.pi, 50)
    cx, cy, cn = curve.coefficients(g)
    mx, my, mn = curve.coefficients(-g)
    np.testing.assert_allclose(mx, cx, atol=1e-12)
    np.testing.assert_allclose(my, -cy, atol=1e-12)
    np.testing.assert_allclose(mn, -cn, atol=1e-12)
    # periodic in 2 pi
    np.testing.assert_allclose(curve.coefficients(g + 2 * math.pi), (cx, cy, cn), atol=1e-12)


def test_values_at_head_beam_following_by_hand():
    cx, cy, cn = SIMPLE.coefficients(np.radians([0.0, 90.0, 180.0]))
    # cos(k*0) = 1; cos(k*90) = 1, 0, -1, 0; cos(k*180) = (-1)^k
    np.testing.assert_allclose(cx, [0.1 - 0.8 + 0.05 - 0.02, 0.1 - 0.05, 0.1 + 0.8 + 0.05 + 0.02], atol=1e-12)
    # sin(k*90) = 1, 0, -1; sin(k*0) = sin(k*180) = 0
    np.testing.assert_allclose(cy, [0.0, -0.7 + 0.02, 0.0], atol=1e-12)
    np.testing.assert_allclose(cn, [0.0, 0.13 - 0.03, 0.0], atol=1e-12)


def test_tanker_curve_follows_the_ocimf_table():
    # OCIMF (1994) loaded VLCC, figs 2.3 and 2.4 as digitised (module docstring); OCIMF's angle 0 is
    # the wind from astern: gamma = 180 - theta.  C_Y = -(C_YA + C_YF), C_N = (C_YA - C_YF) / 2.
    theta = np.array([180, 170, 160, 140, 120, 100, 80, 60, 40, 20, 10, 0.0])
    cx_t = [-0.945, -0.9, -0.82, -0.62, -0.325, -0.07, 0.15, 0.275, 0.55, 0.74, 0.75, 0.74]
    ya = np.array([0, 0.05, 0.12, 0.275, 0.375, 0.43, 0.475, 0.49, 0.44, 0.285, 0.15, 0])
    yf = np.array([0, 0.025, 0.075, 0.175, 0.24, 0.267, 0.225, 0.172, 0.1, 0.05, 0.015, 0])
    cx, cy, cn = TANKER_LOADED.coefficients(np.radians(180.0 - theta))
    np.testing.assert_allclose(cx, cx_t, atol=0.06)
    np.testing.assert_allclose(cy, -(ya + yf), atol=0.04)
    np.testing.assert_allclose(cn, (ya - yf) / 2, atol=0.015)


def test_loads_by_hand():
    ship = mmg.load_ship(mmg.ship_path("esso_osaka"))
    p = ship.wind.particulars()
    X, Y, N = SIMPLE.loads(20.0, math.pi / 2, p, rho_air=1.2)
    q = 0.5 * 1.2 * 400.0
    assert X == pytest.approx(q * p.A_T * 0.05)
    assert Y == pytest.approx(q * p.A_L * -0.68)
    assert N == pytest.approx(q * p.A_L * p.L * 0.10)


def test_round_trip_and_draw_spread():
    assert HarmonicWindCurve.from_dict(TANKER_LOADED.to_dict()) == TANKER_LOADED
    d = TANKER_LOADED.drawn(np.random.default_rng(1), 0.3)
    for new, old in ((d.a, TANKER_LOADED.a), (d.b, TANKER_LOADED.b), (d.c, TANKER_LOADED.c)):
        r = np.array(new) / np.array(old)
        assert np.all((r >= 0.7) & (r <= 1.3)) and np.any(np.abs(r - 1) > 0.01)


@pytest.fixture(scope="module")
def families():
    ship = mmg.load_ship(mmg.ship_path("esso_osaka"))
    return ship, {k: mismatch_family(ship, 8, 11, MismatchSpec(wind_curve=k)) for k in ("fujiwara", "harmonic", "mixed")}


def test_family_options_keep_the_members(families):
    _, fam = families
    for kind in ("harmonic", "mixed"):
        for (s0, f0), (s1, f1) in zip(fam["fujiwara"], fam[kind]):
            assert s0 == s1
            assert {k: v for k, v in f1.items() if k != "wind_curve"} == f0
    assert not any("wind_curve" in f for _, f in fam["fujiwara"])
    assert all("wind_curve" in f for _, f in fam["harmonic"])
    assert sum("wind_curve" in f for _, f in fam["mixed"]) == 4
    with pytest.raises(ValueError, match="wind_curve"):
        mismatch_family(families[0], 2, 1, MismatchSpec(wind_curve="isherwood"))


def test_trial_record_sails_the_member_curve(families):
    ship, fam = families
    member, f = fam["harmonic"][0]
    wind = {"wind": {}}
    tw = (15.0, math.radians(90.0))
    fuji = trial_records(ship, member, "zz10", TrialConditions(wind, tw), seed=1, noise=(0.0,) * 6)
    harm = trial_records(ship, member, "zz10", TrialConditions(wind, tw), seed=1, noise=(0.0,) * 6,
                         wind_curve=f["wind_curve"])
    n = min(len(fuji.t), len(harm.t))
    assert np.max(np.abs(np.asarray(fuji.r[:n]) - np.asarray(harm.r[:n]))) > 1e-5
    calm = trial_records(ship, member, "zz10", {}, seed=1, noise=(0.0,) * 6, wind_curve=f["wind_curve"])
    calm0 = trial_records(ship, member, "zz10", {}, seed=1, noise=(0.0,) * 6)
    np.testing.assert_array_equal(calm.r, calm0.r)
