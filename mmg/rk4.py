"""The classical fourth-order Runge-Kutta step every compiled integrator of :mod:`mmg` takes."""
from __future__ import annotations

from ._jit import njit

__all__ = ["rk4_step"]


@njit(cache=True, error_model="numpy", inline="always")
def rk4_step(f, axpy, zero, xs, dt, args):
    """One classical RK4 step of length ``dt`` from the state ``xs`` (a tuple of floats): the one
    integrator step of the simulator (:func:`mmg.kernel.simulate_kernel`, 8 states), the replay
    (:mod:`mmg.replay`, 6) and the steering gear of a rebuilt rudder (:func:`mmg.rudder.reconstruct_rudder`, 1).

    ``f(y, tau, args)`` is the right-hand side at the stage state ``y`` and the stage's fraction
    ``tau`` of the step (0, 1/2, 1/2, 1: where inputs that vary within the step are taken), as a
    tuple like ``xs``; ``args`` its other arguments (a tuple); ``axpy(a, c, b)`` = a + c b of two
    such tuples and ``zero`` the zero one (the state's length: each caller keeps only its own states
    in scalars, i.e. registers).  The stage derivatives are summed with the RK4 weights as they come."""
    k = zero
    acc = k
    for s in range(4):
        tau = 0.0 if s == 0 else (0.5 if s < 3 else 1.0)
        y = axpy(xs, tau * dt, k)
        k = f(y, tau, args)
        acc = axpy(acc, 1.0 if (s == 0 or s == 3) else 2.0, k)
    return axpy(xs, dt / 6.0, acc)
