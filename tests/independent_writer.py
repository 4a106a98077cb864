"""The independent writer of ``mmg diagnose``'s test records, shared by the tests that use it.

The records are NOT made by :mod:`mmg.effects` (the code the diagnosis inverts): the clean ship is
simulated by :func:`mmg.simulation.simulate`, and each effect is applied afterwards by the plain
formulas of :func:`log`, in the conventions of ``../shared/data/diagnose-dev/README.md``:

* current ``c`` setting towards ``chi`` (clockwise from north; x north, y east): the simulation in
  still water is the motion relative to the water; over ground x += c cos(chi) t, y += c sin(chi) t,
  and the logged u, v are the over-ground velocity resolved in the heading axes;
* heading bias ``b``: logged heading = true + b, logged u, v = the over-ground velocity resolved in
  the logged heading's axes, positions right;
* rudder offset ``o``: the blade sits o to starboard of the indicator: the ship is simulated with
  the actual blade angle, the indicator logs actual - o (a zigzag: the helm orders +-a on the
  indicator, so the blade is at +-a + o);
* noise: uniform, independent per sample, seeded (the dev set's half-widths, Froude-scaled).

:func:`mirror` turns a written record into its port <-> starboard mirror image about a heading.
"""
import math
from dataclasses import replace

import numpy as np
import pandas as pd

G = 9.80665
DT = 0.2                     # logged sampling step [s] of the 3 m model records
DT_SIM = 0.02                # integration step [s]
TURN_S, ZIGZAG_S = 120.0, 160.0   # record lengths [sqrt(L/g)]


def angdiff(a_deg, b_deg):
    """a - b [deg] wrapped to [-180, 180)."""
    return (a_deg - b_deg + 180.0) % 360.0 - 180.0


def load_config():
    """The 3 m Esso Osaka model's config."""
    from mmg.resources import ship_path
    from mmg.ship import load_ship

    return load_ship(ship_path("esso_osaka_3m"))


def truth_ship(config):
    """The ship that makes the records: a few hull coefficients 5 % off the config's."""
    h = config.hull
    moved = {"Y_beta": 1.05, "N_r": 1.05, "Y_r": 0.95, "N_beta": 0.95, "Y_bb": 1.05, "N_rr": 0.95}
    vals = tuple(v * moved.get(n, 1.0) for n, v in zip(h.names, h.values))
    return replace(config, hull=replace(h, values=vals))


def without_hand(ship):
    """``ship`` with no preference for either hand: its hull's side force and yaw moment at zero drift
    and yaw (``Y_0``, ``N_0``, and any other even term, whose term is 1), its propeller walk
    (``Y_P_astern``) at zero and its rudder's flow straightening equal for either sign of the inflow
    angle (both at their mean).  The hull's remaining terms are odd in (beta, r) (checked: a term
    whose sign does not flip with beta and r is refused)."""
    h = ship.hull
    even = [n for n, ax, t in zip(h.names, h.axes, h.terms) if ax in ("Y", "N") and t == "1"]
    odd = ("beta", "r", "v", "beta|beta|", "r|r|", "beta^2*r", "beta*r^2", "v^3", "v^2*r", "v*r^2", "r^3", "v|v|",
           "v*cos(beta)", "r*cos(beta)", "int(|v+x*r|*(v+x*r))", "int(x*|v+x*r|*(v+x*r))")
    left = [n for n, ax, t in zip(h.names, h.axes, h.terms) if ax in ("Y", "N") and t != "1" and t not in odd]
    if left:
        raise ValueError(f"hull terms of unknown hand symmetry: {left}")
    ru = ship.rudder
    g = 0.5 * (ru.gamma_R_pos + ru.gamma_R_neg)
    return replace(ship, hull=h.with_values({n: 0.0 for n in even}),
                   propeller=replace(ship.propeller, Y_P_astern=0.0),
                   rudder=replace(ru, gamma_R_pos=g, gamma_R_neg=g))


def speed(ship):
    """The approach speed [m/s]: Froude number 0.09."""
    return 0.09 * math.sqrt(G * ship.particulars.L)


def simulate(ship, order_t, order_delta, T, wind=None):
    """The clean ship in still water under a rudder schedule (actual blade orders); ``wind``: a steady
    true wind (speed [m/s], from [deg clockwise from north]) with the ship's published (Fujiwara) loads,
    written straight into the compiled model's wind slots (:func:`mmg.model.wind_loads`)."""
    from mmg.integrate import CommandLaw, integrate
    from mmg.simulation import SimulationResult, prepare
    from mmg.simulation import simulate as still_air

    law = CommandLaw.schedule(order_t, order_delta)
    if wind is None:
        return still_air(ship, law, T, DT_SIM, speed(ship), trim=False)
    pk, eq = prepare(ship, speed(ship), trim=False)          # what simulate does, with the wind's slots set
    t, states, orders, done = integrate(_with_wind(pk, ship, *wind), eq.state(), law, T, DT_SIM)
    return SimulationResult(t, states, orders, eq, done, ship.name)


def _with_wind(pk, ship, V, from_deg):
    """The packed ship with a steady true wind in :func:`mmg.model.wind_loads`'s slots."""
    import mmg.model as M
    from mmg.wind import RHO_AIR, amplitude_vector

    g = ship.wind.particulars()
    p = pk.p.copy()
    p[M.P_WIND_V], p[M.P_WIND_FROM], p[M.P_WIND_Q] = V, math.radians(from_deg), 0.5 * RHO_AIR
    p[M.P_WIND_AT], p[M.P_WIND_AL], p[M.P_WIND_ALL] = g.A_T, g.A_L, g.A_L * g.L
    p[M.P_WIND_AMP:M.P_WIND_AMP + M.N_WIND_AMP] = amplitude_vector(g)
    return replace(pk, p=p)


def turn(ship, rudder_deg, T, wind=None):
    """A turn: blade 0 in the approach, ``rudder_deg`` (+ starboard) from 5 sqrt(L/g) on (actual angles)."""
    s = math.sqrt(ship.particulars.L / G)
    a = math.radians(rudder_deg)
    t1 = 5.0 * s
    return simulate(ship, [0.0, t1, t1 + 1e-6, T], [0.0, 0.0, a, a], T, wind)


def zigzag(ship, rudder_deg, heading_deg, offset_deg, T, first=1.0, wind=None):
    """A zigzag steered on the indicator: the helm orders +-a there, the blade goes to +-a + o; the
    order reverses when the (true) heading passes +-heading_deg.  ``first``: +1 starboard first, -1
    port first.  Built by re-simulating with the reversal times found so far (the schedule is the
    helm's, the simulator only integrates)."""
    s = math.sqrt(ship.particulars.L / G)
    a, o, lim = math.radians(rudder_deg), math.radians(offset_deg), math.radians(heading_deg)
    t0 = 5.0 * s
    switches = []                                   # reversal times

    def table():
        # before the execute the helm holds the indicator at -o (blade at 0: a straight approach)
        side = float(np.sign(first))
        ts, ds = [0.0, t0, t0 + 1e-6], [0.0, 0.0, side * a + o]
        for tk in switches:
            ts += [tk, tk + 1e-6]
            ds += [side * a + o, -side * a + o]
            side = -side
        ts.append(T)
        ds.append(side * a + o)
        return ts, ds, side

    while True:
        ts, ds, side = table()
        sim = simulate(ship, ts, ds, T, wind)
        psi = sim.states[:, 5]
        after = sim.t > (switches[-1] if switches else t0) + 1e-9
        hit = np.nonzero(after & ((psi >= lim) if side > 0 else (psi <= -lim)))[0]
        if not len(hit):
            return sim
        switches.append(float(sim.t[hit[0]]))


def log(ship, sim, *, current=None, bias_deg=0.0, offset_deg=0.0, wind=None, seed=0, noise=True):
    """Sample the simulation every DT and log it with the effects and noise (plain formulas); ``wind``:
    the steady true wind the simulation had (speed [m/s], from [deg]), logged as it is and as the
    apparent wind at midship (the true wind's velocity minus the ship's over ground, in the ship's
    axes; its direction the one it comes from, from the bow, clockwise)."""
    L = ship.particulars.L
    lam = 325.0 / L                                       # Froude scale of the dev set's noise
    t = np.arange(0.0, sim.t[-1] + 1e-9, DT)
    i = np.minimum(np.searchsorted(sim.t, t - 1e-9), len(sim.t) - 1)
    u, v, r, x, y, psi, delta, n = (sim.states[i, j] for j in range(8))
    # earth-frame velocity through the water (x north, y east)
    xd = u * np.cos(psi) - v * np.sin(psi)
    yd = u * np.sin(psi) + v * np.cos(psi)
    if current is not None:
        c, chi = current[0], math.radians(current[1])
        xd, yd = xd + c * math.cos(chi), yd + c * math.sin(chi)
        x, y = x + c * math.cos(chi) * t, y + c * math.sin(chi) * t
    psi_log = psi + math.radians(bias_deg)
    u_log = xd * np.cos(psi_log) + yd * np.sin(psi_log)
    v_log = -xd * np.sin(psi_log) + yd * np.cos(psi_log)
    delta_log = delta - math.radians(offset_deg)
    wv, wd, wr, wg = _wind_channels(wind, xd, yd, psi)
    rng = np.random.default_rng(seed)
    uni = (lambda h: rng.uniform(-h, h, len(t))) if noise else (lambda h: 0.0 * t)   # noqa: E731
    vel = 0.02 / math.sqrt(lam)
    return pd.DataFrame({
        "t [s]": t,
        "x_position_mid [m]": x + uni(0.5 / lam),
        "u_velo [m/s]": u_log + uni(vel),
        "y_position_mid [m]": y + uni(0.5 / lam),
        "vm_velo [m/s]": v_log + uni(vel),
        "psi_hat [rad]": np.mod(psi_log + uni(math.radians(0.05)) + math.pi, 2 * math.pi) - math.pi,
        "r_angvelo [rad/s]": r + uni(0.0002 * math.sqrt(lam)),
        "n_prop [rps]": n,
        "delta_rudder [rad]": delta_log,
        "wind_velo_relative_mid [m/s]": wr,
        "wind_dir_relative_mid [rad]": wg,
        "wind_velo_true [m/s]": wv,
        "wind_dir_true [rad]": wd,
    })


def _wind_channels(wind, xd, yd, psi):
    """(true speed, true from-direction, apparent speed, apparent from-direction off the bow), arrays."""
    z = 0.0 * psi
    if wind is None:
        return z, z, z, z
    V, frm = wind[0], math.radians(wind[1])
    an, ae = -V * math.cos(frm) - xd, -V * math.sin(frm) - yd          # apparent air velocity, north/east
    ax = an * np.cos(psi) + ae * np.sin(psi)
    ay = -an * np.sin(psi) + ae * np.cos(psi)
    return z + V, z + frm % (2 * math.pi), np.hypot(ax, ay), np.mod(np.arctan2(-ay, -ax), 2 * math.pi)


def records(tmp_path, ship, kinds=("turn", "zigzag"), zigzag_s=ZIGZAG_S, turn_s=TURN_S, **effects):
    """Write the records (35 deg starboard turn of ``turn_s``, 20/20 zigzag of ``zigzag_s`` sqrt(L/g))
    with ``effects`` as FRT-DS-ESSO CSVs; returns their paths."""
    s = math.sqrt(ship.particulars.L / G)
    off = effects.get("offset_deg", 0.0)
    paths = []
    for k, kind in enumerate(kinds):
        if kind == "turn":
            sim = turn(ship, 35.0, turn_s * s, wind=effects.get("wind"))
        else:
            sim = zigzag(ship, 20.0, 20.0, off, zigzag_s * s, wind=effects.get("wind"))
        p = tmp_path / f"{kind}.csv"
        log(ship, sim, seed=k + 1, **effects).to_csv(p, index=False)
        paths.append(p)
    return paths


# --------------------------------------------------------------------------- the mirror image

MIRROR_NEGATED = ("vm_velo [m/s]", "r_angvelo [rad/s]", "delta_rudder [rad]")
"""Columns of a record that change sign in its port <-> starboard mirror image: sway, yaw rate and
rudder angle (+ starboard); the relative wind's direction (from the bow, clockwise) too, in [0, 2 pi)."""


def _wrap(a):
    return np.mod(np.asarray(a, float) + math.pi, 2 * math.pi) - math.pi


def mirror(frame, about_deg=0.0):
    """The port <-> starboard mirror image of a written record about the heading ``about_deg``
    (clockwise from north; the approach heading): headings and the true wind's direction psi ->
    2 about - psi; positions reflected in the line through the origin along ``about_deg``; sway,
    yaw rate, rudder angle (:data:`MIRROR_NEGATED`) and the relative wind's direction negated;
    surge, revolutions, times and wind speeds as they are."""
    a = math.radians(about_deg)
    out = frame.copy()
    for c in MIRROR_NEGATED:
        out[c] = -frame[c]
    out["psi_hat [rad]"] = _wrap(2 * a - frame["psi_hat [rad]"])
    out["wind_dir_relative_mid [rad]"] = np.mod(-frame["wind_dir_relative_mid [rad]"], 2 * math.pi)
    out["wind_dir_true [rad]"] = np.mod(2 * a - frame["wind_dir_true [rad]"], 2 * math.pi)
    x, y = frame["x_position_mid [m]"].to_numpy(), frame["y_position_mid [m]"].to_numpy()
    along = x * math.cos(a) + y * math.sin(a)
    across = -x * math.sin(a) + y * math.cos(a)
    out["x_position_mid [m]"] = along * math.cos(a) + across * math.sin(a)
    out["y_position_mid [m]"] = along * math.sin(a) - across * math.cos(a)
    return out
