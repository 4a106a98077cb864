"""From a sea-trial log file, or a trial simulated in memory, to what the estimators take; and their reports.

:func:`data_from_log` reads a project log and checks that it fits the ship;
:func:`data_from_trial` simulates a trial (with any noise seed) and builds the same
:class:`ekf.data.TrialData` straight from the simulation, with no file written or read;
:func:`record_info` turns a log header into the :class:`ekf.data.RecordInfo` the estimators
take (so no estimator parses a header); :func:`write_reports` writes the estimates, the
Table-10-style error table, the convergence figures and the free-run check.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from ekf.data import RecordInfo, TrialData, estimable_names, hull_slots
from ekf.estimate import Estimate, error_table, estimates_json, free_run
from ekf.preprocess import compare_with_truth, recover
from mmg.errors import InputError
from mmg.rudder import REBUILT_KINDS
from mmg.ship import Ship, load_ship
from mmg.simulation import prepare
from mmg.units import DEG, KNOT, M_PER_DEG_LAT, M_PER_DEG_LON

from ..files.logio import as_written, read_record, record_from_frame, require_finite
from ..files.records import CHANNELS
from ..files.rudder import manoeuvre_from_meta

G = 9.80665
DEFAULT_SHIP = "esso_osaka"
# Rhee & Kim Table 4 log noise (uniform half-widths), for a log header that does not give its own
TABLE4_HALF_WIDTH = {"lat_deg": 8.0e-7, "lon_deg": 4.0e-7, "heading_deg": 1.2e-2, "rpm": 0.2}


# --------------------------------------------------------------------------- log header -> RecordInfo


def _legacy_noise(text: str) -> dict:
    """Half-widths from an old header line 'uniform: lat 8e-07 deg, lon 4e-07 deg, heading ..., rpm 0.2 rpm'."""
    out = {}
    if text.startswith("uniform:"):
        for part in text.split(":", 1)[1].split(","):
            w = part.split()
            if len(w) >= 2:
                try:
                    out[{"lat": "lat_deg", "lon": "lon_deg", "heading": "heading_deg", "rpm": "rpm"}[w[0]]] = float(w[1])
                except (KeyError, ValueError):
                    continue
    return out


def noise_half_widths(meta: dict) -> dict:
    """Uniform noise half-widths of a log (lat_deg, lon_deg [deg], heading_deg [deg], rpm [rpm]).

    From the header's numeric keys ``noise_lat_deg``, ``noise_lon_deg``, ``noise_heading_deg``,
    ``noise_rpm`` (written by :meth:`trials.runs.run.TrialRun.log_meta`), or an older header's
    ``noise`` line; a channel logged without noise, or not stated, gets Rhee & Kim's Table 4
    level (the weights must stay finite).
    """
    out = dict(TABLE4_HALF_WIDTH)
    given = {k: meta[f"noise_{k}"] for k in TABLE4_HALF_WIDTH if f"noise_{k}" in meta}
    if not given:
        given = _legacy_noise(str(meta.get("noise", "")))
    for k, v in given.items():
        try:
            v = float(v)
        except (TypeError, ValueError):
            continue
        if np.isfinite(v) and v > 0:
            out[k] = v
    return out


def noise_std(half_widths: dict, m_per_deg_lat: float = M_PER_DEG_LAT, m_per_deg_lon: float = M_PER_DEG_LON) -> dict:
    """Std (SI) of psi, x, y, n from uniform half-widths in log units (a / sqrt(3))."""
    s3 = np.sqrt(3.0)
    return {"psi": half_widths["heading_deg"] * DEG / s3, "x": half_widths["lat_deg"] * m_per_deg_lat / s3,
            "y": half_widths["lon_deg"] * m_per_deg_lon / s3, "n": half_widths["rpm"] / 60.0 / s3}


def record_info(rec) -> RecordInfo:
    """The :class:`RecordInfo` of a project log record, from its header (SI).

    Raises
    ------
    InputError
        When the log has no rudder channel and its header gives no trial logic to rebuild it from.
    """
    meta = rec.meta
    src = rec.source or "log"
    if rec.delta is None:
        kind, man = manoeuvre_from_meta(meta, src)
    else:                                   # a rudder channel: the trial logic is optional
        try:
            kind, man = manoeuvre_from_meta(meta, src)
        except InputError:
            kind, man = "", {}
    mlat = float(meta.get("m_per_deg_lat", M_PER_DEG_LAT))
    mlon = float(meta.get("m_per_deg_lon", M_PER_DEG_LON))
    u0 = float(meta["approach_speed_kn"]) * KNOT if "approach_speed_kn" in meta else None
    n0 = float(meta["approach_rpm"]) / 60.0 if "approach_rpm" in meta else None
    return RecordInfo(kind=kind, manoeuvre=man, trim_rudder=float(meta.get("trim_rudder_deg", 0.0)) * DEG,
                      approach_speed=u0, approach_rpm=n0, execute=float(meta.get("execute_s", 0.0)),
                      noise_std=noise_std(noise_half_widths(meta), mlat, mlon))


# --------------------------------------------------------------------------- data


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


def _ship_of(rec, ship) -> Ship:
    """The ship to estimate with: given, else the log header's ship file, else the bundled default."""
    if isinstance(ship, Ship):
        return ship
    if ship is not None:
        return load_ship(ship)
    hdr = rec.meta.get("ship_file")
    if hdr:
        p = Path(str(hdr))
        if not p.is_absolute() and rec.source:
            p = Path(rec.source).parent / p
        if p.is_file():
            return load_ship(p)
    return load_ship(DEFAULT_SHIP)


def data_from_record(rec, cfg: dict, ship=None, truth=None, true_values: dict | None = None,
                     names=None, info: RecordInfo | None = None) -> TrialData:
    """A :class:`TrialData` from a log record (checked against the ship, measurements recovered).

    Parameters
    ----------
    rec : TrialRecord
        A project sea-trial log as read (or built in memory by :func:`data_from_trial`).
    cfg : dict
        Estimation config (:func:`ekf.estimate.load_config`).
    ship : Ship, str or Path, optional
        The model to estimate with (a Ship, a bundled name or a ship YAML); default the log's
        own ship file when its header names one, else the bundled Esso Osaka.
    truth : TrialRecord, optional
        The true states (enables errors against ``true_values``).
    true_values : dict, optional
        The true hull coefficients.
    names : sequence of str, optional
        Coefficients to estimate; default :func:`ekf.data.estimable_names` of the ship.
    info : RecordInfo, optional
        Default :func:`record_info` of the record's header.
    """
    src = rec.source or "log"
    if rec.meta.get("format", "log") != "log":
        raise InputError(src, "", f"expected a project sea-trial log (time_s, lat_deg, lon_deg, heading_deg, speed_kn, "
                                  f"rpm), got a {rec.meta.get('format')} file")
    if len(rec.t) < 10:
        raise InputError(src, "time_s", f"only {len(rec.t)} samples; too short to estimate from")
    ship = _ship_of(rec, ship)
    info = info or record_info(rec)
    u0 = info.approach_speed if info.approach_speed is not None else float(rec.U[0])
    if not (u0 > 0 and np.isfinite(u0)):
        raise InputError(src, "speed_kn", "the approach speed must be positive")
    if u0 / np.sqrt(G * ship.particulars.L) > cfg.get("fit_checks", {}).get("froude_max", 0.35):
        raise InputError(src, "speed_kn", f"approach speed {u0 / KNOT:.3g} kn is far beyond what the {ship.name} model covers")
    try:
        pk, eq = prepare(ship, u0)
    except Exception as e:  # noqa: BLE001 - a failed equilibrium means the log doesn't fit
        raise InputError(src, "speed_kn", f"no straight run of {ship.name} at {u0 / KNOT:.3g} kn ({e})") from None
    _fit_checks(rec, ship, eq.n, cfg, src)
    meas = recover(rec, pk.p, dt=cfg["dt_s"], kind=info.kind or None, manoeuvre=info.manoeuvre, delta0=info.trim_rudder)
    names = tuple(names) if names is not None else estimable_names(ship)
    try:
        slots = hull_slots(ship, names)
    except KeyError as e:
        raise InputError(src, "names", str(e.args[0])) from None
    return TrialData(rec.name, meas, ship, pk, slots, ship.hull.as_dict(), names, info, truth, true_values, src, rec)


def data_from_log(path: str | Path, cfg: dict, ship_path=None, truth_path: str | Path | None = None,
                  names=None) -> TrialData:
    """Read a project log (and optionally its truth file), check it fits the ship, recover the measurements.

    With a truth file the true values are the ship's coefficients (the truth file was simulated
    with it); the truth file must be of the same trial as the log (same header ``trial`` and
    ``seed``, same time span) and its header's ship the ship estimated with, or it is refused.
    A log (or truth file) of another ship (:func:`trials.files.shipcheck.check_record_ship`) is refused.
    """
    from ..files.shipcheck import check_record_ship

    rec = read_record(path)
    require_finite(rec, CHANNELS, "mmg estimate")                 # not the wind: the EKF has no wind loads
    truth = tv = None
    ship = _ship_of(rec, ship_path)
    if rec.meta.get("format") == "log":          # another layout: data_from_record says it is not a log
        check_record_ship(rec, ship)
    if truth_path is not None:
        truth = read_record(truth_path)
        require_finite(truth, CHANNELS, "mmg estimate")
        _check_truth(rec, truth, str(truth_path))
        check_record_ship(truth, ship)
        _check_truth_ship(rec, truth, ship, str(truth_path))
        tv = ship.hull.as_dict()
    return data_from_record(rec, cfg, ship, truth, tv, names)


def _check_truth_ship(rec, truth, ship: Ship, src: str) -> None:
    """The true values are the ship's coefficients: refuse a truth file (or log) whose header names another ship."""
    from ..files.shipcheck import ShipMismatch

    for r, where in ((truth, src), (rec, rec.source or "log")):
        named = str(r.meta.get("ship", "") or "").strip()
        if named and named != ship.name:
            raise ShipMismatch(where, "ship", f"the header's ship is {named!r}, but the estimate uses {ship.name!r}, whose "
                                              f"coefficients would be taken as the true values: give the log's own ship "
                                              f"with --ship")


def _check_truth(rec, truth, src: str) -> None:
    if truth.meta.get("format") != "truth":
        raise InputError(src, "", f"expected a project truth file, got a {truth.meta.get('format')} file")
    for key in ("trial", "seed", "config"):
        a, b = rec.meta.get(key), truth.meta.get(key)
        if a is not None and b is not None and str(a) != str(b):
            raise InputError(src, key, f"the truth file is of {key} {b!r} but the log of {a!r}: not the same trial")
    if abs(float(truth.t[0]) - float(rec.t[0])) > 1e-6 or float(truth.t[-1]) + 1e-6 < float(rec.t[-1]):
        raise InputError(src, "time_s", f"the truth file spans {truth.t[0]:g}-{truth.t[-1]:g} s but the log "
                                        f"{rec.t[0]:g}-{rec.t[-1]:g} s: not the same trial")


def data_from_trial(trial, cfg: dict, seed: int | None = None, names=None) -> TrialData:
    """Simulate a trial (a :class:`trials.runs.trial.Trial`, a bundled name or a trial YAML) with noise seed
    ``seed`` and build its :class:`TrialData` in memory: the log and the truth as the files would hold
    them, the true values the trial ship's coefficients.

    ``trial`` may also be a simulated :class:`trials.runs.run.TrialRun`: the simulation is then reused and
    only the log is drawn again with ``seed`` (the trajectory does not depend on the log's noise), so
    a Monte Carlo over noise seeds simulates each trial once.
    """
    from ..runs.run import TrialRun, run_trial
    from ..runs.trial import Trial, load_trial

    run = trial if isinstance(trial, TrialRun) else None
    tr = run.trial if run is not None else (trial if isinstance(trial, Trial) else load_trial(trial))
    if tr.kind not in REBUILT_KINDS:
        raise InputError(str(tr.path or tr.name), "manoeuvre.kind", f"the estimator rebuilds the rudder of turning, "
                                                                    f"zigzag and S-type trials only, not {tr.kind}")
    if seed is not None:
        tr = replace(tr, log=replace(tr.log, seed=int(seed)))
    run = run_trial(tr) if run is None else TrialRun(tr, run.result)
    meta = run.log_meta()
    src = str(tr.path or tr.name)
    rec = record_from_frame(as_written(run.log()), meta, src)    # as the log file holds it
    truth = record_from_frame(run.truth(), meta, src)
    return data_from_record(rec, cfg, tr.ship, truth, tr.ship.hull.as_dict(), names)


# --------------------------------------------------------------------------- reports


def to_markdown(df: pd.DataFrame) -> str:
    """A Markdown table of an error table (coefficients in 4 significant digits, errors in %)."""
    cols = list(df.columns)
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for _, r in df.iterrows():
        cells = []
        for c in cols:
            v = r[c]
            if isinstance(v, str):
                cells.append(v)
            elif c.endswith("(%)"):
                cells.append("" if not np.isfinite(v) else f"{v:.2f}")
            else:
                cells.append("" if not np.isfinite(v) else f"{v:+.4e}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_reports(ests: list, out, plots: bool = True) -> dict:
    """estimates.json, error_table.csv/.md, final_estimates.csv, convergence_*.png, preprocessing_*.png,
    free_run.json (:class:`ekf.estimate.FreeRun` of each trial; with ``true_derivatives`` when the truth
    is known).

    ``out`` is a folder path or a staging object with ``.path(name)``.  Returns the table, the
    preprocessing RMS, the free-run checks and the names of the figures written.
    """
    from ..files.output import dump_json

    def P(name):
        if hasattr(out, "path"):
            return out.path(name)
        p = Path(out) / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    dump_json(estimates_json(ests), P("estimates.json"))
    tab = error_table(ests)
    tab.to_csv(P("error_table.csv"), index=False, float_format="%.6g")
    P("error_table.md").write_text(to_markdown(tab))
    fin = pd.DataFrame({e.name: e.final for e in ests})
    fin.index.name = "coefficient"
    fin.to_csv(P("final_estimates.csv"), float_format="%.6g")
    rms, figures = {}, []
    if plots:
        # a joint (multi-trial) history spans all trials end to end: not on the per-trial time axis
        from ekf.plots import plot_comparison, plot_convergence

        per_trial = [e for e in ests if isinstance(e, Estimate) and not e.data.joint]
        if per_trial:
            figures += [p.name for p in plot_convergence(per_trial, P("convergence_x.png").parent)]
        for e in ests:
            if e.data.truth is not None and not e.data.joint:
                safe = e.name.replace(" ", "_").replace("/", "_")
                rms[e.name] = plot_comparison(e.data.meas, e.data.truth, P(f"preprocessing_{safe}.png"))
                figures.append(f"preprocessing_{safe}.png")
    else:
        for e in ests:
            if e.data.truth is not None and not e.data.joint:
                rms[e.name] = compare_with_truth(e.data.meas, e.data.truth)
    if rms:
        dump_json(rms, P("preprocessing_rms.json"))
    runs = {}
    for e in ests:
        fr = e.free_run if isinstance(e, Estimate) else None
        if fr is None:
            continue
        runs[e.name] = fr.to_dict()
        if e.data.true_values:            # the check's floor: the same re-simulation with the truth
            runs[e.name]["true_derivatives"] = free_run(e.data, e.data.true_values).to_dict()
    if runs:
        dump_json(runs, P("free_run.json"))
    return {"table": tab, "rms": rms, "free_run": runs, "figures": figures}


__all__ = ["data_from_log", "data_from_trial", "data_from_record", "record_info", "noise_half_widths", "noise_std",
           "write_reports", "to_markdown"]


# --------------------------------------------------------------------------- files in, reports out


def load_inputs(inputs, cfg: dict, seed: int | None = None, ship=None, truth=None) -> list[TrialData]:
    """TrialData of each input: a project log (with ``ship`` and ``truth`` when given) or a trial
    (YAML file or bundled name; simulated in memory with noise seed ``seed``).  All inputs are read
    and checked before anything is estimated; two inputs of the same trial name are refused."""
    if truth is not None and len(inputs) != 1:
        raise InputError("--truth", "", "give --truth with a single log only")
    datas = []
    for path in inputs:
        p = Path(str(path))
        if p.suffix.lower() in (".yaml", ".yml") or (not p.exists() and p.suffix == ""):
            datas.append(data_from_trial(str(path), cfg, seed=seed))
        else:
            if not p.exists():
                raise InputError(str(path), "", "file not found")
            datas.append(data_from_log(p, cfg, ship_path=ship, truth_path=truth))
    names = [d.name for d in datas]
    if len(set(names)) != len(names):
        raise InputError(str(inputs[0]), "trial", f"two inputs have the same trial name ({names})")
    return datas


def estimate_and_report(datas: list[TrialData], cfg: dict, out, joint: bool = False, plots: bool = True,
                        method: str = "ekf", verbose: bool = True, n_jobs: int = 2, ekf_start: dict | None = None) -> dict:
    """Estimate (``method`` "ekf": the augmented EKF per input, ``joint`` adding one run through all
    of them; "output-error": the joint EKF then the joint output-error fit, its Jacobian's simulations
    on ``n_jobs`` workers, the EKF skipped when ``ekf_start`` gives its result) and write the reports
    into ``out``.  Returns the report dict (``table``, ``estimates``, ``warnings``, ...)."""
    from ekf.estimate import estimate, joint_estimate

    if method == "output-error":
        return _output_error_report(datas, cfg, out, verbose, n_jobs, ekf_start)
    ests = [estimate(d, cfg) for d in datas]
    warns = [w for e in ests for w in e.warnings()]
    if joint and len(datas) > 1:
        ests.append(joint_estimate(datas, cfg, name="joint"))
    rep = write_reports(ests, out, plots=plots)
    rep.update(estimates=ests, warnings=warns, method="ekf")
    return rep


def _output_error_report(datas, cfg, out, verbose: bool, n_jobs: int = 2, ekf_start=None) -> dict:
    from ekf.output_error import OEEstimate, refine

    from ..files.output import dump_json

    out = _paths(out)
    ekf, res = refine(datas, cfg, verbose=verbose, n_jobs=n_jobs, ekf_start=ekf_start)
    name = "output-error" if len(datas) == 1 else "output-error joint"
    est = OEEstimate(datas[0], res, name)
    js = estimates_json([est])
    for n in res.names:
        js[n]["std_error"] = res.std_errors[n]
        if ekf is not None:
            js[n]["ekf_start"] = ekf[n]
    dump_json(js, out.path("estimates.json"))
    fit = {"method": "output-error", "trials": list(res.trials), "chi2_per_dof": res.chi2_per_dof,
           "cost": res.cost, "residuals": res.nres, "nfev": res.nfev, "seconds": res.seconds, "status": res.status,
           "nuisance": {t: {"v0": float(nu[0]), "psi0": float(nu[1]), "x0": float(nu[2]), "y0": float(nu[3]),
                            "reversal_times_s": [float(v) for v in nu[4:]]} for t, nu in zip(res.trials, res.nuisance)}}
    dump_json(fit, out.path("oe_fit.json"))
    tab = error_table([est])
    tab[f"{name} std err"] = [res.std_errors[n] for n in res.names]
    if ekf is not None:
        tv = datas[0].true_values
        tab["EKF start"] = [ekf[n] for n in res.names]
        if tv:
            tab["EKF start err(%)"] = [100.0 * abs(ekf[n] - tv[n]) / abs(tv[n]) for n in res.names]
    tab.to_csv(out.path("error_table.csv"), index=False, float_format="%.6g")
    out.path("error_table.md").write_text(to_markdown(tab))
    # the free-run check of the EKF path, here with the output-error estimates
    checks, warns = {}, []
    for d in datas:
        fr = free_run(d, res.final)
        if fr is None:
            continue
        checks[d.name] = fr.to_dict()
        if not fr.ok:
            warns.append(f"trial {d.name!r}: re-simulated with the output-error estimates, the model misses the logged "
                         f"heading by {fr.heading_rms_deg:.2f} deg RMS (limit 1): the fit did not find a model that "
                         f"reproduces the data (chi2/dof {res.chi2_per_dof:.3g}); try another start or check the log "
                         f"for an effect the model lacks")
    if checks:
        dump_json(checks, out.path("free_run.json"))
    return {"table": tab, "rms": {}, "method": "output-error", "estimates": [est], "warnings": warns,
            "fit": fit, "free_run": checks}


def _paths(out):
    from ..files.output import out_path

    return out_path(out)


def estimate(source, ship=None, config=None, seed: int | None = None, truth=None, method: str = "ekf",
             names=None, engine: str = "compiled"):
    """Estimate the hull coefficients of one record: the everyday entry point (``mmg.estimate``).

    Parameters
    ----------
    source : str, Path, Trial or TrialRun
        A project log file, a trial (bundled name, YAML path or :class:`trials.runs.trial.Trial`:
        simulated first with noise seed ``seed``) or a simulated :class:`trials.runs.run.TrialRun`
        (its log taken with ``seed``).
    ship : Ship, str or Path, optional
        The model to estimate with, for a log file (default: the log's own ship file, else the
        bundled Esso Osaka).  Trials bring their own ship.
    config : str, Path or dict, optional
        Estimation settings over the bundled Rhee & Kim ones (:func:`ekf.estimate.load_config`).
    truth : str or Path, optional
        The truth file of a simulated log (enables errors against the true values).
    method : {"ekf", "output-error"}
        The augmented EKF (default) or the EKF followed by the output-error fit of the raw log.
    names : sequence of str, optional
        Coefficients to estimate (default: every sway/yaw coefficient of the ship's table).
    engine : {"compiled", "filterpy"}
        For ``method="ekf"``: the numba loop or the filterpy class (same numbers).

    Returns
    -------
    ekf.estimate.Estimate or ekf.output_error.OEEstimate
        ``.final``, ``.to_pandas()`` (estimates, std, true values and % errors where known),
        ``.plot()`` (EKF convergence), ``.warnings()`` (EKF).

    Examples
    --------
    >>> import mmg
    >>> est = mmg.estimate("zz20")                     # doctest: +SKIP
    >>> est.to_pandas()[["estimate", "true", "error_pct"]]  # doctest: +SKIP
    """
    from ekf.estimate import estimate as ekf_estimate
    from ekf.estimate import load_config
    from ekf.output_error import OEEstimate, refine

    from ..runs.run import TrialRun
    from ..runs.trial import Trial

    cfg = load_config(config)
    if isinstance(source, TrialRun):
        run = source
        if seed is not None:
            run = TrialRun(replace(run.trial, log=replace(run.trial.log, seed=int(seed))), run.result)
        meta = run.log_meta()
        src = str(run.trial.path or run.trial.name)
        data = data_from_record(record_from_frame(as_written(run.log()), meta, src), cfg, run.trial.ship,
                                record_from_frame(run.truth(), meta, src), run.trial.ship.hull.as_dict(), names)
    elif isinstance(source, Trial) or Path(str(source)).suffix.lower() in (".yaml", ".yml") \
            or not Path(str(source)).exists():
        data = data_from_trial(source, cfg, seed=seed, names=names)
    else:
        data = data_from_log(source, cfg, ship_path=ship, truth_path=truth, names=names)
    if method == "output-error":
        _, res = refine([data], cfg)
        return OEEstimate(data, res, "output-error")
    if method != "ekf":
        raise InputError("method", str(method), "must be 'ekf' or 'output-error'")
    return ekf_estimate(data, cfg, engine=engine)
