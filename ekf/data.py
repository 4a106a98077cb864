"""What every estimator takes: one trial's measurements, its ship and how it was run.

The estimators work on arrays and the physics model; they know no file format.  The
trials layer (:mod:`trials.estimates.estimation`) reads a log or simulates a trial and fills a
:class:`TrialData`; everything an estimator needs from a log's header arrives here as
plain SI values in :class:`RecordInfo`, so no estimator parses a header.

The parameters an estimator frees are named from the ship's hull coefficient table
(:func:`estimable_names`), never from a fixed list: the Kijima derivatives of the Esso
Osaka (``Y_beta`` ... ``N_brr``) and the MMG-2015 ones of the KVLCC2 (``Y_v`` ... ``N_rrr``)
alike.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mmg.ship import Ship

PAPER_DERIVATIVES = ("Y_beta", "Y_r", "Y_bb", "Y_rr", "Y_bbr", "Y_brr",
                     "N_beta", "N_r", "N_bb", "N_rr", "N_bbr", "N_brr")
"""The 12 sway/yaw derivatives Rhee & Kim (1999) estimate for the Esso Osaka (Kijima form)."""

LOG_CHANNELS = ("psi", "x", "y", "n")
"""Channels of a sea-trial log the raw-log estimators measure: heading [rad], x north, y east [m], shaft [rps]."""


def estimable_names(ship: Ship) -> tuple[str, ...]:
    """The sway and yaw hull coefficients an estimator frees, in the ship file's order.

    Every coefficient of the Y and N equations except the constant terms (``term: "1"``,
    e.g. ``Y_0``, ``N_0``: asymmetry offsets that a trimmed straight approach cannot
    tell from the trim rudder).  Surge (X) coefficients are kept at the ship file's
    values: Rhee & Kim estimate none, and the approach speed fixes the resistance.

    Parameters
    ----------
    ship : Ship

    Returns
    -------
    tuple of str
    """
    h = ship.hull
    return tuple(n for n, a, t in zip(h.names, h.axes, h.terms) if a in ("Y", "N") and t != "1")


@dataclass(frozen=True)
class RecordInfo:
    """How a record was run, in SI, as its source says (a trial file or a log header).

    Attributes
    ----------
    kind : str
        ``"turning"``, ``"zigzag"``, ``"stype"`` or ``""`` when unknown.
    manoeuvre : dict
        The rudder logic: ``rudder`` [rad] and ``first`` (``"starboard"``/``"port"``),
        plus ``heading`` [rad] (zigzag) or ``switch_heading`` [rad] (S-type).
    trim_rudder : float
        Rudder angle of the steady approach [rad].
    approach_speed : float or None
        u of the steady approach [m/s] (None: take the first logged speed).
    approach_rpm : float or None
        Shaft speed of the approach [rps] (None: take the first logged rpm).
    execute : float
        Time of the turning execute [s].
    noise_std : dict
        Standard deviation of each logged channel of :data:`LOG_CHANNELS` (psi [rad], x, y [m], n [rps]).
    """

    kind: str = ""
    manoeuvre: dict = field(default_factory=dict)
    trim_rudder: float = 0.0
    approach_speed: float | None = None
    approach_rpm: float | None = None
    execute: float = 0.0
    noise_std: dict = field(default_factory=dict)

    def sigma(self) -> np.ndarray:
        """Noise std of :data:`LOG_CHANNELS` as an array (psi, x, y, n)."""
        return np.array([float(self.noise_std[c]) for c in LOG_CHANNELS])


@dataclass
class TrialData:
    """What an estimator needs for one trial, and the truth when it is known.

    Attributes
    ----------
    name : str
        Trial name (keys the R table of the estimation config).
    meas : ekf.preprocess.Measurements
        The 0.1 s measurements recovered from the log (Rhee & Kim section 4.2).
    ship : Ship
    packed : mmg.model.PackedShip
        The K_Q-calibrated packed ship of the approach.
    slots : ndarray of int
        Indices of :attr:`names` in ``packed.hull_coef``.
    reference : dict
        The ship file's hull coefficients (the initial guess is ``scale`` x these).
    names : tuple of str
        The estimated coefficients (:func:`estimable_names` unless chosen).
    info : RecordInfo
    truth : object, optional
        A record of the true states (t, u, v, r, delta, n arrays), when known.
    true_values : dict, optional
        The true coefficients, when known.
    source : str
        Where the data came from (file path or trial file).
    record : object, optional
        The raw log as read (t, x, y, psi, n, U arrays), for the raw-log estimators.
    """

    name: str
    meas: object
    ship: Ship
    packed: object
    slots: np.ndarray
    reference: dict
    names: tuple = PAPER_DERIVATIVES
    info: RecordInfo = field(default_factory=RecordInfo)
    truth: object = None
    true_values: dict | None = None
    source: str = ""
    record: object = None
    joint: bool = False       # a joint record of several trials (no log of its own)


def hull_slots(ship: Ship, names) -> np.ndarray:
    """Indices in the packed ``hull_coef`` of the coefficients ``names`` (in that order).

    Raises
    ------
    KeyError
        Naming the unknown coefficient and the ship's table.
    """
    have = ship.hull.names
    for n in names:
        if n not in have:
            raise KeyError(f"{ship.name} has no hull coefficient {n!r}; its table: {', '.join(have)}")
    return np.array([ship.hull.index(n) for n in names], dtype=np.int64)
