"""Checks any matplotlib figure can be put through: legends inside the canvas, no two texts on top of each
other, no text cut by the canvas's edge, the data filling a fair share of the canvas (:func:`check_figure`)."""
from __future__ import annotations

import itertools

import numpy as np

__all__ = ["render", "legends", "check_figure"]


def render(fig):
    """Draw ``fig`` on an Agg canvas (a pyplot figure or one made with ``pyplot=False``); returns its renderer."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def legends(fig) -> list:
    """The figure's legends and every axes' legend."""
    return list(fig.legends) + [a.get_legend() for a in fig.axes if a.get_legend() is not None]


def _texts(fig, renderer) -> list:
    """(owner, bbox, text) of every visible, non-empty text: titles, axis labels, legend entries and titles,
    figure texts, texts placed on axes; tick labels are left out (their own axes packs them)."""
    out = []

    def add(owner, t):
        if t is not None and t.get_visible() and t.get_text().strip():
            out.append((owner, t.get_window_extent(renderer), t.get_text()))

    for t in {id(t): t for t in [*fig.texts, fig._suptitle]}.values():
        add("figure", t)
    for k, ax in enumerate(fig.axes):
        if not ax.get_visible():
            continue
        for t in (ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label, *ax.texts):
            add(("axes", k), t)
    for k, lg in enumerate(legends(fig)):
        for t in (*lg.get_texts(), lg.get_title()):
            add(("legend", k), t)
    return out


def check_figure(fig, min_data_share: float = 0.3, tol_px: float = 1.0) -> None:
    """Assert that ``fig``, rendered, is readable.

    * every legend's window extent lies inside the figure's canvas (``tol_px`` pixels of slack), and so does
      every text (:func:`_texts`: no title or label cut by the canvas's edge);
    * no two texts (:func:`_texts`) overlap by more than ``tol_px`` in both directions;
    * the data (each axes' data limits of what it draws, cut to its box, in display coordinates) cover at
      least ``min_data_share`` of the canvas (a constant series counts its axes' box in that direction).
    """
    r = render(fig)
    fb = fig.bbox
    for lg in legends(fig):
        b = lg.get_window_extent(r)
        assert (b.x0 >= fb.x0 - tol_px and b.y0 >= fb.y0 - tol_px and b.x1 <= fb.x1 + tol_px
                and b.y1 <= fb.y1 + tol_px), f"a legend {b.bounds} leaves the canvas {fb.bounds}"
    texts = _texts(fig, r)
    for o, b, s in texts:
        assert (b.x0 >= fb.x0 - tol_px and b.y0 >= fb.y0 - tol_px and b.x1 <= fb.x1 + tol_px
                and b.y1 <= fb.y1 + tol_px), f"a text is cut by the canvas's edge: {s!r} ({o}) at {b.bounds}"
    for (o1, b1, s1), (o2, b2, s2) in itertools.combinations(texts, 2):
        dx = min(b1.x1, b2.x1) - max(b1.x0, b2.x0)
        dy = min(b1.y1, b2.y1) - max(b1.y0, b2.y0)
        assert not (dx > tol_px and dy > tol_px), f"texts overlap: {s1!r} ({o1}) and {s2!r} ({o2})"
    area = 0.0
    for ax in fig.axes:
        if not ax.get_visible() or not np.all(np.isfinite(ax.dataLim.get_points())):
            continue
        d = ax.transData.transform(ax.dataLim.get_points())
        box = ax.get_window_extent(r)
        w = min(d[:, 0].max(), box.x1) - max(d[:, 0].min(), box.x0)
        h = min(d[:, 1].max(), box.y1) - max(d[:, 1].min(), box.y0)
        w = box.width if np.ptp(d[:, 0]) < 1.0 else w       # a constant series: the autoscaled axes is its extent
        h = box.height if np.ptp(d[:, 1]) < 1.0 else h
        area += max(w, 0.0) * max(h, 0.0)
    share = area / (fb.width * fb.height)
    assert share >= min_data_share, f"the data cover {100 * share:.0f} % of the canvas (< {100 * min_data_share:.0f} %)"
