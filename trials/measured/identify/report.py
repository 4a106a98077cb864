"""What :func:`trials.measured.identify.identify` writes: ``ship.yaml`` (the ship config with the fitted values,
:func:`ship_yaml`), ``report.md`` (values, standard errors, stages, training and test fits, fold spread) and
the summary and fold-spread JSON (:func:`write_identification`, :func:`identification_summary`,
:func:`fold_spread_json`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mmg.errors import InputError

from ..predict import replay_record
from .covariance import identification_covariance, model_form, run_spread
from .fit import Identification, _wind_keys, stage_description

__all__ = ["write_identification", "ship_yaml", "fold_spread_json", "identification_summary", "free_parameter_text"]


METRIC_COLUMNS = (("advance_L", "advance [L]"), ("tactical_diameter_L", "tactical diameter [L]"),
                  ("overshoots_deg", "overshoots [deg]"))


def manoeuvre_metrics(rep) -> tuple[dict | None, dict | None]:
    """Turning / zigzag metrics (:func:`trials.analysis.metrics.record_metrics`) of the measured record and of
    its replay (a :class:`trials.measured.predict.Replayed`); ``None`` where the record is neither manoeuvre."""
    from ...analysis.metrics import record_metrics
    from ...files.records import TrialRecord

    run = rep.run
    out = []
    for s in (run.meas, rep.pred):
        rec = TrialRecord(t=run.t, name=run.name, source=run.source, x=s[:, 3], y=s[:, 4], psi=s[:, 5],
                          u=s[:, 0], v=s[:, 1], r=s[:, 2], U=np.hypot(s[:, 0], s[:, 1]), delta=run.inputs.delta,
                          n=run.inputs.n, meta={"length_m": rep.L})
        try:
            out.append(record_metrics(rec) if np.all(np.isfinite(s)) else None)
        except (InputError, ValueError):
            out.append(None)
    return out[0], out[1]


def _fmt_metric(m: dict | None, key: str) -> str:
    if m is None or m.get(key) is None:
        return "-"
    v = m[key]
    if isinstance(v, (list, tuple)):
        return ", ".join(f"{x:.1f}" for x in v[:3]) if len(v) else "-"
    return f"{v:.2f}" if np.isfinite(v) else "-"


def _change_text(pct: float) -> str:
    """A fitted value's change from its config value, in per cent; "-" where the config value is 0
    (a term the config does not have, e.g. ``Y_P_astern``: no relative change to give)."""
    return "-" if not np.isfinite(pct) else f"{pct:+.0f} %"


def ship_yaml(ship_path: Path, values: dict, note: str, covariance: dict | None = None,
              identification: dict | None = None, spread: dict | None = None, model_form: dict | None = None) -> str:
    """The ship YAML at ``ship_path`` with the fitted ``values`` written in (hull coefficients,
    ``w_P0`` constant term, ``Y_P_astern``, the rudder's ``epsilon``, ``kappa``, ``gamma_R_pos``,
    ``gamma_R_neg``, ``l_R_prime``, the added masses, a rudder offset and the wind factors) and ``note`` in its header and ``source``; with
    ``covariance`` (:func:`fit_covariance`) its ``covariance:`` section (else none: the initial
    ship's own section, if any, is about other values and is dropped); with ``identification``
    (:func:`identification_summary`) its ``identification:`` section and its warnings as header comments,
    with ``spread`` (:func:`run_spread`) its ``run_spread:`` section (else none of either, as the covariance),
    with ``model_form`` (:func:`trials.measured.identify.covariance.model_form`) its ``model_form:`` section."""
    import yaml

    from mmg.parameters import write_yaml_value

    data = yaml.safe_load(Path(ship_path).read_text())
    for k, v in values.items():
        write_yaml_value(data, k, v, ship_path)
    data.pop("covariance", None)
    data.pop("identification", None)
    if covariance is not None:
        data["covariance"] = covariance
    if identification is not None:
        data["identification"] = identification
    data.pop("run_spread", None)
    if spread is not None:
        data["run_spread"] = spread
    data.pop("model_form", None)
    if model_form is not None:
        data["model_form"] = model_form
    data["name"] = f"{data['name']} (identified)"
    data["source"] = f"{data.get('source', '')}; identified by mmg identify: {note}"
    head = "".join(f"# {ln}\n" for ln in note.splitlines() + _warning_lines(identification))
    return head + yaml.safe_dump(data, sort_keys=False, allow_unicode=True)


def _warning_lines(identification: dict | None) -> list[str]:
    """The header comment lines of an ``identification:`` section: whether the fit converged, then its warnings."""
    if identification is None:
        return []
    from mmg.ship import one_line

    w = identification["warnings"]
    out = [("every fit stage converged" if identification["converged"] else
            "NOT CONVERGED: a fit stage stopped at its evaluation limit")
           + (f"; {len(w)} warning(s) (also in the identification: section):" if w else "; no warnings")]
    return out + [f"- {one_line(x)}" for x in w]


_COMPUTE = object()


def identification_summary(ident: Identification, covariance=_COMPUTE) -> dict:
    """What ``mmg identify`` says of its own fit: the ``identification:`` section of the ship.yaml it writes.

    Parameters
    ----------
    ident : Identification
    covariance : dict or None, optional
        The ``covariance:`` section written beside it (:func:`identification_covariance` of ``ident`` when
        omitted; None: none written).

    Returns
    -------
    dict
        ``converged`` (bool: every fit stage converged, scipy status > 0), ``warnings`` (list of str, one
        sentence each: the fit's own (a value on its bound, a changed sign), each stage stopped at its
        evaluation limit, each training record the identified model replays worse than the initial one,
        each failed physical check), ``covariance_method`` (the covariance section's ``method`` when it
        has one, else how :func:`identification_covariance` made it) and ``training_replays_worse``
        (those records' names).
    """
    if covariance is _COMPUTE:
        covariance = identification_covariance(ident)
    fit = ident.fit
    st = ident.stages or ({"description": stage_description(ident.segment_s), "max_nfev": None,
                           "evaluations": fit.iterations, "status": fit.status},)
    warn = [w for w in fit.warnings() if not (fit.status == 0 and w.startswith("the fit stopped at its evaluation"))]
    for k, x in enumerate(st):                        # every stage's stop (the fit's own says the last one's only)
        if not x["status"] > 0:
            lim = "" if x.get("max_nfev") is None else f" ({x['max_nfev']})"
            warn.append(f"stage {k + 1}/{len(st)} ({x['description'].split(':')[0]}) stopped at its evaluation "
                        f"limit{lim} after {x['evaluations']} evaluations without converging: mmg identify --max-nfev "
                        f"raises it")
    worse = []
    for a, b in zip(ident.scores(model="initial"), ident.scores()):
        ha, hb = a["heading_rms_deg"], b["heading_rms_deg"]
        if np.isfinite(ha) and not hb <= ha:
            worse.append(a["name"])
            warn.append(f"training record {a['name']}: the identified model replays it worse than the initial model "
                        f"(heading RMS {hb:.2f} deg against {ha:.2f} deg)")
    warn += [f"physical check: {w}" for w in ident.physical_check().warnings()]
    return {"converged": bool(all(x["status"] > 0 for x in st)), "warnings": warn,
            "covariance_method": _covariance_method(ident, covariance), "training_replays_worse": worse}


def _covariance_method(ident: Identification, covariance: dict | None) -> str:
    """The ``method`` of a covariance section, else how :func:`identification_covariance` makes it."""
    if covariance is None:
        return "none written (the fit's covariance is not finite)"
    if covariance.get("method"):
        return str(covariance["method"])
    return (f"linearised posterior (J_d^T J_d / (s_d^2 tau) + diag(1 / sigma_prior^2))^-1: the prior at its stated "
            f"std, the data's information divided by the residuals' correlation time tau = "
            f"{max(float(ident.tau), 1.0):.3g} samples")


def _stage_lines(ident: Identification) -> list[str]:
    """The report's account of the fit stages: what each fitted, how many evaluations of its limit it
    used and why it stopped (a stage at its limit says how to raise it)."""
    st = ident.stages or ({"description": stage_description(ident.segment_s), "evaluations": ident.fit.iterations,
                           "max_nfev": None, "status": ident.fit.status, "message": ident.fit.message},)
    out = [f"Fitted in {len(st)} stage{'s' if len(st) > 1 else ''}, each starting from the previous one's values:"]
    for k, s in enumerate(st):
        lim = "" if s.get("max_nfev") is None else f" of at most {s['max_nfev']}"
        stop = (" (stopped at its evaluation limit, not converged: mmg identify --max-nfev raises it)"
                if s["status"] == 0 else f" ({s['message']})")
        out.append(f"{k + 1}. {s['description']}; {s['evaluations']} evaluations{lim}{stop}.")
    if len(st) > 1:
        out += ["", "Each stage has its own cost (segments restarted from the record, or the whole record open loop): "
                    "a stage's cost is not comparable with the one before it (the whole record usually costs more)."]
    return out


def _cov_std(cov: dict | None) -> dict:
    """{name: standard error} of a ``covariance:`` section (:func:`identification_covariance`); {} for None."""
    return dict(zip(cov["names"], np.sqrt(np.diag(np.asarray(cov["matrix"], float))))) if cov else {}


def free_parameter_text(fit) -> str:
    """The fit's free parameters counted in words, the same on the console and in report.md: ``"22 model
    parameters and 12 start-state offsets (34 in all)"``, or ``"22 model parameters"`` without offsets.

    ``fit`` has ``free``, each with its ``kind``: ``"start"`` for a record's start-state offset (a nuisance
    that moves one replay's start, not the model), anything else a model parameter."""
    starts = sum(1 for f in fit.free if f.kind == "start")
    model = len(fit.free) - starts
    text = f"{model} model parameter{'s' * (model != 1)}"
    if starts:
        text += f" and {starts} start-state offset{'s' * (starts != 1)} ({model + starts} in all)"
    return text


def _report_fit(ident: Identification, cov: dict | None, warn: list) -> list:
    """The report's title, stages, values with standard errors (of ``cov``, the written covariance section),
    warnings (``warn``: :func:`identification_summary`'s) and strong correlations."""
    fit = ident.fit
    lines = [f"# Identification of {ident.initial.name}", ""]
    if ident.prior is not None:
        lines += [f"Fitted in the form of {ident.prior.name} (the prior, 'config' below); 'initial' scores are "
                  f"{ident.initial.name}'s.", ""]
    lines += [
             f"Records: {len(ident.runs)}; fitted: {free_parameter_text(fit)}; residuals {fit.n_residuals}; "
             f"records weighted {ident.record_weighting!r}; velocity residuals weighted {ident.velocity_weight:g} "
             f"beside the heading's.", "", *_stage_lines(ident), "",
             "## Values and standard errors", "",
             "Standard errors from the covariance written into ship.yaml "
             f"(method `{(cov or {}).get('method', 'none')}`: the linearised posterior, the prior at "
             f"its stated std, the data's information divided by the residuals' correlation time tau = "
             f"{max(ident.tau, 1.0):.3g} samples, plus the delete-one-run jackknife over the independent runs where "
             "there are two or more; :func:`identification_covariance`); where it is singular, the "
             "fit's own Gauss-Newton ones.", "",
             "| parameter | config | identified | std | change |", "|---|---|---|---|---|"]
    std = _cov_std(cov)
    starts = [f for f in fit.free if f.kind == "start"]
    for name, row in fit.to_pandas().iterrows():
        if name.startswith("start."):
            continue
        lines.append(f"| {name} | {row.prior:.5g} | {row.estimate:.5g} | {std.get(name, row['std']):.2g} | "
                     f"{_change_text(row.change_pct)} |")
    if starts:
        lines += ["", f"Each record's start state (u, v, r, heading of its first sample) was fitted as a nuisance "
                      f"({len(starts)} offsets, not listed; prior 0 with twice the record's noise level as std)."]
    if warn:
        lines += ["", "## Warnings", "",
                  "Where the identified values should not be read as the ship's physics, or the fit not as "
                  "finished (also in ship.yaml's identification: section, which mmg imo reads):", ""] + \
                 [f"- {w}" for w in warn]
    names = [f.name for f in fit.free]
    lines += ["", "## Correlations (|rho| >= 0.8)", ""]
    strong = [(names[i], names[j], fit.corr[i, j]) for i in range(len(names)) for j in range(i + 1, len(names))
              if np.isfinite(fit.corr[i, j]) and abs(fit.corr[i, j]) >= 0.8]
    lines += [f"- {x} / {y}: {c:+.2f}" for x, y, c in strong] or ["- none"]
    return lines


def _report_physical(chk) -> list:
    """The report's physical checks (:mod:`trials.measured.physical`)."""
    lines = ["", "## Physical checks", "",
             "Energy: with the propeller stopped and the rudder amidships the ship must lose energy at every "
             "state (dT/dt <= 0, mmg.dissipation), checked at the states the training records log and over "
             "the box of their ranges; replays: every training record replayed open loop.", ""]
    for what, c in (("identified, logged states", chk.logged), ("identified, range box", chk.box),
                    ("prior, logged states", chk.prior_logged), ("prior, range box", chk.prior_box)):
        lines.append(f"- {what}: {c.describe()}")
    lines.append(f"- replays: {len(chk.divergences)} diverged" + "".join(f"\n  - {d.describe()}" for d in chk.divergences))
    return lines


def _report_model_form(form: dict | None, why: str, L: float) -> list:
    """The report's model-form term (the ``model_form:`` section): its half-width per elapsed time, in
    seconds of this ship and in sqrt(L/g), and where it came from; ``why``: what limits it."""
    from mmg.model import G

    if form is None:
        return ["", "## Model-form term", "", f"None written: {why}."]
    unit = float(np.sqrt(L / G))
    lines = ["", "## Model-form term (`model_form:`, drawn by `mmg predict --samples`)", "",
             f"Made from the {form['source']}.", "",
             "| elapsed [s] | elapsed [sqrt(L/g)] | heading error, 90 % [deg] | position error, 90 % [m] |",
             "|---|---|---|---|"]
    pos = form.get("position_q90_L") or [None] * len(form["elapsed_froude"])
    lines += [f"| {t * unit:.4g} | {t:.4g} | {q:.3g} | {'-' if p is None else f'{p * L:.3g}'} |"
              for t, q, p in zip(form["elapsed_froude"], form["heading_q90_deg"], pos)]
    u = form.get("unbounded_from_froude")
    if u is not None:
        lines += ["", f"Unbounded from {u * unit:.4g} s ({u:.4g} sqrt(L/g)) of elapsed time on: replays diverged "
                      "there, and `mmg predict --samples` draws unbounded bands beyond."]
    return lines


def _report_training(ident: Identification) -> list:
    """The report's training fits (heading and speed RMS) and manoeuvre metrics, measured and replayed."""
    a = ident.scores(model="initial")
    b = ident.scores()
    lines = []
    lines += ["", "## Training fits (open-loop replay from each record's first state)", "",
              "| record | heading RMS initial [deg] | identified [deg] | speed RMS initial [m/s] | identified [m/s] |",
              "|---|---|---|---|---|"]
    for x, y in zip(a, b):
        lines.append(f"| {x['name']} | {x['heading_rms_deg']:.2f} | {y['heading_rms_deg']:.2f} | "
                     f"{x['speed_rms_mps']:.3f} | {y['speed_rms_mps']:.3f} |")
    ha, hb = np.nanmean([x["heading_rms_deg"] for x in a]), np.nanmean([y["heading_rms_deg"] for y in b])
    lines.append(f"| **mean** | {ha:.2f} | {hb:.2f} | | |")
    lines += ["", "## Manoeuvre metrics: measured, initial model, identified model", "",
              "From each record and from its open-loop replays (same inputs); '-' where the record or the "
              "replay is not a complete turn / zigzag.", "",
              "| record | " + " | ".join(f"{h} meas / init / ident" for _, h in METRIC_COLUMNS) + " |",
              "|---|" + "---|" * len(METRIC_COLUMNS)]
    for r in ident.runs:
        m0, mi = manoeuvre_metrics(replay_record(ident.initial, r))
        _, mf = manoeuvre_metrics(ident.replay(r))
        lines.append(f"| {r.name} | " + " | ".join(f"{_fmt_metric(m0, k)} / {_fmt_metric(mi, k)} / {_fmt_metric(mf, k)}"
                                                    for k, _ in METRIC_COLUMNS) + " |")
    return lines


def _report_test(ident: Identification, test_runs) -> list:
    """The report's predictions of the records never trained on."""
    lines = []
    lines += ["", "## Predictions of records never trained on", "",
              "| record | heading RMS initial [deg] | identified [deg] | speed RMS initial [m/s] | identified [m/s] | "
              "final position error initial [L] | identified [L] |", "|---|---|---|---|---|---|---|"]
    gone = []
    for r in test_runs:
        ri, rf = ident.replay(r, "initial"), ident.replay(r)
        x, y = ri.scores(), rf.scores()
        gone += [f"{r.name} ({who}, at t = {g.diverged_at:.1f} s)" for who, g in (("initial", ri), ("identified", rf))
                 if g.diverged_at is not None]
        lines.append(f"| {r.name} | {x['heading_rms_deg']:.2f} | {y['heading_rms_deg']:.2f} | {x['speed_rms_mps']:.3f} | "
                     f"{y['speed_rms_mps']:.3f} | {x['final_position_error_L']:.2f} | {y['final_position_error_L']:.2f} |")
    if gone:
        lines += ["", f"'nan': the replay diverged (its state stopped being finite): {', '.join(gone)}."]
    return lines


def _comparable_spread(cv: list, ident: Identification, cov: dict | None):
    """(:class:`~trials.measured.foldspread.FoldSpread` of ``cv`` against ``cov``'s standard errors, the shared
    parameters not in every fold) where the folds fitted the model written; else (None, the reason)."""
    from ..foldspread import fold_spread

    if cov is None:
        return None, "No covariance was written (singular fit): the folds' spread is not compared."
    sp = fold_spread(cv, _cov_std(cov))
    shared = {n for n in ident.fit.values() if "[" not in n}
    left = sorted(shared - set(sp.names))
    droppable = {"Y_P_astern", *_wind_keys()}          # left out of a fold whose records cannot fit them (_free_of)
    if not sp.same_choice or not set(sp.names) <= shared or not set(left) <= droppable:
        return None, ("The folds fitted another model than the one written (another hull form or free set): "
                      "no fold spread (it compares fits of one model).")
    return sp, left


def fold_spread_json(cv: list, ident: Identification, cov: dict | None, posterior=None) -> dict | None:
    """What ``mmg identify --cv`` writes to ``DIR/fold_spread.json``: the written standard errors against the
    folds' jackknife (:mod:`trials.measured.foldspread`).

    Returns
    -------
    dict or None
        ``{"median_ratio", "folds", "method", "parameters": [{"name", "stated_se", "jackknife_se", "ratio",
        "posterior_se"}, ...]}`` (ratio: jackknife over stated; ``posterior_se`` the linearised posterior's
        alone, from ``posterior``, the full matrix over the fit's free parameters, where given) with
        ``median_ratio_posterior`` beside it; ``{"median_ratio": None, "note": ...}`` where the folds
        cannot be compared; None where the folds carry no values.
    """
    if not all("values" in c for c in cv):
        return None
    sp, left = _comparable_spread(cv, ident, cov)
    if sp is None:
        return {"median_ratio": None, "note": left, "parameters": []}
    post = {}
    if posterior is not None:
        d = np.sqrt(np.abs(np.diag(np.asarray(posterior, float))))
        post = {f.name: float(x) for f, x in zip(ident.fit.free, d)}

    def num(x):
        return float(x) if np.isfinite(x) else None

    params = [{"name": n, "stated_se": num(sp.stated[j]), "jackknife_se": num(sp.jackknife[j]),
               "ratio": num(sp.ratio[j]), "posterior_se": post.get(n)} for j, n in enumerate(sp.names)]
    rp = [p["jackknife_se"] / p["posterior_se"] for p in params
          if p["jackknife_se"] is not None and p["posterior_se"]]
    return {"median_ratio": num(sp.median_ratio()), "folds": len(sp.values), "method": cov.get("method", ""),
            "median_ratio_posterior": float(np.median(rp)) if rp else None, "not_in_every_fold": left,
            "parameters": params}


def _report_spread(cv: list, ident: Identification, cov: dict | None) -> list:
    """The report's check of the written standard errors (``cov``, ship.yaml's covariance section) against
    the folds' spread (:mod:`trials.measured.foldspread`); nothing where the folds carry no values."""
    if not all("values" in c for c in cv):
        return []
    sp, left = _comparable_spread(cv, ident, cov)
    if sp is None:
        return ["", left]
    lines = ["", "## The written standard errors against the folds' spread", "",
             "Each fold fitted the model without its kept-out records.  The jackknife standard error over the "
             f"{len(sp.values)} folds counts how the fit moves when a group of records is left out; the written one "
             "(ship.yaml's covariance) is meant to count the same: its run-to-run part is a jackknife over single "
             "runs of the fit on all the records.  A ratio well above 1 says the written covariance (and "
             "`mmg imo --samples`, which draws from it) is too sure by about that factor; well below 1, too cautious "
             "(or that the folds' fits stopped short of their optimum: the report's stages).  "
             "`DIR/fold_spread.json` has the same figures.", "",
             "| parameter | identified | written std | jackknife std | ratio | folds' signs differ |",
             "|---|---|---|---|---|---|"]
    fitted = ident.fit.values()
    for j, n in enumerate(sp.names):
        lines.append(f"| {n} | {fitted.get(n, np.nan):.5g} | {sp.stated[j]:.2g} | {sp.jackknife[j]:.2g} | "
                     f"{sp.ratio[j]:.1f} | {'yes' if sp.sign_differs[j] else ''} |")
    lines += ["", f"Median ratio {sp.median_ratio():.2f} over {int(np.isfinite(sp.ratio).sum())} parameters "
                  f"({len(sp.values)} folds: a rough figure)."]
    if left:
        lines += [f"Not in every fold's fit (no record to fit it on there): {', '.join(left)}."]
    return lines


def _report_cv(cv: list) -> list:
    """The report's cross-validation table and summary."""
    lines = []
    lines += ["", f"## Cross-validation ({max(c['fold'] for c in cv) + 1} folds, each record kept out once)", "",
              "| record | fold | heading RMS initial [deg] | identified without it [deg] | ratio |", "|---|---|---|---|---|"]
    for c in cv:
        x, y = c["initial"]["heading_rms_deg"], c["identified"]["heading_rms_deg"]
        lines.append(f"| {c['name']} | {c['fold']} | {x:.2f} | {y:.2f} | {x / y:.2f} |")
    ok = [c for c in cv if np.isfinite(c["identified"]["heading_rms_deg"])]   # (a diverged replay: below)
    xa = np.mean([c["initial"]["heading_rms_deg"] for c in ok])
    xb = np.mean([c["identified"]["heading_rms_deg"] for c in ok])
    better = sum(c["identified"]["heading_rms_deg"] < c["initial"]["heading_rms_deg"] for c in cv)
    lines.append(f"| **mean** | | {xa:.2f} | {xb:.2f} | {xa / xb:.2f} |")
    lines += ["", f"Identified better on {better} of {len(cv)} kept-out records; mean ratio {xa / xb:.2f}."]
    diverged = [c["name"] for c in cv if not np.isfinite(c["identified"]["heading_rms_deg"])]
    if diverged:
        lines += ["", f"The identified model's replay diverged on {len(diverged)} kept-out record(s) "
                      f"({', '.join(diverged)}): counted as not better, left out of both means."]
    return lines


def write_identification(ident: Identification, ship_path, out_dir, cv: list | None = None, test_runs=None) -> dict:
    """Write ``out_dir/ship.yaml`` (with :func:`identification_summary` as its ``identification:`` section
    and header comments) and ``out_dir/report.md``; return the paths written.

    ``ship_path`` is the initial ship's YAML (its comments are not kept; the fitted values
    replace the config's).  ``cv`` is :func:`cross_validate`'s output, reported when given;
    ``test_runs`` (records never trained on) are predicted with both models and reported."""
    out_dir = Path(out_dir)
    fit = ident.fit
    note = (f"segment-wise output error over {len(ident.runs)} records "
            f"({', '.join(r.name for r in ident.runs)}); cost {fit.cost_initial:.4g} -> {fit.cost_final:.4g}")
    cov, post, _ = identification_covariance(ident, parts=True)
    summary = identification_summary(ident, cov)
    form, why = model_form(ident, cv)
    (out_dir / "ship.yaml").write_text(ship_yaml(ship_path, fit.values(), note, cov, summary, spread=run_spread(ident),
                                                 model_form=form))
    lines = (_report_fit(ident, cov, summary["warnings"]) + _report_physical(ident.physical_check())
             + _report_training(ident) + _report_model_form(form, why, ident.ship.particulars.L))
    if test_runs:
        lines += _report_test(ident, test_runs)
    written = {"ship": out_dir / "ship.yaml", "report": out_dir / "report.md"}
    if cv:
        lines += _report_cv(cv) + _report_spread(cv, ident, cov)
        spread = fold_spread_json(cv, ident, cov, post)
        if spread is not None:
            import json

            (out_dir / "fold_spread.json").write_text(json.dumps(spread, indent=1) + "\n")
            written["fold_spread"] = out_dir / "fold_spread.json"
    (out_dir / "report.md").write_text("\n".join(lines) + "\n")
    return written
