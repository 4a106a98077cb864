"""Rhee & Kim (1999) eqs. (1)-(20) written again, independently, and compared with the compiled model.

Why: a wrong sign or factor inside the compiled model (``mmg/model.py``,
``mmg/terms.py``) keeps the simulator stable and plausible, so the trial and
estimator tests cannot see it (a sign flip of the beta^2 r' terms moves the ST35
tactical diameter from 3.57 L to 3.11 L and every older fast test passed).  Here
the forces and the equations of motion are written once more *from the paper*
in plain numpy -- no project force code is imported for the reference -- and
the compiled state derivative is compared with them at a few hundred random
states to ~1e-9.

What is read from where
-----------------------
* The reference reads the coefficient *values* from ``configs/ships/esso_osaka.yaml``
  with ``yaml.safe_load`` and parses the units itself (``_si``), so a change to a
  number in the config is followed by both sides.  Whether the config's numbers
  are the paper's is a separate test (:func:`test_config_is_the_paper`), with the
  paper's Tables 1-4 and eqs. (12)-(20) transcribed below; it is what catches a
  wrong number (e.g. a sign flip of a Table 2 coefficient) in the YAML.
* The compiled model is called only through its public packing: ``load_ship`` /
  ``ship_from_dict`` -> ``prepare`` (or ``pack``) -> ``rhs(x, delta_cmd, *packed.args(), out)``
  and ``forces(x, *packed.args())``, with the documented state order
  ``[u, v, r, x, y, psi, delta, n]``.

Documented modelling choices followed here (fact sheet ``../shared/reference/esso_osaka_mmg.md``
and the config comments), each marked "CHOICE" where it enters:

* rudder: the paper only points to "the equations of section 2.2.2 [JIN 1995]" and
  prints none; the project uses the MMG form of Yasukawa & Yoshimura (2015) with
  the Table 3 constants and kappa = 0.595, l_R' = -1.0, x_R' = -0.5 (fact sheet s. 2);
* wake in manoeuvring: w_P = w_P0(u) exp(-4 beta_P^2), beta_P = beta - x_P' r', x_P' = -0.5
  (fact sheet s. 3, config ``propeller.wake``); t_P = t_P0(u) of eq. (13) at the current u;
* masses m_x', m_y', I_zG', J_z' (fact sheet s. 4) and K_Q(J) (B-series fit, fact
  sheet s. 3), with K_Q scaled so the shaft is in torque balance at the 10 kn
  straight run (fact sheet s. 6, ``mmg/equilibrium.py``); the scale is
  re-derived here from the reference's own straight run;
* Q_E = 745 SHP_0(u_0) / (2 pi n), eq. (18) as printed (745 W per "PS"), SHP_0 at the
  approach speed u_0 = 10 kn and held constant (steam turbine);
* (I_Pp + J_Pp) = 2.0 D^5 read as kg m^2 (eq. 16 as printed);
* eq. (1) prints "(m - Y_v) v r": the dot of Y_vdot is lost in the extraction; the
  standard MMG form (m + m_y) v r is used;
* the steering gear clips the *order* to +-delta_max (Table 1) before eq. (20).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.optimize import fsolve

REPO = Path(__file__).resolve().parents[1]
SHIP_YAML = REPO / "configs" / "ships" / "esso_osaka.yaml"

KN = 1852.0 / 3600.0          # one knot [m/s]
DEGREE = np.pi / 180.0
U_APPROACH = 10.0 * KN        # Rhee & Kim section 2.2.4: "initial velocity is set to 10 knots"

# state order of the compiled model (mmg/model.py docstring)
STATE_ORDER = ("u", "v", "r", "x", "y", "psi", "delta", "n")
IU, IV, IR, IX, IY, IPSI, IDELTA, IN = range(8)

# --------------------------------------------------------------------------- the paper, transcribed

# Table 1 (principal particulars)
PAPER_TABLE1 = {"L": 325.00, "B": 53.00, "T": 21.73, "C_b": 0.831, "A_w": 27313.50, "D_P": 9.10,
                "P": 6.51, "A_R": 119.82, "H_R": 13.85, "L_R": 9.00, "delta_max_deg": 35.00,
                "delta_rate_max_deg_s": 2.34}
# Table 2 (hydrodynamic derivatives, Kijima form) with the term each multiplies in eqs. (4)-(6),
# written in primes: r' = r L / U (the paper's brackets [rho/2 L^k T U^j] are the primes).
PAPER_TABLE2 = {
    "X_br": (+0.278e-1, "r*sin(beta)"), "X_uu": (-0.873e-2, "cos(beta)^2"),
    "Y_0": (+0.2991e-3, "1"), "N_0": (-0.1496e-3, "1"),
    "Y_beta": (+0.3998, "beta"), "N_beta": (+0.1337, "beta"),
    "Y_r": (+0.8774e-1, "r"), "N_r": (-0.5433e-1, "r"),
    "Y_bb": (+0.6732, "beta|beta|"), "N_bb": (-0.5180e-3, "beta|beta|"),
    "Y_rr": (+0.4686e-1, "r|r|"), "N_rr": (-0.2224e-1, "r|r|"),
    "Y_bbr": (-0.1389, "beta^2*r"), "N_bbr": (-0.1625, "beta^2*r"),
    "Y_brr": (+0.4123, "beta*r^2"), "N_brr": (-0.1204, "beta*r^2"),
}
# Table 3 (rudder): eta, lambda, C_N, gamma, epsilon, t_R, a_H, x_H
PAPER_TABLE3 = {"eta": 0.657, "lambda": 1.539, "C_N": 2.490, "gamma": 0.275, "epsilon": 1.009,
                "t_R": 0.217, "a_H": 0.865, "x_H": -0.181}
PAPER_KT = (0.3493, -0.3340, -0.1509, 0.0102)          # eq. (12), in J_P
PAPER_TP0 = (0.1093, 0.0296, -0.0032, 0.000115)         # eq. (13), in u [m/s]
PAPER_WP0 = (0.2616, 0.0253, -0.0034, 0.00013)          # eq. (14), in u [m/s]
PAPER_SHAFT_INERTIA_COEF = 2.0                          # eq. (16): (I_Pp + J_Pp) = 2.0 D_P^5
PAPER_W_PER_SHP = 745.0                                 # eq. (18)
PAPER_SHP0 = (-601.1, 632.0, -182.0, 74.7)              # eq. (19), in u [m/s]
PAPER_T_E = 2.5                                         # section 2.2.3: "T_E is 2.5 (sec)"
PAPER_N0_RPM = 54.12                                    # Table 4 (printed under "Table 4. Other conditions")
PAPER_C_R = 0.002256                                    # eq. (11)
PAPER_CM = (-0.484, 1.643)                              # eq. (10): c_m = -0.484 + 1.643 C_b

# --------------------------------------------------------------------------- config reading (own unit parser)

_UNITS = {"m": 1.0, "m^2": 1.0, "s": 1.0, "deg": DEGREE, "deg/s": DEGREE, "rad": 1.0, "rad/s": 1.0,
          "kg/m^3": 1.0, "kn": KN, "m/s": 1.0}


def _si(value) -> float:
    """'325.0 m' -> 325.0, '2.34 deg/s' -> rad/s, plain numbers unchanged."""
    if isinstance(value, (int, float)):
        return float(value)
    number, unit = value.split()
    return float(number) * _UNITS[unit]


def _poly(c, x):
    """sum c_k x^k (lowest power first), written out, not via the project's polyval."""
    return sum(ck * x**k for k, ck in enumerate(c))


def load_config(path=SHIP_YAML) -> dict:
    with open(path) as fh:
        return yaml.safe_load(fh)


class PaperModel:
    """Rhee & Kim (1999) eqs. (1)-(20) for the Esso Osaka, plain numpy, vectorised over states."""

    def __init__(self, cfg: dict, u0: float = U_APPROACH):
        pa, ms, hull = cfg["particulars"], cfg["mass"], cfg["hull"]["coefficients"]
        pr, ru, st, en = cfg["propeller"], cfg["rudder"], cfg["steering"], cfg["engine"]
        self.rho, self.L, self.T = _si(pa["rho"]), _si(pa["L"]), _si(pa["T"])
        self.x_G = _si(pa.get("x_G", "0 m"))
        half_rho_L2T = 0.5 * self.rho * self.L**2 * self.T
        self.m = ms["m_prime"] * half_rho_L2T
        self.m_x = ms["m_x_prime"] * half_rho_L2T
        self.m_y = ms["m_y_prime"] * half_rho_L2T
        self.I_zG = ms["I_zG_prime"] * half_rho_L2T * self.L**2
        self.J_z = ms["J_z_prime"] * half_rho_L2T * self.L**2
        self.c = {name: float(c["value"]) for name, c in hull.items()}
        self.D = _si(pr["D"])
        self.K_T, self.K_Q = tuple(pr["K_T"]), tuple(pr["K_Q"])
        self.t_P0, self.w_P0 = tuple(pr["t_P"]), tuple(pr["w_P0"])
        assert pr["wake"]["model"] == "kijima"
        self.x_P, self.C_wake = pr["wake"]["x_P_prime"], pr["wake"]["C_wake"]
        self.A_R, self.f_alpha, self.eps = _si(ru["A_R"]), ru["f_alpha"], ru["epsilon"]
        self.kappa, self.eta = ru["kappa"], ru["eta"]
        self.t_R, self.a_H = ru["t_R"], ru["a_H"]
        self.x_H, self.x_R = ru["x_H_prime"] * self.L, ru["x_R_prime"] * self.L
        self.g_pos, self.g_neg, self.l_R = ru["gamma_R_pos"], ru["gamma_R_neg"], ru["l_R_prime"]
        self.T_E, self.rate_max, self.delta_max = _si(st["T_E"]), _si(st["rate_max"]), _si(st["delta_max"])
        assert en["mode"] == "constant_power"
        self.I_shaft = en["shaft_inertia_coefficient"] * self.D**5               # eq. (16)
        self.u0 = u0
        self.P0 = en["watts_per_hp"] * _poly(en["SHP_0"], u0)                    # eqs. (18)-(19)
        self.kq_scale = 1.0
        self.n0, self.v0, self.delta0 = self._straight_run()
        J0 = self.propeller(self.u0, self.v0, 0.0, self.n0)[1]
        # CHOICE (fact sheet s. 6): scale K_Q so that Q_P balances Q_E at the straight run
        self.kq_scale = (self.P0 / (2 * np.pi * self.n0)) / (self.rho * self.n0**2 * self.D**5 * _poly(self.K_Q, J0))

    # ---- kinematics
    def kinematics(self, u, v, r):
        U = np.sqrt(u * u + v * v)
        beta = np.arctan(-v / u)           # drift angle, beta > 0 in a starboard turn
        return U, beta, r * self.L / U

    # ---- eqs. (4)-(6), dimensional as printed: [rho/2 L^a T U^b] brackets
    def hull(self, u, v, r):
        c, rho, L, T = self.c, self.rho, self.L, self.T
        U, b, _ = self.kinematics(u, v, r)
        h = 0.5 * rho
        X = c["X_br"] * h * L**2 * T * U * r * np.sin(b) + c["X_uu"] * h * L * T * U**2 * np.cos(b) ** 2
        Y = (c["Y_0"] * h * L * T * U**2 + c["Y_beta"] * h * L * T * U**2 * b + c["Y_r"] * h * L**2 * T * U * r
             + c["Y_bb"] * h * L * T * U**2 * b * np.abs(b) + c["Y_rr"] * h * L**3 * T * r * np.abs(r)
             + c["Y_bbr"] * h * L**2 * T * U * b * b * r + c["Y_brr"] * h * L**3 * T * b * r * r)
        N = (c["N_0"] * h * L**2 * T * U**2 + c["N_beta"] * h * L**2 * T * U**2 * b + c["N_r"] * h * L**3 * T * U * r
             + c["N_bb"] * h * L**2 * T * U**2 * b * np.abs(b) + c["N_rr"] * h * L**4 * T * r * np.abs(r)
             + c["N_bbr"] * h * L**3 * T * U * b * b * r + c["N_brr"] * h * L**4 * T * b * r * r)
        return X, Y, N

    # ---- eqs. (12)-(14) with the Kijima wake in manoeuvring (CHOICE, see module docstring)
    def one_minus_wake(self, u, v, r):
        _, beta, rp = self.kinematics(u, v, r)
        beta_P = beta - self.x_P * rp
        return 1.0 - _poly(self.w_P0, u) * np.exp(-self.C_wake * beta_P**2)

    def propeller(self, u, v, r, n):
        omw = self.one_minus_wake(u, v, r)
        J = u * omw / (n * self.D)
        KT = _poly(self.K_T, J)
        X_P = (1.0 - _poly(self.t_P0, u)) * self.rho * n**2 * self.D**4 * KT
        return X_P, J, KT, omw

    # ---- rudder (CHOICE: MMG 2015 form, Table 3 constants; the paper prints no rudder equations)
    def rudder(self, u, v, r, delta, n):
        U, beta, rp = self.kinematics(u, v, r)
        _, J, KT, omw = self.propeller(u, v, r, n)
        u_P = u * omw
        slip_factor = 1.0 + self.kappa * (np.sqrt(1.0 + 8.0 * KT / (np.pi * J**2)) - 1.0)
        u_R = self.eps * u_P * np.sqrt(self.eta * slip_factor**2 + (1.0 - self.eta))
        beta_R = beta - self.l_R * rp
        gamma = np.where(beta_R >= 0.0, self.g_pos, self.g_neg)
        v_R = U * gamma * beta_R
        alpha_R = delta - np.arctan(v_R / u_R)
        F_N = 0.5 * self.rho * self.A_R * (u_R**2 + v_R**2) * self.f_alpha * np.sin(alpha_R)
        X_R = -(1.0 - self.t_R) * F_N * np.sin(delta)
        Y_R = -(1.0 + self.a_H) * F_N * np.cos(delta)
        N_R = -(self.x_R + self.a_H * self.x_H) * F_N * np.cos(delta)
        return X_R, Y_R, N_R, F_N

    def total_forces(self, u, v, r, delta, n):
        XH, YH, NH = self.hull(u, v, r)
        XP = self.propeller(u, v, r, n)[0]
        XR, YR, NR, _ = self.rudder(u, v, r, delta, n)
        return XH + XP + XR, YH + YR, NH + NR

    # ---- eq. (20), order clipped to +-delta_max first
    def steering(self, delta_cmd, delta):
        err = np.clip(delta_cmd, -self.delta_max, self.delta_max) - delta
        return np.where(np.abs(err) <= self.T_E * self.rate_max, err / self.T_E, np.sign(err) * self.rate_max)

    # ---- eqs. (15)-(18), constant power
    def shaft(self, u, v, r, n):
        J = self.propeller(u, v, r, n)[1]
        Q_P = self.rho * n**2 * self.D**5 * self.kq_scale * _poly(self.K_Q, J)   # torque absorbed
        Q_E = self.P0 / (2.0 * np.pi * n)
        return (Q_E - Q_P) / (2.0 * np.pi * self.I_shaft)

    # ---- eqs. (1)-(3) (x_G = 0, about G = midship) and (9)
    def accelerations(self, u, v, r, delta, n):
        X, Y, N = self.total_forces(u, v, r, delta, n)
        m, mx, my = self.m, self.m_x, self.m_y
        if self.x_G == 0.0:
            du = (X + (m + my) * v * r) / (m + mx)                     # eq. (1)
            dv = (Y - (m + mx) * u * r) / (m + my)                     # eq. (2)
            dr = N / (self.I_zG + self.J_z)                            # eq. (3)
        else:
            # Not in the paper (it has x_G = 0): the MMG 2015 midship form of Yasukawa & Yoshimura,
            #   (m+m_x) du - (m+m_y) v r - x_G m r^2 = X
            #   (m+m_y) dv + x_G m dr + (m+m_x) u r = Y
            #   (I_zG + x_G^2 m + J_z) dr + x_G m (dv + u r) = N
            xG = self.x_G
            du = (X + (m + my) * v * r + xG * m * r * r) / (m + mx)
            A = np.array([[m + my, xG * m], [xG * m, self.I_zG + xG * xG * m + self.J_z]])
            b1 = Y - (m + mx) * u * r
            b2 = N - xG * m * u * r
            sol = np.linalg.solve(A, np.array([np.atleast_1d(b1), np.atleast_1d(b2)]))
            dv, dr = sol[0].reshape(np.shape(b1)), sol[1].reshape(np.shape(b2))
        return du, dv, dr

    def derivative(self, X, delta_cmd):
        """State derivative for states X (..., 8) in the compiled model's order."""
        u, v, r, psi, delta, n = (X[..., i] for i in (IU, IV, IR, IPSI, IDELTA, IN))
        du, dv, dr = self.accelerations(u, v, r, delta, n)
        out = np.empty(np.shape(X))
        out[..., IU], out[..., IV], out[..., IR] = du, dv, dr
        out[..., IX] = u * np.cos(psi) - v * np.sin(psi)             # eq. (9)
        out[..., IY] = u * np.sin(psi) + v * np.cos(psi)
        out[..., IPSI] = r
        out[..., IDELTA] = self.steering(delta_cmd, delta)
        out[..., IN] = self.shaft(u, v, r, n)
        return out

    # ---- section 2.2.4: the straight run at 10 kn (rpm from the surge equation; rudder/drift trim Y_0, N_0)
    def _straight_run(self):
        u0 = self.u0

        def resid(z):
            n, v, d = z
            du, dv, dr = self.accelerations(u0, v, 0.0, d, n)
            return [du, dv, dr]

        n, v, d = fsolve(resid, [u0 / (0.6 * self.D), 0.0, 0.0], xtol=1e-14)
        return float(n), float(v), float(d)


def random_states(rng, count):
    """Random states in the ranges of a turning/zigzag manoeuvre (u 2-8 m/s, |v| < 1, |r| < 0.01, |delta| < 35 deg)."""
    X = np.zeros((count, 8))
    X[:, IU] = rng.uniform(2.0, 8.0, count)
    X[:, IV] = rng.uniform(-1.0, 1.0, count)
    X[:, IR] = rng.uniform(-0.01, 0.01, count)
    X[:, IX] = rng.uniform(-5e3, 5e3, count)
    X[:, IY] = rng.uniform(-5e3, 5e3, count)
    X[:, IPSI] = rng.uniform(-np.pi, np.pi, count)
    X[:, IDELTA] = rng.uniform(-35.0, 35.0, count) * DEGREE
    X[:, IN] = rng.uniform(0.75, 1.05, count)
    # a third of the orders near the rudder (linear band of eq. 20), the rest anywhere up to +-40 deg
    cmd = rng.uniform(-40.0, 40.0, count) * DEGREE
    near = rng.random(count) < 1 / 3
    cmd[near] = X[near, IDELTA] + rng.uniform(-5.5, 5.5, near.sum()) * DEGREE
    return X, cmd


def assert_close_per_column(actual, expected, names, rtol=1e-9):
    """Columnwise allclose with rtol and an absolute floor of rtol x the column's largest magnitude."""
    bad = []
    for j, name in enumerate(names):
        scale = np.max(np.abs(expected[:, j])) or 1.0
        err = np.abs(actual[:, j] - expected[:, j])
        tol = rtol * np.abs(expected[:, j]) + rtol * scale
        if not np.all(err <= tol):
            k = int(np.argmax(err / tol))
            bad.append(f"{name}: worst at row {k}: compiled {actual[k, j]!r} vs paper {expected[k, j]!r} "
                       f"(|diff|/scale = {err[k] / scale:.3e}, {np.sum(err > tol)} of {len(err)} rows off)")
    assert not bad, "compiled model disagrees with the paper's equations:\n  " + "\n  ".join(bad)


# --------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def cfg():
    return load_config()


@pytest.fixture(scope="module")
def paper(cfg):
    return PaperModel(cfg)


@pytest.fixture(scope="module")
def compiled():
    """The compiled model as the simulator uses it: prepare() at 10 kn (K_Q calibrated, engine power packed)."""
    from mmg.model import STATE_NAMES
    from mmg.ship import load_ship
    from mmg.simulation import prepare

    assert tuple(STATE_NAMES) == STATE_ORDER
    return prepare(load_ship(SHIP_YAML), U_APPROACH)


def compiled_rhs(packed, X, cmd):
    from mmg.model import rhs

    out = np.zeros_like(X)
    buf = np.zeros(8)
    for i in range(X.shape[0]):
        rhs(np.ascontiguousarray(X[i]), float(cmd[i]), *packed.args(), buf)
        out[i] = buf
    return out


def compiled_forces(packed, X):
    from mmg.model import forces

    return np.array([forces(np.ascontiguousarray(x), *packed.args())[:3] for x in X])


# --------------------------------------------------------------------------- the config is the paper


def test_config_is_the_paper(cfg):
    """Every number the paper prints is in the ship config unchanged (Tables 1-4, eqs. 12-20)."""
    pa, pr, ru, st, en = cfg["particulars"], cfg["propeller"], cfg["rudder"], cfg["steering"], cfg["engine"]
    t1 = PAPER_TABLE1
    got = {"L": _si(pa["L"]), "B": _si(pa["B"]), "T": _si(pa["T"]), "C_b": pa["C_b"], "A_w": _si(pa["S_wetted"]),
           "D_P": _si(pr["D"]), "P": _si(pr["P"]), "A_R": _si(ru["A_R"]), "H_R": _si(ru["H_R"]),
           "delta_max_deg": _si(st["delta_max"]) / DEGREE, "delta_rate_max_deg_s": _si(st["rate_max"]) / DEGREE}
    for k, v in got.items():
        assert v == pytest.approx(t1[k], rel=1e-12), f"Table 1 {k}"
    # Table 2: value and the term it multiplies in eqs. (4)-(6)
    hull = cfg["hull"]["coefficients"]
    assert set(hull) == set(PAPER_TABLE2), "hull coefficient names"
    for name, (value, term) in PAPER_TABLE2.items():
        assert hull[name]["value"] == pytest.approx(value, rel=1e-12), f"Table 2 {name}"
        assert hull[name]["term"] == term, f"eqs. (4)-(6): {name} multiplies {term}"
    t3 = PAPER_TABLE3
    assert ru["eta"] == t3["eta"] and ru["f_alpha"] == t3["C_N"] and ru["epsilon"] == t3["epsilon"]
    assert ru["gamma_R_pos"] == t3["gamma"] and ru["gamma_R_neg"] == t3["gamma"]
    assert ru["t_R"] == t3["t_R"] and ru["a_H"] == t3["a_H"] and ru["x_H_prime"] == t3["x_H"]
    assert tuple(pr["K_T"]) == PAPER_KT and tuple(pr["t_P"]) == PAPER_TP0 and tuple(pr["w_P0"]) == PAPER_WP0
    assert en["mode"] == "constant_power"
    assert tuple(en["SHP_0"]) == PAPER_SHP0 and en["watts_per_hp"] == PAPER_W_PER_SHP
    assert en["shaft_inertia_coefficient"] == PAPER_SHAFT_INERTIA_COEF
    assert _si(st["T_E"]) == PAPER_T_E
    # CHOICE (config comment): Kijima wake w_P = w_P0 exp(-4 beta_P^2)
    assert pr["wake"]["model"] == "kijima" and pr["wake"]["C_wake"] == 4.0


def test_config_constants_follow_the_papers_relations(cfg):
    """The constants the paper derives (eqs. 8, 10, 11; Table 3) hold for the config's numbers."""
    pa, ms, ru, pr = cfg["particulars"], cfg["mass"], cfg["rudder"], cfg["propeller"]
    L, B, T, Cb = _si(pa["L"]), _si(pa["B"]), _si(pa["T"]), pa["C_b"]
    hull = {k: c["value"] for k, c in cfg["hull"]["coefficients"].items()}
    # eq. (11): X_uu = -A_w/(L T) C_r with C_r = 0.002256 (Table 2 prints 3 digits)
    assert -_si(pa["S_wetted"]) / (L * T) * PAPER_C_R == pytest.approx(hull["X_uu"], rel=1e-3)
    # eqs. (8), (10): X_br = (c_m - 1) Y_vdot = (1 - c_m) m_y'  (fact sheet s. 1: m_y' implied by Table 2)
    c_m = PAPER_CM[0] + PAPER_CM[1] * Cb
    assert (1.0 - c_m) * ms["m_y_prime"] == pytest.approx(hull["X_br"], rel=2e-3)
    # primes on 1/2 rho L^2 T: m' = 2 C_b B / L (fact sheet s. 0), Y_r = m' + m_x' - 1.5 C_b B/L (s. 1)
    assert ms["m_prime"] == pytest.approx(2 * Cb * B / L, rel=1e-3)
    assert ms["m_prime"] + ms["m_x_prime"] - 1.5 * Cb * B / L == pytest.approx(hull["Y_r"], rel=1e-3)
    # Table 3: C_N = 6.13 lambda / (lambda + 2.25) plays f_alpha; eta = D_P / H_R
    lam = PAPER_TABLE3["lambda"]
    assert 6.13 * lam / (lam + 2.25) == pytest.approx(ru["f_alpha"], rel=1e-3)
    assert _si(pr["D"]) / _si(ru["H_R"]) == pytest.approx(ru["eta"], rel=1e-3)


def test_config_keeps_the_fact_sheet_choices(cfg):
    """The constants the paper omits are the fact sheet's documented choices (not paper values: a deliberate
    change must update the fact sheet and this test together)."""
    pa, ms, ru, pr = cfg["particulars"], cfg["mass"], cfg["rudder"], cfg["propeller"]
    assert _si(pa["x_G"]) == 0.0 and _si(pa["rho"]) == 1025.0                          # s. 4, eqs. (1)-(3) about G
    assert ms["I_zG_prime"] == pytest.approx(ms["m_prime"] * 0.25**2, rel=1e-3)        # s. 4: k_zz = 0.25 L
    assert ms["J_z_prime"] == 0.0117                                                   # s. 4: Zhou
    assert ru["kappa"] == pytest.approx(0.6 / ru["epsilon"], rel=1e-3)                 # s. 2: kappa = 0.6/eps
    assert ru["x_R_prime"] == -0.5 and ru["l_R_prime"] == 2 * ru["x_R_prime"]          # s. 2: l_R' = 2 x_R'
    assert pr["wake"]["x_P_prime"] == -0.5                                             # s. 3
    assert tuple(pr["K_Q"]) == (0.03521, -0.02800, -0.01562)                           # s. 3: B-series Z=4 fit


# --------------------------------------------------------------------------- compiled vs paper


def test_straight_run_is_the_papers(paper, compiled):
    """prepare() solves the same 10 kn straight run as the paper's equations; n_0 is Table 4's 54.12 rpm."""
    packed, eq = compiled
    assert eq.u == U_APPROACH
    assert eq.n == pytest.approx(paper.n0, rel=1e-9)
    assert eq.delta == pytest.approx(paper.delta0, rel=1e-6, abs=1e-12)
    assert eq.v == pytest.approx(paper.v0, rel=1e-6, abs=1e-12)
    assert eq.power_W == pytest.approx(paper.P0, rel=1e-12)
    assert eq.K_Q_scale == pytest.approx(paper.kq_scale, rel=1e-9)
    assert abs(paper.n0 * 60.0 - PAPER_N0_RPM) < 0.3
    # and the paper's equations are at rest there (all eight derivatives)
    x0 = np.array([[eq.u, eq.v, 0.0, 0.0, 0.0, 0.0, eq.delta, eq.n]])
    d = paper.derivative(x0, np.array([eq.delta]))[0]
    assert np.all(np.abs(d[[IU, IV, IR, IDELTA, IN]]) < 1e-9)


def test_forces_match_the_paper_at_random_states(paper, compiled):
    """Total X, Y [N] and N [N m] of the compiled model = eqs. (4)-(6) + propeller + rudder, 400 states."""
    packed, _ = compiled
    X, _ = random_states(np.random.default_rng(19990701), 400)
    got = compiled_forces(packed, X)
    ref = np.column_stack(paper.total_forces(X[:, IU], X[:, IV], X[:, IR], X[:, IDELTA], X[:, IN]))
    assert_close_per_column(got, ref, ("X", "Y", "N"))


def test_state_derivative_matches_the_paper_at_random_states(paper, compiled):
    """All eight derivatives of rhs() = eqs. (1)-(3), (9), (15)-(20) of the paper, 400 random states."""
    packed, _ = compiled
    X, cmd = random_states(np.random.default_rng(1999), 400)
    got = compiled_rhs(packed, X, cmd)
    ref = paper.derivative(X, cmd)
    assert_close_per_column(got, ref, STATE_ORDER)


def test_each_hull_term_is_seen(paper, compiled):
    """Discrimination check of the comparison itself: flipping any one Table 2 coefficient's sign in the
    reference moves some derivative by far more than the tolerance at these states."""
    packed, _ = compiled
    X, cmd = random_states(np.random.default_rng(7), 400)
    got = compiled_rhs(packed, X, cmd)
    base = paper.c.copy()
    try:
        for name in base:
            paper.c = {**base, name: -base[name]}
            ref = paper.derivative(X, cmd)
            rel = max(np.max(np.abs(got[:, j] - ref[:, j])) / np.max(np.abs(ref[:, j])) for j in (IU, IV, IR))
            assert rel > 1e-4, f"a sign flip of {name} is invisible to the comparison ({rel:.2e})"
    finally:
        paper.c = base


def test_midship_equations_with_x_G(cfg):
    """x_G != 0 (not used by the paper's Esso Osaka, x_G = 0): the compiled midship equations are the
    MMG 2015 ones (Yasukawa & Yoshimura 2015), so a later change of x_G does not bring in wrong terms."""
    from mmg.ship import ship_from_dict
    from mmg.simulation import prepare

    cfg_g = {**cfg, "particulars": {**cfg["particulars"], "x_G": "10.3 m"}}
    paper_g = PaperModel(cfg_g)
    packed, eq = prepare(ship_from_dict(cfg_g), U_APPROACH)
    assert eq.n == pytest.approx(paper_g.n0, rel=1e-9)
    X, cmd = random_states(np.random.default_rng(103), 200)
    assert_close_per_column(compiled_rhs(packed, X, cmd), paper_g.derivative(X, cmd), STATE_ORDER)
