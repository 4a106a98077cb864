"""The check of a trial's approach revolutions: the rpm a file gives must drive the straight run at its
approach speed (:func:`_check_approach_rpm`, within :data:`APPROACH_RPM_TOLERANCE` for a constant-power
engine and :data:`CONSTANT_RPM_FACTOR_MAX` for a constant-rpm motor), with the propeller pushing ahead
(below :func:`zero_thrust_advance_ratio`).
"""
from __future__ import annotations

import numpy as np

from mmg.errors import InputError
from mmg.ship import Ship
from mmg.units import MAX_FROUDE


def _polyval(c, x: float) -> float:
    return float(np.polyval(np.asarray(c, float)[::-1], x))


APPROACH_RPM_TOLERANCE = 0.05
"""How far (relative) a constant-power engine's ``approach.rpm`` may be from the rpm the straight run
at ``approach.speed`` needs (the engine's power is SHP_0 at that speed: the rpm follows from it)."""


CONSTANT_RPM_FACTOR_MAX = 2.0
"""How far (a factor, either way) a constant-rpm motor's ``approach.rpm`` may be from the rpm the straight
run at ``approach.speed`` needs: the MMG-2015 KVLCC2 convention (the model-scale self-propulsion point,
17.95 rps where the model's own straight run at 1.179 m/s needs 11.85 rps) is a factor 1.51; beyond 2 the
ship runs away from its approach during the trial (3000 rpm at 1.179 m/s: 3.58 m/s), so the trial's
approach speed and its metrics would describe another run."""


def zero_thrust_advance_ratio(ship: Ship) -> float:
    """The advance ratio J where the open-water K_T(J) first falls to zero (inf if it never does):
    beyond it the propeller no longer pushes ahead and the K_T, K_Q polynomials are extrapolations."""
    roots = np.roots(np.asarray(ship.propeller.K_T, float)[::-1]) if len(ship.propeller.K_T) > 1 else []
    pos = [float(r.real) for r in roots if abs(r.imag) < 1e-12 and r.real > 0]
    return min(pos) if pos else float("inf")


def _surge(ship: Ship, n: float, effects):
    """du/dt [m/s^2] of the straight run (no drift, rudder amidships) at surge speed u and rpm ``n``, a function of u."""
    from mmg.equilibrium import _accels
    from mmg.model import pack

    pk = pack(ship, 0.0)
    pk = effects.pack(pk, ship) if effects is not None else pk
    return lambda u: _accels(pk, u, 0.0, 0.0, n)[0]


def _check_approach_rpm(src: str, ap, ship: Ship, label: str, u0: float, n0: float, effects) -> None:
    """InputError naming ``approach.rpm`` unless the given rpm can drive the approach at ``approach.speed``.

    * At the approach the propeller must push ahead: its advance ratio J = u (1 - w_P0(u)) / (n D)
      below the zero-thrust J of K_T (a lower rpm, or one of the wrong sign, is refused);
    * a constant-power engine delivers SHP_0(u) at the approach speed, so the rpm is the one the
      straight run needs (within :data:`APPROACH_RPM_TOLERANCE`; the simulator calibrates the
      propeller's torque at it, and a far one would rescale K_Q by the cube of the ratio);
    * a constant-rpm motor holds the rpm: the ship starts at the approach speed and runs up or
      down to the speed that rpm gives (the MMG 2015 convention of a model-scale self-propulsion
      rpm), which must be within :data:`CONSTANT_RPM_FACTOR_MAX` (either way) of the rpm the straight
      run needs and drive it to a speed within the ship's data (Froude number, t_P(u), w_P0(u) in [0, 1)).

    ``effects``: the trial's (:attr:`Trial.effects`), added to the ship's as the simulator adds them."""
    from mmg.equilibrium import straight_run

    es = ship.effect_set().merged(effects)                  # as mmg.simulation.prepare builds them
    es = es if es.items else None
    pr = ship.propeller
    rpm = f"{ap.rpm} ({n0 * 60:.4g} rpm)" if not ap.rpm.strip().endswith("rpm") else ap.rpm
    try:
        need = straight_run(ship, u0, None, True, es).n
    except ValueError:
        return                                               # no straight run at all: the simulator says so
    needs = f"the straight run at {ap.speed} needs {need * 60:.4g} rpm"
    J0, Jz = u0 * (1 - _polyval(pr.w_P0, u0)) / (n0 * pr.D), zero_thrust_advance_ratio(ship)
    if J0 >= Jz:
        raise InputError(src, "approach.rpm", f"{rpm} at {ap.speed} is an advance ratio J = {J0:.3g}, beyond the "
                                              f"zero-thrust J = {Jz:.3g} of {label}'s propeller: it would not push "
                                              f"ahead; {needs} (or write 'solve')")
    if ship.engine.mode == "constant_power":
        if abs(n0 / need - 1) > APPROACH_RPM_TOLERANCE:
            raise InputError(src, "approach.rpm", f"{rpm} cannot hold {ap.speed} with the constant-power engine of "
                                                  f"{label} (its power is SHP_0 at that speed): {needs} (within "
                                                  f"{APPROACH_RPM_TOLERANCE:.0%}; or write 'solve')")
        return
    if not 1 / CONSTANT_RPM_FACTOR_MAX <= n0 / need <= CONSTANT_RPM_FACTOR_MAX:
        raise InputError(src, "approach.rpm", f"{rpm} is {n0 / need:.3g} times the rpm of the straight run at "
                                              f"{ap.speed} with the constant-rpm motor of {label}: {needs}; the ship "
                                              f"would run {'up' if n0 > need else 'down'} from its approach speed "
                                              f"during the trial (at most a factor {CONSTANT_RPM_FACTOR_MAX:g} either "
                                              f"way; or write 'solve')")
    surge = _surge(ship, n0, es)
    top = MAX_FROUDE * np.sqrt(9.81 * ship.particulars.L)
    if surge(top) > 0:
        raise InputError(src, "approach.rpm", f"{rpm} would drive {label} beyond a Froude number of {MAX_FROUDE:g} "
                                              f"({top:.3g} m/s); {needs}")
    lo, hi = u0, top
    if surge(u0) < 0:                                       # slows down: the speed it gives is below u0
        lo, hi = 0.0, u0
        if surge(1e-6 * u0) < 0:
            return                                          # coasts to rest: physical, nothing to check
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if surge(mid) > 0 else (lo, mid)
    u_n = 0.5 * (lo + hi)
    for name, poly in (("t_P", pr.t_P), ("w_P0", pr.w_P0)):
        if not 0.0 <= _polyval(poly, u_n) < 1.0:
            raise InputError(src, "approach.rpm", f"{rpm} drives {label} to {u_n:.4g} m/s, where its {name}(u) is "
                                                  f"{_polyval(poly, u_n):.3g}, outside [0, 1): beyond the propeller "
                                                  f"data; {needs}")
