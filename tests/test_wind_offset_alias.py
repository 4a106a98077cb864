"""bench/wind_offset_alias.py: what a wind-curve departure takes up of a rudder offset's signature on a zigzag.

Physics, not the bench's own numbers: in a head wind the zigzag swings the relative wind to either side
of the bow alike, and the side force and yaw moment are odd in that angle, so any change of their shape
acts to both sides alike and cannot make the one-sided moment of an offset: nothing is taken up; in a beam
wind the yaw moment keeps one sign over the whole record, and a shape departure within two prior standard
deviations takes up most of a 10/10 zigzag's offset signature."""
from __future__ import annotations

import numpy as np
import pytest

from .conftest import load_bench


@pytest.fixture(scope="module")
def alias():
    return load_bench("wind_offset_alias")


def test_head_wind_shape_takes_up_nothing(alias):
    r = alias.alias_case("esso_osaka", 10.0, 10.0, 20.0, 0.0, 1.0)
    assert r["signature_heading_rms_deg"] > 1.0                   # a 1 deg offset shows on a 10/10 zigzag
    assert abs(r["taken_up"]) < 0.05


def test_beam_wind_shape_within_the_prior_takes_up_most_of_it(alias):
    r = alias.alias_case("esso_osaka", 10.0, 10.0, 20.0, 90.0, 1.0)
    assert r["taken_up"] > 0.5 and r["left_heading_rms_deg"] < 0.5 * r["signature_heading_rms_deg"]
    assert np.all(np.abs(list(r["shape_prior_sd"].values())) < 2.0)
