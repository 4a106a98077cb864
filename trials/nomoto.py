"""Linear Nomoto steering models and their identification from zigzag tests.

Everything here is in the fully dimensionless form of Artyszuk (2018), "A study
on the identification of the second-order linear Nomoto model from the zigzag
test", Sci. J. Maritime Univ. Szczecin 53(125), 59-67:

* s' = t U / L            dimensionless distance (ship lengths travelled), eq. (2)
* omega' = dpsi/ds' = r L / U          dimensionless yaw rate, eq. (3)
* eps' = domega'/ds' = rdot L^2 / U^2  dimensionless yaw acceleration, eq. (4)
* Delta(s') = integral_0^s' delta ds'  rudder integral [rad], eq. (6)

Models
    1st order, eq. (1):  T omega'' + omega' = K delta
    2nd order, eq. (13): T1 T2 eps'' + (T1 + T2) eps' ... i.e.
                         T1 T2 domega'^2/ds'^2 + (T1+T2) domega'/ds' + omega'
                             = K (delta + T3 ddelta/ds')

K, T, T1, T2, T3 are dimensionless (T in ship lengths).  Angles are radians,
rudder positive to starboard, heading positive clockwise (to starboard), so a
stable ship has K > 0.

Identification methods (all work on the *integrated* model, eqs. (5)/(14)):

* :func:`classical_first_order` - Nomoto (1960), eqs. (10)-(12), per half-cycle.
* :func:`four_point` - Artyszuk's four-point 2nd-order method, eqs. (15)-(18), (23),
  with the Cramer determinants of his Table 7.
* :func:`fit_least_squares` - eq. (15) fitted to every sample (beyond the paper).
* :func:`fit_output_error` - the ODE simulated with the recorded rudder and fitted
  to the whole heading history (beyond the paper).

This module is pure numerics: it imports neither matplotlib nor the CLI.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Optional, Sequence

import numpy as np
from scipy import linalg, optimize, stats
from scipy.integrate import cumulative_trapezoid, solve_ivp
from scipy.interpolate import make_lsq_spline

from trials.errors import InputError
from trials.records import TrialRecord

Z95 = 1.959963984540054
"""Two-sided 95 % quantile of the standard normal distribution."""


# --------------------------------------------------------------------------- models
@dataclass(frozen=True)
class NomotoModel:
    """Parameters of a linear Nomoto model (dimensionless, distance form).

    Parameters
    ----------
    K : float
        Gain constant [-]: steady dimensionless yaw rate per radian of rudder.
    T1 : float
        First (largest) distance constant [-] (ship lengths).  For a first-order
        model this is Nomoto's T.
    T2 : float
        Second distance constant [-]; 0 for a first-order model.
    T3 : float
        Rudder-rate (zero) distance constant [-]; 0 for a first-order model.
    name : str
        Label used in reports.
    """

    K: float
    T1: float
    T2: float = 0.0
    T3: float = 0.0
    name: str = ""

    @property
    def order(self) -> int:
        """1 when T2 = T3 = 0 (eq. 1), else 2 (eq. 13)."""
        return 1 if (self.T2 == 0.0 and self.T3 == 0.0) else 2

    @property
    def T(self) -> float:
        """Equivalent first-order constant T = T1 + T2 - T3, eq. (26)."""
        return self.T1 + self.T2 - self.T3

    def to_dict(self) -> dict:
        """Plain dict of the parameters (and order)."""
        d = asdict(self)
        d["order"] = self.order
        return d

    def to_pandas(self):
        """The parameters as a one-row DataFrame."""
        import pandas as pd

        return pd.DataFrame([self.to_dict()])


def first_order(K: float, T: float, name: str = "") -> NomotoModel:
    """A first-order model, eq. (1).

    Parameters
    ----------
    K : float
        Gain [-].
    T : float
        Distance constant [-].
    name : str
        Label.
    """
    return NomotoModel(K=float(K), T1=float(T), T2=0.0, T3=0.0, name=name)


def load_model(path) -> NomotoModel:
    """Read a Nomoto model from YAML.

    The file holds ``K`` and either ``T`` (first order) or ``T1``, ``T2``, ``T3``
    (second order), all dimensionless, plus an optional ``name``.

    Parameters
    ----------
    path : str or Path
        YAML file.

    Raises
    ------
    InputError
        Missing, non-numeric or non-finite parameters.
    """
    import yaml

    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as err:
        raise InputError(str(path), "", f"cannot read Nomoto parameters ({err})") from None
    if not isinstance(data, dict):
        raise InputError(str(path), "", "expected a mapping of Nomoto parameters")
    model = data.get("model", data)

    def num(key):
        if key not in model:
            raise InputError(str(path), key, "missing")
        try:
            v = float(model[key])
        except (TypeError, ValueError):
            raise InputError(str(path), key, f"not a number: {model[key]!r}") from None
        if not np.isfinite(v):
            raise InputError(str(path), key, "not finite")
        return v

    name = str(data.get("name", path.stem))
    if "T" in model:
        return first_order(num("K"), num("T"), name=name)
    return NomotoModel(num("K"), num("T1"), num("T2"), num("T3"), name=name)


def zigzag_spec(path) -> dict:
    """Zigzag settings stored next to the model in a YAML file (all optional).

    Keys: ``delta0_deg`` (rudder angle, default 10), ``psi0_deg`` (check heading,
    default = delta0_deg), ``rudder_rate_deg_per_L`` (default 23, Artyszuk's
    reference rate), ``s_max`` (default 14), ``ds`` (output step, default 0.001).

    Parameters
    ----------
    path : str or Path
        YAML file.
    """
    import yaml

    data = yaml.safe_load(Path(path).read_text()) or {}
    z = dict(data.get("zigzag", {}))
    z.setdefault("delta0_deg", 10.0)
    z.setdefault("psi0_deg", z["delta0_deg"])
    z.setdefault("rudder_rate_deg_per_L", 23.0)
    z.setdefault("s_max", 14.0)
    z.setdefault("ds", 0.001)
    return z


# ------------------------------------------------------------------ trapezoidal rudder
def trapezoid_knots(delta0: float, s_R: float, s_cr: Sequence[float]):
    """Knots (s', delta) of the piecewise-linear zigzag rudder.

    The rudder leaves midships at s' = 0 and reaches +delta0 at s'_R (eq. 19);
    at each counter-rudder s'_CRk it starts to move to the opposite side at the
    same rate, taking 2 s'_R.

    Parameters
    ----------
    delta0 : float
        Nominal rudder angle [rad] of the first execute (sign = side).
    s_R : float
        Rudder steering distance s'_R = delta0 / (ddelta/ds') [-], eq. (19).
    s_cr : sequence of float
        Counter-rudder abscissas s'_CR1, s'_CR2, ... [-], increasing.
    """
    ks, kd = [0.0, s_R], [0.0, delta0]
    side = 1.0
    for s in s_cr:
        ks += [float(s), float(s) + 2.0 * s_R]
        kd += [side * delta0, -side * delta0]
        side = -side
    return np.asarray(ks), np.asarray(kd)


def trapezoid_rudder(s, delta0: float, s_R: float, s_cr: Sequence[float]):
    """Rudder angle and its integral Delta(s') for the trapezoidal zigzag rudder.

    Delta is integrated exactly over the piecewise-linear rudder; on the constant
    parts this reduces to Artyszuk's eqs. (20)-(22), e.g. for a 10 deg zigzag
    Delta(s'_R < s' <= s'_CR1) = pi/18 (s' - 0.5 s'_R).

    Parameters
    ----------
    s : array_like
        Dimensionless distances s' >= 0 [-].
    delta0, s_R, s_cr
        See :func:`trapezoid_knots`.

    Returns
    -------
    delta, Delta : ndarray
        Rudder [rad] and its integral [rad] at ``s``.
    """
    s = np.asarray(s, dtype=float)
    ks, kd = trapezoid_knots(delta0, s_R, s_cr)
    # extend the last value flat to infinity
    ks = np.append(ks, max(ks[-1], np.max(s, initial=0.0)) + 1.0)
    kd = np.append(kd, kd[-1])
    delta = np.interp(s, ks, kd)
    area = np.concatenate([[0.0], np.cumsum(0.5 * (kd[1:] + kd[:-1]) * np.diff(ks))])
    i = np.clip(np.searchsorted(ks, s, side="right") - 1, 0, len(ks) - 2)
    Delta = area[i] + 0.5 * (kd[i] + delta) * (s - ks[i])
    return delta, Delta


# ------------------------------------------------------------------ simulation
@dataclass(frozen=True)
class ZigzagSimulation:
    """A simulated zigzag in dimensionless distance.

    Attributes
    ----------
    model : NomotoModel
        The model simulated.
    s, psi, omega, eps, delta, Delta : ndarray
        s' [-], heading [rad], omega' [-], eps' [-], rudder [rad], rudder integral [rad].
    s_cr : tuple of float
        Counter-rudder abscissas (heading reached the check angle) [-].
    s_os : tuple of float
        Overshoot abscissas (omega' = 0 after each counter-rudder) [-].
    delta0, psi0, s_R : float
        Rudder angle [rad], check heading [rad], rudder steering distance [-].
    """

    model: NomotoModel
    s: np.ndarray
    psi: np.ndarray
    omega: np.ndarray
    eps: np.ndarray
    delta: np.ndarray
    Delta: np.ndarray
    s_cr: tuple
    s_os: tuple
    delta0: float
    psi0: float
    s_R: float

    def state_at(self, s: float) -> dict:
        """Exact (re-integrated) state at one abscissa: s, eps, omega, Delta, delta, psi."""
        return _exact_states(self, [s])[0]

    def points(self, n: int = 2) -> "ZigzagPoints":
        """The four-point abscissas CR1, OS1, CR2, OS2, ... (exact states), as :class:`ZigzagPoints`."""
        names, ss = [], []
        for k in range(n):
            names += [f"CR{k + 1}", f"OS{k + 1}"]
            ss += [self.s_cr[k], self.s_os[k]]
        rows = _exact_states(self, ss)
        return ZigzagPoints.from_rows(names, rows)

    def to_record(self, L: float = 100.0, U: float = 5.0, name: str = "nomoto-sim") -> TrialRecord:
        """The simulation as a :class:`TrialRecord` for a ship of length L [m] at speed U [m/s]."""
        t = self.s * L / U
        return TrialRecord(
            t=t, name=name, ship=self.model.name or "nomoto", source="simulation",
            psi=self.psi.copy(), r=self.omega * U / L, delta=self.delta.copy(),
            U=np.full_like(t, U), meta={"L": L, "model": self.model.to_dict()},
        )

    def to_pandas(self):
        """Time series as a DataFrame indexed by s'."""
        import pandas as pd

        return pd.DataFrame(
            {"psi": self.psi, "omega": self.omega, "eps": self.eps, "delta": self.delta, "Delta": self.Delta},
            index=pd.Index(self.s, name="s"),
        )

    def to_dict(self) -> dict:
        """Summary: model, zigzag settings and the characteristic abscissas."""
        return {"model": self.model.to_dict(), "delta0": self.delta0, "psi0": self.psi0, "s_R": self.s_R,
                "s_cr": list(self.s_cr), "s_os": list(self.s_os)}


def _rhs(model: NomotoModel):
    """Right-hand side f(s, y, delta, ddelta) with y = (psi, omega[, eps])."""
    K, T1, T2, T3 = model.K, model.T1, model.T2, model.T3
    if model.order == 1:
        return lambda s, y, d, dd: [y[1], (K * d - y[1]) / T1]
    a, b = T1 * T2, T1 + T2
    return lambda s, y, d, dd: [y[1], y[2], (K * (d + T3 * dd) - y[1] - b * y[2]) / a]


def _eps_of(model: NomotoModel, y, d):
    """eps' from the state (1st order: (K delta - omega')/T)."""
    if model.order == 1:
        return (model.K * d - y[1]) / model.T1
    return y[2]


def simulate_zigzag(model: NomotoModel, delta0_deg: float = 10.0, psi0_deg: Optional[float] = None,
                    rudder_rate_deg_per_L: float = 23.0, s_max: float = 14.0, ds: float = 0.001,
                    n_cr: int = 8, rtol: float = 1e-11, atol: float = 1e-13) -> ZigzagSimulation:
    """Simulate a delta0/psi0 zigzag with a trapezoidal rudder.

    At s' = 0 the ship runs straight (psi = omega' = eps' = 0) and the rudder
    starts to move to +delta0 at the given rate; whenever the heading reaches the
    check angle on the side the rudder points to, the rudder is reversed at the
    same rate (counter-rudder).  Integration is adaptive (``solve_ivp``, DOP853)
    piece by piece between the rudder's knots, with the heading events located
    exactly; the output is then sampled every ``ds``.

    Parameters
    ----------
    model : NomotoModel
        Model to simulate (first or second order).
    delta0_deg : float
        Rudder angle [deg], e.g. 10 for a 10/10 zigzag.
    psi0_deg : float, optional
        Check heading [deg]; defaults to ``delta0_deg``.
    rudder_rate_deg_per_L : float
        Rudder rate [deg per ship length travelled]; Artyszuk uses 23 deg/L.
    s_max : float
        Length of the run [-] (ship lengths).
    ds : float
        Output sampling step in s' [-]; the paper interpolates to 0.001.
    n_cr : int
        Maximum number of counter-rudders.
    rtol, atol : float
        Integrator tolerances.
    """
    if psi0_deg is None:
        psi0_deg = delta0_deg
    d0, p0 = np.radians(delta0_deg), np.radians(psi0_deg)
    s_R = delta0_deg / rudder_rate_deg_per_L
    rate = d0 / s_R
    f = _rhs(model)
    y = np.zeros(2 if model.order == 1 else 3)
    s0, dstart, side = 0.0, 0.0, 1.0
    pieces, s_cr, s_os = [], [], []
    # ramp 0 -> +delta0 then hold; the loop alternates (ramp, hold)
    ramp_to = d0
    while s0 < s_max:
        # ramp from dstart to ramp_to
        L_ramp = abs(ramp_to - dstart) / rate
        dd = np.sign(ramp_to - dstart) * rate
        fun = (lambda dst, ddd, st: (lambda s, yy: f(s, yy, dst + ddd * (s - st), ddd)))(dstart, dd, s0)
        s1 = min(s0 + L_ramp, s_max)
        ev_os = lambda s, yy: yy[1]  # overshoot: omega' changes sign towards the new side
        ev_os.terminal, ev_os.direction = False, side
        sol = solve_ivp(fun, (s0, s1), y, method="DOP853", rtol=rtol, atol=atol, dense_output=True,
                        events=ev_os)
        if s_cr and len(s_os) < len(s_cr) and len(sol.t_events[0]):
            s_os.append(float(sol.t_events[0][0]))
        pieces.append((s0, s1, sol.sol, dstart, dd))
        y, s0 = sol.y[:, -1], s1
        if s0 >= s_max:
            break
        # hold at ramp_to until the heading reaches side*psi0 (the overshoot is omega'=0 on the way)
        hold = ramp_to
        target = side * p0
        ev_cr = (lambda tg: (lambda s, yy: yy[0] - tg))(target)
        ev_cr.terminal, ev_cr.direction = True, side
        ev_os = lambda s, yy: yy[1]
        ev_os.terminal, ev_os.direction = False, side
        fun = (lambda dh: (lambda s, yy: f(s, yy, dh, 0.0)))(hold)
        sol = solve_ivp(fun, (s0, s_max), y, method="DOP853", rtol=rtol, atol=atol,
                        dense_output=True, events=(ev_cr, ev_os))
        pieces.append((s0, sol.t[-1], sol.sol, hold, 0.0))
        if s_cr and len(s_os) < len(s_cr) and len(sol.t_events[1]):
            s_os.append(float(sol.t_events[1][0]))
        y, s0 = sol.y[:, -1], sol.t[-1]
        if len(sol.t_events[0]) == 0 or len(s_cr) >= n_cr:
            break
        s_cr.append(float(sol.t_events[0][0]))
        dstart, ramp_to, side = hold, -hold, -side
    s = np.arange(0.0, s0 + 0.5 * ds, ds)
    s = s[s <= s0 + 1e-12]
    out = np.zeros((len(y), len(s)))
    dl = np.zeros(len(s))
    for (a, b, sol, dst, ddd) in pieces:
        m = (s >= a) & (s <= b)
        if m.any():
            out[:, m] = sol(s[m])
            dl[m] = dst + ddd * (s[m] - a)
    eps = _eps_of(model, out, dl)
    delta, Delta = trapezoid_rudder(s, d0, s_R, s_cr)
    sim = ZigzagSimulation(model=model, s=s, psi=out[0], omega=out[1], eps=eps, delta=delta, Delta=Delta,
                           s_cr=tuple(s_cr), s_os=tuple(s_os), delta0=d0, psi0=p0, s_R=s_R)
    object.__setattr__(sim, "_pieces", pieces)
    return sim


def _exact_states(sim: ZigzagSimulation, ss) -> list:
    """States at arbitrary abscissas from the simulation's dense output."""
    rows = []
    for s in ss:
        for (a, b, sol, dst, ddd) in sim._pieces:  # noqa: SLF001 - set by simulate_zigzag
            if a <= s <= b:
                y = sol(s)
                d = dst + ddd * (s - a)
                break
        else:
            raise ValueError(f"s'={s} outside the simulation")
        _, Delta = trapezoid_rudder([s], sim.delta0, sim.s_R, sim.s_cr)
        rows.append({"s": float(s), "eps": float(_eps_of(sim.model, y, d)), "omega": float(y[1]),
                     "Delta": float(Delta[0]), "delta": float(d), "psi": float(y[0])})
    return rows


# ------------------------------------------------------------- exact linear response
def _state_space(model: NomotoModel):
    """(A, B, C_eps, D_eps) with state (psi, omega', q); q = eps' - b1 delta removes ddelta/ds'.

    For the first-order model the state is (psi, omega').
    """
    K, T1, T2, T3 = model.K, model.T1, model.T2, model.T3
    if model.order == 1:
        A = np.array([[0.0, 1.0], [0.0, -1.0 / T1]])
        B = np.array([0.0, K / T1])
        return A, B, None
    return _state_space_x(K, T1 * T2, T1 + T2, T3)


def _state_space_x(K, x1, x2, T3):
    """State space of eq. (13) from K, x1 = T1 T2, x2 = T1 + T2, T3 (valid for complex T1, T2 too)."""
    T1T2 = x1
    a0, a1 = 1.0 / x1, x2 / x1
    b1, b0 = K * T3 / T1T2, K / T1T2
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, -a0, -a1]])
    B = np.array([0.0, b1, b0 - a1 * b1])
    return A, B, b1


def simulate_response(model: NomotoModel, s, delta, psi0: float = 0.0, omega0: float = 0.0,
                      eps0: float = 0.0, delta_bias: float = 0.0) -> np.ndarray:
    """Heading response [rad] of a Nomoto model to a sampled rudder history.

    The rudder is taken as piecewise linear between samples (first-order hold),
    which is exact for a trapezoidal rudder; the linear ODE is then propagated
    exactly with matrix exponentials, so stiff models (tiny T2) are no problem.

    Parameters
    ----------
    model : NomotoModel or tuple
        Model, or a tuple (K, x1, x2, T3) with x1 = T1 T2, x2 = T1 + T2 (eq. 16),
        which also covers complex T1, T2.
    s : ndarray
        Dimensionless distances [-], increasing.  Non-uniform steps are allowed
        (a matrix exponential is computed per distinct step).
    delta : ndarray
        Rudder [rad] at ``s``.
    psi0, omega0, eps0 : float
        Initial heading [rad], omega' [-] and eps' [-] at ``s[0]`` (eps0 unused for
        a first-order model).
    delta_bias : float
        Neutral rudder angle [rad] (the rudder that keeps the ship straight); the
        model is driven by ``delta - delta_bias``.
    """
    s = np.asarray(s, float)
    u = np.asarray(delta, float) - delta_bias
    A, B, b1 = _state_space_x(*model) if isinstance(model, tuple) else _state_space(model)
    n = A.shape[0]
    x = np.array([psi0, omega0] + ([] if b1 is None else [eps0 - b1 * u[0]]), float)
    out = np.empty((len(s), n))
    out[0] = x
    h = np.diff(s)
    cache = {}
    for k, hk in enumerate(h):
        key = round(float(hk), 12)
        if key not in cache:
            M = np.zeros((n + 2, n + 2))
            M[:n, :n] = A * hk
            M[:n, n] = B * hk
            M[n, n + 1] = 1.0
            E = linalg.expm(M)
            cache[key] = (E[:n, :n], E[:n, n], E[:n, n + 1])
        Phi, G0, G1 = cache[key]
        x = Phi @ x + G0 * u[k] + G1 * (u[k + 1] - u[k])
        out[k + 1] = x
    return out[:, 0]


# ------------------------------------------------------------------ differentiator
def _lsq_spline(x, y, per_knot: int, k: int = 5):
    """Least-squares spline of degree k with uniform knots every ``per_knot`` samples; (spline, GCV)."""
    n = len(x)
    nint = max(1, int(round((n - 1) / per_knot)))
    inner = np.linspace(x[0], x[-1], nint + 1)[1:-1]
    t = np.r_[[x[0]] * (k + 1), inner, [x[-1]] * (k + 1)]
    spl = make_lsq_spline(x, y, t, k=k)
    p = len(t) - k - 1
    rss = float(np.sum((spl(x) - y) ** 2))
    return spl, n * rss / max(n - p, 1) ** 2


def smooth_derivatives(x, y, per_knot: Optional[int] = None):
    """Smoothed signal and its first two derivatives from one quintic regression spline.

    The signal is fitted by least squares with a quintic B-spline on uniform
    knots, the knot spacing (in samples) picked by generalised cross-validation
    from 2, 3, 4, 6, ... 128 samples per knot interval; derivatives are the
    spline's analytic derivatives.  Why this and not Savitzky-Golay or a
    penalised cubic smoothing spline:

    * one smooth curve is differentiated, so omega' and eps' are exactly the
      derivatives of the smoothed heading (the consistency Artyszuk obtained
      with his Bezier fit and that eq. (15) needs); a Savitzky-Golay filter
      gives each sample its own local polynomial, so the derivatives are not
      those of any single curve, and it must be truncated at the record's ends;
    * quintic, so eps' (the second derivative) is still a smooth cubic, and the
      ends are free (a natural cubic smoothing spline, e.g. scipy's
      ``make_smoothing_spline``, forces the second derivative to zero at both
      ends, which is wrong for eps' at the end of a zigzag record);
    * the only tuning, the knot spacing, is chosen by GCV from the data, so the
      same code serves noise-free simulations (dense knots, near interpolation)
      and noisy trial records (wider knots).

    Parameters
    ----------
    x : ndarray
        Abscissa (e.g. s' or t), strictly increasing.
    y : ndarray
        Signal at ``x`` (e.g. heading [rad]).
    per_knot : int, optional
        Fixed samples per knot interval (skip GCV).

    Returns
    -------
    y_s, dy, d2y : ndarray
        Smoothed signal, dy/dx, d2y/dx2 at ``x``.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    cands = [per_knot] if per_knot else [m for m in (2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128)
                                         if (len(x) - 1) / m >= 2] or [max(1, (len(x) - 1) // 2)]
    best = None
    for m in cands:
        try:
            spl, g = _lsq_spline(x, y, m)
        except (ValueError, np.linalg.LinAlgError):
            continue
        if best is None or g < best[1]:
            best = (spl, g)
    if best is None:
        raise InputError("differentiator", "", "cannot fit a spline to the signal (too few or irregular samples)")
    spl = best[0]
    return spl(x), spl.derivative(1)(x), spl.derivative(2)(x)


# ------------------------------------------------------------------ zigzag in s'
@dataclass(frozen=True)
class ZigzagData:
    """A recorded zigzag converted to Artyszuk's dimensionless variables.

    Heading, rudder and their integrals are relative to the first execute
    (s' = 0 there); if the first execute was to port all signs are flipped so
    that the first rudder is positive, as in the paper.

    Attributes
    ----------
    s, psi, omega, eps, delta, Delta : ndarray
        From the first execute to the end of the last zigzag rudder plateau.
        psi, delta are increments from their values at the execute [rad];
        omega', eps' are absolute [-]; Delta = integral of the absolute rudder [rad].
    psi_e, omega_e, eps_e, delta_e : float
        Values at the execute (initial state for simulations) [rad, -, -, rad].
    sign : float
        +1 or -1, the flip applied.
    L, U : float
        Ship length [m] and the speed used for s' [m/s].
    t_execute : float
        Record time of the execute [s].
    s_cr, s_os, s_z : tuple of float
        Counter-rudder abscissas (rudder leaves a zigzag plateau), overshoot
        abscissas (omega' = 0) and heading zero crossings, [-].
    delta0 : float
        Nominal rudder angle from the plateaus [rad].
    yaw_rate_source : str
        "recorded" or "derived from heading".
    name : str
        Record name.
    psi_raw : ndarray
        Recorded (unsmoothed) heading increment from the execute [rad]; the
        whole-record fits use it, so the smoother cannot bias them.
    """

    s: np.ndarray
    psi: np.ndarray
    omega: np.ndarray
    eps: np.ndarray
    delta: np.ndarray
    Delta: np.ndarray
    psi_e: float
    omega_e: float
    eps_e: float
    delta_e: float
    sign: float
    L: float
    U: float
    t_execute: float
    s_cr: tuple
    s_os: tuple
    s_z: tuple
    delta0: float
    yaw_rate_source: str
    name: str = ""
    psi_raw: Optional[np.ndarray] = None

    def at(self, s: float) -> dict:
        """Linearly interpolated values at one abscissa (psi, delta as increments)."""
        return {"s": float(s), **{k: float(np.interp(s, self.s, getattr(self, k)))
                                  for k in ("eps", "omega", "Delta", "delta", "psi")}}

    def points(self, n: int = 2) -> "ZigzagPoints":
        """Artyszuk's abscissas CR1, OS1, CR2, OS2 (n pairs), omega' = 0 at the overshoots.

        eps' and omega' enter the four-point matrix as increments from the execute,
        which makes eq. (15) exact for a ship that was not yet steady at the execute.
        """
        if len(self.s_cr) < n or len(self.s_os) < n:
            raise InputError(self.name, "heading",
                             f"too short for the four-point method: found {len(self.s_cr)} counter-rudder(s) "
                             f"and {len(self.s_os)} overshoot(s), need {n} of each")
        names, rows = [], []
        for k in range(n):
            for nm, s in ((f"CR{k + 1}", self.s_cr[k]), (f"OS{k + 1}", self.s_os[k])):
                r = self.at(s)
                r["eps"] -= self.eps_e
                r["omega"] = 0.0 if nm.startswith("OS") else r["omega"] - self.omega_e
                names.append(nm)
                rows.append(r)
        return ZigzagPoints.from_rows(names, rows)


def _runs(mask):
    """(start, end_inclusive) index pairs of True runs."""
    m = np.concatenate([[False], mask, [False]]).astype(int)
    d = np.diff(m)
    return list(zip(np.where(d == 1)[0], np.where(d == -1)[0] - 1))


def _check_finite(record: TrialRecord, names):
    src = record.source or record.name or "record"
    for c in names:
        a = getattr(record, c)
        if a is None:
            continue
        bad = ~np.isfinite(a)
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(src, c, f"contains {int(bad.sum())} NaN/inf value(s), first at t = {record.t[i]:g} s")


def approach_speed(record: TrialRecord, t_execute: float) -> float:
    """Mean approach speed [m/s] before the first execute.

    The mean of the speed over the pre-execute samples whose speed is at least
    90 % of the speed at the execute: a ship (or a free-running model that starts
    from rest, as in the FRT-DS-ESSO pond tests) is then taken in its settled
    approach condition, not while still accelerating.

    Parameters
    ----------
    record : TrialRecord
        Record with a speed channel (U, u/v or the track).
    t_execute : float
        Time of the first execute [s].
    """
    sp = np.asarray(record.speed(), float)
    pre = record.t <= t_execute
    if pre.sum() < 1:
        return float(sp[0])
    ue = sp[pre][-1]
    sel = pre & (sp >= 0.9 * ue)
    return float(np.mean(sp[sel])) if sel.any() else float(ue)


def _plateaus(delta):
    """Zigzag rudder plateaus: list of (start, end, sign) with alternating sign, and delta0 [rad]."""
    # plateau levels from the samples where the rudder is held still, so that operator
    # steering before the execute (which may go beyond the zigzag angle) is ignored
    amax = np.max(np.abs(delta))
    d = np.diff(delta)
    flat = np.zeros(len(delta), bool)
    flat[1:-1] = (np.abs(d[:-1]) < 1e-3 * amax) & (np.abs(d[1:]) < 1e-3 * amax)
    dp = np.max(delta[flat], initial=0.0)
    dm = np.min(delta[flat], initial=0.0)
    if dp <= 0 or dm >= 0:
        return [], 0.0
    lp = np.median(delta[flat & (delta >= 0.5 * dp)])
    lm = np.median(delta[flat & (delta <= 0.5 * dm)])
    d0 = 0.5 * (lp - lm)
    tol = max(0.05 * d0, np.radians(0.25))
    n = len(delta)
    min_len = max(3, int(0.02 * n))
    runs = []
    for lev, sg in ((lp, 1.0), (lm, -1.0)):
        for a, b in _runs(np.abs(delta - lev) < tol):
            if b - a + 1 >= min_len:
                runs.append([a, b, sg])
    runs.sort()
    merged = []
    for r in runs:  # same-sign runs separated by a short glitch are one plateau
        if merged and merged[-1][2] == r[2] and r[0] - merged[-1][1] <= min_len:
            merged[-1][1] = r[1]
        else:
            merged.append(r)
    # the longest chain of alternating plateaus, each joined to the next by one monotone
    # rudder movement (a counter-rudder), not by operator steering back and forth
    def monotone(a, b, direction):
        d = np.diff(delta[a:b + 1])
        return bool(np.all(direction * d >= -0.5 * tol))

    best, cur = [], []
    for r in merged:
        if cur and cur[-1][2] != r[2] and monotone(cur[-1][1], r[0], r[2]):
            cur.append(r)
        else:
            cur = [r]
        if len(cur) > len(best):
            best = list(cur)
    return [tuple(r) for r in best], float(d0)


def zigzag_data(record: TrialRecord, L: float, U: Optional[float] = None, per_knot: Optional[int] = None) -> ZigzagData:
    """Find the zigzag in a record and convert it to dimensionless variables.

    Steps: (1) the rudder plateaus at +-delta0 are found and the longest chain of
    alternating plateaus is taken as the zigzag (operator steering before it is
    ignored); (2) the execute is where the rudder starts moving to the first
    plateau, each counter-rudder where it leaves a plateau; (3) s' = (t - t_e) U/L
    with a constant speed (the linear model's assumption), U defaulting to the
    approach speed (:func:`approach_speed`); (4) omega' from the recorded yaw rate
    (smoothed), or from the heading by :func:`smooth_derivatives`; eps' is the
    derivative of the same spline; (5) overshoots are the extremes of the
    smoothed heading between counter-rudders, refined to omega' = 0.

    Parameters
    ----------
    record : TrialRecord
        Needs t, psi and delta (r and a speed channel optional).
    L : float
        Ship length [m].
    U : float, optional
        Speed for s' [m/s]; default: approach speed.
    per_knot : int, optional
        Samples per knot interval of the differentiator (None: chosen by GCV),
        see :func:`smooth_derivatives`.

    Raises
    ------
    InputError
        Missing channels, NaN, no zigzag (no counter-rudder), bad L or U.
    """
    src = record.source or record.name or "record"
    if not (np.isfinite(L) and L > 0):
        raise InputError("--length", "", f"ship length must be positive, got {L}")
    for c in ("psi", "delta"):
        if getattr(record, c) is None:
            raise InputError(src, c, "channel missing; a zigzag analysis needs heading and rudder")
    _check_finite(record, ("t", "psi", "delta", "r"))
    t = np.asarray(record.t, float)
    if len(t) < 10 or np.any(np.diff(t) <= 0):
        raise InputError(src, "t", "need at least 10 samples with strictly increasing time")
    delta_raw = np.asarray(record.delta, float)
    plats, d0 = _plateaus(delta_raw)
    if len(plats) < 2:
        raise InputError(src, "delta", "not a zigzag: no counter-rudder found (need the rudder held at +delta0 "
                                       "then reversed to -delta0)")
    sign = plats[0][2]
    delta = sign * delta_raw
    # execute: walk back from the first plateau while the rudder was still moving towards it
    j = plats[0][0]
    while j > 0 and delta[j] - delta[j - 1] > 1e-4 * d0:
        j -= 1
    ie = j
    t_e = t[ie]
    if U is None:
        try:
            U = approach_speed(record, t_e)
        except ValueError:
            raise InputError(src, "U", "no speed channel; give --speed") from None
    if not (np.isfinite(U) and U > 0):
        raise InputError(src if U is None else "--speed", "U", f"speed must be positive, got {U}")
    end = plats[-1][1]
    sl = slice(ie, end + 1)
    s = (t[sl] - t_e) * U / L
    if len(s) < 10:
        raise InputError(src, "t", "zigzag too short")
    psi_abs = sign * np.asarray(record.psi, float)[sl]
    psi_s, dpsi, d2psi = smooth_derivatives(s, psi_abs, per_knot)
    if record.r is not None:
        om_raw = sign * np.asarray(record.r, float)[sl] * L / U
        omega, eps, _ = smooth_derivatives(s, om_raw, per_knot)
        src_r = "recorded"
    else:
        omega, eps = dpsi, d2psi
        src_r = "derived from heading"
    dl = delta[sl]
    Delta = cumulative_trapezoid(dl, s, initial=0.0)
    psi = psi_s - psi_s[0]
    # counter-rudder: where the ramp leaving plateau k, extended back, meets the plateau level
    s_cr = []
    for (a, b, sg) in plats[:-1]:
        level = float(np.median(delta[a:b + 1]))
        sc = s[b - ie]
        if b + 2 - ie < len(s):
            i1, i2 = b + 1 - ie, b + 2 - ie
            slope = (dl[i2] - dl[i1]) / (s[i2] - s[i1])
            if slope * sg * sign < 0:
                sc = float(np.clip(s[i1] - (dl[i1] - level) / slope, s[a - ie] if a >= ie else s[0], s[i1]))
        s_cr.append(float(sc))
    s_cr = tuple(s_cr)
    # overshoots: extreme of heading between counter-rudder k and the next one
    s_os = []
    bounds = list(s_cr) + [s[-1]]
    side = 1.0
    for k, a in enumerate(s_cr):
        m = np.where((s >= a) & (s <= bounds[k + 1]))[0]
        if len(m) < 3:
            break
        i = m[np.argmax(side * psi[m])]
        if i == m[-1]:  # still turning at the end of the window: no overshoot yet
            break
        # refine: omega' sign change next to the extreme
        lo, hi = max(i - 1, m[0]), min(i + 1, m[-1])
        so = s[i]
        for q in range(lo, hi):
            if omega[q] * side > 0 >= omega[q + 1] * side:
                so = s[q] + (s[q + 1] - s[q]) * omega[q] / (omega[q] - omega[q + 1])
        s_os.append(float(so))
        side = -side
    # heading zero crossings after each overshoot
    s_z = []
    for k, so in enumerate(s_os):
        m = np.where((s > so))[0]
        for q in m[:-1]:
            if psi[q] * psi[q + 1] <= 0 and psi[q] != psi[q + 1] and abs(psi[q]) > 0:
                s_z.append(float(s[q] + (s[q + 1] - s[q]) * psi[q] / (psi[q] - psi[q + 1])))
                break
    return ZigzagData(s=s, psi=psi, omega=omega, eps=eps, delta=dl - dl[0], Delta=Delta,
                      psi_e=float(sign * psi_s[0]), omega_e=float(omega[0]), eps_e=float(eps[0]),
                      delta_e=float(dl[0]), sign=float(sign), L=float(L), U=float(U), t_execute=float(t_e),
                      s_cr=s_cr, s_os=tuple(s_os), s_z=tuple(s_z), delta0=d0, yaw_rate_source=src_r,
                      name=record.name or src, psi_raw=psi_abs - psi_s[0])


# ------------------------------------------------------------------ four points
@dataclass(frozen=True)
class ZigzagPoints:
    """Motion values at the characteristic abscissas (one row per point).

    Attributes
    ----------
    names : tuple of str
        e.g. ("CR1", "OS1", "CR2", "OS2").
    s, eps, omega, Delta, delta, psi : ndarray
        s' [-], eps' [-], omega' [-], Delta [rad], delta [rad], psi [rad] per point.
    """

    names: tuple
    s: np.ndarray
    eps: np.ndarray
    omega: np.ndarray
    Delta: np.ndarray
    delta: np.ndarray
    psi: np.ndarray

    @classmethod
    def from_rows(cls, names, rows):
        """Build from a list of dicts with keys s, eps, omega, Delta, delta, psi."""
        return cls(tuple(names), *(np.array([r[k] for r in rows], float)
                                   for k in ("s", "eps", "omega", "Delta", "delta", "psi")))

    def scaled(self, **factors) -> "ZigzagPoints":
        """A copy with values multiplied, e.g. ``scaled(eps={'CR1': 1.1})`` or ``scaled(omega=1.05)``."""
        kw = {}
        for k in ("s", "eps", "omega", "Delta", "delta", "psi"):
            v = getattr(self, k).copy()
            f = factors.get(k)
            if isinstance(f, dict):
                for nm, fac in f.items():
                    v[self.names.index(nm)] *= fac
            elif f is not None:
                v *= f
            kw[k] = v
        return ZigzagPoints(self.names, **kw)

    def to_dict(self) -> dict:
        """{name: {s, eps, omega, Delta, delta, psi, psi_deg}}."""
        return {n: {"s": float(self.s[i]), "eps": float(self.eps[i]), "omega": float(self.omega[i]),
                    "Delta": float(self.Delta[i]), "delta": float(self.delta[i]), "psi": float(self.psi[i]),
                    "psi_deg": float(np.degrees(self.psi[i]))} for i, n in enumerate(self.names)}

    def to_pandas(self):
        """The points as a DataFrame (Artyszuk's Table 1 layout)."""
        import pandas as pd

        return pd.DataFrame.from_dict(self.to_dict(), orient="index")


@dataclass(frozen=True)
class FourPointResult:
    """Result of the four-point 2nd-order identification (eqs. 16-18, 23).

    Attributes
    ----------
    K, T1, T2, T3 : float
        Model parameters [-]; T1, T2 are NaN when x2^2 - 4 x1 < 0 (no real
        roots, Artyszuk's Table 6 case).
    x : ndarray
        x1 = T1 T2, x2 = T1 + T2, x3 = -K, x4 = -K T3, eq. (16).
    W : float
        Main determinant of eq. (17)/(18).
    Wx : ndarray
        Cramer determinants W_x1..W_x4 (x_i = W_xi / W), Table 7.
    discriminant : float
        x2^2 - 4 x1 under the square roots of eq. (23).
    real : bool
        True when T1, T2 are real.
    cond : float
        Condition number of the 4x4 matrix.
    rank_deficient : bool
        The matrix is singular to working precision (first-order data): x is the
        minimum-norm solution, T2 = T3 is then indeterminate (Artyszuk, Table 4).
    """

    K: float
    T1: float
    T2: float
    T3: float
    x: np.ndarray
    W: float
    Wx: np.ndarray
    discriminant: float
    real: bool
    cond: float
    rank_deficient: bool = False

    @property
    def model(self) -> NomotoModel:
        """As a :class:`NomotoModel` (NaN T1, T2 if not real)."""
        return NomotoModel(self.K, self.T1, self.T2, self.T3, name="four-point")

    def note(self) -> str:
        """Plain-words remark for reports ('' when all is well)."""
        if self.rank_deficient:
            return ("four-point matrix singular (first-order behaviour): T2 = T3 indeterminate, "
                    "minimum-norm solution reported")
        if not self.real:
            return (f"T1, T2 not real: (T1+T2)^2 - 4 T1 T2 = {self.discriminant:.4g} < 0 "
                    f"(T1 T2 = {self.x[0]:.4g}, T1 + T2 = {self.x[1]:.4g})")
        return ""

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        f = lambda v: None if not np.isfinite(v) else float(v)  # noqa: E731
        return {"K": f(self.K), "T1": f(self.T1), "T2": f(self.T2), "T3": f(self.T3),
                "T1T2": float(self.x[0]), "T1_plus_T2": float(self.x[1]), "real_T1_T2": bool(self.real),
                "discriminant": float(self.discriminant), "W": float(self.W),
                "W_x": [float(v) for v in self.Wx], "condition_number": float(self.cond),
                "rank_deficient": bool(self.rank_deficient), "note": self.note()}

    def to_pandas(self):
        """One-row DataFrame."""
        import pandas as pd

        return pd.DataFrame([self.to_dict()])


def four_point(points: ZigzagPoints) -> FourPointResult:
    """Artyszuk's four-point identification of the 2nd-order model.

    Solves eq. (17) (with the corrected right-hand side -psi_#4),
    [eps' omega' Delta delta] x = -psi at four abscissas, by Cramer's rule so
    that the determinants of Table 7 are reported, then eq. (23).

    Parameters
    ----------
    points : ZigzagPoints
        Exactly four points (e.g. CR1, OS1, CR2, OS2).
    """
    if len(points.names) != 4:
        raise ValueError("the four-point method needs exactly four points")
    A = np.column_stack([points.eps, points.omega, points.Delta, points.delta])
    b = -points.psi
    if not np.all(np.isfinite(A)) or not np.all(np.isfinite(b)):
        raise InputError("four-point", "", "non-finite input values")
    W = float(np.linalg.det(A))
    Wx = np.empty(4)
    for i in range(4):
        Ai = A.copy()
        Ai[:, i] = b
        Wx[i] = np.linalg.det(Ai)
    # relative size of W against Hadamard's bound tells a rank-deficient matrix, which is
    # what exact first-order data give (eps' = (K delta - omega')/T is a combination of
    # the other columns): then T2 = T3 is indeterminate and the minimum-norm solution is
    # returned (it has T1 = T and T2 = T3 exactly).
    hadamard = float(np.prod(np.linalg.norm(A, axis=0)))
    rank_deficient = hadamard == 0 or abs(W) < 1e-9 * hadamard
    if rank_deficient:
        x = np.linalg.lstsq(A, b, rcond=1e-9)[0]
    else:
        x = Wx / W
    disc = x[1] ** 2 - 4 * x[0]
    real = bool(disc >= 0)
    r = np.sqrt(disc) if real else np.nan
    K = -x[2]
    T3 = x[3] / x[2]
    return FourPointResult(K=float(K), T1=float(0.5 * (x[1] + r)), T2=float(0.5 * (x[1] - r)), T3=float(T3),
                           x=x, W=W, Wx=Wx, discriminant=float(disc), real=real, cond=float(np.linalg.cond(A)),
                           rank_deficient=bool(rank_deficient))


# --------------------------------------------------------------- classical 1st order
@dataclass(frozen=True)
class ClassicalResult:
    """Nomoto (1960) first-order K, T from a zigzag, per half-cycle and averaged.

    Attributes
    ----------
    K, T : float
        Averages over the half-cycles used [-] (T from the counter-rudder
        variant, eq. 12, generalised).
    rows : tuple of dict
        Per half-cycle k: K (from OS_k), T_zero (eq. 11, heading zero crossing
        after OS_k), T_cr (eq. 12, counter-rudder CR_k+1), and the
        overshoot-to-overshoot form K_os, T_os (see :func:`classical_first_order`).
    K_os, T_os : float
        Averages of the overshoot-to-overshoot form.
    """

    K: float
    T: float
    rows: tuple
    K_os: float = float("nan")
    T_os: float = float("nan")

    @property
    def model(self) -> NomotoModel:
        """As a first-order :class:`NomotoModel`."""
        return first_order(self.K, self.T, name="classical")

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return {"K": float(self.K), "T": float(self.T), "K_overshoot_to_overshoot": float(self.K_os),
                "T_overshoot_to_overshoot": float(self.T_os), "half_cycles": [dict(r) for r in self.rows]}

    def to_pandas(self):
        """Per-half-cycle DataFrame."""
        import pandas as pd

        return pd.DataFrame(list(self.rows))


def classical_first_order(z, n_half: int = 3) -> ClassicalResult:
    """First-order K, T by Nomoto's two-point method, eqs. (10)-(12).

    From the integrated model (7), T omega' + psi = K Delta, with origin at the
    execute (zero initial state):

    * K_k = psi_OSk / Delta_OSk  (eq. 10, omega' = 0 at an overshoot);
    * T_k = (K_k Delta_Zk - psi_Zk) / omega'_Zk at the heading zero crossing
      after OS_k (eq. 11, psi_Z = 0), and
    * T_k = (K_k Delta_CRk+1 - psi_CRk+1) / omega'_CRk+1 at the next counter-rudder
      (eq. 12, Artyszuk's economical variant).

    Also reported, the overshoot-to-overshoot form (model (7) integrated from
    OS_k-1, where omega' = 0, to OS_k; OS_0 = execute):
    K_os = (psi_OSk - psi_OSk-1) / (Delta_OSk - Delta_OSk-1) and
    T_os = (K_os (Delta_CRk - Delta_OSk-1) - (psi_CRk - psi_OSk-1)) / (omega'_CRk - omega'_OSk-1)
    at the counter-rudder CR_k inside that half-cycle.  It does not depend on the
    state at the execute.

    The averages use the first ``n_half`` half-cycles (as is usual, at most three).

    Parameters
    ----------
    z : ZigzagData or ZigzagSimulation
        Dimensionless zigzag with s_cr, s_os and (for eq. 11) heading zero crossings.
    n_half : int
        Maximum number of half-cycles to average.
    """
    def at(s):
        if isinstance(z, ZigzagSimulation):
            return z.state_at(s)
        r = z.at(s)
        return r

    zs = getattr(z, "s_z", None)
    if zs is None:  # simulation: zero crossings of heading after each overshoot
        zs = []
        for so in z.s_os:
            m = np.where(z.s > so)[0]
            for q in m[:-1]:
                if z.psi[q] * z.psi[q + 1] <= 0 and z.psi[q] != 0:
                    zs.append(float(z.s[q] - z.psi[q] * (z.s[q + 1] - z.s[q]) / (z.psi[q + 1] - z.psi[q])))
                    break
    rows = []
    prev = {"s": 0.0, "psi": 0.0, "Delta": 0.0, "omega": 0.0}
    for k in range(min(n_half, len(z.s_os))):
        os_ = at(z.s_os[k])
        K = os_["psi"] / os_["Delta"]
        Kos = (os_["psi"] - prev["psi"]) / (os_["Delta"] - prev["Delta"])
        row = {"half_cycle": k + 1, "s_OS": os_["s"], "K": K, "T_zero": np.nan, "T_cr": np.nan,
               "K_os": Kos, "T_os": np.nan}
        if k < len(zs):
            zz = at(zs[k])
            row["T_zero"] = (K * zz["Delta"] - zz["psi"]) / zz["omega"]
        if k + 1 < len(z.s_cr):
            cr = at(z.s_cr[k + 1])
            row["T_cr"] = (K * cr["Delta"] - cr["psi"]) / cr["omega"]
        # overshoot-to-overshoot: K over [OS_k-1, OS_k], T at the counter-rudder inside it
        if k < len(z.s_cr):
            cr = at(z.s_cr[k])
            row["T_os"] = ((Kos * (cr["Delta"] - prev["Delta"]) - (cr["psi"] - prev["psi"]))
                           / (cr["omega"] - prev["omega"]))
        rows.append(row)
        prev = {"s": os_["s"], "psi": os_["psi"], "Delta": os_["Delta"], "omega": 0.0}
    if not rows:
        raise InputError(getattr(z, "name", "zigzag"), "heading", "no overshoot found: not a zigzag")
    K = float(np.nanmean([r["K"] for r in rows]))
    T = float(np.nanmean([r["T_cr"] for r in rows])) if any(np.isfinite(r["T_cr"]) for r in rows) \
        else float(np.nanmean([r["T_zero"] for r in rows]))
    Kos = float(np.nanmean([r["K_os"] for r in rows]))
    Tos = float(np.nanmean([r["T_os"] for r in rows]))
    return ClassicalResult(K=K, T=T, rows=tuple(rows), K_os=Kos, T_os=Tos)


# --------------------------------------------------------------- whole-record fits
@dataclass(frozen=True)
class FitResult:
    """A 2nd-order model fitted to a whole record, with 95 % confidence intervals.

    Attributes
    ----------
    method : str
        "least_squares" (equation error, eq. 15) or "output_error" (heading).
    K, T1, T2, T3 : float
        Parameters [-] (T1, T2 NaN if not real).
    ci95 : dict
        {name: (low, high)} 95 % intervals for K, T1, T2, T3 (and delta_bias).
    delta_bias : float
        Fitted neutral rudder angle [rad] (0 if not fitted).
    rms : float
        RMS residual (heading units, rad).
    n : int
        Number of samples.
    note : str
        Remarks (e.g. complex roots).
    """

    method: str
    K: float
    T1: float
    T2: float
    T3: float
    ci95: dict
    delta_bias: float
    rms: float
    n: int
    note: str = ""

    @property
    def model(self) -> NomotoModel:
        """As a :class:`NomotoModel`."""
        return NomotoModel(self.K, self.T1, self.T2, self.T3, name=self.method)

    def to_dict(self) -> dict:
        """JSON-ready dict with ``K_ci95`` ... keys as [low, high]."""
        f = lambda v: None if not np.isfinite(v) else float(v)  # noqa: E731
        d = {"K": f(self.K), "T1": f(self.T1), "T2": f(self.T2), "T3": f(self.T3)}
        for k, (lo, hi) in self.ci95.items():
            d[f"{k}_ci95"] = [f(lo), f(hi)]
        d.update({"delta_bias_deg": float(np.degrees(self.delta_bias)), "rms_residual_deg": float(np.degrees(self.rms)),
                  "n_samples": int(self.n), "note": self.note})
        return d

    def to_pandas(self):
        """One-row DataFrame."""
        import pandas as pd

        return pd.DataFrame([self.to_dict()])


def _params_from_x(x):
    """(K, T1, T2, T3, real) from x1 = T1T2, x2 = T1+T2, x3 = -K, x4 = -K T3."""
    disc = x[1] ** 2 - 4 * x[0]
    r = np.sqrt(disc) if disc >= 0 else np.nan
    return -x[2], 0.5 * (x[1] + r), 0.5 * (x[1] - r), x[3] / x[2], disc >= 0


def fit_least_squares(z: ZigzagData, form: str = "integrated2", fit_bias: bool = True) -> FitResult:
    """Least-squares fit of eq. (15) over every sample of the zigzag, with 95 % intervals.

    ``form="eq15"`` regresses eq. (15) as it stands,
    -psi = x1 eps' + x2 omega' + x3 Delta + x4 delta + c0 (+ c1 s'),
    with x1 = T1 T2, x2 = T1 + T2, x3 = -K, x4 = -K T3 (eq. 16); c0 absorbs the
    state at the execute and c1 = K delta_bias a neutral rudder angle.

    ``form="integrated"`` fits the same equation integrated once more
    from the execute:
    x1 omega' + x2 psi + int psi ds' + x3 int Delta ds' + x4 Delta + c0 + c1 s' (+ c2 s'^2) = 0,
    (c0, c1 absorb the unknown omega', eps' at the execute, c2 = K delta_bias / 2),
    solved for the recorded heading psi (its noise then sits in the dependent
    variable, not in a regressor, so it causes no attenuation bias).
    Same parameters, but the regressors are heading and yaw rate instead of
    yaw rate and yaw acceleration.  Why: in eq. (15) the error of eps' is
    multiplied by T1 T2 and that of omega' by T1 + T2; with eps' differentiated
    twice from a heading with 0.05 deg noise this errors-in-variables bias
    pulls T1 down by tens of percent, whereas psi is measured and omega' is
    only differentiated once (see the extended Table 8 of ``mmg nomoto-paper``).

    ``form="integrated2"`` (default) integrates twice more, so only the recorded
    heading and rudder enter (no derivative at all):
    x1 psi + x2 int psi + intint psi + x3 intint Delta + x4 int Delta + cubic(s') = 0,
    solved for psi; the cubic absorbs the state at the execute and the neutral
    rudder (c3 = K delta_bias / 6).  On the eq. (24) record with 0.05 deg heading
    noise it keeps K, T1 within about 3 %, where the once-integrated form
    scatters to 4 % and eq. (15) itself is 20-40 % low.

    The 95 % intervals propagate sigma^2 (A^T A)^-1 through eq. (23) by the
    delta method.  Residuals of a record are autocorrelated, so the intervals
    are optimistic: they reflect the scatter, not the differentiator or model bias.

    Parameters
    ----------
    z : ZigzagData
        Dimensionless zigzag (:func:`zigzag_data`).
    form : {"integrated2", "integrated", "eq15"}
        Which equation error to minimise.
    fit_bias : bool
        Also fit a neutral rudder angle.
    """
    one = np.ones_like(z.s)
    if form == "eq15":
        cols = [z.eps, z.omega, z.Delta, z.delta, one] + ([z.s] if fit_bias else [])
        b = -z.psi

        def to_params(th):  # th = x1..x4, c0 (, K delta_bias)
            K, T1, T2, T3, _ = _params_from_x(th[:4])
            return np.array([K, T1, T2, T3] + ([th[5] / K] if fit_bias else []), float)
    elif form == "integrated":
        psi = z.psi if z.psi_raw is None else z.psi_raw
        Psi = cumulative_trapezoid(psi, z.s, initial=0.0)
        DD = cumulative_trapezoid(z.Delta, z.s, initial=0.0)
        # x1 omega' + x2 psi + Psi + x3 DD + x4 Delta + c0 + c1 s' + c2 s'^2 = 0, solved for the
        # measured heading so that its noise is in the dependent variable, not in a regressor
        cols = [Psi, z.omega, DD, z.Delta, one, z.s] + ([z.s ** 2] if fit_bias else [])
        b = psi

        def to_params(th):
            x2 = -1.0 / th[0]
            x = np.array([-th[1] * x2, x2, -th[2] * x2, -th[3] * x2])
            K, T1, T2, T3, _ = _params_from_x(x)
            return np.array([K, T1, T2, T3] + ([2.0 * (-th[6] * x2) / K] if fit_bias else []), float)
    elif form == "integrated2":
        psi = z.psi if z.psi_raw is None else z.psi_raw
        Psi = cumulative_trapezoid(psi, z.s, initial=0.0)
        PP = cumulative_trapezoid(Psi, z.s, initial=0.0)
        DD = cumulative_trapezoid(z.Delta, z.s, initial=0.0)
        DDD = cumulative_trapezoid(DD, z.s, initial=0.0)
        # x1 psi + x2 Psi + PP + x3 DDD + x4 DD + c0 + c1 s' + c2 s'^2 (+ c3 s'^3) = 0, solved for psi
        cols = [PP, Psi, DDD, DD, one, z.s, z.s ** 2] + ([z.s ** 3] if fit_bias else [])
        b = psi

        def to_params(th):
            x1 = -1.0 / th[0]
            x = np.array([x1, -th[1] * x1, -th[2] * x1, -th[3] * x1])
            K, T1, T2, T3, _ = _params_from_x(x)
            return np.array([K, T1, T2, T3] + ([6.0 * (-th[7] * x1) / K] if fit_bias else []), float)
    else:
        raise ValueError(f"unknown form {form!r}")
    A = np.column_stack(cols)
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    ths, *_ = np.linalg.lstsq(A / scale, b, rcond=None)
    th = ths / scale
    res = b - A @ th
    n, p = A.shape
    s2 = res @ res / max(n - p, 1)
    cov = s2 * np.linalg.pinv(A.T @ A)
    par = to_params(th)
    K, T1, T2, T3 = par[:4]
    db = float(par[4]) if fit_bias else 0.0
    ci = _delta_method(th, cov, to_params, ["K", "T1", "T2", "T3"] + (["delta_bias"] if fit_bias else []))
    note = "" if np.isfinite(T1) else "T1, T2 not real ((T1+T2)^2 < 4 T1 T2)"
    method = {"integrated2": "least_squares", "integrated": "least_squares_integrated",
              "eq15": "least_squares_eq15"}[form]
    return FitResult(method, float(K), float(T1), float(T2), float(T3), ci, db,
                     float(np.sqrt(np.mean(res ** 2))), n, note)


def _delta_method(th, cov, g, names):
    """95 % intervals of g(th) from the covariance of th (numerical Jacobian of g)."""
    g0 = g(th)
    J = np.empty((len(g0), len(th)))
    for j in range(len(th)):
        h = 1e-6 * max(abs(th[j]), 1e-8)
        xp, xm = th.copy(), th.copy()
        xp[j] += h
        xm[j] -= h
        J[:, j] = (g(xp) - g(xm)) / (2 * h)
    sd = np.sqrt(np.abs(np.diag(J @ cov @ J.T)))
    return {nm: (float(v - Z95 * e), float(v + Z95 * e)) for nm, v, e in zip(names, g0, sd)}


def fit_output_error(z: ZigzagData, start: Optional[NomotoModel] = None, fit_bias: bool = True) -> FitResult:
    """Output-error fit: the 2nd-order ODE driven by the recorded rudder, fitted to the heading.

    The model is simulated exactly (:func:`simulate_response`) from the state at
    the execute; K, T1, T2, T3 (and a neutral rudder angle) minimise the heading
    residual over the whole zigzag (``scipy.optimize.least_squares`` over K,
    T1 T2, T1 + T2, T3, unconstrained, so a course-unstable ship with T1 < 0 or
    complex T1, T2 can be fitted).  Only heading and
    rudder enter, so errors in the derived yaw rate and acceleration do not bias
    the parameters (they only set the initial state).  95 % intervals from
    sigma^2 (J^T J)^-1 at the optimum (optimistic if residuals are correlated).

    Parameters
    ----------
    z : ZigzagData
        Dimensionless zigzag.
    start : NomotoModel, optional
        Starting point (default: the best of three starts, the least-squares
        fit, the four-point result and the classical K, T with T2 = T3 = 0.1 T).
    fit_bias : bool
        Also fit a neutral rudder angle [rad].
    """
    s = z.s
    # decimate long records for speed (the ODE is smooth; 2000 samples are plenty)
    step = max(1, len(s) // 2000)
    idx = np.arange(0, len(s), step)
    ss, dd, pp = s[idx], (z.delta + z.delta_e)[idx], (z.psi if z.psi_raw is None else z.psi_raw)[idx]
    if start is None:
        starts = []
        ls = fit_least_squares(z, fit_bias=fit_bias)
        starts.append(ls.model)
        try:
            fp = four_point(z.points(2))
            starts.append(fp.model)
        except InputError:
            pass
        try:  # the robust first-order estimate, with a small T2 and T3 = T2
            cl = classical_first_order(z)
            starts.append(NomotoModel(cl.K, cl.T, 0.1 * abs(cl.T), 0.1 * abs(cl.T)))
        except InputError:
            pass
    else:
        starts = [start]
    starts = [m for m in starts if np.isfinite([m.K, m.T1, m.T2, m.T3]).all() and abs(m.T1 * m.T2) > 1e-6] \
        or [NomotoModel(2.0, 3.0, 0.3, 1.0)]
    nb = 1 if fit_bias else 0

    # parameters q = (K, x1 = T1 T2, x2 = T1 + T2, T3[, delta_bias], psi_0, omega'_0, eps'_0): no bounds,
    # so unstable ships (T1 < 0) and complex T1, T2 are reachable; the state at the execute is fitted too
    def resid(q):
        return simulate_response((q[0], q[1], q[2], q[3]), ss, dd, q[4 + nb], q[5 + nb], q[6 + nb],
                                 q[4] if fit_bias else 0.0) - pp

    sol = None
    for st in starts:  # several starts: the heading misfit is not convex in these parameters
        q0 = np.array([st.K, st.T1 * st.T2, st.T1 + st.T2, st.T3] + ([0.0] if fit_bias else [])
                      + [0.0, z.omega_e, z.eps_e])
        try:
            with np.errstate(all="ignore"):
                cand = optimize.least_squares(resid, q0, x_scale="jac", max_nfev=300)
        except (ValueError, np.linalg.LinAlgError):
            continue
        if np.isfinite(cand.cost) and (sol is None or cand.cost < sol.cost):
            sol = cand
    if sol is None:
        raise InputError(z.name, "heading", "output-error fit failed from every starting point")
    q = sol.x
    J = _jac(resid, q)
    r = sol.fun
    n, p = len(r), len(q)
    s2 = r @ r / max(n - p, 1)
    cov = s2 * np.linalg.pinv(J.T @ J)

    def to_params(th):
        K, T1, T2, T3, _ = _params_from_x(np.array([th[1], th[2], -th[0], -th[0] * th[3]]))
        return np.array([K, T1, T2, T3] + ([th[4]] if fit_bias else []), float)

    par = to_params(q)
    names = ["K", "T1", "T2", "T3"] + (["delta_bias"] if fit_bias else [])
    ci = _delta_method(q, cov, to_params, names)
    note = "" if sol.success else f"optimiser: {sol.message}"
    if not np.isfinite(par[1]):
        note = (note + "; " if note else "") + f"T1, T2 not real (T1 T2 = {q[1]:.4g}, T1 + T2 = {q[2]:.4g})"
    m = NomotoModel(par[0], par[1], par[2], par[3])
    db = par[4] if fit_bias else 0.0
    ini = q[4 + nb:7 + nb]
    res = FitResult("output_error", float(m.K), float(m.T1), float(m.T2), float(m.T3), ci, float(db),
                    float(np.sqrt(np.mean(r ** 2))), n, note)
    object.__setattr__(res, "initial_state", tuple(float(v) for v in ini))
    return res


def _jac(fun, q):
    """Central-difference Jacobian of a vector function."""
    f0 = fun(q)
    J = np.empty((len(f0), len(q)))
    for j in range(len(q)):
        h = 1e-6 * max(abs(q[j]), 1e-4)
        a, b = q.copy(), q.copy()
        a[j] += h
        b[j] -= h
        J[:, j] = (fun(a) - fun(b)) / (2 * h)
    return J


def heading_rms(model: NomotoModel, z: ZigzagData, delta_bias: float = 0.0) -> float:
    """RMS [rad] of (simulated - recorded) heading over the zigzag, from the execute state.

    Parameters
    ----------
    model : NomotoModel
        Model to simulate (NaN parameters give NaN).
    z : ZigzagData
        The record.
    delta_bias : float
        Neutral rudder angle [rad].
    """
    if not np.all(np.isfinite([model.K, model.T1, model.T2, model.T3])) or model.T1 == 0 or \
            (model.order == 2 and model.T2 == 0):
        return float("nan")
    psi = simulate_response(model, z.s, z.delta + z.delta_e, 0.0, z.omega_e, z.eps_e, delta_bias)
    return float(np.sqrt(np.mean((psi - z.psi) ** 2)))


# ------------------------------------------------------------------ all together
@dataclass(frozen=True)
class NomotoIdentification:
    """Everything identified from one zigzag record.

    Attributes
    ----------
    zigzag : ZigzagData
        The dimensionless record and its characteristic points.
    points : ZigzagPoints
        CR1, OS1, CR2, OS2 used by the four-point method.
    classical : ClassicalResult
        First-order K, T (eqs. 10-12).
    four_point : FourPointResult
        Four-point K, T1, T2, T3 and determinants.
    least_squares : FitResult
        Eq. (15) over all samples.
    output_error : FitResult or None
        Heading-history fit.
    rms : dict
        Heading RMS [deg] of each model against the record.
    """

    zigzag: ZigzagData
    points: ZigzagPoints
    classical: ClassicalResult
    four_point: FourPointResult
    least_squares: FitResult
    output_error: Optional[FitResult]
    rms: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON-ready dict with the keys the CLI promises."""
        z = self.zigzag
        return {
            "record": z.name, "L_m": z.L, "U_m_per_s": z.U, "t_execute_s": z.t_execute,
            "first_execute_to": "starboard" if z.sign > 0 else "port",
            "delta0_deg": float(np.degrees(z.delta0)), "yaw_rate": z.yaw_rate_source,
            "first_order": self.classical.to_dict(),
            "second_order_four_point": self.four_point.to_dict(),
            "second_order_least_squares": self.least_squares.to_dict(),
            "second_order_output_error": None if self.output_error is None else self.output_error.to_dict(),
            "points": self.points.to_dict(),
            "heading_rms_deg": {k: (None if not np.isfinite(v) else float(v)) for k, v in self.rms.items()},
        }

    def to_pandas(self):
        """Summary table: one row per method with K, T/T1, T2, T3, heading RMS [deg]."""
        import pandas as pd

        rows = [
            {"method": "1st order (Nomoto, eq. 10/12)", "K": self.classical.K, "T1": self.classical.T,
             "T2": np.nan, "T3": np.nan, "rms_deg": self.rms.get("first_order", np.nan)},
            {"method": "2nd order four-point", "K": self.four_point.K, "T1": self.four_point.T1,
             "T2": self.four_point.T2, "T3": self.four_point.T3, "rms_deg": self.rms.get("four_point", np.nan)},
            {"method": "2nd order least squares", "K": self.least_squares.K, "T1": self.least_squares.T1,
             "T2": self.least_squares.T2, "T3": self.least_squares.T3,
             "rms_deg": self.rms.get("least_squares", np.nan)},
        ]
        if self.output_error is not None:
            oe = self.output_error
            rows.append({"method": "2nd order output error", "K": oe.K, "T1": oe.T1, "T2": oe.T2, "T3": oe.T3,
                         "rms_deg": self.rms.get("output_error", np.nan)})
        return pd.DataFrame(rows)


def identify(record: TrialRecord, L: float, U: Optional[float] = None, output_error: bool = True,
             per_knot: Optional[int] = None) -> NomotoIdentification:
    """Run all identifications on a zigzag record.

    Parameters
    ----------
    record : TrialRecord
        Zigzag record (t, psi, delta; r and speed optional).
    L : float
        Ship length [m].
    U : float, optional
        Speed [m/s] for s'; default approach speed.
    output_error : bool
        Also run the (slower) output-error fit.
    per_knot : int, optional
        Samples per knot interval of the differentiator (None: chosen by GCV).

    Raises
    ------
    InputError
        Not a zigzag, too short, NaN, missing channels.
    """
    z = zigzag_data(record, L, U, per_knot)
    pts = z.points(2)
    cl = classical_first_order(z)
    fp = four_point(pts)
    ls = fit_least_squares(z)
    oe = fit_output_error(z) if output_error else None
    rms = {"first_order": heading_rms(cl.model, z), "four_point": heading_rms(fp.model, z),
           "least_squares": heading_rms(ls.model, z, ls.delta_bias)}
    if oe is not None:
        rms["output_error"] = oe.rms  # from its own fitted state at the execute
    rms = {k: float(np.degrees(v)) for k, v in rms.items()}
    return NomotoIdentification(z, pts, cl, fp, ls, oe, rms)
