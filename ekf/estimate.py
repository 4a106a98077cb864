"""The augmented EKF estimate of one trial (or several in turn), and its checks.

:func:`load_config` reads the estimation config (the bundled
``configs/estimation/rhee_kim.yaml``, overridable, keyed by coefficient name with defaults
for names it does not list); :func:`estimate` runs the filter on a
:class:`ekf.data.TrialData` and returns an :class:`Estimate` (``.final``, ``.to_pandas()``,
``.plot()``, ``.warnings()``, ``.free_run``); :func:`joint_estimate` runs it through several
trials in turn.  Building a TrialData from a log file or a trial YAML, and writing the
reports, is the trials layer's job (:mod:`trials.estimation`).
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
from mmg.units import to_si

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
    parts = key.strip().split(".")
    if parts[0] not in CONFIG_KEYS:
        raise InputError("--set", key, f"unknown key {parts[0]!r}; known: {', '.join(CONFIG_KEYS)}")
    d = cfg
    for p in parts[:-1]:
        if not isinstance(d.get(p), dict):
            d[p] = {}
        d = d[p]
    try:
        d[parts[-1]] = float(val)
    except ValueError:
        d[parts[-1]] = yaml.safe_load(val)


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
        Naming the file and the field: unknown keys, non-positive covariances, a bad step.
    """
    default = default_config_path()
    with open(default) as fh:
        cfg = yaml.safe_load(fh)
    src = str(default)
    if isinstance(path, dict):
        src = "<config dict>"
        _check_keys(path, src)
        cfg = _merge(cfg, path)
    elif path is not None:
        src = str(path)
        try:
            with open(path) as fh:
                over = yaml.safe_load(fh) or {}
        except FileNotFoundError:
            raise InputError(src, "", "file not found") from None
        except (IsADirectoryError, UnicodeDecodeError) as e:
            raise InputError(src, "", f"cannot read as a YAML text file ({e.__class__.__name__})") from None
        except yaml.YAMLError as e:
            raise InputError(src, "", f"not valid YAML ({str(e).splitlines()[0]})") from None
        if not isinstance(over, dict):
            raise InputError(src, "", "expected a mapping")
        _check_keys(over, src)
        cfg = _merge(cfg, over)
    for s in sets:
        _set(cfg, s)
    src = src + (" with --set " + " ".join(sets) if sets else "")
    _check_keys(cfg, src)
    _validate(cfg, src)
    return cfg


def _positive(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and bool(np.isfinite(v)) and v > 0


def _validate(cfg: dict, src: str) -> None:
    try:
        cfg["dt_s"] = to_si(str(cfg["dt"]), "time")
    except Exception as e:  # noqa: BLE001 - any bad dt is an input error
        raise InputError(src, "dt", f"bad time step ({e})") from None
    if not (cfg["dt_s"] > 0 and np.isfinite(cfg["dt_s"])):
        raise InputError(src, "dt", "must be positive")
    if cfg.get("P0_is") not in ("variance", "std"):
        raise InputError(src, "P0_is", "must be 'variance' or 'std'")
    P0 = cfg.get("P0") or {}
    for name in STATES:
        if not _positive(P0.get(name)):
            raise InputError(src, f"P0.{name}", f"must be a positive number, got {P0.get(name)!r}")
    for name, v in P0.items():
        if not _positive(v):
            raise InputError(src, f"P0.{name}", f"must be a positive number, got {v!r}")
    if not _positive(cfg.get("P0_default_relative_std", 0.5)):
        raise InputError(src, "P0_default_relative_std", "must be a positive number")
    q = cfg.get("Q", 0.0)
    if not isinstance(q, (int, float)) or not np.isfinite(q) or q < 0:
        raise InputError(src, "Q", "must be a non-negative number")
    sc = cfg.get("initial", {}).get("scale", 1.2)
    if not isinstance(sc, (int, float)) or not np.isfinite(sc):
        raise InputError(src, "initial.scale", "must be a number")
    for k, v in (cfg.get("initial", {}).get("values") or {}).items():
        if not isinstance(v, (int, float)) or not np.isfinite(v):
            raise InputError(src, f"initial.values.{k}", "must be a finite number")
    if "default" not in cfg.get("R", {}):
        raise InputError(src, "R.default", "missing")
    for trial, row in cfg["R"].items():
        for ch in STATES:
            v = (row or {}).get(ch)
            if not _positive(v):
                raise InputError(src, f"R.{trial}.{ch}", f"must be a positive number, got {v!r}")


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
        When a name is neither listed nor has a nonzero reference value.
    """
    P0 = cfg["P0"]
    rel = float(cfg.get("P0_default_relative_std", 0.5))
    v = []
    for n in tuple(STATES) + tuple(names):
        if n in P0:
            x = float(P0[n])
            v.append(x if cfg["P0_is"] == "variance" else x * x)
        elif reference is not None and reference.get(n):
            v.append((rel * float(reference[n])) ** 2)
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
        ``"compiled"`` (default): :func:`ekf.filter.run_filter`, the numba loop (about a second
        for 3000 s).  ``"filterpy"``: :class:`ekf.filter.AugmentedEKF` stepped in Python, the
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
    """The pass of :func:`run_filter` stepped with filterpy (:class:`ekf.filter.AugmentedEKF`)."""
    from .filter import AugmentedEKF, FilterDivergence, is_pd

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
