"""The parameter table's diagnosis fields (:class:`mmg.parameters.ShipParameter`: ``diagnosis_family``,
``diagnosis_floor``, ``keeps_sign``, ``multiplies``) as the diagnosis baseline and the identification's wind
bounds read them, checked against the documented rules worked out here by hand:

- the diagnosis's prior std of a hull coefficient is its width in
  :data:`mmg.parameters.DIAGNOSIS_PRIOR_REL_STD` times |config value|, at least ``hull_floor``; the width is
  ``hull`` for a term in beta, r, v (:data:`mmg.parameters.LINEAR_TERMS`), ``resistance`` for the
  straight-ahead resistance, ``hull_nonlinear`` for every other term; w_P0's is ``w_P0`` (relative), at least
  0.01;
- a hull coefficient is bounded to its config value's sign (a positive Y_beta, a negative N_r); w_P0 keeps
  its own bounds 0-0.8;
- a fitted wind value is a factor on the config's, so its bounds are the wind effect's range (scale 0-10,
  shape factors 0.2-3, :mod:`mmg.effects.wind`) over the config value it multiplies.

The config values are read from the ship's YAML file, not from the packed ship the fit reads.
"""
from __future__ import annotations

import math

import pytest
import yaml

import mmg
from ekf.identify import free_parameters
from mmg.model import pack
from trials.measured.diagnose.baseline import _ship_free
from trials.measured.identify import _bounded_wind

SHIP = "esso_osaka_3m"
INF = math.inf
FLOOR = 0.002
"""The documented smallest std of a primed hull coefficient (``hull_floor``)."""


def _yaml():
    with open(mmg.config_path("ships", f"{SHIP}.yaml")) as fh:
        return yaml.safe_load(fh)


def _hull_value(name):
    return float(_yaml()["hull"]["coefficients"][name]["value"])


# name -> (documented relative width, expected bounds given the config value's sign).  Y_beta, N_r: linear
# (terms beta, r), 15 %; X_uu: the resistance (cos(beta)^2), 10 %; N_rr: nonlinear (r|r|), 30 %; N_bb:
# nonlinear and so small (-5.18e-4) that 30 % of it falls below the floor.  With the ship's values:
# Y_beta 0.15 * 0.3998 = 0.05997, N_r 0.15 * 0.05433 = 0.00815, X_uu 0.10 * 0.0228 = 0.00228,
# N_rr 0.30 * 0.02224 = 0.00667, N_bb max(0.30 * 5.18e-4, 0.002) = 0.002.
HULL_CASES = {
    "Y_beta": (0.15, (0.0, INF)),
    "N_r": (0.15, (-INF, 0.0)),
    "X_uu": (0.10, (-INF, 0.0)),
    "N_rr": (0.30, (-INF, 0.0)),
    "N_bb": (0.30, (-INF, 0.0)),
}


@pytest.fixture(scope="module")
def baseline():
    ship = mmg.load_ship(SHIP)
    free = _ship_free(ship, pack(ship), names=[*HULL_CASES, "w_P0"])
    return {f.name: f for f in free}


@pytest.mark.parametrize("name", list(HULL_CASES))
def test_the_diagnosis_prior_of_a_hull_coefficient_is_its_terms_width_floored(baseline, name):
    width, _ = HULL_CASES[name]
    v = _hull_value(name)
    sigma = max(width * abs(v), FLOOR)
    f = baseline[name]
    assert f.prior == pytest.approx(v, rel=1e-12)
    assert f.sigma == pytest.approx(sigma, rel=1e-9)


@pytest.mark.parametrize("name", list(HULL_CASES))
def test_the_diagnosis_bounds_a_hull_coefficient_to_its_config_sign(baseline, name):
    _, (lo, hi) = HULL_CASES[name]
    assert math.copysign(1.0, _hull_value(name)) == (1.0 if hi == INF else -1.0)
    f = baseline[name]
    assert (f.lower, f.upper) == (lo, hi)


def test_the_diagnosis_prior_of_the_wake_is_relative_and_keeps_its_own_bounds(baseline):
    v = float(_yaml()["propeller"]["w_P0"][0])
    f = baseline["w_P0"]
    assert f.sigma == pytest.approx(max(0.20 * v, 0.01), rel=1e-9)   # 0.20 * 0.3946 = 0.07892
    assert (f.lower, f.upper) == (0.0, 0.8)


def test_the_wind_factors_bounds_are_the_effects_range_over_the_config_value_they_multiply(tmp_path):
    """Config wind scale 2 and sway factor 1.5 (yaw factor 1): the written products scale x f stay within
    0-10 and the shape factors' within 0.2-3 when f is within 0-5, 0.133-2 and 0.2-3."""
    data = _yaml()
    data["wind"]["scale"] = 2.0
    data["wind"]["sway_factor"] = 1.5
    path = tmp_path / "ship.yaml"
    path.write_text(yaml.safe_dump(data))
    ship = mmg.load_ship(path)
    assert (ship.wind.scale, ship.wind.sway_factor, ship.wind.yaw_factor) == (2.0, 1.5, 1.0)
    names = ["wind_scale", "wind_sway_factor", "wind_yaw_factor"]
    got = {f.name: (f.lower, f.upper) for f in _bounded_wind(ship, free_parameters(pack(ship), ship.hull.names, names))}
    assert got["wind_scale"] == pytest.approx((0.0 / 2.0, 10.0 / 2.0))
    assert got["wind_sway_factor"] == pytest.approx((0.2 / 1.5, 3.0 / 1.5))
    assert got["wind_yaw_factor"] == pytest.approx((0.2 / 1.0, 3.0 / 1.0))
