"""The identified parameters' covariance and run-to-run spread: the linearised posterior inflated by the
residuals' autocorrelation time, the delete-one-run jackknife over the independent runs
(:func:`identification_covariance`), and the spread of each record's fitted start state and nuisances
(:func:`run_spread`).
"""
from __future__ import annotations

import numpy as np

from mmg.parameters import unit_of

from .fit import Identification, _nuisance_effects, same_run_groups, start_noise

__all__ = ["fit_covariance", "identification_covariance", "run_covariance", "COVARIANCE_METHOD", "run_spread",
           "START_UNITS", "training_state_range"]


def _covariance_section(fit, cov: np.ndarray, note: str, method: str = "") -> dict | None:
    """The ``covariance:`` section of the shared parameters (a record's own nuisance left out: the block
    of the joint covariance is their marginal); None when it is not finite."""
    keep = [i for i, f in enumerate(fit.free) if f.record is None]
    cov = np.asarray(cov, float)[np.ix_(keep, keep)]
    if not np.all(np.isfinite(cov)):
        return None
    cov = 0.5 * (cov + cov.T)
    names = [fit.free[i].name for i in keep]
    return {"names": names, "units": [unit_of(n) for n in names],
            "values": [float(f"{fit.theta[i]:.10g}") for i in keep],
            "matrix": [[float(f"{x:.10g}") for x in row] for row in cov], "source": note,
            **({"method": method} if method else {})}


def fit_covariance(fit, note: str = "") -> dict | None:
    """The ``covariance:`` section of a ship YAML from a fit (:class:`ekf.identify.IdentifyResult`) with
    its own Gauss-Newton covariance (``corr * std std^T``: the whole inverse J^T J, prior rows included,
    times the residual variance): its shared parameters' names, units (:func:`mmg.parameters.unit_of`), fitted
    values and covariance; None when it is not finite (a singular fit).  What ``mmg identify`` writes is
    :func:`identification_covariance`'s."""
    std = np.asarray(fit.std, dtype=float)
    cov = np.asarray(fit.corr, dtype=float) * np.outer(std, std)
    return _covariance_section(fit, cov, note or "Gauss-Newton covariance of the fit scaled by the residual variance")


def posterior_covariance(fit, tau: float = 1.0) -> np.ndarray:
    """(J_d^T J_d / (s_d^2 max(tau, 1)) + diag(1 / sigma_prior^2))^-1 over every free parameter of ``fit``:
    the data rows' information (:attr:`ekf.identify.IdentifyResult.info_data`) scaled by their own
    residual variance s_d^2 = ss_d / (N_d - n) and divided by their correlation time, the prior's at its
    stated std; NaN where the fit has no data information or it is singular."""
    n = len(fit.free)
    if fit.info_data is None or fit.ss_data is None:
        return np.full((n, n), np.nan)
    n_data = int(fit.n_residuals) - n
    sd2 = float(fit.ss_data) / max(n_data - n, 1)
    sig = np.array([f.sigma for f in fit.free], float)
    info = np.asarray(fit.info_data, float) / (sd2 * max(float(tau), 1.0)) + np.diag(1.0 / sig ** 2)
    try:
        return np.linalg.inv(info)
    except np.linalg.LinAlgError:
        return np.full((n, n), np.nan)


COVARIANCE_METHOD = "posterior+run-jackknife"
"""The ``method`` of the covariance ``mmg identify`` writes (:func:`identification_covariance`)."""


def run_covariance(ident: Identification) -> np.ndarray | None:
    """The run-to-run part of the written covariance: :func:`ekf.identify.run_jackknife_covariance` over
    the training records' independent runs (:func:`same_run_groups`: a record and its cuts are one run),
    over every free parameter; None with fewer than two runs or a fit without per-record scores."""
    from ekf.identify import run_jackknife_covariance

    try:
        return run_jackknife_covariance(ident.fit, same_run_groups(ident.runs))
    except ValueError:
        return None


def identification_covariance(ident: Identification, parts: bool = False):
    """The ``covariance:`` section ``mmg identify`` writes into ship.yaml (the docstring of
    :mod:`trials.measured.identify.fit`).

    The sum of two parts over the shared parameters' block: the linearised posterior
    (:func:`posterior_covariance` with the fit's residual correlation time :attr:`Identification.tau`:
    the residuals' noise and the prior at its stated std, which alone speaks for a parameter the records
    do not inform) and the run-to-run jackknife (:func:`run_covariance`: how far the fit moves when one
    independent run is left out, which counts what the records disagree on: a model form that is not
    the ship's, a disturbance that differs from run to run).  Where the model is right and the runs
    agree, the two count the same noise and the sum overstates the variance by up to 2 (standard errors
    by up to 1.41); on real records the run-to-run part dominates.

    Parameters
    ----------
    ident : Identification
    parts : bool
        Also return the two parts' full matrices (every free parameter): ``(section, posterior, runs)``.

    Returns
    -------
    dict or None
        The section (``names``, ``units``, ``values``, ``matrix``, ``source``, ``method``); None when it
        is not finite.  With ``parts``, a tuple as above (``runs`` None where it could not be made).
    """
    tau = max(float(ident.tau), 1.0)
    start = ("each record's start state fitted as a nuisance" if ident.initial_state == "fit"
             else "each record replayed from its first sample")
    post = posterior_covariance(ident.fit, tau)
    runs = run_covariance(ident)
    n_runs = len(set(same_run_groups(ident.runs)))
    note = (f"linearised posterior of mmg identify's fit ({start}): (J_d^T J_d / (s_d^2 tau) + "
            f"diag(1 / sigma_prior^2))^-1, the prior at its stated std, the data's information divided by the "
            f"residuals' integrated autocorrelation time tau = {tau:.3g} samples"
            + (" (inflated)" if tau > 1.0 else " (not inflated: white residuals)"))
    if runs is not None:
        note += (f"; plus the delete-one-run jackknife over the {n_runs} independent runs (one Gauss-Newton step "
                 f"from the fit without each run): the spread from run to run")
        section = _covariance_section(ident.fit, post + runs, note, COVARIANCE_METHOD)
    else:
        note += f"; no run-to-run part ({n_runs} independent run: the jackknife needs two or more)"
        section = _covariance_section(ident.fit, post, note, "posterior")
    state_range = training_state_range(ident.runs) if section is not None else {}
    if state_range:
        section["state_range"] = state_range
    return (section, post, runs) if parts else section


def training_state_range(runs) -> dict:
    """The ``state_range`` of the covariance section: ``u_mps``, ``v_mps``, ``r_radps``, each [min, max] of
    the states the records ``runs`` log (those :func:`trials.measured.physical.physical_check` checks), over
    which a drawn ship is checked not to gain energy (:func:`trials.measured.draws.support_of`); {} without a
    finite logged state."""
    from ..physical import logged_states

    if not any(np.isfinite(r.meas[:, :3]).all(axis=1).any() for r in runs):
        return {}
    return {k: [float(f"{np.min(a):.6g}"), float(f"{np.max(a):.6g}")]
            for k, a in zip(("u_mps", "v_mps", "r_radps"), logged_states(runs))}


START_UNITS = {"u": "m/s", "v": "m/s", "r": "rad/s", "psi": "rad"}
"""The SI unit of each fitted start-state offset (kind ``"start"``), by state name."""


def _nuisance_groups(ident: Identification) -> dict:
    """{quantity name: (SI unit, factor to SI, [fitted value of each record that has it])} of the fit's
    per-record nuisances: start offsets as ``start.<state>``, effect parameters as ``<effect>.<parameter>``
    (a parameter in degrees as ``..._rad``, in radians)."""
    from mmg.replay import STATE

    effects = _nuisance_effects(ident.record_nuisance)
    out = {}
    for f, v in zip(ident.fit.free, ident.fit.theta):
        if f.record is None:
            continue
        if f.kind == "start":
            name, unit, k = f"start.{STATE[f.sub]}", START_UNITS[STATE[f.sub]], 1.0
        else:
            q = effects[f.index].fit_parameters()[f.sub]
            deg = q.unit == "deg"
            name = f"{effects[f.index].name}.{q.name[:-4] + '_rad' if deg and q.name.endswith('_deg') else q.name}"
            unit, k = ("rad", np.pi / 180.0) if deg else (q.unit, 1.0)
        out.setdefault(name, (unit, k, []))[2].append(float(v))
    order = {f"start.{x}": i for i, x in enumerate(STATE)}          # the start offsets in state order, first
    return dict(sorted(out.items(), key=lambda kv: order.get(kv[0], len(order))))


def run_spread(ident: Identification) -> dict | None:
    """The ``run_spread:`` section of ship.yaml: how much each record's own disturbance varies between runs.

    Where the fit has per-record nuisances (each record's start-state offsets, ``initial_state="fit"``;
    the ``record_nuisance`` effects), each quantity's sample standard deviation (ddof 1) of its fitted
    values across the training records that have it (two at least); otherwise (``initial_state="sample"``,
    or a single record) the measured start-state noise (:func:`start_noise`: the std of a first sample's
    error), the root mean square over the records, for u, v, r and the heading.

    Returns
    -------
    dict or None
        ``names`` (``start.u``, ``start.v``, ``start.r``, ``start.psi``, ``<effect>.<parameter>``), ``units``
        (SI), ``std`` (in ``units``), ``records`` (the training records) and ``source`` (how it was
        computed); None when there is nothing finite to write.
    """
    groups = {k: g for k, g in _nuisance_groups(ident).items() if len(g[2]) >= 2}
    n = len(ident.runs)
    if groups:
        names = list(groups)
        units = [groups[k][0] for k in names]
        std = [groups[k][1] * float(np.std(groups[k][2], ddof=1)) for k in names]
        counts = sorted({len(groups[k][2]) for k in names})
        over = f"{counts[0]}" if len(counts) == 1 else f"{counts[0]} to {counts[-1]}"
        source = (f"sample standard deviation (ddof 1) of mmg identify's fitted per-record nuisances across "
                  f"{over} of the {n} training records (a start offset is fitted only where the channel shows noise)")
    else:
        from mmg.replay import STATE

        noise = np.array([start_noise(r) for r in ident.runs])
        names, units, std = [], [], []
        for j in (0, 1, 2, 5):
            col = noise[:, j][np.isfinite(noise[:, j])]
            if len(col):
                names.append(f"start.{STATE[j]}")
                units.append(START_UNITS[STATE[j]])
                std.append(float(np.sqrt(np.mean(col ** 2))))
        source = (f"no per-record nuisance fitted on two or more records: the measured start-state noise "
                  f"(start_noise, the RMS over the {n} training records of each channel's noise std), the std of "
                  f"a first sample's error")
    keep = [i for i, s in enumerate(std) if np.isfinite(s)]
    if not keep:
        return None
    return {"names": [names[i] for i in keep], "units": [units[i] for i in keep],
            "std": [float(f"{std[i]:.6g}") for i in keep], "records": n, "source": source}


def model_form(ident: Identification, cv: list | None = None) -> tuple[dict | None, str]:
    """(the ``model_form:`` section of ship.yaml or None, what limits it):
    :func:`trials.measured.modelform.model_form_section`, the heading and position error a replay gains
    with elapsed time.  With ``cv`` (:func:`~.fit.cross_validate`'s records, each kept-out record with the ``ship`` and
    ``values`` of the fit that did not see it) from those kept-out replays; otherwise from the fit's own
    training replays, in sample (a lower bound, said in the section's ``source``)."""
    from ..modelform import heading_error_curves, model_form_section, position_error_curves
    from .fit import replay_fitted

    L = ident.ship.particulars.L
    by_name = {r.name: r for r in ident.runs}
    kept = [c for c in (cv or []) if c.get("ship") is not None and c.get("name") in by_name]
    if kept:
        reps = [replay_fitted(c["ship"], c["values"], by_name[c["name"]]) for c in kept]
        folds = len({c.get("fold") for c in kept})
        source = (f"heading and position errors of the {len(reps)} kept-out replays of a {folds}-fold cross-validation (each by "
                  "the fit that did not see it), 90 % quantile per bin of elapsed time")
    else:
        reps = [ident.replay(r) for r in ident.runs]
        source = (f"heading and position errors of the fit's own {len(reps)} training replays, in sample (a new record's are "
                  "larger: identify with --cv for kept-out ones), 90 % quantile per bin of elapsed time")
    return model_form_section(heading_error_curves(reps), L, source, position_error_curves(reps, L))
