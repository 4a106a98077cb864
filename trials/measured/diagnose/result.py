"""The result of the diagnosis, :class:`Diagnosis`, built once from the steps' outputs
(:func:`_diagnosis`): the named effects with their values and standard errors, the residuals before and
after, what is left unexplained (:func:`_describe`), the ship's fitted coefficients and those far from
their priors (:func:`model_form_mismatch`)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from mmg.parameters import config_values

from .decision import record_kind, residual_floor
from .rules import module_rule, rule
from .fit import _Model
from .statistics import _effect_report, _r2, _rms, _taus

__all__ = ["Diagnosis", "CHANNELS", "UNEXPLAINED_FACTOR", "MISMATCH_Z", "ship_fit_table",
           "model_form_mismatch", "straight_run_table", "absent_table"]


_RULES = {"UNEXPLAINED_FACTOR": "unexplained_factor", "MISMATCH_Z": "mismatch_z"}
"""The module's names of numbers of the diagnosis rules (:mod:`.rules`), read-only: ``UNEXPLAINED_FACTOR``,
the multiple of the channel's noise level above which a residual RMS is reported unexplained; ``MISMATCH_Z``,
the prior std from its config value beyond which a fitted ship coefficient is reported as model-form mismatch
(:attr:`Diagnosis.model_form_mismatch`) and not written to ``--out-ship``."""
__getattr__ = module_rule(__name__, _RULES)


CHANNELS = ("u", "v", "r", "heading", "position")
"""Channels of ``rms_*``: u, v [m/s], r [deg/s], heading [deg], position [m] (RMS of the distance)."""


def absent_table(recs) -> list:
    """``[{"record", "channel", "column", "compared_instead"}]``: the residual channels each record does not log
    (:func:`trials.measured.diagnose.records.absent_channels`)."""
    return [{"record": r.name, "channel": c, **a} for r in recs for c, a in getattr(r, "absent", {}).items()]


def ship_fit_table(free, theta) -> list:
    """[{"name", "config", "fitted", "prior_std", "z"}] of the freed ship coefficients (added masses
    and moment in kg, kg m^2; hull coefficients primed), z their distance from the config in prior std."""
    return [{"name": f.name, "config": float(f"{f.prior:.5g}"), "fitted": float(f"{float(v):.5g}"),
             "prior_std": float(f"{f.sigma:.3g}"), "z": round((float(v) - f.prior) / f.sigma, 2) if f.sigma > 0 else 0.0}
            for f, v in zip(free, theta)]


def model_form_mismatch(free, theta) -> dict:
    """{coefficient: {"config", "fitted", "prior_std", "z"}} of the ship coefficients the fit took
    more than :data:`MISMATCH_Z` prior std from the config: the data ask for another model form (or
    an effect the candidates lack), not for these values."""
    return {r["name"]: {k: r[k] for k in ("config", "fitted", "prior_std", "z")}
            for r in ship_fit_table(free, theta) if abs(r["z"]) > rule("mismatch_z")}


def _describe(recs, diffs, noise, rms_after, L: float | None = None, kind: str | None = None) -> tuple[bool, str, dict]:
    """Unexplained flag, description and per-channel ratio residual / noise: a channel is unexplained
    when its residual is above :data:`UNEXPLAINED_FACTOR` times its noise *and* above what the ship's
    own mismatch leaves (:func:`trials.measured.diagnose.decision.residual_floor`, with the ship length ``L``
    and the kind of record set, :func:`~trials.measured.diagnose.decision.record_kind` when not given)."""
    D = np.vstack(diffs)
    M = np.vstack([r.seg.meas for r in recs])
    delta = np.concatenate([r.seg.inputs.delta for r in recs])
    ok = np.isfinite(D).all(axis=1)
    D, M, delta = D[ok], M[ok], delta[ok]
    names = ("u", "v", "r", "x", "y", "heading")
    ratio = {}
    for j, c in enumerate(names):
        ratio[c] = float(np.sqrt(np.mean(D[:, j] ** 2)) / max(noise[j], 1e-12))
    # position: the track's own growth within segments is not noise; judge u, v, r, heading
    U = float(np.median(np.hypot(M[:, 0], M[:, 1]))) if len(M) else 0.0
    rms = {c: float(np.sqrt(np.mean(D[:, names.index(c)] ** 2))) for c in ("u", "v", "r", "heading")}
    kind = kind or record_kind([r.seg.inputs.delta for r in recs])
    big = [c for c in ("u", "v", "r", "heading") if ratio[c] > rule("unexplained_factor")
           and (L is None or rms[c] > residual_floor(c, U, L, kind))]
    if not big:
        return False, "", ratio
    from .report import channel_text

    parts = []
    psi = M[:, 5]
    for c in big:
        j = names.index(c)
        e = D[:, j] - D[:, j].mean()
        desc = [channel_text(c, float(np.sqrt(np.mean(D[:, j] ** 2))), float(noise[j]), float(D[:, j].mean()))]
        # earth-fixed: explained by cos/sin of heading; rudder: by delta
        A = np.column_stack([np.cos(psi), np.sin(psi), np.ones_like(psi)])
        r2_h = _r2(A, D[:, j])
        r2_d = _r2(np.column_stack([delta, np.abs(delta), np.ones_like(delta)]), D[:, j])
        r2_c = 1.0 - float(np.var(e)) / max(float(np.mean(D[:, j] ** 2)), 1e-300)
        desc.append(f"its constant part {r2_c:.0%} of the mean square")
        desc.append(f"correlated with heading (earth-fixed) R2 {r2_h:.2f}")
        desc.append(f"with rudder R2 {r2_d:.2f}")
        ws = [r.seg.context.channels.get("wind_speed_rel") if r.seg.context else None for r in recs]
        if all(w is not None for w in ws):
            wd = [r.seg.context.channels.get("wind_dir_rel") for r in recs]
            w = np.concatenate(ws)[ok]
            g = np.concatenate(wd)[ok]
            q = w * w
            r2_w = _r2(np.column_stack([q * np.cos(g), q * np.sin(g), q * np.sin(2 * g), np.ones_like(q)]), D[:, j])
            desc.append(f"with relative wind R2 {r2_w:.2f}")
        parts.append(", ".join(desc))
    return True, "; ".join(parts) + ": no candidate effect explains it", ratio


@dataclass(frozen=True)
class Diagnosis:
    """The result of :func:`diagnose` (see :meth:`to_json`)."""

    named: list
    parameters: dict
    standard_errors: dict
    rms_config: dict
    rms_before: dict
    rms_after: dict
    unexplained: bool
    unexplained_description: str
    candidates: list
    rounds: list
    ship_values: dict
    records: list
    pred_before: list
    pred_after: list
    seconds: float
    runs: list = field(default_factory=list)
    effects: list = field(default_factory=list)
    ship_fit_values: dict = field(default_factory=dict)
    """The ship's values as written to ``--out-ship``, by fit name in the fit's units (:mod:`mmg.parameters`;
    :attr:`ship_values` has them under the config's keys)."""
    intervals_95: dict = field(default_factory=dict)
    """{effect: {parameter: [lo, hi] or "any"}} (:func:`trials.measured.diagnose.report.effect_intervals`)."""
    evidence: dict = field(default_factory=dict)
    """{effect: {"delta_bic", "z", "false_alarm_probability"}} (:func:`~trials.measured.diagnose.report.effect_evidence`)."""
    not_identifiable: list = field(default_factory=list)
    """[{"effect", "confused_with", "correlation", "what_would_separate"}]: effects these records cannot separate."""
    identifiability: list = field(default_factory=list)
    """Every candidate's correlation with the rest, std and detection size (:mod:`trials.measured.diagnose.identifiability`)."""
    model_form_mismatch: dict = field(default_factory=dict)
    """Ship coefficients the fit took far outside their priors (which, how far): :func:`model_form_mismatch`."""
    ship_fit: list = field(default_factory=list)
    """The freed ship coefficients: config, fitted, prior std, z (:func:`ship_fit_table`)."""
    baseline: str = "fitted"
    """"fitted", or "config (the fit replayed worse)" when the baseline fit was not kept."""
    straight_runs: list = field(default_factory=list)
    """The records' leading straight runs the fit used (:func:`straight_run_table`)."""
    absent_channels: list = field(default_factory=list)
    """Residual channels a record does not log and what was compared instead (:func:`absent_table`)."""
    model_form_effects: list = field(default_factory=list)
    """Effects the search named whose fit stands for a gap of the model's form, reported ``model_form_mismatch``
    instead (:func:`~.model_form.reclassify`): kept in the fitted model, not named."""

    @property
    def effect_status(self) -> dict:
        """{effect: "named", "model_form_mismatch" or "not_identifiable"} of the effects reported."""
        out = {x["effect"]: "not_identifiable" for x in self.not_identifiable or []}
        out.update({x["effect"]: x["status"] for x in self.model_form_effects})
        return {**out, **{e: "named" for e in self.named}}

    def summary_lines(self) -> list:
        """The console text (:func:`trials.measured.diagnose.report.summary_lines`)."""
        from .report import summary_lines

        return summary_lines(self)

    def to_json(self) -> dict:
        out = {"named_effects": list(self.named), "parameters": self.parameters,
               "standard_errors": self.standard_errors, "intervals_95": self.intervals_95,
               "evidence": self.evidence, "not_identifiable": list(self.not_identifiable),
               "model_form_mismatch": self.model_form_mismatch, "baseline": self.baseline,
               "ship_fit": self.ship_fit,
               "rms_before": self.rms_before, "rms_after": self.rms_after, "rms_config": self.rms_config,
               "rms_units": {"u": "m/s", "v": "m/s", "r": "deg/s", "heading": "deg", "position": "m"},
               "unexplained": bool(self.unexplained), "unexplained_description": self.unexplained_description,
               "candidates": self.candidates, "rounds": self.rounds,
               "threshold": {"delta_bic": rule("bic_threshold"), "z": rule("z_threshold")},
               "ship_coefficients": self.ship_values,
               "files": [r.source for r in self.records], "names": [r.name for r in self.records],
               "seconds": round(self.seconds, 2),
               "identifiability": self.identifiability, "straight_runs": self.straight_runs,
               "absent_channels": self.absent_channels, "model_form_effects": self.model_form_effects,
               "effect_status": self.effect_status}
        if self.runs:
            out["runs"] = [dict(r.to_json(), name=r.records[0].name, file=r.records[0].source) for r in self.runs]
        return out


def straight_run_table(recs, before: _Model, after: _Model) -> list:
    """[{"record", "samples", "seconds", "logged_drift_deg", "sd_deg", "z_before", "z_after"}] of the
    records that open with a straight run (:class:`ekf.identify.StraightRun`): its length, the drift
    angle over ground it logs, atan2(-v, u) in the logged heading's axes (a heading bias b reads as b,
    a current as its cross part over the speed), that angle's standard error, and its residual in
    those standard errors before and after the named effects."""
    out, k = [], 0
    for r in recs:
        st = r.seg.straight
        if st is None:
            continue
        m = np.asarray(r.seg.meas[:st.n], float)
        t = np.asarray(r.seg.inputs.t, float)
        U = float(np.mean(np.hypot(m[:, 0], m[:, 1])))
        zb = float(before.straight[k]) if k < len(before.straight) else math.nan
        za = float(after.straight[k]) if k < len(after.straight) else math.nan
        out.append({"record": r.name, "samples": int(st.n), "seconds": float(f"{t[st.n - 1] - t[0]:.3g}"),
                    "logged_drift_deg": float(f"{math.degrees(float(np.mean(np.arctan2(-m[:, 1], m[:, 0])))):.3g}"),
                    "sd_deg": float(f"{math.degrees(st.sigma / U):.3g}"),
                    "z_before": round(zb, 2), "z_after": round(za, 2)})
        k += 1
    return out


def _diagnosis(fitter, baseline, search, cands, verdicts, noise) -> Diagnosis:
    """The :class:`Diagnosis`, built once: ``fitter`` the fitter of the final model (ship, records, the kind
    of record set the floors were read for), baseline = (the config's differences, the baseline fit,
    whether the fit was kept), search = (final fit, named effects, rounds), cands = (candidates, log) of
    :func:`~.search._candidates`, verdicts = (``not_identifiable`` entries, identifiability figures) of
    :func:`~.verdicts.verdicts`; the named effects' values with standard errors inflated by the residuals'
    correlation, what is left; ``seconds`` 0 and no ``runs`` (the caller's)."""
    ship, recs, kind, ns = fitter.ship, fitter.recs, fitter.kind, len(fitter.ship_free)
    d_config, base, kept = baseline
    current, named, rounds = search
    cand, cand_log = cands
    not_identifiable, table = verdicts
    _, inflate = _taus(current, fitter.stride)
    from .report import effect_estimate, effect_evidence, effect_intervals

    params, ses, ivs = {}, {}, {}
    for cls in current.effects:
        v, s, _ = _effect_report(current, cls, inflate)
        params[cls.name] = v
        ses[cls.name] = s
        ivs[cls.name] = effect_intervals(cls, *effect_estimate(current, cls, inflate))
    cand_log = cand_log + [{"effect": c.name, "named": c.name in named} for c in cand]
    unexpl, desc, _ = _describe(recs, current.diffs, noise, None, ship.particulars.L, kind)
    mfm = model_form_mismatch(current.free[:ns], current.theta[:ns])
    th_out = [f.prior if f.name in mfm else v for f, v in zip(current.free[:ns], current.theta[:ns])]
    fit_vals = {f.name: float(v) for f, v in zip(current.free[:ns], th_out)}   # mismatched: the config's, not written as fitted
    ship_vals = config_values(ship, fit_vals)
    return Diagnosis(named=named, parameters=params, standard_errors=ses, rms_config=_rms(d_config, recs),
                     rms_before=_rms(base.diffs, recs), rms_after=_rms(current.diffs, recs), unexplained=unexpl,
                     unexplained_description=desc, candidates=cand_log, rounds=rounds, ship_values=ship_vals,
                     ship_fit_values=fit_vals, records=recs, pred_before=[r.seg.meas + d for r, d in zip(recs, base.diffs)],
                     pred_after=[r.seg.meas + d for r, d in zip(recs, current.diffs)],
                     seconds=0.0, effects=current.effects, intervals_95=ivs, evidence=effect_evidence(named, rounds),
                     model_form_mismatch=mfm, ship_fit=ship_fit_table(current.free[:ns], current.theta[:ns]),
                     straight_runs=straight_run_table(recs, base, current), absent_channels=absent_table(recs),
                     not_identifiable=not_identifiable, identifiability=table,
                     baseline="fitted" if kept else "config (the fit replayed worse)")
