"""The augmented EKF estimate of one trial (or several in turn), and its checks.

:func:`load_config` reads the estimation config (the bundled
``configs/estimation/rhee_kim.yaml``, overridable, keyed by coefficient name with defaults
for names it does not list); :func:`estimate` runs the filter on a
:class:`ekf.data.TrialData` and returns an :class:`Estimate` (``.final``, ``.to_pandas()``,
``.plot()``, ``.warnings()``, ``.free_run``); :func:`joint_estimate` runs it through several
trials in turn.  Building a TrialData from a log file or a trial YAML, and writing the
reports, is the trials layer's job (:mod:`trials.estimates.estimation`).
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from mmg.errors import InputError
from mmg.resources import config_path
from mmg.units import is_finite_number, to_si

from .data import PAPER_DERIVATIVES, TrialData
from .filter import NS, STATES, FilterResult, run_filter

CONFIG_KEYS = ("dt", "initial", "P0_is", "P0", "P0_default_relative_std", "Q", "R", "fit_checks", "divergence")
"""The keys of an estimation config; anything else is refused."""


# --------------------------------------------------------------------------- configuration


_NESTED = {"initial": ("scale", "values"), "fit_checks": ("froude_min", "froude_max", "rpm_mismatch", "length_mismatch"),
           "divergence": ("nis_window_s", "nis_max")}


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in (over or {}).items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _merge(out[k], v)
        else:
            out[k] = v
    return out


def _check_keys(cfg: dict, src: str) -> None:
    """Refuse keys the estimator does not know (a typo must not be ignored)."""
    for k in cfg:
        if k not in CONFIG_KEYS and k != "dt_s":
            raise InputError(src, str(k), f"unknown key; known: {', '.join(CONFIG_KEYS)}")
    for k, allowed in _NESTED.items():
        sub = cfg.get(k)
        if sub is None:
            continue
        if not isinstance(sub, dict):
            raise InputError(src, k, "expected a mapping")
        for kk in sub:
            if kk not in allowed:
                raise InputError(src, f"{k}.{kk}", f"unknown key; known: {', '.join(allowed)}")


def _set(cfg: dict, assignment: str) -> None:
    if "=" not in assignment:
        raise InputError("--set", assignment, "expected key.path=value")
    key, val = assignment.split("=", 1)
    key = key.strip()
    parts = key.split(".")
    if any(not p for p in parts):
        raise InputError("--set", key, "expected key.path=value with no empty part")
    if parts[0] not in CONFIG_KEYS:
        raise InputError("--set", key, f"unknown key {parts[0]!r}; known: {', '.join(CONFIG_KEYS)}")
    d = cfg
    for i, p in enumerate(parts[:-1]):
        if d.get(p) is None:
            d[p] = {}
        elif not isinstance(d[p], dict):
            raise InputError("--set", key, f"{'.'.join(parts[:i + 1])} is a value, not a mapping")
        d = d[p]
    try:
        d[parts[-1]] = float(val)
    except ValueError:
        try:
            d[parts[-1]] = yaml.safe_load(val)
        except yaml.YAMLError as e:
            problem = getattr(e, "problem", None) or e
            raise InputError("--set", key, f"cannot read the value {val!r} ({' '.join(str(problem).split())})") from None


def default_config_path() -> Path:
    """The bundled estimation config (Rhee & Kim's settings)."""
    return config_path("estimation", "rhee_kim.yaml")


def load_config(path: str | Path | dict | None = None, sets=()) -> dict:
    """The estimation config: the bundled default merged with ``path`` and ``--set`` assignments; validated.

    Parameters
    ----------
    path : str, Path or dict, optional
        A YAML file with any subset of the keys (:data:`CONFIG_KEYS`), or a dict of them.
    sets : sequence of str
        ``key.path=value`` assignments (``initial.scale=1.5``, ``R.ZZ20.u=0.1``, ``P0.Y_v=0.01``).

    Returns
    -------
    dict
        Validated; ``dt_s`` holds the filter step in seconds.

    Raises
    ------
    InputError
        Naming the file and the field: unknown keys, duplicate keys, a file that is not YAML
        text, non-positive or absurd covariances (see :data:`P0_VARIANCE_RANGE`,
        :data:`R_VARIANCE_RANGE`), a bad step.
    """
    from mmg.ship import read_yaml

    default = default_config_path()
    cfg = read_yaml(default)
    src = str(default)
    if isinstance(path, dict):
        src = "<config dict>"
        _check_keys(path, src)
        cfg = _merge(cfg, path)
    elif path is not None:
        src = str(path)
        over = read_yaml(path, empty_ok=True)
        _check_keys(over, src)
        cfg = _merge(cfg, over)
    for s in sets:
        _set(cfg, s)
    src = src + (" with --set " + " ".join(sets) if sets else "")
    _check_keys(cfg, src)
    _validate(cfg, src)
    return cfg


P0_VARIANCE_RANGE = (1e-20, 1e6)
"""Each initial variance (after squaring when ``P0_is: std``): 1e-20 to 1e6 in SI and primes.  The
paper's are 2e-4 to 0.5; outside this range the first covariance update is singular or overflows."""

R_VARIANCE_RANGE = (1e-20, 1e10)
"""Each measurement variance of R: 1e-20 to 1e10 (the paper's are 2e-4 to 0.5)."""

DT_RANGE = (1e-4, 60.0)
"""The filter step [s]: 0.1 ms to 60 s (the paper's is 0.1 s)."""


def _number(v) -> bool:
    return isinstance(v, (int, float)) and is_finite_number(v)


def _positive(v) -> bool:
    return _number(v) and v > 0


def _sub(cfg: dict, key: str, src: str) -> dict:
    v = cfg.get(key)
    if v is None:
        return {}
    if not isinstance(v, dict):
        raise InputError(src, key, f"expected a mapping, got {v!r}")
    return v


def _variance(x: float, is_std: bool, src: str, field: str, what: str = "P0") -> float:
    v = x * x if is_std else x
    lo, hi = P0_VARIANCE_RANGE if what == "P0" else R_VARIANCE_RANGE
    if not (np.isfinite(v) and lo <= v <= hi):
        how = f"{x:g} squared" if is_std else f"{x:g}"
        raise InputError(src, field, f"a variance of {how} is outside {lo:g} to {hi:g}: the covariance would be "
                                     "singular or overflow")
    return v


def _validate(cfg: dict, src: str) -> None:
    try:
        cfg["dt_s"] = to_si(cfg.get("dt"), "time", *DT_RANGE)
    except Exception as e:  # noqa: BLE001 - any bad dt is an input error
        raise InputError(src, "dt", f"bad time step ({e})") from None
    if cfg.get("P0_is") not in ("variance", "std"):
        raise InputError(src, "P0_is", f"must be 'variance' or 'std', got {cfg.get('P0_is')!r}")
    is_std = cfg["P0_is"] == "std"
    P0 = _sub(cfg, "P0", src)
    for name in STATES:
        if not _positive(P0.get(name)):
            raise InputError(src, f"P0.{name}", f"must be a positive number, got {P0.get(name)!r}")
    for name, v in P0.items():
        if not _positive(v):
            raise InputError(src, f"P0.{name}", f"must be a positive number, got {v!r}")
        _variance(float(v), is_std, src, f"P0.{name}")
    rel = cfg.get("P0_default_relative_std", 0.5)
    if not (_positive(rel) and rel <= 10):
        raise InputError(src, "P0_default_relative_std", f"must be a positive number at most 10, got {rel!r}")
    q = cfg.get("Q", 0.0)
    if not (_number(q) and 0 <= q <= P0_VARIANCE_RANGE[1]):
        raise InputError(src, "Q", f"must be a number from 0 to {P0_VARIANCE_RANGE[1]:g}, got {q!r}")
    initial = _sub(cfg, "initial", src)
    sc = initial.get("scale", 1.2)
    if not _number(sc):
        raise InputError(src, "initial.scale", f"must be a finite number, got {sc!r}")
    values = initial.get("values") or {}
    if not isinstance(values, dict):
        raise InputError(src, "initial.values", f"expected a mapping of derivative name to value, got {values!r}")
    for k, v in values.items():
        if not _number(v):
            raise InputError(src, f"initial.values.{k}", f"must be a finite number, got {v!r}")
    R = _sub(cfg, "R", src)
    if "default" not in R:
        raise InputError(src, "R.default", "missing")
    for trial, row in R.items():
        if not isinstance(row, dict):
            raise InputError(src, f"R.{trial}", f"expected a mapping of u, v, r, n, got {row!r}")
        for ch in row:
            if ch not in STATES:
                raise InputError(src, f"R.{trial}.{ch}", f"unknown channel; known: {', '.join(STATES)}")
        for ch in STATES:
            v = row.get(ch)
            if not _positive(v):
                raise InputError(src, f"R.{trial}.{ch}", f"must be a positive number, got {v!r}")
            _variance(float(v), False, src, f"R.{trial}.{ch}", "R")
    fc = _sub(cfg, "fit_checks", src)
    for k in ("froude_min", "froude_max", "rpm_mismatch", "length_mismatch"):
        if k in fc and not (_number(fc[k]) and fc[k] >= 0):
            raise InputError(src, f"fit_checks.{k}", f"must be a number 0 or more, got {fc[k]!r}")
    if _number(fc.get("froude_min")) and _number(fc.get("froude_max")) and fc["froude_min"] >= fc["froude_max"]:
        raise InputError(src, "fit_checks.froude_max", "must be above froude_min")
    dv = _sub(cfg, "divergence", src)
    if "nis_window_s" in dv and not _positive(dv["nis_window_s"]):
        raise InputError(src, "divergence.nis_window_s", f"must be a positive number, got {dv['nis_window_s']!r}")
    if "nis_max" in dv and not (_number(dv["nis_max"]) and dv["nis_max"] >= 0):
        raise InputError(src, "divergence.nis_max", f"must be a number 0 or more (0 disables), got {dv['nis_max']!r}")


def R_for(cfg: dict, trial: str) -> np.ndarray:
    """Diagonal R (4x4) of u, v, r, n for a trial name (Table 8; ``default`` otherwise)."""
    row = cfg["R"].get(trial, cfg["R"]["default"])
    return np.diag([float(row[c]) for c in STATES])


def P0_for(cfg: dict, names=PAPER_DERIVATIVES, reference: dict | None = None) -> np.ndarray:
    """Diagonal P0 of u, v, r, n and the coefficients ``names``.

    A coefficient the config's ``P0`` lists gets that entry (a variance or a std, ``P0_is``);
    any other gets the std ``P0_default_relative_std`` x |its reference value| (the ship
    file's; 0.5 by default, i.e. a prior wide enough for a 120 % start).

    Raises
    ------
    InputError
        When a name is neither listed nor has a nonzero reference value, or when a variance
        falls outside :data:`P0_VARIANCE_RANGE` (the covariance would be singular).
    """
    P0 = cfg["P0"]
    rel = float(cfg.get("P0_default_relative_std", 0.5))
    v = []
    for n in tuple(STATES) + tuple(names):
        if n in P0:
            v.append(_variance(float(P0[n]), cfg["P0_is"] == "std", "estimation config", f"P0.{n}"))
        elif reference is not None and reference.get(n):
            try:
                v.append(_variance(rel * float(reference[n]), True, "estimation config", f"P0.{n}"))
            except InputError:
                raise InputError("estimation config", f"P0.{n}",
                                 f"not given, and {rel:g} x the reference value {float(reference[n]):g} is not a "
                                 f"usable std (variance outside {P0_VARIANCE_RANGE[0]:g} to "
                                 f"{P0_VARIANCE_RANGE[1]:g}): give P0.{n}") from None
        else:
            raise InputError("estimation config", f"P0.{n}", "not given, and no nonzero reference value to scale a default from")
    return np.diag(np.asarray(v, float))


# --------------------------------------------------------------------------- estimation


HEADING_RMS_MAX_DEG = 1.0      # free-run check: heading RMS [deg] above which the model misses the log


@dataclass(frozen=True)
class FreeRun:
    """A trial re-simulated with estimated derivatives, against its log.

    The simulator runs from the logged approach (speed, rpm, first logged heading and position;
    no sway, no yaw rate) with the trial's own rudder logic switching on the *simulated* heading,
    so nothing is fitted: it is the check a naval architect makes by eye, "does the model with
    these derivatives sail the trial that was logged?".  Over ST35, ZZ10, ZZ20 and S-type 120
    (seed 1000) the true derivatives reproduce the logs to 0.007-0.04 deg heading RMS and
    0.2-1.7 m position RMS (the start state comes from noisy samples; L = 325 m); the paper
    EKF's estimates from a 120 % start to 0.04-0.26 deg and 0.9-2.5 m; from a 500 % start,
    where it converges to wrong values without diverging, to 2.3-17 deg and 75-223 m.

    Only the heading is judged (:attr:`ok`: RMS <= ``HEADING_RMS_MAX_DEG``, 1 deg): a uniform
    current, which the model does not know of, leaves the heading alone but moves the track
    (0.3 kn: 0.8 L position RMS over ZZ20 with the true derivatives), so the position RMS is
    reported, not judged.  A miss means the derivatives are wrong *or* the log holds an effect
    the model lacks: a 1 deg rudder offset alone gives 1.4 deg heading RMS on ZZ20.

    t (K,) log times [s]; log, sim (K, 4) heading [rad], x, y [m], shaft speed [rps] (``sim``
    None when the run stopped early, e.g. the speed fell to zero); L ship length [m].
    """

    trial: str
    t: np.ndarray
    log: np.ndarray
    sim: np.ndarray | None
    L: float

    @property
    def heading_rms_deg(self) -> float:
        return np.inf if self.sim is None else float(np.degrees(np.sqrt(np.mean((self.sim[:, 0] - self.log[:, 0]) ** 2))))

    @property
    def position_rms_m(self) -> float:
        if self.sim is None:
            return np.inf
        return float(np.sqrt(np.mean(np.sum((self.sim[:, 1:3] - self.log[:, 1:3]) ** 2, axis=1))))

    @property
    def ok(self) -> bool:
        return self.heading_rms_deg <= HEADING_RMS_MAX_DEG

    def to_dict(self) -> dict:
        """JSON-ready summary (RMS values None when the re-simulation stopped early)."""
        done = self.sim is not None
        return {"heading_rms_deg": self.heading_rms_deg if done else None,
                "position_rms_m": self.position_rms_m if done else None,
                "position_rms_L": self.position_rms_m / self.L if done else None,
                "heading_limit_deg": HEADING_RMS_MAX_DEG, "completed": done, "ok": self.ok}


def free_run(data: TrialData, values: dict) -> FreeRun | None:
    """Re-simulate ``data``'s trial with the derivatives ``values`` (:class:`FreeRun`); None when the
    log does not say how to rebuild its rudder logic (no turning/zigzag/S-type header) or the data
    are a joint record of several trials (no log of their own)."""
    from .output_error.trial import trial_from_data

    if data.record is None or data.joint:
        return None
    try:
        tr = trial_from_data(data, rudder="law")
    except (InputError, KeyError, ValueError):
        return None
    theta = np.array([values[n] for n in data.names], float)
    return FreeRun(data.name, tr.t_log, tr.obs, tr.simulate(theta, tr.nuisance0()), data.ship.particulars.L)


@dataclass
class Estimate:
    """An augmented-EKF estimate of one trial (or several in turn, :func:`joint_estimate`).

    Attributes
    ----------
    data : TrialData
    result : FilterResult
        The pass: time history of the states and coefficients and their variances.
    initial : dict
        Start values of the coefficients.
    R : ndarray (4, 4)
        Measurement covariance used.
    """

    data: TrialData
    result: FilterResult
    initial: dict
    R: np.ndarray

    @property
    def name(self) -> str:
        return self.data.name

    @property
    def final(self) -> dict:
        return self.result.final

    @cached_property
    def free_run(self) -> FreeRun | None:
        """The trial re-simulated with the final estimates, against the log (:func:`free_run`)."""
        return free_run(self.data, self.final)

    def warnings(self, min_shrink: float = 0.1) -> list[str]:
        """Signs that the pass is not to be trusted although it did not diverge.

        A filter whose derivative standard deviations shrank, in the median, by less than
        ``min_shrink`` (10 %) of their start values over the record has learned almost nothing
        from it: typically R is far too large, or the trial does not excite the derivatives.
        (With the paper's settings the median shrink is about 40 %; with R 1e6 times larger, 0.2 %.)
        And when the trial re-simulated with the estimates (:attr:`free_run`) misses the logged
        heading by more than 1 deg RMS, the estimated model does not reproduce the data: the filter
        converged to wrong values (with the paper's R the innovations stay small even then), or
        the log holds an effect the model lacks.
        """
        out = []
        sd0 = np.sqrt(self.result.pdiag[0, NS:])
        sd1 = np.sqrt(np.maximum(self.result.pdiag[-1, NS:], 0.0))
        shrink = 1.0 - sd1 / sd0
        if np.median(shrink) < min_shrink:
            out.append(f"trial {self.name!r}: the filter learned almost nothing over {self.result.t[-1]:.0f} s "
                       f"(the derivatives' standard deviations shrank by {100 * np.median(shrink):.1f} % in the median, "
                       f"at most {100 * shrink.max():.1f} %): R is probably far too large, or the trial does not "
                       f"excite them")
        fr = self.free_run
        if fr is not None and not fr.ok:
            miss = ("the re-simulation stopped early" if fr.sim is None else
                    f"it misses the logged heading by {fr.heading_rms_deg:.2f} deg RMS (limit {HEADING_RMS_MAX_DEG:g}; "
                    f"position RMS {fr.position_rms_m:.0f} m = {fr.position_rms_m / fr.L:.2f} L)")
            out.append(f"trial {self.name!r}: re-simulated with the estimated derivatives, {miss}: the estimated "
                       f"model does not reproduce the data. Either the filter converged to wrong values (try "
                       f"another start: initial.scale, P0, or --method output-error) or the log holds an effect "
                       f"the model lacks (rudder offset, wind, current, sensor bias)")
        return out

    def errors_pct(self) -> dict | None:
        """|final - true| / |true| in % by coefficient; None when the truth is not known."""
        tv = self.data.true_values
        if tv is None:
            return None
        return {n: 100.0 * abs(self.final[n] - tv[n]) / abs(tv[n]) for n in self.final}

    def to_pandas(self) -> pd.DataFrame:
        """The estimates: one row per coefficient with ``initial``, ``estimate``, ``std`` and,
        when the truth is known, ``true`` and ``error_pct``."""
        std = self.result.std
        err = self.errors_pct()
        rows = []
        for n, v in self.final.items():
            row = {"coefficient": n, "initial": self.initial[n], "estimate": v, "std": std[n]}
            if err is not None:
                row.update(true=self.data.true_values[n], error_pct=err[n])
            rows.append(row)
        return pd.DataFrame(rows).set_index("coefficient")

    def history(self) -> pd.DataFrame:
        """The filter's time history (:meth:`FilterResult.to_pandas`)."""
        return self.result.to_pandas()

    def plot(self, names=None, show: bool = False):
        """Convergence of the coefficients over the record (true values dashed where known); a Figure."""
        from .plots import convergence_figure

        return convergence_figure([self], names=names, show=show)


def initial_state(data: TrialData, cfg: dict) -> np.ndarray:
    """Start state: u, v, r, n of the first measurement, then the coefficients at ``initial.scale``
    x the reference values (or ``initial.values``)."""
    m = data.meas
    ini = cfg.get("initial", {})
    sc = float(ini.get("scale", 1.2))
    vals = ini.get("values") or {}
    for k in vals:
        if k not in data.names:
            raise InputError("estimation config", f"initial.values.{k}",
                             f"not an estimated coefficient of {data.ship.name}; estimated: {', '.join(data.names)}")
    der = [float(vals[n]) if n in vals else sc * data.reference[n] for n in data.names]
    return np.r_[m.u[0], m.v[0], m.r[0], m.n[0], der]


def estimate(data: TrialData, cfg: dict, engine: str = "compiled") -> Estimate:
    """Run the augmented EKF on one trial.

    Parameters
    ----------
    data : TrialData
    cfg : dict
        Estimation config (:func:`load_config`).
    engine : {"compiled", "filterpy"}
        ``"compiled"`` (default): :func:`ekf.filter.run_filter`, the numba loop (about half a second
        for 3000 s).  ``"filterpy"``: :class:`ekf.filterpy_ekf.AugmentedEKF` stepped in Python, the
        same predict and filterpy's Joseph-form update (about 100 x slower; the same numbers
        to rounding, ``tests/test_ekf.py``), for users who want to step or modify the filter.

    Returns
    -------
    Estimate

    Raises
    ------
    FilterDivergence
        Naming the trial and the time.
    """
    z0 = initial_state(data, cfg)
    R = R_for(cfg, data.name)
    P0 = P0_for(cfg, data.names, data.reference)
    q = float(cfg.get("Q", 0.0))
    dv = cfg.get("divergence", {})
    if engine == "filterpy":
        res = _filterpy_pass(data, z0, P0, R, q)
        return Estimate(data, res, dict(zip(data.names, z0[NS:])), R)
    if engine != "compiled":
        raise ValueError(f"engine must be 'compiled' or 'filterpy', not {engine!r}")
    res = run_filter(data.packed, data.slots, data.meas.t, data.meas.z(), data.meas.delta, z0, P0, R,
                     trial=data.name, q=q, nis_window_s=float(dv.get("nis_window_s", 60.0)),
                     nis_max=float(dv.get("nis_max", 20.0)), names=data.names)
    return Estimate(data, res, dict(zip(data.names, z0[NS:])), R)


def _filterpy_pass(data: TrialData, z0, P0, R, q: float) -> FilterResult:
    """The pass of :func:`run_filter` stepped with filterpy (:class:`ekf.filterpy_ekf.AugmentedEKF`)."""
    from .filter import FilterDivergence, is_pd
    from .filterpy_ekf import AugmentedEKF

    m = data.meas
    t = np.asarray(m.t, float)
    meas, delta = m.z(), np.asarray(m.delta, float)
    f = AugmentedEKF(data.packed, data.slots, float(t[1] - t[0]))
    f.x, f.P, f.R = np.asarray(z0, float).copy(), np.asarray(P0, float).copy(), np.asarray(R, float)
    f.Q = q * np.eye(len(z0))
    zs = np.empty((len(t), len(z0)))
    pd_ = np.empty_like(zs)
    zs[0], pd_[0] = f.x, np.diag(f.P)
    for k in range(1, len(t)):
        f.predict((delta[k - 1], delta[k]))
        f.update_uvrn(meas[k])
        if not (np.all(np.isfinite(f.x)) and f.x[0] > 0 and is_pd(f.P)):
            raise FilterDivergence(data.name, t[k], "the state left the valid range or P is no longer positive definite")
        zs[k], pd_[k] = f.x, np.diag(f.P)
    return FilterResult(t, zs, pd_, f.P.copy(), tuple(data.names))


# --------------------------------------------------------------------------- summaries


def estimates_json(ests) -> dict:
    """{coefficient: {"estimate", "true", "error_pct"}} (true/error_pct when the truth is known).

    Top-level keys are the estimated coefficients of the first estimate.  With several trials
    the values are those of the first input, ``"trial"`` names it and ``"by_trial"`` holds
    every trial's.
    """
    def one(e, n: str) -> dict:
        err = e.errors_pct()
        d = {"estimate": e.final[n]}
        if err is not None:
            d["true"] = e.data.true_values[n]
            d["error_pct"] = err[n]
        return d
    out = {}
    for n in ests[0].final:
        d = one(ests[0], n)
        if len(ests) > 1:
            d["trial"] = ests[0].name
            d["by_trial"] = {e.name: one(e, n) for e in ests}
        out[n] = d
    return out


def error_table(ests) -> pd.DataFrame:
    """Table 10 layout: per coefficient the true value (where known), and per trial the final value and % error.

    The true values are those of the estimates' own data (the log's own ship), never a default
    ship's; the ``real`` column is left out when no estimate knows the truth.
    """
    rows = []
    tv = next((e.data.true_values for e in ests if e.data.true_values), None)
    for n in ests[0].final:
        row = {"coeff": n}
        if tv:
            row["real"] = tv[n]
        for e in ests:
            row[f"{e.name} final"] = e.final[n]
            err = e.errors_pct()
            if err is not None:
                row[f"{e.name} err(%)"] = err[n]
        rows.append(row)
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------- joint multi-trial estimate


def joint_estimate(datas: list[TrialData], cfg: dict, name: str = "joint") -> Estimate:
    """One estimate from several trials: the filter runs through the trials in turn.

    The derivatives and their covariance block carry over from one trial to the next
    (u, v, r, n restart at each trial's first measurement with their Table 7 variances
    and no correlation with the derivatives), which is the sequential form of fitting
    all trials at once. With Q = 0 and the same linearisation it equals a single pass
    over the concatenated records. Returns an Estimate whose history spans the trials
    end to end (time offset by each trial's length).
    """
    first = datas[0]
    for d in datas[1:]:
        if tuple(d.names) != tuple(first.names):
            raise InputError(d.source, "names", "a joint estimate needs the same estimated coefficients in every trial")
    P0 = P0_for(cfg, first.names, first.reference)
    q = float(cfg.get("Q", 0.0))
    dv = cfg.get("divergence", {})
    z = initial_state(first, cfg)
    P = P0.copy()
    ts, zs, pds = [], [], []
    offset = 0.0
    for d in datas:
        m = d.meas
        z0 = np.r_[m.u[0], m.v[0], m.r[0], m.n[0], z[NS:]]
        P_start = P0.copy()
        P_start[NS:, NS:] = P[NS:, NS:]
        res = run_filter(d.packed, d.slots, m.t, m.z(), m.delta, z0, P_start, R_for(cfg, d.name), trial=d.name, q=q,
                         nis_window_s=float(dv.get("nis_window_s", 60.0)), nis_max=float(dv.get("nis_max", 20.0)),
                         names=d.names)
        z, P = res.z[-1], res.P
        ts.append(m.t + offset)
        zs.append(res.z)
        pds.append(res.pdiag)
        offset += m.t[-1] + (m.t[1] - m.t[0])
    res = FilterResult(np.concatenate(ts), np.vstack(zs), np.vstack(pds), P, tuple(first.names))
    data = TrialData(name, first.meas, first.ship, first.packed, first.slots, first.reference, first.names,
                     first.info, None, first.true_values, "+".join(d.name for d in datas), joint=True)
    return Estimate(data, res, dict(zip(first.names, initial_state(first, cfg)[NS:])), R_for(cfg, first.name))
