"""What yaw moment at low speed does a model leave unexplained, record by record?

The target is a heading RMS of at most 5 deg over the first 60 s of every shared random and berthing
record, predicted open loop.  Those first minutes are spent at 0.05-0.2 m/s, where the hull's yaw damping
is weak: a yaw acceleration the model does not predict is integrated twice, little damped.  An
unexplained constant yaw acceleration a [deg/s^2] from the start gives, undamped, a heading error
a t^2 / 2, whose RMS over the first T seconds is a T^2 / (2 sqrt 5): 5 deg over 60 s is a = 0.0062 deg/s^2.
With the yaw damping of a first-order response of time constant T_r the yaw-rate error settles at a T_r
and the heading error is a T_r (t - T_r (1 - exp(-t / T_r))); T_r is the model's, at the record's samples:
the yaw inertia (I_z + x_G^2 m + J_z) over -dN/dr (:func:`yaw_time_constant`; the sway coupling of the
mass matrix is left out: it lowers the effective yaw inertia of the 3 m Esso Osaka by 0.5 %).  The mean is
over every qualifying sample of a record, not only those of its first minute: errors of both signs within
a record cancel, and a late slow stretch counts as much as the start.

Per record, over its samples at low speed (U < ``--speed``) with the propeller ahead (n > 3 rps) and the
rudder amidships (|delta| < 5 deg), this prints the logged yaw acceleration (the logged yaw rate
differentiated with a Savitzky-Golay filter, 3.1 s), the model's at the same logged states (hull, propeller,
rudder and the record's wind loads, :func:`mmg.model.forces_of` and :func:`mmg.model.accelerations_of`;
no replay, so no error carried from earlier), their mean difference (the equation error in yaw) and the
heading RMS over 60 s that a constant yaw acceleration of that size would give, undamped and with the
model's yaw damping.  No fitting is done here:
``--ship`` names the model (e.g. ``mmg identify``'s DIR/ship.yaml, fitted on these very records).

    python bench/yaw_residual_check.py [--ship SHIP] [--data DIR] [--records random berthing] [--speed 0.15]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

RUDDER_AMIDSHIPS = math.radians(5.0)
N_AHEAD = 3.0           # rps
WINDOW = 31             # samples of the derivative filter (3.1 s at 10 Hz)
HORIZON = 60.0          # s


def heading_rms_of(a_degps2: float, horizon: float = HORIZON) -> float:
    """Heading RMS [deg] over ``horizon`` s of an undamped constant yaw acceleration ``a_degps2`` from rest:
    the RMS of a t^2 / 2 over [0, T] is |a| T^2 / (2 sqrt 5)."""
    return abs(a_degps2) * horizon ** 2 / (2.0 * math.sqrt(5.0))


def heading_rms_damped(a_degps2: float, t_r: float, horizon: float = HORIZON, n: int = 6000) -> float:
    """Heading RMS [deg] over ``horizon`` s of a constant yaw acceleration ``a_degps2`` from rest through a
    first-order yaw response of time constant ``t_r`` [s] (module docstring); undamped for t_r = inf."""
    if not np.isfinite(t_r) or t_r <= 0:
        return heading_rms_of(a_degps2, horizon)
    t = (np.arange(n) + 0.5) * (horizon / n)
    psi = a_degps2 * t_r * (t - t_r * (-np.expm1(-t / t_r)))
    return float(np.sqrt(np.mean(psi ** 2)))


def yaw_time_constant(ship, run, sel) -> float:
    """The model's yaw time constant [s] at the logged states ``sel`` of ``run``: the yaw inertia about
    midship (I_z + x_G^2 m + J_z) over the mean of -dN/dr (central difference of :func:`mmg.model.forces_of`'s
    yaw moment in r, 1e-4 rad/s); inf where that damping is not positive."""
    from mmg.model import P_IZ, P_JZ, P_M, P_XG, forces_of, pack

    pk = pack(ship)
    args, p = pk.args(), pk.p
    m, inp, h = run.meas, run.inputs, 1e-4
    d = [(forces_of(m[i, 0], m[i, 1], m[i, 2] + h, inp.delta[i], inp.n[i], *args)[2]
          - forces_of(m[i, 0], m[i, 1], m[i, 2] - h, inp.delta[i], inp.n[i], *args)[2]) / (2 * h)
         for i in np.flatnonzero(sel)]
    damping = -float(np.mean(d))
    inertia = p[P_IZ] + p[P_XG] ** 2 * p[P_M] + p[P_JZ]
    return inertia / damping if damping > 0 else float("inf")


def model_yaw_acceleration(ship, run) -> np.ndarray:
    """The model's yaw acceleration [rad/s^2] at each logged state of ``run`` (its wind loads included)."""
    from mmg.model import accelerations_of, forces_of, pack

    pk = pack(ship)
    args = pk.args()
    m, inp = run.meas, run.inputs
    ext = inp.external()
    out = np.empty(len(m))
    for i in range(len(m)):
        u, v, r = m[i, 0], m[i, 1], m[i, 2]
        X, Y, N, _ = forces_of(u, v, r, inp.delta[i], inp.n[i], *args)
        out[i] = accelerations_of(X + ext[i, 0], Y + ext[i, 1], N + ext[i, 2], u, v, r, pk.p)[2]
    return out


def record_row(ship, path: Path, speed: float) -> dict | None:
    """The figures of one record (module docstring); None when no sample qualifies."""
    from scipy.signal import savgol_filter

    from trials.files.logio import read_record
    from trials.measured.predict import measured_run

    run = measured_run(ship, read_record(path, length_m=ship.particulars.L))
    t, m, inp = run.t, run.meas, run.inputs
    rdot = savgol_filter(m[:, 2], WINDOW, 2, deriv=1, delta=float(np.median(np.diff(t))))
    sel = ((np.hypot(m[:, 0], m[:, 1]) < speed) & (inp.n > N_AHEAD) & (np.abs(inp.delta) < RUDDER_AMIDSHIPS)
           & np.isfinite(rdot))
    sel[: WINDOW // 2] = sel[-(WINDOW // 2):] = False          # the filter's ends
    if sel.sum() < WINDOW:
        return None
    model = model_yaw_acceleration(ship, run)
    logged, pred = float(np.degrees(rdot[sel].mean())), float(np.degrees(model[sel].mean()))
    t_r = yaw_time_constant(ship, run, sel)
    return {"name": path.stem, "samples": int(sel.sum()), "logged": logged, "model": pred, "error": pred - logged,
            "speed": float(np.mean(np.hypot(m[sel, 0], m[sel, 1]))), "t_r": t_r,
            "heading_rms_60s": heading_rms_of(pred - logged), "heading_rms_60s_damped": heading_rms_damped(pred - logged, t_r)}


def main(argv=None) -> int:
    from mmg.ship import load_ship
    from trials.files.data import frt_folder

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", default="esso_osaka_3m")
    ap.add_argument("--data", type=Path, default=None)
    ap.add_argument("--records", nargs="+", default=["random", "berthing"],
                    choices=("turning", "zigzag", "random", "berthing"))
    ap.add_argument("--speed", type=float, default=0.15, help="largest speed U [m/s] of the samples used")
    a = ap.parse_args(argv)
    data = a.data or frt_folder()
    files = [p for s in a.records for p in sorted((Path(data) / s).glob("*.csv"))] if data else []
    if not files:
        print(f"no records under {data}", file=sys.stderr)
        return 2
    ship = load_ship(a.ship)
    print(f"model {a.ship}; samples with U < {a.speed:g} m/s, n > {N_AHEAD:g} rps, |delta| < 5 deg")
    print("| record | samples | mean U [m/s] | yaw acceleration logged [deg/s^2] | model | model - logged | "
          "model's T_r [s] | heading RMS over 60 s of that error, undamped / damped [deg] |")
    print("|---|---|---|---|---|---|---|---|")
    rows = [x for x in (record_row(ship, f, a.speed) for f in files) if x is not None]
    for x in rows:
        print(f"| {x['name']} | {x['samples']} | {x['speed']:.3f} | {x['logged']:+.4f} | {x['model']:+.4f} | "
              f"{x['error']:+.4f} | {x['t_r']:.1f} | {x['heading_rms_60s']:.1f} / {x['heading_rms_60s_damped']:.1f} |")
    if rows:
        e = np.array([x["error"] for x in rows])
        print(f"model - logged over {len(rows)} records: mean {e.mean():+.4f}, sd {e.std(ddof=1) if len(e) > 1 else 0:.4f}, "
              f"median |.| {np.median(np.abs(e)):.4f} deg/s^2; {int(np.sum(np.abs(e) <= 0.0062))} of {len(e)} within "
              f"the 0.0062 deg/s^2 that 5 deg over 60 s allows undamped; "
              f"{sum(x['heading_rms_60s_damped'] <= 5.0 for x in rows)} of {len(rows)} give at most 5 deg damped")
    return 0


if __name__ == "__main__":
    sys.exit(main())
