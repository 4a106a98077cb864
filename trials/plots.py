"""Figures users look at: tracks with ship outlines and time histories (PNG)."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from mmg.units import DEG, KNOT  # noqa: E402


def ship_outline(x, y, psi, L, B):
    """Polygon (north, east) of a simple hull plan (parallel body, pointed bow) at midship x, y."""
    s = np.array([-0.5, 0.35, 0.5, 0.35, -0.5, -0.5]) * L
    b = np.array([-0.5, -0.5, 0.0, 0.5, 0.5, -0.5]) * B
    c, sn = np.cos(psi), np.sin(psi)
    return x + s * c - b * sn, y + s * sn + b * c


def plot_track(t, x, y, psi, L, B, title, path, every_s=None, show=False):
    """Track (east right, north up) in ship lengths with outlines every ``every_s`` seconds."""
    fig, ax = plt.subplots(figsize=(7, 7))
    ax.plot(y / L, x / L, "b-", lw=1, label="midship track")
    every_s = every_s or max(60.0, (t[-1] - t[0]) / 25)
    for tk in np.arange(t[0], t[-1] + 1e-9, every_s):
        i = min(int(np.searchsorted(t, tk)), len(t) - 1)
        px, py = ship_outline(x[i], y[i], psi[i], L, B)
        ax.fill(py / L, px / L, fc="0.8", ec="k", lw=0.6)
    ax.set_aspect("equal")
    ax.set_xlabel("y, east (L)")
    ax.set_ylabel("x, north (L)")
    ax.set_title(f"{title}: track (L = {L:g} m)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    _save(fig, path, show)


def plot_histories(t, psi, delta, r, U, n, title, path, delta_order=None, show=False):
    """Heading, rudder, yaw rate, speed and rpm against time."""
    fig, axs = plt.subplots(5, 1, figsize=(9, 11), sharex=True)
    axs[0].plot(t, psi / DEG, "b")
    axs[0].set_ylabel("heading ψ (deg)")
    axs[1].plot(t, delta / DEG, "r", label="rudder δ")
    if delta_order is not None:
        axs[1].plot(t, delta_order / DEG, "k--", lw=0.8, label="order δ*")
        axs[1].legend(loc="best")
    axs[1].set_ylabel("rudder (deg)")
    axs[2].plot(t, r / DEG, "g")
    axs[2].set_ylabel("yaw rate r (deg/s)")
    axs[3].plot(t, U / KNOT, "m")
    axs[3].set_ylabel("speed U (kn)")
    axs[4].plot(t, n * 60, "k")
    axs[4].set_ylabel("propeller n (rpm)")
    axs[4].set_xlabel("time t (s)")
    for a in axs:
        a.grid(True, alpha=0.3)
    axs[0].set_title(f"{title}: time histories")
    fig.tight_layout()
    _save(fig, path, show)


def _save(fig, path, show):
    fig.savefig(Path(path), dpi=110)
    if show:
        plt.show()
    plt.close(fig)
