"""bench/wind_alias.py: what a wind-curve departure takes up of another effect's signature on a zigzag.

Physics, not the bench's own numbers: in a head wind the zigzag swings the relative wind to either side
of the bow alike, and the side force and yaw moment are odd in that angle, so any change of their shape
acts to both sides alike and cannot make the one-sided moment of an offset: nothing is taken up; in a beam
wind the yaw moment keeps one sign over the whole record, and a shape departure of about two prior standard
deviations takes up most of a 10/10 zigzag's offset signature."""
from __future__ import annotations

import numpy as np
import pytest

from .conftest import load_bench


@pytest.fixture(scope="module")
def alias():
    return load_bench("wind_alias")


def test_head_wind_shape_takes_up_nothing(alias):
    r = alias.alias_case("esso_osaka", 10.0, 10.0, 20.0, 0.0, 1.0, "rudder_offset")
    assert r["signature_heading_rms_deg"] > 1.0                   # a 1 deg offset shows on a 10/10 zigzag
    assert abs(r["taken_up"]) < 0.05


def test_beam_wind_shape_about_two_prior_sd_off_takes_up_most_of_it(alias):
    r = alias.alias_case("esso_osaka", 10.0, 10.0, 20.0, 90.0, 1.0, "rudder_offset")
    assert r["taken_up"] > 0.5 and r["left_heading_rms_deg"] < 0.5 * r["signature_heading_rms_deg"]
    assert np.all(np.abs(list(r["shape_prior_sd"].values())) < 2.5)      # the starts' grid reaches 2 sd


def test_a_heading_bias_is_a_measurement_no_wind_curve_takes_up(alias):
    """The bias shifts the logged heading by its size at every sample and leaves the track alone (it is in the
    log, not the ship); a wind load moves the ship, so it cannot make a constant heading shift with no track."""
    r = alias.alias_case("esso_osaka", 10.0, 10.0, 20.0, 90.0, 1.0, "heading_bias")
    assert r["signature_heading_rms_deg"] == pytest.approx(1.0, abs=1e-6) and r["signature_position_rms_m"] < 1e-6
    assert r["taken_up"] < 0.2


def test_the_fit_starts_from_a_grid_within_two_prior_sd_clipped_to_the_bounds():
    """The residual of a zigzag jumps where a reversal moves, so a local fit stays at its start: the starts are
    every combination of -2..2 prior sd per shape term (125), clipped to the terms' hard bounds."""
    from mmg.effects import Wind

    from .conftest import load_bench

    alias = load_bench("wind_alias")
    p = {q.name: q for q in Wind.fit_parameters()}
    mu, sd = (np.array([getattr(p[n], k) for n in alias.SHAPES]) for k in ("default", "sigma"))
    lo, hi = (np.array([getattr(p[n], k) for n in alias.SHAPES]) for k in ("lower", "upper"))
    g = np.array(alias._grid(mu, sd, lo, hi))
    assert g.shape == (125, 3) and np.all(g >= lo) and np.all(g <= hi)
    assert np.allclose(sorted(set(np.round(g[:, 2], 12))), mu[2] + sd[2] * np.array([-2, -1, 0, 1, 2]))


def test_the_current_sets_downwind():
    from .conftest import load_bench

    alias = load_bench("wind_alias")
    assert alias.target_effect("current", 0.15, 90.0) == {"current": {"speed_mps": 0.15, "direction_deg": 270.0}}
    assert alias.target_effect("rudder_offset", 1.0, 90.0) == {"rudder_offset": {"offset_deg": 1.0}}
