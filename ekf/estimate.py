"""From a sea-trial log (or a trial YAML, simulated first) to derivative estimates and reports.

:func:`load_config` reads ``configs/estimation/rhee_kim.yaml`` (overridable);
:func:`data_from_log` / :func:`data_from_trial` give a :class:`TrialData` (the recovered
0.1 s measurements, the packed ship, the truth if known); :func:`estimate` runs the
filter; :func:`write_reports` writes the estimates, the Table-10-style error table and
the convergence figures (Rhee & Kim Figs 15-26, all trials on one figure per derivative).
"""
from __future__ import annotations

import copy
import json
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from mmg.errors import InputError
from mmg.simulation import prepare
from mmg.ship import Ship, load_ship
from mmg.units import KNOT, to_si

from .filter import DERIVATIVES, NS, STATES, FilterResult, derivative_slots, run_filter
from .preprocess import Measurements, compare_with_truth, recover

REPO = Path(__file__).resolve().parents[1]
DEFAULT_CONFIG = REPO / "configs" / "estimation" / "rhee_kim.yaml"
DEFAULT_SHIP = REPO / "configs" / "ships" / "esso_osaka.yaml"
G = 9.80665


# --------------------------------------------------------------------------- configuration


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in (over or {}).items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _merge(out[k], v)
        else:
            out[k] = v
    return out


def _set(cfg: dict, assignment: str) -> None:
    if "=" not in assignment:
        raise InputError("--set", assignment, "expected key.path=value")
    key, val = assignment.split("=", 1)
    parts = key.strip().split(".")
    d = cfg
    for p in parts[:-1]:
        if not isinstance(d.get(p), dict):
            d[p] = {}
        d = d[p]
    try:
        d[parts[-1]] = float(val)
    except ValueError:
        d[parts[-1]] = yaml.safe_load(val)


def load_config(path: str | Path | None = None, sets=()) -> dict:
    """The estimation config: the default file, merged with ``path`` and ``--set`` assignments; validated."""
    with open(DEFAULT_CONFIG) as fh:
        cfg = yaml.safe_load(fh)
    src = str(DEFAULT_CONFIG)
    if path is not None:
        src = str(path)
        try:
            with open(path) as fh:
                over = yaml.safe_load(fh) or {}
        except FileNotFoundError:
            raise InputError(src, "", "file not found") from None
        except yaml.YAMLError as e:
            raise InputError(src, "", f"not valid YAML ({str(e).splitlines()[0]})") from None
        if not isinstance(over, dict):
            raise InputError(src, "", "expected a mapping")
        cfg = _merge(cfg, over)
    for s in sets:
        _set(cfg, s)
    _validate(cfg, src + (" with --set " + " ".join(sets) if sets else ""))
    return cfg


def _validate(cfg: dict, src: str) -> None:
    try:
        cfg["dt_s"] = to_si(str(cfg["dt"]), "time")
    except Exception as e:  # noqa: BLE001 - any bad dt is an input error
        raise InputError(src, "dt", f"bad time step ({e})") from None
    if not cfg["dt_s"] > 0:
        raise InputError(src, "dt", "must be positive")
    if cfg.get("P0_is") not in ("variance", "std"):
        raise InputError(src, "P0_is", "must be 'variance' or 'std'")
    for name in STATES + DERIVATIVES:
        v = cfg.get("P0", {}).get(name)
        if not isinstance(v, (int, float)) or not np.isfinite(v) or v <= 0:
            raise InputError(src, f"P0.{name}", f"must be a positive number, got {v!r}")
    q = cfg.get("Q", 0.0)
    if not isinstance(q, (int, float)) or q < 0:
        raise InputError(src, "Q", "must be a non-negative number")
    sc = cfg.get("initial", {}).get("scale", 1.2)
    if not isinstance(sc, (int, float)) or not np.isfinite(sc):
        raise InputError(src, "initial.scale", "must be a number")
    for k, v in (cfg.get("initial", {}).get("values") or {}).items():
        if k not in DERIVATIVES:
            raise InputError(src, f"initial.values.{k}", f"unknown derivative; known: {', '.join(DERIVATIVES)}")
        if not isinstance(v, (int, float)) or not np.isfinite(v):
            raise InputError(src, f"initial.values.{k}", "must be a finite number")
    if "default" not in cfg.get("R", {}):
        raise InputError(src, "R.default", "missing")
    for trial, row in cfg["R"].items():
        for ch in STATES:
            v = (row or {}).get(ch)
            if not isinstance(v, (int, float)) or not np.isfinite(v) or v <= 0:
                raise InputError(src, f"R.{trial}.{ch}", f"must be a positive number, got {v!r}")


def R_for(cfg: dict, trial: str) -> np.ndarray:
    """Diagonal R (4x4) for a trial name (Table 8; ``default`` otherwise)."""
    row = cfg["R"].get(trial, cfg["R"]["default"])
    return np.diag([float(row[c]) for c in STATES])


def P0_for(cfg: dict) -> np.ndarray:
    v = np.array([float(cfg["P0"][n]) for n in STATES + DERIVATIVES])
    return np.diag(v if cfg["P0_is"] == "variance" else v * v)


# --------------------------------------------------------------------------- data


@dataclass
class TrialData:
    """What the filter needs for one trial, and the truth when it is known."""

    name: str
    meas: Measurements
    ship: Ship
    packed: object
    slots: np.ndarray
    reference: dict          # the ship file's derivatives (initial guess = scale x these)
    truth: object = None     # TrialRecord of the truth file, when known
    true_values: dict | None = None
    source: str = ""
    record: object = None    # the log as read (TrialRecord), so later stages need not read it again


def _fit_checks(rec, ship: Ship, n_eq: float, cfg: dict, src: str) -> None:
    fc = cfg.get("fit_checks", {})
    L = ship.particulars.L
    if "length_m" in rec.meta:
        lm = float(rec.meta["length_m"])
        if abs(lm / L - 1) > fc.get("length_mismatch", 0.05):
            raise InputError(src, "length_m", f"log is for a {lm:g} m ship but {ship.name} is {L:g} m long")
    if rec.U is not None:
        Fn = np.asarray(rec.U) / np.sqrt(G * L)
        lo, hi = fc.get("froude_min", 0.01), fc.get("froude_max", 0.35)
        if np.nanmax(Fn) > hi or np.nanmedian(Fn) < lo:
            raise InputError(src, "speed_kn", f"logged speeds {np.nanmin(rec.U) / KNOT:.3g}-{np.nanmax(rec.U) / KNOT:.3g} kn "
                                              f"(Froude {np.nanmin(Fn):.3g}-{np.nanmax(Fn):.3g}) are outside the range "
                                              f"{lo:g}-{hi:g} the {ship.name} model covers")
    n0 = float(rec.n[0])
    if not n0 > 0 or abs(n0 / n_eq - 1) > fc.get("rpm_mismatch", 0.25):
        raise InputError(src, "rpm", f"first logged rpm {n0 * 60:.4g} does not fit {ship.name}: its straight run at "
                                     f"the logged speed needs {n_eq * 60:.4g} rpm")


def data_from_log(path: str | Path, cfg: dict, ship_path: str | Path | None = None,
                  truth_path: str | Path | None = None) -> TrialData:
    """Read a project log, check it fits the ship, recover the 0.1 s measurements."""
    from trials.logio import read_record

    rec = read_record(path)
    src = str(path)
    if rec.meta.get("format") != "log":
        raise InputError(src, "", f"expected a project sea-trial log (time_s, lat_deg, lon_deg, heading_deg, speed_kn, "
                                  f"rpm), got a {rec.meta.get('format')} file")
    if len(rec.t) < 10:
        raise InputError(src, "time_s", f"only {len(rec.t)} samples; too short to estimate from")
    ship = load_ship(ship_path or DEFAULT_SHIP)
    u0 = float(rec.meta.get("approach_speed_kn", rec.U[0] / KNOT)) * KNOT
    if not (u0 > 0 and np.isfinite(u0)):
        raise InputError(src, "speed_kn", "the approach speed must be positive")
    if u0 / np.sqrt(G * ship.particulars.L) > cfg.get("fit_checks", {}).get("froude_max", 0.35):
        raise InputError(src, "speed_kn", f"approach speed {u0 / KNOT:.3g} kn is far beyond what the {ship.name} model covers")
    try:
        pk, eq = prepare(ship, u0)
    except Exception as e:  # noqa: BLE001 - a failed equilibrium means the log doesn't fit
        raise InputError(src, "speed_kn", f"no straight run of {ship.name} at {u0 / KNOT:.3g} kn ({e})") from None
    _fit_checks(rec, ship, eq.n, cfg, src)
    meas = recover(rec, pk.p, dt=cfg["dt_s"])
    truth = None
    tv = None
    if truth_path is not None:
        truth = read_record(truth_path)
        tv = ship.hull.as_dict()
    ref = ship.hull.as_dict()
    return TrialData(rec.name, meas, ship, pk, derivative_slots(pk, DERIVATIVES, ship), ref, truth, tv, src, rec)


def data_from_trial(path: str | Path, cfg: dict, seed: int | None = None, workdir: str | Path | None = None) -> TrialData:
    """Simulate a trial YAML (with noise seed ``seed``), write its log and truth, recover the measurements."""
    import tempfile

    from trials.logio import write_csv
    from trials.run import run_trial
    from trials.rudder import REBUILT_KINDS
    from trials.trial import load_trial

    tr = load_trial(path)
    if tr.kind not in REBUILT_KINDS:
        raise InputError(str(path), "manoeuvre.kind", f"the estimator rebuilds the rudder of turning, zigzag and S-type "
                                                      f"trials only, not {tr.kind}")
    if seed is not None:
        tr = replace(tr, log=replace(tr.log, seed=int(seed)))
    run = run_trial(tr)
    wd = Path(workdir) if workdir is not None else Path(tempfile.mkdtemp(prefix="ekf-"))
    wd.mkdir(parents=True, exist_ok=True)
    meta = run.log_meta()
    log_path, truth_path = wd / "log.csv", wd / "truth.csv"
    write_csv(log_path, run.log(), meta)
    write_csv(truth_path, run.truth(), meta)
    ship_path = tr.ship_path
    return data_from_log(log_path, cfg, ship_path=ship_path, truth_path=truth_path)


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
    from .output_error import trial_from_data

    if data.record is None and not Path(data.source).is_file():
        return None
    try:
        tr = trial_from_data(data, rudder="law")
    except (InputError, KeyError, ValueError):
        return None
    theta = np.array([values[n] for n in DERIVATIVES], float)
    return FreeRun(data.name, tr.t_log, tr.obs, tr.simulate(theta, tr.nuisance0()), data.ship.particulars.L)


@dataclass
class Estimate:
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
        tv = self.data.true_values
        if tv is None:
            return None
        return {n: 100.0 * abs(self.final[n] - tv[n]) / abs(tv[n]) for n in DERIVATIVES}


def initial_state(data: TrialData, cfg: dict) -> np.ndarray:
    m = data.meas
    ini = cfg.get("initial", {})
    sc = float(ini.get("scale", 1.2))
    vals = ini.get("values") or {}
    der = [float(vals[n]) if n in vals else sc * data.reference[n] for n in DERIVATIVES]
    return np.r_[m.u[0], m.v[0], m.r[0], m.n[0], der]


def estimate(data: TrialData, cfg: dict) -> Estimate:
    """Run the augmented EKF on one trial (raises FilterDivergence naming the trial and time)."""
    z0 = initial_state(data, cfg)
    R = R_for(cfg, data.name)
    P0 = P0_for(cfg)
    q = float(cfg.get("Q", 0.0))
    dv = cfg.get("divergence", {})
    res = run_filter(data.packed, data.slots, data.meas.t, data.meas.z(), data.meas.delta, z0, P0, R,
                     trial=data.name, q=q, nis_window_s=float(dv.get("nis_window_s", 60.0)),
                     nis_max=float(dv.get("nis_max", 20.0)))
    return Estimate(data, res, dict(zip(DERIVATIVES, z0[NS:])), R)


# --------------------------------------------------------------------------- reports


def estimates_json(ests: list[Estimate]) -> dict:
    """{derivative: {"estimate", "true", "error_pct"}} (true/error_pct when the truth is known).

    Top-level keys are always the 12 derivative names. With several trials the values are
    those of the first input, ``"trial"`` names it and ``"by_trial"`` holds every trial's.
    """
    def one(e: Estimate, n: str) -> dict:
        err = e.errors_pct()
        d = {"estimate": e.final[n]}
        if err is not None:
            d["true"] = e.data.true_values[n]
            d["error_pct"] = err[n]
        return d
    out = {}
    for n in DERIVATIVES:
        d = one(ests[0], n)
        if len(ests) > 1:
            d["trial"] = ests[0].name
            d["by_trial"] = {e.name: one(e, n) for e in ests}
        out[n] = d
    return out


def error_table(ests: list[Estimate]) -> pd.DataFrame:
    """Table 10 layout: per derivative the real value, and per trial final value and % error."""
    rows = []
    for n in DERIVATIVES:
        row = {"coeff": n}
        tv = next((e.data.true_values for e in ests if e.data.true_values), None)
        row["real"] = tv[n] if tv else np.nan
        for e in ests:
            row[f"{e.name} final"] = e.final[n]
            err = e.errors_pct()
            row[f"{e.name} err(%)"] = err[n] if err else np.nan
        rows.append(row)
    return pd.DataFrame(rows)


def to_markdown(df: pd.DataFrame) -> str:
    cols = list(df.columns)
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for _, r in df.iterrows():
        cells = []
        for c in cols:
            v = r[c]
            if isinstance(v, str):
                cells.append(v)
            elif "err" in c:
                cells.append("" if not np.isfinite(v) else f"{v:.2f}")
            else:
                cells.append("" if not np.isfinite(v) else f"{v:+.4e}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"




def write_reports(ests: list[Estimate], out, plots: bool = True) -> dict:
    """estimates.json, error_table.csv/.md, final_estimates.csv, convergence_*.png, preprocessing_*.png,
    free_run.json (:class:`FreeRun` of each trial; with ``true_derivatives`` when the truth is known).

    ``out`` is a folder path or a staging object with ``.path(name)``.
    """
    def P(name):
        if hasattr(out, "path"):
            return out.path(name)
        p = Path(out) / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    with open(P("estimates.json"), "w") as fh:
        json.dump(estimates_json(ests), fh, indent=2)
    tab = error_table(ests)
    tab.to_csv(P("error_table.csv"), index=False, float_format="%.6g")
    P("error_table.md").write_text(to_markdown(tab))
    fin = pd.DataFrame({e.name: e.final for e in ests})
    fin.index.name = "derivative"
    fin.to_csv(P("final_estimates.csv"), float_format="%.6g")
    rms = {}
    if plots:
        # a joint (multi-trial) history spans all trials end to end: not on the per-trial time axis
        from .plots import plot_comparison, plot_convergence

        plot_convergence([e for e in ests if "+" not in e.data.source], P("convergence_Y_beta.png").parent)
        for e in ests:
            if e.data.truth is not None:
                safe = e.name.replace(" ", "_").replace("/", "_")
                rms[e.name] = plot_comparison(e.data.meas, e.data.truth, P(f"preprocessing_{safe}.png"))
    else:
        for e in ests:
            if e.data.truth is not None:
                rms[e.name] = compare_with_truth(e.data.meas, e.data.truth)
    if rms:
        with open(P("preprocessing_rms.json"), "w") as fh:
            json.dump(rms, fh, indent=2)
    runs = {}
    for e in ests:
        fr = e.free_run if isinstance(e, Estimate) else None
        if fr is None:
            continue
        runs[e.name] = fr.to_dict()
        if e.data.true_values:            # the check's floor: the same re-simulation with the truth
            runs[e.name]["true_derivatives"] = free_run(e.data, e.data.true_values).to_dict()
    if runs:
        with open(P("free_run.json"), "w") as fh:
            json.dump(runs, fh, indent=2)
    return {"table": tab, "rms": rms, "free_run": runs}


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
    P0 = P0_for(cfg)
    q = float(cfg.get("Q", 0.0))
    dv = cfg.get("divergence", {})
    z = initial_state(datas[0], cfg)
    P = P0.copy()
    ts, zs, pds = [], [], []
    offset = 0.0
    for d in datas:
        m = d.meas
        z0 = np.r_[m.u[0], m.v[0], m.r[0], m.n[0], z[NS:]]
        P_start = P0.copy()
        P_start[NS:, NS:] = P[NS:, NS:]
        res = run_filter(d.packed, d.slots, m.t, m.z(), m.delta, z0, P_start, R_for(cfg, d.name), trial=d.name, q=q,
                         nis_window_s=float(dv.get("nis_window_s", 60.0)), nis_max=float(dv.get("nis_max", 20.0)))
        z, P = res.z[-1], res.P
        ts.append(m.t + offset)
        zs.append(res.z)
        pds.append(res.pdiag)
        offset += m.t[-1] + (m.t[1] - m.t[0])
    res = FilterResult(np.concatenate(ts), np.vstack(zs), np.vstack(pds), P)
    first = datas[0]
    data = TrialData(name, first.meas, first.ship, first.packed, first.slots, first.reference, None,
                     first.true_values, "+".join(d.name for d in datas))
    return Estimate(data, res, dict(zip(DERIVATIVES, initial_state(first, cfg)[NS:])), R_for(cfg, first.name))
