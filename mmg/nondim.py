"""The non-dimensionalisation (primes) of the MMG model, defined once.

Conventions (Rhee & Kim 1999; Yasukawa & Yoshimura 2015), with L the length
between perpendiculars [m], T (written d in MMG 2015) the draught [m], U the
speed through the water [m/s] and rho the water density [kg/m^3]:

=========  ==========================  ===========================
quantity   divided by                  function
=========  ==========================  ===========================
force      1/2 rho L T U^2             :func:`force_scale`
moment     1/2 rho L^2 T U^2           :func:`moment_scale`
mass       1/2 rho L^2 T               :func:`mass_scale`
inertia    1/2 rho L^4 T               :func:`inertia_scale`
yaw rate   U / L  (r' = r L / U)       :func:`r_prime`
velocity   U      (v' = v / U)
=========  ==========================  ===========================

Every module converts through these functions; none writes the factors again.
They are numba-compiled so the integrator can call them at full speed, and
they work on plain floats from Python as well.
"""
from __future__ import annotations

from ._jit import njit


@njit(cache=True, inline="always")
def force_scale(rho, L, T, U):
    """1/2 rho L T U^2 [N]: multiplies a primed force."""
    return 0.5 * rho * L * T * U * U


@njit(cache=True, inline="always")
def moment_scale(rho, L, T, U):
    """1/2 rho L^2 T U^2 [N m]: multiplies a primed yaw moment."""
    return 0.5 * rho * L * L * T * U * U


@njit(cache=True, inline="always")
def mass_scale(rho, L, T):
    """1/2 rho L^2 T [kg]: multiplies a primed mass (m', m_x', m_y')."""
    return 0.5 * rho * L * L * T


@njit(cache=True, inline="always")
def inertia_scale(rho, L, T):
    """1/2 rho L^4 T [kg m^2]: multiplies a primed yaw inertia (I_zG', J_z')."""
    return 0.5 * rho * L * L * L * L * T


@njit(cache=True, inline="always")
def r_prime(r, L, U):
    """Non-dimensional yaw rate r' = r L / U (r in rad/s, L in m, U in m/s)."""
    return r * L / U
