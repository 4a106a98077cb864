"""A learned correction of the MMG model's residual forces: an MMG + regression hybrid.

The identified MMG model (:mod:`trials.measured.identify`) leaves on each training record a residual
force, what the measured motion needed beyond what the model gives at the measured state:

    F_res = M (a_meas - a_MMG(u, v, r, delta, n, wind)),

``M`` the model's mass matrix about midship (rigid body and added mass: the inverse of
:func:`mmg.model.inverse_mass`), ``a_meas`` the measured accelerations (du/dt, dv/dt, dr/dt: a
Savitzky-Golay derivative of the logged u, v, r over :data:`SMOOTH_L` sqrt(L/g), cubic) and ``a_MMG``
the model's right-hand side (:func:`mmg.replay.deriv`: hull, propeller, rudder, the run's wind
loads).  It is made nondimensional with the speed scale

    V^2 = u^2 + v^2 + (n D)^2 + U_low^2

(:func:`speed_scale`: the flow past the hull and through the propeller; U_low the model's low-speed
floor, so that V > 0 at rest): X' = X / (1/2 rho L T V^2), Y' likewise, N' = N / (1/2 rho L^2 T V^2).
A regressor maps the features (:data:`FEATURES`: u/V, v/V, r L/V, n D/V, delta [rad]; all bounded
but r L/V) to (X', Y', N').  Two forms (:data:`KINDS`), both evaluated in compiled code inside the
replay:

* ``"ridge"``: ridge regression on the monomials up to ``degree`` of the standardised features;
* ``"mlp"``: one hidden layer of ``hidden`` tanh units (scikit-learn's ``MLPRegressor``), L2 penalty.

The penalty (``alpha``) is chosen by a grouped cross-validation over the training records only
(scikit-learn's ``GroupKFold``, a record and its cut copies one group,
:func:`trials.measured.identify.same_run_groups`): the lowest held-out weighted mean square of the
standardised residual forces.  The fit weights each sample by V^4 (a least-squares fit of the
dimensional force: a drifting ship with the propeller stopped, whose nondimensional residual is mostly
noise, counts little).

Out of the training data: the box between the 0.1 and 99.9 percentiles of each training feature
(:attr:`Correction.lo`, :attr:`Correction.hi`).  A state outside it is *flagged*
(:meth:`Correction.outside`), and the correction there is the one at the nearest point of the box,
damped by exp(-(d / :data:`TAPER_SD`)^2) with d the distance outside the box in training standard
deviations: far outside, the model is the MMG model alone.

The corrected replay (:func:`hybrid_states`) is the open-loop replay of :mod:`mmg.replay` (its
right-hand side and RK4 step, :func:`mmg.kernel.rk4_step`) plus the correction force through the
inverse mass matrix; the uncorrected replay is not touched.  Runs with effects besides the wind loads
(a current, a rudder offset) are refused.  Needs scikit-learn (the ``hybrid`` extra) to fit, not to
replay.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from mmg._jit import carray, njit
from mmg.kernel import rk4_step
from mmg.model import G, P_D, P_L, P_RHO, P_T, P_ULOW, PackedShip, inverse_mass, pack
from mmg.replay import ZERO6, ReplayInputs, axpy6, default_dt_max, deriv, replay_rhs

from .predict import MeasuredRun, Replayed
from .window import EVERY_S, WINDOW_S, WindowScores, _window_run, window_bounds

__all__ = ["Correction", "CorrectionForm", "CorrectionSelection", "ResidualSamples", "residual_samples",
           "fit_correction", "hybrid_states", "replay_hybrid",
           "hybrid_window_scores", "speed_scale", "FEATURES", "KINDS", "SMOOTH_L", "TAPER_SD", "ALPHAS", "SELECT",
           "fit_output_correction", "OUTPUT_ALPHAS"]

FEATURES = ("u/V", "v/V", "rL/V", "nD/V", "delta")
"""The correction's inputs, in order: u/V, v/V, r L/V, n D/V (V: :func:`speed_scale`), rudder angle [rad]."""
KINDS = ("ridge", "mlp")
"""The regressor forms (module docstring)."""
SMOOTH_L = 4.0
"""Savitzky-Golay window of the measured accelerations in units of sqrt(L/g) (2.2 s on a 3 m model)."""
TAPER_SD = 0.25
"""Width of the damping of the correction outside the training box [training standard deviations]."""
ALPHAS = {"ridge": (1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0, 1000.0), "mlp": (1e-4, 1e-2, 1.0)}
"""The penalties the grouped cross-validation chooses among, per form."""
_K = len(FEATURES)


@njit(cache=True, error_model="numpy", inline="always")
def _scale_sq(u, v, n, p):
    """V^2 [m^2/s^2] of :func:`speed_scale`."""
    nd = n * p[P_D]
    return u * u + v * v + nd * nd + p[P_ULOW] * p[P_ULOW]


def speed_scale(u, v, n, packed: PackedShip) -> np.ndarray:
    """V = sqrt(u^2 + v^2 + (n D)^2 + U_low^2) [m/s] of u, v [m/s] and n [rps] (arrays): the speed that makes
    the residual forces nondimensional (module docstring)."""
    p = packed.p
    return np.sqrt(np.asarray(u) ** 2 + np.asarray(v) ** 2 + (np.asarray(n) * p[P_D]) ** 2 + p[P_ULOW] ** 2)


def _features(u, v, r, n, delta, packed: PackedShip) -> np.ndarray:
    """(N, 5) features (:data:`FEATURES`) of arrays of states and inputs."""
    V = speed_scale(u, v, n, packed)
    return np.column_stack([u / V, v / V, r * packed.p[P_L] / V, n * packed.p[P_D] / V, delta])


def _force_units(V, packed: PackedShip) -> np.ndarray:
    """(N, 3) force scales 1/2 rho L T V^2 [N], the same, 1/2 rho L^2 T V^2 [N m]."""
    p = packed.p
    f = 0.5 * p[P_RHO] * p[P_L] * p[P_T] * np.asarray(V) ** 2
    return np.column_stack([f, f, f * p[P_L]])


@njit(cache=True, error_model="numpy")
def _model_accelerations(meas, delta, n, ext, minv, p, poly, hull_axis, hull_term, hull_coef, out):
    """The model's du/dt, dv/dt, dr/dt at each measured state (rows of ``meas``) with the sample's inputs."""
    for i in range(meas.shape[0]):
        s = (meas[i, 0], meas[i, 1], meas[i, 2], meas[i, 3], meas[i, 4], meas[i, 5])
        d = deriv(s, delta[i], n[i], ext[i, 0], ext[i, 1], ext[i, 2], minv, p, poly, hull_axis, hull_term, hull_coef)
        out[i, 0], out[i, 1], out[i, 2] = d[0], d[1], d[2]


@dataclass(frozen=True)
class ResidualSamples:
    """Residual forces of the MMG model on measured records (:func:`residual_samples`).

    Attributes
    ----------
    features : ndarray (N, 5)
        :data:`FEATURES` at each sample.
    target : ndarray (N, 3)
        Nondimensional residual X', Y', N' (module docstring).
    weight : ndarray (N,)
        V^4 [m^4/s^4]: the fit's sample weight (normalised there).
    group : ndarray (N,) of int
        The sample's record group (a record and its cut copies share one).
    record : ndarray (N,) of int
        The sample's record, an index into ``names``.
    names : list of str
        The records, in order of their samples.
    """

    features: np.ndarray
    target: np.ndarray
    weight: np.ndarray
    group: np.ndarray
    record: np.ndarray
    names: list

    def of(self, records) -> "ResidualSamples":
        """The samples of the records of indices ``records`` only."""
        kept = sorted(set(int(i) for i in records))
        keep = np.isin(self.record, kept)
        renumber = {old: new for new, old in enumerate(kept)}
        return ResidualSamples(self.features[keep], self.target[keep], self.weight[keep], self.group[keep],
                               np.array([renumber[int(i)] for i in self.record[keep]], dtype=self.record.dtype),
                               [self.names[i] for i in kept])


def _check_run(run: MeasuredRun) -> None:
    if run.effects is not None:
        raise ValueError(f"{run.name}: the learned correction handles runs whose only effect is the wind loads; "
                         f"this one has {', '.join(type(e).__name__ for e, _ in run.effects.items)}")


def _measured_accelerations(run: MeasuredRun, L: float) -> np.ndarray:
    from scipy.signal import savgol_filter

    dt = float(np.median(np.diff(run.t)))
    w = max(5, int(round(SMOOTH_L * np.sqrt(L / G) / dt)) | 1)
    w = min(w, len(run.t) - (1 - len(run.t) % 2))           # odd, within the record
    if w <= 3:
        return np.gradient(run.meas[:, :3], run.t, axis=0)
    return savgol_filter(run.meas[:, :3], w, 3, deriv=1, delta=dt, axis=0, mode="interp")


def residual_samples(packed: PackedShip, runs: list[MeasuredRun], stride: int = 1) -> ResidualSamples:
    """The residual forces of the model ``packed`` on each of ``runs`` (module docstring), every ``stride``-th sample.

    Parameters
    ----------
    packed : PackedShip
        The MMG model (:func:`mmg.model.pack` of the identified ship).
    runs : list of MeasuredRun
        The records, their wind loads as the model replays them
        (:meth:`trials.measured.identify.Identification.replay`: scaled by the fitted wind factors).
    stride : int
        Keep every ``stride``-th sample.
    """
    from .identify import same_run_groups

    L = float(packed.p[P_L])
    minv = np.array(inverse_mass(packed.p, np.zeros(8)))
    M = np.linalg.inv(minv.reshape(3, 3))
    groups = same_run_groups(runs)
    F, Y, W, G, R = [], [], [], [], []
    for j, (run, g) in enumerate(zip(runs, groups)):
        _check_run(run)
        m, inp = run.meas, run.inputs
        a_mod = np.empty((len(run.t), 3))
        _model_accelerations(carray(m), carray(inp.delta), carray(inp.n), carray(inp.external()), minv,
                             *(carray(a, a.dtype) for a in packed.args()), a_mod)
        force = (_measured_accelerations(run, L) - a_mod) @ M.T
        V = speed_scale(m[:, 0], m[:, 1], inp.n, packed)
        f = _features(m[:, 0], m[:, 1], m[:, 2], inp.n, inp.delta, packed)
        y = force / _force_units(V, packed)
        keep = np.zeros(len(run.t), bool)
        keep[::stride] = True
        keep &= np.isfinite(f).all(axis=1) & np.isfinite(y).all(axis=1)
        F.append(f[keep]); Y.append(y[keep]); W.append(V[keep] ** 4); G.append(np.full(int(keep.sum()), g))  # noqa: E702
        R.append(np.full(int(keep.sum()), j))
    return ResidualSamples(np.concatenate(F), np.concatenate(Y), np.concatenate(W), np.concatenate(G),
                           np.concatenate(R), [r.name for r in runs])


@dataclass(frozen=True)
class Correction:
    """A fitted correction of the residual forces (:func:`fit_correction`), ready for the compiled replay.

    Its value at the features f (:data:`FEATURES`) is, with z = (clip(f, lo, hi) - mu) / sd,
    ``b2 + h(z) @ W2`` (X', Y', N'; :attr:`b2`, :attr:`W2` include the targets' scale), ``h_k(z)`` the
    monomial prod_j z_j^A[k, j] (``"ridge"``) or tanh(b1_k + sum_j A[k, j] z_j) (``"mlp"``), times the
    damping exp(-(d / :data:`TAPER_SD`)^2) outside the training box (module docstring).

    Attributes
    ----------
    kind : str
        ``"ridge"`` or ``"mlp"``.
    mu, sd, lo, hi : ndarray (5,)
        The training features' mean, standard deviation and box (0.1 and 99.9 percentiles).
    A, b1, W2, b2 : ndarray
        The evaluation arrays (above): (m, 5), (m,), (m, 3), (3,).
    alpha : float
        The penalty the grouped cross-validation chose.
    cv : dict
        Each penalty tried: its grouped held-out weighted mean square of the standardised residuals.
    degree, hidden : int
        The ridge's polynomial degree / the network's hidden units (0 for the other form).
    records : list of str
        The training records (the only ones the fit saw).
    r2 : float
        The share of the weighted variance of the standardised residuals the fit explains on its training
        samples.
    """

    kind: str
    mu: np.ndarray
    sd: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    A: np.ndarray
    b1: np.ndarray
    W2: np.ndarray
    b2: np.ndarray
    alpha: float
    cv: dict = field(default_factory=dict)
    degree: int = 0
    hidden: int = 0
    records: list = field(default_factory=list)
    r2: float = float("nan")

    @property
    def label(self) -> str:
        """``ridge-2`` (form and degree) or ``mlp-16`` (form and hidden units)."""
        return f"{self.kind}-{self.degree if self.kind == 'ridge' else self.hidden}"

    def arrays(self) -> tuple:
        """The arguments of the compiled evaluation: (kind code, mu, sd, lo, hi, A, b1, W2, b2, taper)."""
        return (KINDS.index(self.kind), *(np.ascontiguousarray(a, float) for a in
                                           (self.mu, self.sd, self.lo, self.hi, self.A, self.b1, self.W2, self.b2)),
                float(TAPER_SD))

    def outside(self, features: np.ndarray) -> np.ndarray:
        """Whether each row of ``features`` (N, 5) lies outside the training box (a flag, bool (N,))."""
        f = np.asarray(features, float)
        return np.any((f < self.lo) | (f > self.hi), axis=1)

    def predict(self, features: np.ndarray) -> np.ndarray:
        """The correction (X', Y', N') at each row of ``features`` (N, 5), damped outside the box, (N, 3)."""
        f = np.ascontiguousarray(features, float)
        out = np.empty((len(f), 3))
        _eval_rows(f, *self.arrays(), out)
        return out

    def outside_share(self, packed: PackedShip, run: MeasuredRun) -> float:
        """The share of ``run``'s measured samples outside the training box (0 to 1)."""
        m = run.meas
        return float(self.outside(_features(m[:, 0], m[:, 1], m[:, 2], run.inputs.n, run.inputs.delta, packed)).mean())

    def to_json(self) -> dict:
        """The form, penalty, cross-validation table, training fit, box and records (not the arrays)."""
        return {"kind": self.kind, "label": self.label, "alpha": self.alpha, "cv": {f"{a:g}": v for a, v in self.cv.items()},
                "r2_train": self.r2, "box": {n: [float(a), float(b)] for n, a, b in zip(FEATURES, self.lo, self.hi)},
                "records": list(self.records)}


@njit(cache=True, error_model="numpy", inline="always")
def _correction(f0, f1, f2, f3, f4, kind, mu, sd, lo, hi, A, b1, W2, b2, taper):
    """(X', Y', N') of the correction at the features f0..f4 (:class:`Correction`)."""
    z = np.empty(5)
    d2 = 0.0
    for j, fj in enumerate((f0, f1, f2, f3, f4)):
        c = min(max(fj, lo[j]), hi[j])
        d2 += ((fj - c) / sd[j]) ** 2
        z[j] = (c - mu[j]) / sd[j]
    o0, o1, o2 = b2[0], b2[1], b2[2]
    for k in range(A.shape[0]):
        if kind == 0:
            h = 1.0
            for j in range(5):
                e = int(A[k, j])
                for _ in range(e):
                    h *= z[j]
        else:
            a = b1[k]
            for j in range(5):
                a += A[k, j] * z[j]
            h = np.tanh(a)
        o0 += h * W2[k, 0]
        o1 += h * W2[k, 1]
        o2 += h * W2[k, 2]
    w = np.exp(-d2 / (taper * taper)) if d2 > 0.0 else 1.0
    return o0 * w, o1 * w, o2 * w


@njit(cache=True, error_model="numpy")
def _eval_rows(f, kind, mu, sd, lo, hi, A, b1, W2, b2, taper, out):
    for i in range(f.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = _correction(f[i, 0], f[i, 1], f[i, 2], f[i, 3], f[i, 4], kind, mu, sd, lo,
                                                      hi, A, b1, W2, b2, taper)


@njit(cache=True, error_model="numpy", inline="always")
def _hybrid_rhs(y, tau, args):
    """The replay's right-hand side (:func:`mmg.replay.replay_rhs`) plus the correction's accelerations."""
    base, corr = args
    k, m, i, delta, n, minv, p = base[0], base[1], base[2], base[3], base[4], base[6], base[7]
    d0 = replay_rhs(y, tau, base)
    a = (k + tau) / m
    d = delta[i] + a * (delta[i + 1] - delta[i])
    nn = n[i] + a * (n[i + 1] - n[i])
    u, v, r = y[0], y[1], y[2]
    V2 = u * u + v * v + (nn * p[P_D]) ** 2 + p[P_ULOW] * p[P_ULOW]
    V = np.sqrt(V2)
    kind, mu, sd, lo, hi, A, b1, W2, b2, taper = corr
    cx, cy, cn = _correction(u / V, v / V, r * p[P_L] / V, nn * p[P_D] / V, d, kind, mu, sd, lo, hi, A, b1, W2, b2,
                             taper)
    q = 0.5 * p[P_RHO] * p[P_L] * p[P_T] * V2
    fx, fy, fn = cx * q, cy * q, cn * q * p[P_L]
    return (d0[0] + minv[0] * fx + minv[1] * fy + minv[2] * fn, d0[1] + minv[3] * fx + minv[4] * fy + minv[5] * fn,
            d0[2] + minv[6] * fx + minv[7] * fy + minv[8] * fn, d0[3], d0[4], d0[5])


@njit(cache=True, error_model="numpy")
def _hybrid_replay(t, delta, n, ext, s0, dt_max, minv, p, poly, hull_axis, hull_term, hull_coef, corr, out):
    """RK4 of the corrected dynamics along a record (sub-steps of at most ``dt_max``, inputs linear between
    samples, as :mod:`mmg.replay`); fills ``out`` (N, 6), NaN after a divergence."""
    N = t.shape[0]
    s = (s0[0], s0[1], s0[2], s0[3], s0[4], s0[5])
    for j in range(6):
        out[0, j] = s[j]
    for i in range(N - 1):
        h = t[i + 1] - t[i]
        m = max(1, int(np.ceil(h / dt_max - 1e-9)))
        dt = h / m
        for k in range(m):
            s = rk4_step(_hybrid_rhs, axpy6, ZERO6, s, dt,
                         ((k, m, i, delta, n, ext, minv, p, poly, hull_axis, hull_term, hull_coef), corr))
        bad = False
        for j in range(6):
            if not np.isfinite(s[j]):
                bad = True
        for j in range(6):
            out[i + 1, j] = np.nan if bad else s[j]
        if bad:
            for ii in range(i + 2, N):
                for j in range(6):
                    out[ii, j] = np.nan
            return


def hybrid_states(packed: PackedShip, inputs: ReplayInputs, s0, correction: Correction,
                  dt_max: float | None = None) -> np.ndarray:
    """The states (N, 6) of :data:`mmg.replay.STATE` replayed open loop with the correction (NaN after a
    divergence): :func:`mmg.replay.replay_states` (no resets) with the correction's forces added."""
    t = np.ascontiguousarray(inputs.t, dtype=float)
    if dt_max is None:
        dt_max = default_dt_max(float(packed.p[P_L]))
    out = np.empty((len(t), 6))
    minv = np.array(inverse_mass(packed.p, np.zeros(8)))
    _hybrid_replay(carray(t), carray(inputs.delta), carray(inputs.n), carray(inputs.external()),
                   carray(np.asarray(s0, float)), float(dt_max), minv, *(carray(a, a.dtype) for a in packed.args()),
                   correction.arrays(), out)
    return out


def replay_hybrid(ship, run: MeasuredRun, correction: Correction, packed: PackedShip | None = None) -> Replayed:
    """Replay ``run`` open loop from its first measured state with ``ship`` and the correction
    (:func:`trials.measured.predict.replay_record`'s result, scored the same way).  ``run``'s wind loads as the
    model replays them (:func:`residual_samples`)."""
    _check_run(run)
    packed = packed or pack(ship)
    pred = hybrid_states(packed, run.inputs, run.meas[0], correction)
    return Replayed(run=run, pred=pred, L=ship.particulars.L, B=ship.particulars.B)


def hybrid_window_scores(ship, run: MeasuredRun, correction: Correction, window_s: float = WINDOW_S,
                         every_s: float = EVERY_S, packed: PackedShip | None = None) -> WindowScores:
    """:func:`trials.measured.window.window_scores` of the corrected model: each window replayed from the
    measured state at its start (:func:`replay_hybrid`) and scored by its heading RMS and final position error."""
    bounds, short = window_bounds(run.t, window_s, every_s)
    packed = packed or pack(ship)
    rows = []
    for i0, i1 in bounds:
        s = replay_hybrid(ship, _window_run(run, i0, i1), correction, packed).scores()
        rows.append((run.t[i0], run.t[i1], s["heading_rms_deg"], s["final_position_error_m"], s["final_position_error_L"]))
    a = np.array(rows, float).reshape(-1, 5)
    return WindowScores(name=run.name, window_s=float(window_s), every_s=float(every_s), start_s=a[:, 0], end_s=a[:, 1],
                        heading_rms_deg=a[:, 2], position_error_m=a[:, 3], position_error_L=a[:, 4], short=short)


def _maker(kind: str, degree: int, hidden: int, seed: int):
    from sklearn.linear_model import Ridge
    from sklearn.neural_network import MLPRegressor
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import PolynomialFeatures

    if kind == "ridge":
        return lambda a: _Weighted(make_pipeline(PolynomialFeatures(degree, include_bias=False), Ridge(alpha=a)),
                                   "ridge__sample_weight")
    if kind == "mlp":
        return lambda a: MLPRegressor(hidden_layer_sizes=(hidden,), activation="tanh", alpha=a, max_iter=300, tol=1e-5,
                                      random_state=seed)
    raise ValueError(f"kind {kind!r}: one of {', '.join(KINDS)}")


class _Weighted:
    """A pipeline whose last step takes the sample weight (``fit(z, y, sample_weight=)``)."""

    def __init__(self, pipe, key: str):
        self.pipe, self.key = pipe, key

    def fit(self, z, y, sample_weight=None):
        self.pipe.fit(z, y, **{self.key: sample_weight})
        return self

    def predict(self, z):
        return self.pipe.predict(z)


SELECT = ("forces", "windows")
"""How :func:`fit_correction` chooses the penalty: by the grouped held-out residual forces, or by the grouped
held-out replays (60 s windows from the measured state; "off", no correction, a candidate too)."""


@dataclass(frozen=True)
class CorrectionForm:
    """The regressor form of a correction (module docstring, :data:`KINDS`).

    Attributes
    ----------
    kind : {"ridge", "mlp"}
        Ridge regression on the monomials of the standardised features, or one hidden layer of tanh units.
    degree : int
        Highest degree of the monomials (``"ridge"``).
    hidden : int
        Number of hidden tanh units (``"mlp"``).

    Raises
    ------
    ValueError
        A ``kind`` not in :data:`KINDS`.
    """

    kind: str = "ridge"
    degree: int = 2
    hidden: int = 16

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind {self.kind!r}: one of {', '.join(KINDS)}")


@dataclass(frozen=True)
class CorrectionSelection:
    """How :func:`fit_correction` samples the training records and chooses the penalty.

    Attributes
    ----------
    alphas : sequence of float or None
        The penalties to choose among (:data:`ALPHAS` of the form when None).
    folds : int
        Folds of the grouped cross-validation over the training records' groups that chooses the penalty.
    stride : int
        Every ``stride``-th sample is fitted (the residuals are smoothed over :data:`SMOOTH_L` sqrt(L/g) anyway).
    select : {"forces", "windows"}
        ``"forces"``: the penalty with the lowest held-out weighted mean square of the standardised residual
        forces; ``"windows"``: the one (or no correction, ``alpha`` inf) whose held-out records' 60 s windows
        replayed from the measured state have the fewest divergences, then the lowest mean heading RMS
        (:data:`SELECT`).

    Raises
    ------
    ValueError
        A ``select`` not in :data:`SELECT`.
    """

    alphas: tuple | None = None
    folds: int = 3
    stride: int = 2
    select: str = "forces"

    def __post_init__(self):
        if self.select not in SELECT:
            raise ValueError(f"select {self.select!r}: one of {', '.join(SELECT)}")


def fit_correction(packed: PackedShip, runs: list[MeasuredRun], form: CorrectionForm = CorrectionForm(),
                   selection: CorrectionSelection = CorrectionSelection(), seed: int = 0) -> Correction:
    """Fit the correction of ``packed``'s residual forces on the training records ``runs`` (module docstring).

    Parameters
    ----------
    packed : PackedShip
        The MMG model the correction adds to (the identified ship, packed).
    runs : list of MeasuredRun
        The training records only, their wind loads as the model replays them.
    form : CorrectionForm
        The regressor: a ridge polynomial of degree 2 by default.
    selection : CorrectionSelection
        The samples fitted and how the penalty is chosen: by the grouped held-out residual forces over 3
        folds, every 2nd sample, by default.
    seed : int
        The network's initial weights.

    Returns
    -------
    Correction
        With ``cv``: each penalty's cross-validated figure.
    """
    sel = selection
    s = residual_samples(packed, runs, sel.stride)
    make = _maker(form.kind, form.degree, form.hidden, seed)
    grid = tuple(ALPHAS[form.kind] if sel.alphas is None else sel.alphas)
    if sel.select == "forces":
        cv = _grouped_cv(make, s, grid, sel.folds)
        alpha = min(cv, key=cv.get)
    else:
        cv = _window_cv(make, s, packed, runs, grid, sel.folds, form)
        alpha = min(cv, key=lambda a: (cv[a]["diverged_windows"], cv[a]["mean_window_heading_rms_deg"]))
    c = _fit_fixed(make, s, alpha, form) if np.isfinite(alpha) else _off(s, form)
    return replace(c, cv=cv)


def _standardised(s: ResidualSamples):
    """The fit's inputs: box, feature and target scales, standardised features and targets, normalised weights."""
    f = s.features
    lo, hi = np.percentile(f, 0.1, axis=0), np.percentile(f, 99.9, axis=0)
    w = s.weight / s.weight.mean()
    mu, sd = f.mean(axis=0), f.std(axis=0)
    sd = np.where(sd > 0, sd, 1.0)
    ys = np.sqrt(np.average((s.target - np.average(s.target, 0, w)) ** 2, 0, w))     # the weighted spread
    ys = np.where(ys > 0, ys, 1.0)
    return lo, hi, mu, sd, ys, (np.clip(f, lo, hi) - mu) / sd, s.target / ys, w


def _grouped_cv(make, s: ResidualSamples, alphas, folds: int) -> dict:
    """{alpha: the held-out weighted mean square of the standardised residuals over a ``GroupKFold``}."""
    from sklearn.model_selection import GroupKFold

    _, _, _, _, _, z, y, w = _standardised(s)
    k = _n_splits(s.group, folds)
    out = {}
    for a in alphas:
        err, tot = 0.0, 0.0
        for tr, te in GroupKFold(n_splits=k).split(z, y, s.group):
            model = make(a).fit(z[tr], y[tr], sample_weight=w[tr])
            err += float(np.sum(w[te, None] * (model.predict(z[te]) - y[te]) ** 2))
            tot += float(np.sum(w[te])) * y.shape[1]
        out[float(a)] = err / tot
    return out


def _n_splits(groups, folds: int) -> int:
    k = min(folds, len(np.unique(groups)))
    if k < 2:
        raise ValueError("the grouped cross-validation of the penalty needs records of 2 or more runs")
    return k


def _window_cv(make, s: ResidualSamples, packed, runs, alphas, folds: int, form) -> dict:
    """{alpha (inf: no correction): {"mean_window_heading_rms_deg", "diverged_windows"}} of the held-out records
    of a ``GroupKFold`` over the training records, each replayed over its 60 s windows from the measured state."""
    from sklearn.model_selection import GroupKFold

    from .identify import same_run_groups

    groups = np.asarray(same_run_groups(runs))
    idx = np.arange(len(runs))
    rows = {float(a): [] for a in (*alphas, np.inf)}
    for tr, te in GroupKFold(n_splits=_n_splits(groups, folds)).split(idx, idx, groups):
        sub = s.of(tr)
        for a in rows:
            c = _fit_fixed(make, sub, a, form) if np.isfinite(a) else _off(sub, form)
            for j in te:
                rows[a].append(_window_headings(packed, runs[j], c))
    return {a: {"mean_window_heading_rms_deg": float(np.nanmean([np.nanmean(h) if np.isfinite(h).any() else np.nan
                                                                 for h in v])),
                "diverged_windows": int(sum(np.sum(~np.isfinite(h)) for h in v))} for a, v in rows.items()}


def _window_headings(packed: PackedShip, run: MeasuredRun, c: Correction) -> np.ndarray:
    """Heading RMS [deg] of each 60 s window of ``run`` replayed from its measured start with the correction."""
    bounds, _ = window_bounds(run.t)
    out = []
    for i0, i1 in bounds:
        w = _window_run(run, i0, i1)
        p = hybrid_states(packed, w.inputs, w.meas[0], c)
        out.append(float(np.sqrt(np.mean(np.degrees(p[:, 5] - w.meas[:, 5]) ** 2))))
    return np.array(out)


def _fit_fixed(make, s: ResidualSamples, alpha: float, form) -> Correction:
    """The correction of penalty ``alpha`` fitted on all of ``s`` (``form``: :class:`CorrectionForm`)."""
    kind, degree, hidden = form.kind, form.degree, form.hidden
    lo, hi, mu, sd, ys, z, y, w = _standardised(s)
    model = make(alpha).fit(z, y, sample_weight=w)
    pred = model.predict(z)
    r2 = 1.0 - float(np.sum(w[:, None] * (pred - y) ** 2) / np.sum(w[:, None] * (y - np.average(y, 0, w)) ** 2))
    if kind == "ridge":
        poly, ridge = model.pipe.steps[0][1], model.pipe.steps[1][1]
        A, b1, W2, b2 = poly.powers_.astype(float), np.zeros(len(poly.powers_)), ridge.coef_.T, ridge.intercept_
    else:
        A, b1, W2, b2 = model.coefs_[0].T, model.intercepts_[0], model.coefs_[1], model.intercepts_[1]
    return Correction(kind=kind, mu=mu, sd=sd, lo=lo, hi=hi, A=np.asarray(A, float), b1=np.asarray(b1, float),
                      W2=np.asarray(W2, float) * ys, b2=np.asarray(b2, float) * ys, alpha=float(alpha),
                      degree=degree if kind == "ridge" else 0, hidden=hidden if kind == "mlp" else 0,
                      records=list(s.names), r2=r2)


def _off(s: ResidualSamples, form) -> Correction:
    """No correction (zero everywhere; ``alpha`` inf), with the training box of ``s`` (still a flag)."""
    kind, degree, hidden = form.kind, form.degree, form.hidden
    lo, hi, mu, sd = *np.percentile(s.features, [0.1, 99.9], axis=0), s.features.mean(0), s.features.std(0)
    return Correction(kind=kind, mu=mu, sd=np.where(sd > 0, sd, 1.0), lo=lo, hi=hi, A=np.zeros((1, 5)), b1=np.zeros(1),
                      W2=np.zeros((1, 3)), b2=np.zeros(3), alpha=float("inf"), degree=degree if kind == "ridge" else 0,
                      hidden=hidden if kind == "mlp" else 0, records=list(s.names), r2=0.0)


OUTPUT_ALPHAS = (1e-3, 1e-2, 1e-1, 1.0, 10.0)
"""Penalties of :func:`fit_output_correction`, relative to the mean diagonal of J^T J."""


def fit_output_correction(packed: PackedShip, runs: list[MeasuredRun], degree: int = 2, alphas=OUTPUT_ALPHAS,
                          folds: int = 3, stride: int = 5) -> Correction:
    """A ridge-polynomial correction fitted by output error: its coefficients minimise the replayed 60 s windows'
    errors on the training records ``runs``, not the residual forces.

    The coefficients theta (the monomials up to ``degree`` of the standardised features, :class:`Correction`
    ``"ridge"``; each output in units of the weighted spread of the residual forces, :func:`residual_samples`)
    are one Gauss-Newton step from zero (the MMG model alone): with r0 the windows' residuals at theta = 0 (u,
    v, r, heading at every ``stride``-th sample, scaled as :func:`trials.measured.identify.identify` scales
    them) and J their Jacobian (forward differences), theta = -(J^T J + alpha mean(diag J^T J) I)^-1 J^T r0.
    The penalty (``alphas``, relative) or no correction is chosen by a grouped cross-validation over the
    training records (:func:`fit_correction` ``select="windows"``: the held-out records' windows replayed
    with the step fitted on the others).  The basis (feature scales, box) is the training records' features.

    Returns
    -------
    Correction
        With ``cv``: each relative penalty's (and ``inf``: no correction's) held-out windows.
    """
    from sklearn.model_selection import GroupKFold
    from sklearn.preprocessing import PolynomialFeatures

    from .identify import same_run_groups

    s = residual_samples(packed, runs, 2)
    lo, hi, mu, sd, ys, *_ = _standardised(s)
    A = PolynomialFeatures(degree).fit(np.zeros((1, _K))).powers_.astype(float)
    base = Correction(kind="ridge", mu=mu, sd=sd, lo=lo, hi=hi, A=A, b1=np.zeros(len(A)), W2=np.zeros((len(A), 3)),
                      b2=np.zeros(3), alpha=float("inf"), degree=degree, records=list(s.names), r2=0.0)

    def with_theta(theta, alpha):
        return replace(base, W2=theta.reshape(len(A), 3) * ys, alpha=float(alpha))

    scales = _output_scales(runs, float(packed.p[P_L]))
    r0, rec = _window_residuals(packed, runs, base, stride, scales)
    J = _window_jacobian(packed, runs, base, stride, scales, r0, len(A) * 3, with_theta)
    groups = np.asarray(same_run_groups(runs))
    idx = np.arange(len(runs))
    rows = {float(a): [] for a in (*alphas, np.inf)}
    for tr, te in GroupKFold(n_splits=_n_splits(groups, folds)).split(idx, idx, groups):
        keep = np.isin(rec, tr)
        for a in rows:
            c = base if not np.isfinite(a) else with_theta(_ridge_step(J[keep], r0[keep], a), a)
            rows[a] += [_window_headings(packed, runs[j], c) for j in te]
    cv = {a: {"mean_window_heading_rms_deg": float(np.nanmean([np.nanmean(h) if np.isfinite(h).any() else np.nan
                                                               for h in v])),
              "diverged_windows": int(sum(np.sum(~np.isfinite(h)) for h in v))} for a, v in rows.items()}
    alpha = min(cv, key=lambda a: (cv[a]["diverged_windows"], cv[a]["mean_window_heading_rms_deg"]))
    c = base if not np.isfinite(alpha) else with_theta(_ridge_step(J, r0, alpha), alpha)
    return replace(c, cv=cv)


def _ridge_step(J, r0, alpha: float) -> np.ndarray:
    """-(J^T J + alpha mean(diag J^T J) I)^-1 J^T r0."""
    H = J.T @ J
    return -np.linalg.solve(H + alpha * np.mean(np.diag(H)) * np.eye(len(H)), J.T @ r0)


def _output_scales(runs, L: float) -> np.ndarray:
    """u, v [m/s], r [rad/s], heading [rad] residual scales: 5 % of the median speed, that over L, 2 deg."""
    U = float(np.median(np.concatenate([np.hypot(r.meas[:, 0], r.meas[:, 1]) for r in runs])))
    return np.array([0.05 * U, 0.05 * U, 0.05 * U / L, np.radians(2.0)])


def _window_residuals(packed, runs, c: Correction, stride: int, scales) -> tuple[np.ndarray, np.ndarray]:
    """The scaled u, v, r, heading errors of every 60 s window of ``runs`` replayed from its measured start with
    ``c`` (every ``stride``-th sample; a diverged sample's error 0), and each residual's record index."""
    out, rec = [], []
    for j, run in enumerate(runs):
        for i0, i1 in window_bounds(run.t)[0]:
            w = _window_run(run, i0, i1)
            p = hybrid_states(packed, w.inputs, w.meas[0], c)
            e = ((p[::stride] - w.meas[::stride])[:, [0, 1, 2, 5]] / scales).ravel()
            out.append(np.where(np.isfinite(e), e, 0.0))
            rec.append(np.full(len(e), j))
    return np.concatenate(out), np.concatenate(rec)


def _window_jacobian(packed, runs, base, stride, scales, r0, n: int, with_theta, h: float = 1e-2) -> np.ndarray:
    """Forward-difference Jacobian (len(r0), n) of :func:`_window_residuals` in theta at zero, step ``h``."""
    J = np.empty((len(r0), n))
    for k in range(n):
        th = np.zeros(n)
        th[k] = h
        J[:, k] = (_window_residuals(packed, runs, with_theta(th, 0.0), stride, scales)[0] - r0) / h
    return J
