"""bench/wind_shape_band.py: the band fit recovers a curve of the candidate's own form, and an extra term
recovers the part the shape alone cannot follow."""
import numpy as np
import pytest

import mmg

from .conftest import load_bench

wsb = load_bench("wind_shape_band")


@pytest.fixture(scope="module")
def particulars():
    return mmg.load_ship(mmg.ship_path("esso_osaka")).wind.particulars()


def test_a_curve_of_the_candidates_own_form_is_followed_exactly(particulars):
    truth = (0.8, 1.3, 0.7, 0.05)
    r = wsb.band_fit(lambda g: wsb.candidate(g, particulars, truth), particulars, 60.0)
    assert max(r["misfit"].values()) < 1e-6
    assert np.allclose(r["theta"], truth, atol=1e-5)


def test_a_surge_harmonic_the_shape_lacks_is_left_over_and_the_extra_term_takes_it(particulars):
    # the published curve with 0.2 cos(2 gamma) added to C_X, written from the series itself (not the bench)
    from mmg.wind import amplitude_vector, fujiwara_series

    def curve(g):
        cx, cy, cn = fujiwara_series(np.cos(g), np.sin(g), amplitude_vector(particulars))
        return cx + 0.2 * np.cos(2 * g), cy, cn

    plain = wsb.band_fit(curve, particulars, 30.0)
    extra = wsb.band_fit(curve, particulars, 30.0, extra="x_cos2")
    assert plain["misfit"]["X"] > 0.05                      # a scale cannot make a harmonic the series lacks
    assert max(extra["misfit"].values()) < 1e-6
    assert extra["theta"][4] == pytest.approx(0.2, abs=1e-5) and extra["theta"][0] == pytest.approx(1.0, abs=1e-5)
