"""The augmented EKF of :mod:`ekf.filter` as a filterpy ``ExtendedKalmanFilter`` a user can step.

Its own module so that the compiled path (:func:`ekf.filter.run_filter`) does not import filterpy,
which pulls scipy.stats (~0.4 s of start-up).  ``ekf.AugmentedEKF`` and
``from ekf.filter import AugmentedEKF`` still work: both import this module on first use.
"""
from __future__ import annotations

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter

from mmg.model import PackedShip

from .propagate import NS, propagate_jacobian


class AugmentedEKF(ExtendedKalmanFilter):
    """filterpy's EKF with the MMG propagation: ``predict((delta0, delta1))``, then filterpy's ``update``.

    This is the filter a user steps by hand (``x``, ``P``, ``F``, ``Q``, ``R`` explicit, as
    filterpy has them); :func:`ekf.filter.run_filter` is its compiled fast path over a whole record and
    gives the same numbers (``tests/test_ekf.py``).

    Parameters
    ----------
    packed : PackedShip
        K_Q-calibrated, from :func:`mmg.simulation.prepare`.
    slots : array of int
        Indices of the m estimated coefficients in ``packed.hull_coef`` (:func:`ekf.data.hull_slots`).
    dt : float
        Filter step [s].
    """

    def __init__(self, packed: PackedShip, slots, dt: float = 0.1):
        self.slots = np.asarray(slots, dtype=np.int64)
        nz = NS + len(self.slots)
        super().__init__(dim_x=nz, dim_z=NS)
        self.nz = nz
        self.H = np.hstack([np.eye(NS), np.zeros((NS, nz - NS))])
        self.packed = packed
        self.dt = float(dt)
        self.Q = np.zeros((nz, nz))

    def predict(self, u=(0.0, 0.0)):
        d0, d1 = u
        z = np.asarray(self.x, float).reshape(-1)
        zn = np.empty(self.nz)
        F = np.empty((self.nz, self.nz))
        propagate_jacobian(z, float(d0), float(d1), self.dt, *self.packed.args(), self.slots, zn, F)
        self.F = F
        self.x = zn
        self.P = F @ self.P @ F.T + self.Q
        self.P = 0.5 * (self.P + self.P.T)
        self.x_prior = self.x.copy()
        self.P_prior = self.P.copy()

    def update_uvrn(self, meas):
        """filterpy's (Joseph-form) update with H = [I_4 0]."""
        self.update(np.asarray(meas, float), HJacobian=lambda x: self.H, Hx=lambda x: np.asarray(x)[:NS])
        self.P = 0.5 * (self.P + self.P.T)
