"""The classical fourth-order Runge-Kutta step every compiled integrator of :mod:`mmg` takes."""
from __future__ import annotations

from ._jit import njit

__all__ = ["rk4_step", "NODES", "WEIGHTS"]

NODES = (0.0, 0.5, 0.5, 1.0)
"""Where in the step each of the four stages is taken (fraction of ``dt``)."""
WEIGHTS = (1.0, 2.0, 2.0, 1.0)
"""The stages' weights (times ``dt / 6``)."""


@njit(cache=True, error_model="numpy", inline="always")
def rk4_step(f, axpy, zero, xs, dt, args):
    """One classical RK4 step of length ``dt`` from the state ``xs`` (a tuple of floats): the one
    integrator step of the simulator (:func:`mmg.kernel.simulate_kernel`, 8 states), the replay
    (:mod:`mmg.replay`, 6), the steering gear of a rebuilt rudder (:func:`mmg.rudder.reconstruct_rudder`, 1)
    and the filters' step (:func:`ekf.kernels.rk4_step`, 8, real or complex).

    ``f(y, tau, args)`` is the right-hand side at the stage state ``y`` and the stage's fraction
    ``tau`` of the step (0, 1/2, 1/2, 1: where inputs that vary within the step are taken), as a
    tuple like ``xs``; ``args`` its other arguments (a tuple); ``axpy(a, c, b)`` = a + c b of two
    such tuples and ``zero`` the zero one (the state's length: each caller keeps only its own states
    in scalars, i.e. registers).  The stage derivatives are summed with the RK4 weights (:data:`WEIGHTS`,
    at :data:`NODES`) as they come."""
    k = zero
    acc = k
    for s in range(4):
        tau = NODES[s]
        y = axpy(xs, tau * dt, k)
        k = f(y, tau, args)
        acc = axpy(acc, WEIGHTS[s], k)
    return axpy(xs, dt / 6.0, acc)
