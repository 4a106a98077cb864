"""Figures users look at: tracks with ship outlines and time histories.

:func:`track_figure` and :func:`histories_figure` draw into a new figure (or into axes
you give) and return the :class:`matplotlib.figure.Figure`; :func:`plot_track` and
:func:`plot_histories` also write it to a PNG (the CLI).  Importing this module does
not choose a matplotlib backend: figures that are only saved are drawn without pyplot
(no window, no global figure state), so the CLI also works without a display.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mmg.units import DEG, KNOT


def _figure(figsize, pyplot: bool):
    """A new figure: pyplot-managed (can be shown) or a bare Agg figure (only saved)."""
    if pyplot:
        import matplotlib.pyplot as plt

        return plt.figure(figsize=figsize)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig


def ship_outline(x, y, psi, L, B):
    """Polygon (north, east) of a simple hull plan (parallel body, pointed bow) at midship x, y."""
    s = np.array([-0.5, 0.35, 0.5, 0.35, -0.5, -0.5]) * L
    b = np.array([-0.5, -0.5, 0.0, 0.5, 0.5, -0.5]) * B
    c, sn = np.cos(psi), np.sin(psi)
    return x + s * c - b * sn, y + s * sn + b * c


TURN_RATIO = 1.5
"""A track whose north-south extent exceeds this many times its east-west one is drawn turned a quarter
(north to the right, east down: the map rotated, not mirrored), its long side along the canvas's."""

PANEL_RATIO = 5.0
"""The longest side ratio of one track panel: a longer track is cut into parts along its long side,
one panel each, stacked (all to the same scale), so that its narrow side stays readable."""


class TrackView:
    """How a track is placed in an Axes: the map view (east right, north up) or turned a quarter
    (north right, east down), always to scale (equal axes).

    Parameters
    ----------
    turned : bool
        Draw north along the horizontal axis (a long north-south track on a wide canvas).
    unit : str
        The axes' unit, for the labels ("L", "m").
    """

    def __init__(self, turned: bool, unit: str = "L"):
        self.turned = turned
        self.unit = unit

    @classmethod
    def for_extent(cls, north, east, unit: str = "L", box_ratio: float = 1.0) -> "TrackView":
        """The view that runs a track's long side along the long side of a box ``box_ratio`` (width /
        height) wide: turned when the track is long north-south (more than ``TURN_RATIO``) and the box is
        wide, or long east-west and the box tall."""
        n_span = float(np.nanmax(north) - np.nanmin(north))
        e_span = float(np.nanmax(east) - np.nanmin(east))
        if box_ratio >= 1.0:
            return cls(n_span > TURN_RATIO * max(e_span, 1e-12), unit)
        return cls(e_span > TURN_RATIO * max(n_span, 1e-12), unit)

    def hv(self, north, east):
        """Horizontal and vertical plot coordinates of (north, east)."""
        return (north, east) if self.turned else (east, north)

    def finish(self, ax, xlabel: bool = True, adjustable: str = "datalim") -> None:
        """Equal axes (``adjustable`` as :meth:`matplotlib.axes.Axes.set_aspect`), labels, the east axis
        downward when turned, the grid."""
        ax.set_aspect("equal", adjustable=adjustable)
        if self.turned:
            if not ax.yaxis_inverted():
                ax.invert_yaxis()                        # east down: the map turned, not mirrored
            if xlabel:
                ax.set_xlabel(f"x, north ({self.unit}) \u2192  (track turned a quarter: north to the right)")
            ax.set_ylabel(f"y, east ({self.unit})")
        else:
            if xlabel:
                ax.set_xlabel(f"y, east ({self.unit})")
            ax.set_ylabel(f"x, north ({self.unit})")
        ax.grid(True, alpha=0.3)


def track_layout(north, east, pad: float, width_in: float = 10.0) -> dict:
    """Canvas of a track figure from the track's extent (in the units of ``north``, ``east``).

    A track close to square keeps the map view on a canvas of its own proportions; a long one is turned so
    its long side runs across a wide canvas, and one longer than ``PANEL_RATIO`` times its width is cut
    into ``panels`` parts along that side, stacked, each to the same scale.

    Returns
    -------
    dict
        ``view`` (:class:`TrackView`), ``panels`` (int), ``lo``, ``hi`` (the horizontal range, padded),
        ``vlim`` (the vertical range, padded), ``figsize`` (inches), ``adjust`` (the subplot margins).
    """
    view = TrackView.for_extent(north, east)
    h, v = view.hv(np.asarray(north), np.asarray(east))
    h_lo, h_hi = float(np.nanmin(h)) - pad, float(np.nanmax(h)) + pad
    v_lo, v_hi = float(np.nanmin(v)) - pad, float(np.nanmax(v)) + pad
    ratio = (h_hi - h_lo) / (v_hi - v_lo)
    lay = {"view": view, "lo": h_lo, "hi": h_hi, "vlim": (v_lo, v_hi)}
    if ratio < 1.0:                                      # taller than wide (close to square): map view
        axes_w, axes_h, panels = max(3.5, 7.0 * ratio), 7.0, 1
    else:
        panels = int(np.ceil(ratio / PANEL_RATIO))
        axes_w = width_in - _MARGIN_IN["left"] - _MARGIN_IN["right"]
        axes_h = axes_w / (ratio / panels)
    w = axes_w + _MARGIN_IN["left"] + _MARGIN_IN["right"]
    h = panels * axes_h + (panels - 1) * _MARGIN_IN["gap"] + _MARGIN_IN["top"] + _MARGIN_IN["bottom"]
    adjust = {"left": _MARGIN_IN["left"] / w, "right": 1 - _MARGIN_IN["right"] / w, "top": 1 - _MARGIN_IN["top"] / h,
              "bottom": _MARGIN_IN["bottom"] / h, "hspace": _MARGIN_IN["gap"] / axes_h}
    return {**lay, "panels": panels, "figsize": (w, h), "adjust": adjust}


_MARGIN_IN = {"left": 0.9, "right": 0.3, "top": 0.5, "bottom": 1.0, "gap": 0.7}
"""A track figure's margins [in]: the labels, the title above, the x label and the legend below."""


def track_figure(t, x, y, psi, L, B, title, every_s=None, ax=None, pyplot: bool = True):
    """Track in ship lengths, to scale, with hull outlines every ``every_s`` seconds and the start marked.

    A new figure takes its shape from the track (:func:`track_layout`): a track close to square in the
    map view (east right, north up); a long one turned so its long side runs across a wide canvas (a
    north-south zigzag: north to the right, east down, labelled so), and cut into stacked parts when
    longer than ``PANEL_RATIO`` times its width, so its narrow side stays readable and the outlines (to
    scale) visible.  The legend sits below the axes, off the track.  Axes you give get the map view.

    Parameters
    ----------
    t, x, y, psi : ndarray
        Time [s], position north, east [m], heading [rad].
    L, B : float
        Ship length and beam [m] (the outlines; the axes are in ship lengths).
    title : str
    every_s : float, optional
        Time between outlines [s]; default a 25th of the run, at least 60 s.
    ax : matplotlib.axes.Axes, optional
        Draw into these axes; default a new figure.
    pyplot : bool, default True
        Make the new figure with pyplot (so ``plt.show()`` shows it).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.collections import PolyCollection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    every_s = every_s or max(60.0, (t[-1] - t[0]) / 25)
    ts = np.arange(t[0], t[-1] + 1e-9, every_s)
    idx = np.minimum(np.searchsorted(t, ts), len(t) - 1)
    px, py = ship_outline(x[idx, None], y[idx, None], psi[idx, None], L, B)
    if ax is None:
        lay = track_layout(x / L, y / L, pad=0.6)
        fig = _figure(lay["figsize"], pyplot)
        axs = list(np.ravel(fig.subplots(lay["panels"], 1, squeeze=False)))
        view = lay["view"]
    else:
        fig, axs, view, lay = ax.figure, [ax], TrackView(False), None
    for k, a in enumerate(axs):
        a.plot(*view.hv(x / L, y / L), "b-", lw=1, label="midship track")
        h, v = view.hv(px / L, py / L)
        # the outlines as one collection: one artist instead of one polygon each
        a.add_collection(PolyCollection(np.stack([h, v], axis=-1), facecolors="0.8", edgecolors="k",
                                        linewidths=0.6, zorder=1.5))
        a.plot(*view.hv(x[:1] / L, y[:1] / L), "o", color="g", ms=6, zorder=3, label="start")
        if lay is not None:                              # this part's stretch; the box takes the shape
            step = (lay["hi"] - lay["lo"]) / lay["panels"]
            a.set_xlim(lay["lo"] + k * step - (0.02 * step if k else 0), lay["lo"] + (k + 1) * step)
            a.set_ylim(*lay["vlim"])
        else:
            a.autoscale_view()
        view.finish(a, xlabel=(k == len(axs) - 1), adjustable="box" if lay is not None else "datalim")
    part = "" if len(axs) == 1 else f", in {len(axs)} parts along its length, each to the same scale"
    axs[0].set_title(f"{title}: track (L = {L:g} m){part}")
    handles = [Line2D([], [], color="b", lw=1, label="midship track"),
               Patch(facecolor="0.8", edgecolor="k", lw=0.6, label=f"hull outline every {every_s:g} s (to scale)"),
               Line2D([], [], color="g", marker="o", ls="none", label="start")]
    if ax is None:                       # fixed margins (no tight_layout: a second rendering)
        fig.subplots_adjust(**lay["adjust"])
        fig.legend(handles=handles, loc="lower center", ncol=3, frameon=False)
    else:
        ax.legend(handles=handles, loc="best")
    return fig


SAVED_LINE_BUCKETS = 1000
"""Time buckets of a line in a figure that is only saved (:func:`min_max_decimate`): more than the
histories' 780 pixel columns, so every column still holds the line's lowest and highest sample."""


def min_max_decimate(t, y, buckets: int = SAVED_LINE_BUCKETS):
    """The samples of ``y(t)`` that a plot ``buckets`` pixels wide shows: in each of ``buckets``
    equal runs of samples its lowest and its highest (in time order), plus the samples after the
    last full run.  A line drawn through them covers, in every pixel column, the same range as the
    full line: peaks, overshoots and spikes stay (nothing is averaged away).  Records of up to
    ``4 * buckets`` samples are returned whole.

    Parameters
    ----------
    t, y : ndarray (N,)
    buckets : int

    Returns
    -------
    t, y : ndarray
        The kept samples, a subset of the input in time order.
    """
    t, y = np.asarray(t), np.asarray(y)
    N = len(t)
    if N <= 4 * buckets:
        return t, y
    k = N // buckets
    blocks = y[: k * buckets].reshape(buckets, k)
    base = np.arange(buckets)[:, None] * k
    pick = np.sort(np.stack([np.argmin(blocks, axis=1), np.argmax(blocks, axis=1)], axis=1), axis=1) + base
    idx = np.concatenate([pick.ravel(), np.arange(k * buckets, N)])
    return t[idx], y[idx]


def histories_figure(t, psi, delta, r, U, n, title, delta_order=None, ax=None, pyplot: bool = True):
    """Heading, rudder, yaw rate, speed and rpm against time (five panels).

    Parameters
    ----------
    t, psi, delta, r, U, n : ndarray
        Time [s], heading [rad], rudder angle [rad], yaw rate [rad/s], speed [m/s],
        propeller speed [rps].
    title : str
    delta_order : ndarray, optional
        Rudder order [rad], drawn dashed with the rudder angle.
    ax : sequence of 5 matplotlib.axes.Axes, optional
        Draw into these axes; default a new figure with five panels sharing the time axis.
    pyplot : bool, default True
        Make the new figure with pyplot.  A new figure that is only saved (``pyplot=False``)
        draws each line through :func:`min_max_decimate` (a 3000 s run at 0.1 s: 30 000 samples,
        2000 drawn; the same picture, a fifth of the rendering time); a pyplot figure, which can be
        zoomed, and axes you give get every sample.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if ax is None:
        fig = _figure((9, 11), pyplot)
        axs = fig.subplots(5, 1, sharex=True)
        new = True
    else:
        axs = list(np.ravel(ax))
        if len(axs) != 5:
            raise ValueError(f"histories need 5 axes, got {len(axs)}")
        fig = axs[0].figure
        new = False
    line = (lambda y: min_max_decimate(t, y)) if new and not pyplot else (lambda y: (t, y))  # noqa: E731
    axs[0].plot(*line(psi / DEG), "b")
    axs[0].set_ylabel("heading ψ (deg)")
    axs[1].plot(*line(delta / DEG), "r", label="rudder δ")
    if delta_order is not None:
        axs[1].plot(*line(delta_order / DEG), "k--", lw=0.8, label="order δ*")
        axs[1].legend(loc="best")
    axs[1].set_ylabel("rudder (deg)")
    axs[2].plot(*line(r / DEG), "g")
    axs[2].set_ylabel("yaw rate r (deg/s)")
    axs[3].plot(*line(U / KNOT), "m")
    axs[3].set_ylabel("speed U (kn)")
    axs[4].plot(*line(n * 60), "k")
    axs[4].set_ylabel("propeller n (rpm)")
    axs[4].set_xlabel("time t (s)")
    for a in axs:
        a.grid(True, alpha=0.3)
    axs[0].set_title(f"{title}: time histories")
    if new:
        # fixed margins (the panels share the time axis): tight_layout would draw every text twice
        fig.subplots_adjust(left=0.1, right=0.97, bottom=0.05, top=0.96, hspace=0.1)
    return fig


def plot_track(t, x, y, psi, L, B, title, path, every_s=None, show=False):
    """:func:`track_figure`, written to the PNG ``path`` (and shown if ``show``)."""
    _save(track_figure(t, x, y, psi, L, B, title, every_s=every_s, pyplot=show), path, show)


def plot_histories(t, psi, delta, r, U, n, title, path, delta_order=None, show=False):
    """:func:`histories_figure`, written to the PNG ``path`` (and shown if ``show``)."""
    _save(histories_figure(t, psi, delta, r, U, n, title, delta_order=delta_order, pyplot=show), path, show)


PNG_DPI = 100
"""Resolution of the written PNGs (a long track 1000 px wide, the histories 900 x 1100 px)."""


def _save(fig, path, show):
    # zlib level 1: a third of the default's encoding time for files a few kB larger
    fig.savefig(Path(path), dpi=PNG_DPI, pil_kwargs={"compress_level": 1})
    if show:
        import matplotlib.pyplot as plt

        plt.show()
        plt.close(fig)
