"""Saved figures draw long lines through a min-max decimation (``trials.files.plots.min_max_decimate``):
properties that make it lossless at the drawn resolution, on arbitrary series (hypothesis)."""
from __future__ import annotations

import matplotlib
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from trials.files.plots import min_max_decimate

matplotlib.use("Agg")                      # no window (as tests/test_api.py)


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 5000), buckets=st.integers(1, 400), seed=st.integers(0, 2**31 - 1),
       spikes=st.integers(0, 5))
def test_every_bucket_keeps_its_extremes_in_time_order(n, buckets, seed, spikes):
    """The kept samples are input samples in time order; every run of samples the function groups
    (equal runs of n // buckets, then the tail whole) keeps its lowest and highest value, so isolated
    spikes survive; up to 4 x buckets samples nothing is dropped."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.01, 1.0, n))
    y = np.cumsum(rng.normal(size=n))
    y[rng.integers(0, n, spikes)] += rng.choice([-1e3, 1e3], spikes)
    tk, yk = min_max_decimate(t, y, buckets)
    if n <= 4 * buckets:
        assert np.array_equal(tk, t) and np.array_equal(yk, y)
        return
    pos = np.searchsorted(t, tk)                                # t strictly increasing: the kept indices
    assert np.array_equal(t[pos], tk) and np.array_equal(y[pos], yk)
    assert np.all(np.diff(pos) > 0)
    k = n // buckets
    assert len(yk) <= 2 * buckets + (n - k * buckets)
    for b in range(buckets):                                    # an independent min / max per run
        sel = (pos >= b * k) & (pos < (b + 1) * k)
        assert yk[sel].min() == y[b * k:(b + 1) * k].min() and yk[sel].max() == y[b * k:(b + 1) * k].max()
    assert np.array_equal(yk[pos >= k * buckets], y[k * buckets:])
    assert yk.min() == y.min() and yk.max() == y.max()


def test_a_saved_histories_figure_draws_decimated_lines_a_shown_one_every_sample():
    from trials.files.plots import histories_figure

    t = np.arange(30000) * 0.1
    z = np.sin(t / 50.0)
    saved = histories_figure(t, z, z, z, z + 2, z + 1, "T", delta_order=z, pyplot=False)
    lens = [len(ln.get_xdata()) for a in saved.axes for ln in a.get_lines()]
    assert len(lens) == 6 and max(lens) <= 2000
    shown = histories_figure(t, z, z, z, z + 2, z + 1, "T", delta_order=z, pyplot=True)
    assert {len(ln.get_xdata()) for a in shown.axes for ln in a.get_lines()} == {30000}
    import matplotlib.pyplot as plt

    plt.close(shown)
