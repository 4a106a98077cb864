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


def track_figure(t, x, y, psi, L, B, title, every_s=None, ax=None, pyplot: bool = True):
    """Track (east right, north up) in ship lengths with outlines every ``every_s`` seconds.

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
    if ax is None:
        fig = _figure((7, 7), pyplot)
        ax = fig.add_subplot()
    fig = ax.figure
    from matplotlib.collections import PolyCollection

    ax.plot(y / L, x / L, "b-", lw=1, label="midship track")
    every_s = every_s or max(60.0, (t[-1] - t[0]) / 25)
    ts = np.arange(t[0], t[-1] + 1e-9, every_s)
    idx = np.minimum(np.searchsorted(t, ts), len(t) - 1)
    px, py = ship_outline(x[idx, None], y[idx, None], psi[idx, None], L, B)
    # the outlines as one collection: one artist instead of one polygon each
    ax.add_collection(PolyCollection(np.stack([py / L, px / L], axis=-1), facecolors="0.8", edgecolors="k",
                                     linewidths=0.6, zorder=1.5))
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("y, east (L)")
    ax.set_ylabel("x, north (L)")
    ax.set_title(f"{title}: track (L = {L:g} m)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
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
"""Resolution of the written PNGs (the 7 x 7 in track 700 x 700 px, the histories 900 x 1100 px)."""


def _save(fig, path, show):
    # zlib level 1: a third of the default's encoding time for files a few kB larger
    fig.savefig(Path(path), dpi=PNG_DPI, pil_kwargs={"compress_level": 1})
    if show:
        import matplotlib.pyplot as plt

        plt.show()
        plt.close(fig)
