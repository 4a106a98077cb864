"""Every track figure is readable whatever the track's shape: a long zigzag is not a thin strip, the hull
outlines are big enough to see, the legend stays in the figure and off the track, all to scale."""
from __future__ import annotations

from types import SimpleNamespace as NS

import matplotlib
import numpy as np
import pytest

from trials.measured.diagnose_plots import diagnose_figure
from trials.files.plots import track_figure
from trials.measured.predict_plots import replay_figure

matplotlib.use("Agg")

L, B = 325.0, 53.0


def zigzag(n=3001):
    """A 10/10-zigzag-like track (north 41 L, east +-0.8 L), heading along it."""
    t = np.linspace(0.0, 3000.0, n)
    x = 4.4 * t                                            # north [m]
    y = 0.8 * L * np.sin(2 * np.pi * t / 780.0)            # east [m]
    psi = np.arctan2(np.gradient(y, t), np.gradient(x, t))
    return t, x, y, psi


def turn(n=3001):
    """A turning circle after a straight approach (about 4 L across)."""
    t = np.linspace(0.0, 3000.0, n)
    ang = np.clip((t - 100.0) / 450.0, 0.0, None) * 2 * np.pi
    R = 1.8 * L
    x = np.where(t < 100.0, 4.4 * t, 440.0 + R * np.sin(ang))
    y = np.where(t < 100.0, 0.0, R * (1 - np.cos(ang)))
    psi = np.where(t < 100.0, 0.0, ang)
    return t, x, y, psi


def _render(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.canvas.draw()


def track_axes(fig):
    """The axes that draw a track: equal aspect."""
    return [a for a in fig.axes if a.get_aspect() == 1.0]


def check_readable(fig, north, east, length, min_px=40):
    """Each track axes: box not a strip, a ship length of at least ``min_px`` pixels, equal scales; the
    start shown; the legend inside the figure and clear of every track point shown."""
    _render(fig)
    axs = track_axes(fig)
    assert axs
    shown, starts = [], []
    for ax in axs:
        box = ax.get_window_extent()
        assert min(box.width, box.height) >= 0.15 * max(box.width, box.height), (box.width, box.height)
        h, v = (north, east) if ax.yaxis_inverted() else (east, north)      # turned: north across
        d = ax.transData.transform([[h[0], v[0]], [h[0] + length, v[0]], [h[0], v[0] + length]])
        px_h, px_v = abs(d[1, 0] - d[0, 0]), abs(d[2, 1] - d[0, 1])
        assert px_h >= min_px and abs(px_h - px_v) < 0.02 * px_h, (px_h, px_v)   # visible, and to scale
        xy = ax.transData.transform(np.column_stack([h, v]))
        inside = (xy[:, 0] >= box.x0) & (xy[:, 0] <= box.x1) & (xy[:, 1] >= box.y0) & (xy[:, 1] <= box.y1)
        shown.append(xy[inside])
        starts.append(inside[0])
    assert any(starts), "the start is not shown"
    shown = np.vstack(shown)
    legends = fig.legends + [a.get_legend() for a in fig.axes if a.get_legend() is not None]
    assert legends
    fb = fig.bbox
    for lg in legends:
        lb = lg.get_window_extent()
        assert lb.x0 >= fb.x0 - 1 and lb.y0 >= fb.y0 - 1 and lb.x1 <= fb.x1 + 1 and lb.y1 <= fb.y1 + 1, lb
        over = (shown[:, 0] > lb.x0) & (shown[:, 0] < lb.x1) & (shown[:, 1] > lb.y0) & (shown[:, 1] < lb.y1)
        assert not over.any(), f"a legend covers {over.sum()} track points, the first at {shown[over][0]}"


@pytest.mark.parametrize("make", [zigzag, turn], ids=["zigzag", "turn"])
def test_track_figure_readable(make):
    t, x, y, psi = make()
    fig = track_figure(t, x, y, psi, L, B, "test", pyplot=False)
    check_readable(fig, x / L, y / L, 1.0)


def _replayed(make, wobble=0.15):
    t, x, y, psi = make(601)
    n = len(t)
    meas = np.zeros((n, 6))
    meas[:, 0], meas[:, 3], meas[:, 4], meas[:, 5] = 5.0, x, y, psi
    pred = meas.copy()
    pred[:, 4] += wobble * L * np.sin(t / 300.0)
    run = NS(meas=meas, t=t, name="rec", wind="off", inputs=NS(delta=np.zeros(n), n=np.ones(n)))
    return NS(run=run, pred=pred, L=L, B=B, diverged_at=None), meas, pred


@pytest.mark.parametrize("make", [zigzag, turn], ids=["zigzag", "turn"])
def test_replay_figure_readable(make):
    rep, meas, pred = _replayed(make)
    fig = replay_figure(rep, pyplot=False)
    both = np.vstack([meas, pred])
    check_readable(fig, both[:, 3] / L, both[:, 4] / L, 1.0, min_px=20)     # a panel beside the histories


@pytest.mark.parametrize("make", [turn], ids=["turn"])
def test_diagnose_figure_readable(make):
    """A turn to scale; a long zigzag is drawn against its mean course, cross-track enlarged:
    tests/test_diagnose_report.py::test_zigzag_track_not_a_strip."""
    rep, meas, pred = _replayed(make)
    after = 0.5 * (meas + pred)
    rec = NS(name="rec", seg=NS(inputs=NS(t=rep.run.t), meas=meas))
    fig = diagnose_figure(NS(records=[rec], pred_before=[pred], pred_after=[after], named=["wind"]), 0)
    both = np.vstack([meas, pred, after])
    check_readable(fig, both[:, 3], both[:, 4], L, min_px=20)      # metres: a ship length of 325 m
