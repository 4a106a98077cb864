"""What the records cannot tell apart (``mmg diagnose``'s ``not_identifiable``).

A candidate effect the forward selection of :func:`trials.measured.diagnose.diagnose` does not
name is either absent or one the records cannot separate from the ship's own coefficients (or
another effect): a rudder offset on a single turning circle moves the turn the way a slightly
different N_delta or N_r would, and the hull terms absorb it.  Such an effect is reported, not
dropped silently.

For each candidate (and each named effect, as a check) the Fisher information of the records is
formed at the final model with the candidate added at its start value: the fit's own residual
(:class:`ekf.identify._SegmentFit`, the same scaled residuals and prior rows the fit minimises)
differentiated by forward differences, ``I = J^T J / s2``, s2 the residual variance per degree of
freedom, and the covariance ``C = I^-1`` inflated by the residuals' correlation time as the
diagnosis's standard errors are.  For the effect's parameter block b:

* the marginal std (others free) is sqrt of the largest eigenvalue of ``C_bb``;
* the conditional std (others fixed) is that of ``(I_bb)^-1``;
* the multiple correlation of the block with the rest (its first canonical correlation) is
  ``R^2 = 1 - 1/lambda``, lambda the largest eigenvalue of ``C_bb I_bb``; for one parameter
  ``R^2 = 1 - 1/(C_ii (C^-1)_ii)`` and marginal / conditional std = sqrt(lambda) = 1/sqrt(1 - R^2).

**Rule.**  An effect is reported ``not_identifiable`` when it is not named, its marginal std times
the naming z threshold (:data:`trials.measured.diagnose.Z_THRESHOLD`, 3; never less than 2)
exceeds its :data:`DETECTION_SIZE` (the records could not have named it at a size that matters:
an effect of that size would have been within the threshold's z of nothing), and confounding is the
reason: R >= :data:`R_CONFOUNDED` or marginal / conditional std >= :data:`STD_RATIO_CONFOUNDED`.
An effect skipped for lack of channels is not assessed.  Also reported, with its
own reason: one whose marginal std could not have shown its detection size though confounding is
not why (the records hold too little information on it at all: a 1.5 deg heading bias on a single
turn of a ship whose hull form is not the model's, sd 2.06 deg, R 0.899, was dropped silently);
:func:`verdict` gives the reasons in order.  And a
candidate whose dBIC showed some evidence, short of a name, while its precision and size passed
(:func:`trials.measured.diagnose.weak_evidence`), and one whose evidence and precision passed but
whose size the calibrated floor stopped (:func:`trials.measured.diagnose.within_mismatch`).  Each
entry's ``reason`` says why in words and figures, its ``reason_kind`` which rule it was
(:data:`trials.measured.diagnose.decision.REASON_KINDS`: statistics, floor, evidence, information, and rival
for a name withheld beside a rival, :func:`trials.measured.diagnose.withheld`).

``what_would_separate``: the information of candidate additional trials (the mirror of a turn,
a 20/20 zigzag where the records have none, a 35 deg turn where they have none), simulated with the
config ship (:func:`trials.measured.diagnose.synthetic_record`) and differentiated the same way at
the same parameters, added to the records'; the trial that brings the effect's marginal std down
most is named with the std before and after.  Several records diagnosed together share the effect's
parameters (:func:`ekf.identify.effect_parameters`: ``record`` None), so a second record adds its
information to the same parameters exactly as here.
"""
from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import mmg.effects as E
from mmg.model import G

from .decision import STATISTICAL_REASON
from .rules import module_rule, rule
from .report import IDENTIFIABILITY_LEGEND, size_with_unit

__all__ = ["DETECTION_SIZE", "R_CONFOUNDED", "STD_RATIO_CONFOUNDED", "detection_size", "floor_in_fit_unit", "block_confounding",
           "assess", "verdict", "not_identifiable_lines", "STATISTICAL_REASON", "identifiability_line"]

DETECTION_SIZE = {n: c.detection_size for n, c in E.REGISTRY.items()}
"""The smallest size of each effect that matters physically, in its fit parameters' unit
(:attr:`mmg.effects.Effect.detection_size`, where each effect states and explains it)."""
_RULES = {"R_CONFOUNDED": "r_confounded", "STD_RATIO_CONFOUNDED": "std_ratio_confounded",
          "_CONFUSED_MIN": "confused_min"}
"""The module's names of numbers of the diagnosis rules (:mod:`.rules`), read-only: ``R_CONFOUNDED``, the
multiple correlation of the effect's parameters with the rest at or above which confounding, not noise, is why
the effect cannot be shown; ``STD_RATIO_CONFOUNDED``, the marginal / conditional std at or above which the same
holds; ``_CONFUSED_MIN``, the least |correlation| of another parameter with the effect's worst direction for it
to be named as confused with it."""
__getattr__ = module_rule(__name__, _RULES)


def _size_of(effect: str) -> tuple:
    """(size, unit) of ``effect``: :data:`DETECTION_SIZE`'s, else the registered effect's own (an effect
    registered after this module was imported), else (inf, "1")."""
    if effect in DETECTION_SIZE:
        return DETECTION_SIZE[effect]
    cls = E.REGISTRY.get(effect)
    return cls.detection_size if cls is not None else (math.inf, "1")


def detection_size(effect: str, L: float) -> float:
    """The :data:`DETECTION_SIZE` of ``effect`` in its fit unit for a ship of length ``L`` [m]
    (inf for an effect not in the table)."""
    v, unit = _size_of(effect)
    return v * math.sqrt(G * L) if unit == "sqrt(gL)" else v


def floor_in_fit_unit(effect: str, fl: float, L: float) -> float:
    """A calibrated floor (:func:`trials.measured.diagnose.decision.floor`, in the unit of
    :func:`~trials.measured.diagnose.decision.magnitude`: a current's speed over sqrt(g L)) in the unit of
    :func:`detection_size` (the effect's fit parameters: m/s for a current), for a ship of length ``L`` [m]."""
    _, unit = _size_of(effect)
    return fl * math.sqrt(G * L) if unit == "sqrt(gL)" else fl


def block_confounding(cov: np.ndarray, idx) -> dict:
    """Confounding of the parameters ``idx`` with the rest, from the posterior covariance ``cov``.

    Returns
    -------
    dict
        ``R``: the multiple (first canonical) correlation of the block with the other parameters;
        ``ratio``: marginal / conditional std along the worst direction (sqrt(1 / (1 - R^2)));
        ``sd``: the largest marginal std of the block; ``sd_conditional``: the conditional std
        along the worst direction; ``direction``: that direction (unit vector in the block);
        ``corr``: the correlation of each parameter with the block's worst linear combination.
    """
    from scipy.linalg import eigh

    cov = np.asarray(cov, float)
    idx = list(idx)
    info = sym_inv(cov)
    Cb = cov[np.ix_(idx, idx)]
    Ib = info[np.ix_(idx, idx)]
    lam, vec = eigh(Cb, np.linalg.inv(Ib))          # C_bb a = lambda I_bb^-1 a
    a = vec[:, -1] / np.linalg.norm(vec[:, -1])
    lam_max = float(max(lam[-1], 1.0))
    sd_dir = math.sqrt(float(a @ Cb @ a))
    cross = cov[:, idx] @ a
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cross / (sd_dir * np.sqrt(np.diag(cov)))
    return {"R": math.sqrt(max(0.0, 1.0 - 1.0 / lam_max)), "ratio": math.sqrt(lam_max),
            "sd": math.sqrt(float(np.linalg.eigvalsh(Cb)[-1])), "sd_conditional": sd_dir / math.sqrt(lam_max),
            "direction": a, "corr": np.nan_to_num(corr)}


def sym_inv(A: np.ndarray) -> np.ndarray:
    """Inverse of a symmetric positive definite ``A`` whose parameters differ by many orders of
    magnitude (added masses in kg beside primed derivatives): inverted in the scaled form
    D A D, D = diag(A)^-1/2, so that the scale does not cost the precision; through its eigenvalues,
    each held at least :data:`EIG_FLOOR` times the largest."""
    A = np.asarray(A, float)
    d = 1.0 / np.sqrt(np.abs(np.diag(A)))
    S = A * np.outer(d, d)
    w, V = np.linalg.eigh(0.5 * (S + S.T))
    w = np.maximum(w, EIG_FLOOR * max(float(w[-1]), np.finfo(float).tiny))
    return d[:, None] * ((V / w) @ V.T) * d[None, :]


EIG_FLOOR = 1e-12
"""Smallest eigenvalue :func:`sym_inv` keeps, relative to the largest (of the scaled matrix): an
``A`` singular to rounding (a turn's drift terms beside the hull's other terms and the added
masses, 19 parameters) still gives a positive definite inverse, where a plain inverse gave a
negative variance (the clean ST35 log of ``tests/test_diagnose_own_logs.py``)."""


# --------------------------------------------------------------------------- information


class _Info:
    """Fisher information of the fit's residuals of some records at one parameter vector."""

    def __init__(self, fitter, stride):
        self.fitter, self.stride = fitter, stride

    def jacobian(self, segs, effects, free, theta):
        """(J of the fit's scaled residuals of ``segs`` without the prior rows, the prior stds)."""
        from ekf.identify import FitOptions, _SegmentFit

        f = self.fitter
        opts = FitOptions(stride=self.stride, effects=list(effects) or None, ship=f.ship,
                          straight_weight=getattr(f, "straight_weight", 1.0))
        with ThreadPoolExecutor(max_workers=2) as pool:
            sf = _SegmentFit(f.packed, segs, free, f.scales, opts, pool)
            J = sf.jac(np.asarray(theta, float))
        return J[:-len(free)], sf.sig0

    def records(self, effects, free, theta, s2):
        """The information of the records with the prior (the fit's residual variance ``s2``)."""
        J, sig0 = self.jacobian([p.seg for p in self.fitter.recs], effects, free, theta)
        return (J.T @ J + np.diag(1.0 / sig0 ** 2)) / s2


def _setup(current, cls, ns, L):
    """(effects, free, theta, s2) of the final model with ``cls`` added (as is when named): its
    parameters at their fit start values, a one-parameter effect at least its detection size from
    its neutral value (the size the question is about: shallow water's forces are not linear in
    T/H); s2 the final fit's residual variance per degree of freedom (the one its standard errors use)."""
    from ekf.identify import effect_parameters

    effects = list(current.effects)
    theta = list(current.theta)
    if cls not in effects:
        effects.append(cls)
        new = effect_parameters([cls])
        x = [f.prior if f.start is None else f.start for f in new]
        if len(new) == 1 and abs(x[0] - new[0].prior) < detection_size(cls.name, L):
            x[0] = min(new[0].prior + detection_size(cls.name, L), new[0].upper)
        theta += x
    free = list(current.free[:ns]) + effect_parameters(effects)
    fit = current.fit
    s2 = 2.0 * float(fit.cost_final) / max(fit.n_residuals - len(fit.free), 1)
    return effects, free, np.array(theta, float), s2


# --------------------------------------------------------------------------- trials that would separate


def _kinds(recs):
    """Each record's manoeuvre: ("turn", +1 starboard / -1 port) or ("zigzag", 0) or ("other", 0)."""
    out = []
    for p in recs:
        d = np.asarray(p.seg.inputs.delta, float)
        big = d[np.abs(d) > math.radians(5.0)]
        if len(big) < 0.2 * len(d):
            out.append(("other", 0))
            continue
        pos = float(np.mean(big > 0))
        out.append(("turn", 1 if pos > 0.5 else -1) if min(pos, 1.0 - pos) < 0.05 else ("zigzag", 0))
    return out


def _trial_specs(recs, L):
    """(label, synthetic_record kwargs) of the trials that could add what the records lack."""
    s = math.sqrt(L / G)
    kinds = _kinds(recs)
    turns = {sg for k, sg in kinds if k == "turn"}
    specs = []
    for sg in (1, -1):
        if sg in turns and -sg not in turns:
            rec = recs[[k for k in kinds].index(("turn", sg))]
            amp = round(math.degrees(float(np.max(np.abs(rec.seg.inputs.delta)))))
            side = "port" if sg > 0 else "starboard"
            T = float(rec.seg.inputs.t[-1] - rec.seg.inputs.t[0])
            specs.append((f"a {amp} deg {side} turn", dict(kind="turning", rudder_deg=-sg * amp, duration=T)))
    if not any(k == "zigzag" for k, _ in kinds):
        specs.append(("a 20/20 zigzag", dict(kind="zigzag", rudder_deg=20.0, duration=330.0 * s)))
    if not turns:
        specs.append(("a 35 deg starboard turn", dict(kind="turning", rudder_deg=35.0, duration=250.0 * s)))
    return specs


def _trial_segments(fitter, specs, segment_s):
    """The candidate trials simulated with the config ship at the records' approach speed, prepared."""
    from dataclasses import replace

    from .records import Manoeuvre, prepare, synthetic_record

    recs = fitter.recs
    U = float(np.median([math.hypot(p.seg.meas[0, 0], p.seg.meas[0, 1]) for p in recs]))
    dt = float(np.median(np.diff(recs[0].seg.inputs.t)))
    out = []
    for label, kw in specs:
        rec = synthetic_record(fitter.ship, Manoeuvre(speed=U, dt=dt, **kw), name=f"trial{len(out)}")
        calm = np.zeros_like(rec.t)              # a trial in calm air: a named wind effect's loads are zero in it
        rec = replace(rec, wind_speed_rel=calm, wind_dir_rel=calm)
        out.append((label, prepare(fitter.ship, [rec], segment_s=segment_s)[0].seg))
    return out


def _separation(info_fn, trials, setup, info_rec, idx, inflate, cls):
    """(text, [(label, sd)]): the trial that brings the effect's marginal std down most; ``setup`` the
    (effects, free, theta, s2) of :func:`_setup`."""
    effects, free, theta, s2 = setup
    sd0 = block_confounding(sym_inv(info_rec) * inflate ** 2, idx)["sd"]
    res = []
    for label, seg in trials:
        if seg.context is not None and cls.unavailable(seg.context):
            continue
        J, _ = info_fn.jacobian([seg], effects, free, theta)
        cov = sym_inv(info_rec + J.T @ J / s2) * inflate ** 2
        res.append((label, block_confounding(cov, idx)["sd"]))
    unit = _unit(cls)
    if not res:
        why = ("no candidate trial informs it without its channels" if trials else
               "the records already hold turns both ways and a zigzag")
        return f"{why}: a longer record, or one where the effect is larger", res
    label, sd = min(res, key=lambda t: t[1])
    text = f"{label} with {'these' if len(info_fn.fitter.recs) > 1 else 'this one'}: sd {_fmt(sd0)} -> {_fmt(sd)}{_sp(unit)}"
    if sd > 0.7 * sd0:
        text = f"none of the trials tried separates it well (best: {text})"
    return text, res


def _unit(cls) -> str:
    u = cls.fit_parameters()[0].unit
    return "" if u == "1" else u


def _size_unit(cls) -> str:
    """The unit of :func:`detection_size` and :func:`floor_in_fit_unit` of ``cls``: its fit parameter's
    where :data:`DETECTION_SIZE` scales with the ship (a current: m/s), else its size's (deg, T/H)."""
    if _size_of(cls.name)[1] == "sqrt(gL)":
        return _unit(cls)
    u = cls.magnitude_unit
    return "" if u == "1" else u


def _sp(unit: str) -> str:
    return f" {unit}" if unit else ""


def identifiability_line(row: dict, R: float, sd_unit: str, det_unit: str, particulars) -> str:
    """The console line of one candidate's identifiability ``row`` (keys ``effect``, ``std``,
    ``std_conditional``, ``detection_size``, ``confused_with``): R, its sd in ``sd_unit`` (the fit
    parameter's) and its detection size in ``det_unit``, a size in a ship-relative unit with its SI value
    beside it (:func:`trials.measured.diagnose.report.size_with_unit`, ``particulars``' L and T [m])."""
    sp = _sp(sd_unit)
    det = size_with_unit(row["detection_size"], det_unit, particulars.L, particulars.T)
    return (f"identifiability of {row['effect']}: R {R:.3f}, sd {row['std']:.3g}{sp} (alone "
            f"{row['std_conditional']:.3g}{sp}), detection size {det}, with {', '.join(row['confused_with']) or '-'}")


def _fmt(x: float) -> str:
    return f"{x:.2g}" if abs(x) < 1 else f"{x:.3g}"


# --------------------------------------------------------------------------- the assessment


def assess(fitter, current, named, cand, inflate: float, segment_s=None, say=None, weak=None):
    """The identifiability of every candidate effect on the records of ``fitter``.

    Parameters
    ----------
    fitter : trials.measured.diagnose._Fitter
        The diagnosis's fitter (ship, packed ship, records, residual scales, the ship's free
        parameters at the head of every fit's, the sample stride).
    current : trials.measured.diagnose._Model
        The final model of the search.
    named : list of str
        The named effects.
    cand : list
        The candidate effect classes (those skipped for lack of channels are not among them).
    inflate : float
        The standard-error inflation of the residuals' correlation (the diagnosis's).
    segment_s : float, optional
        The diagnosis's segment length (the candidate trials are cut alike).
    say : callable, optional
        Progress lines.
    weak : dict, optional
        ``{effect: reason}`` of candidates with some evidence short of a name
        (:func:`trials.measured.diagnose.weak_evidence`): reported with that reason when the
        statistics and floor would not report them.

    Returns
    -------
    (list of dict, list of dict)
        The ``not_identifiable`` entries (module docstring) and, for every candidate, its figures
        (effect, named, correlation, std, std_conditional, detection_size, confused_with, and
        ``confounded``: the rule's test without "not named", i.e. for a named effect that its value
        leans on the ship's coefficients or another effect, a check on it).
    """
    from .decision import least_floor

    say = say or (lambda m: None)
    L = fitter.ship.particulars.L
    ns = len(fitter.ship_free)
    info_fn = _Info(fitter, fitter.stride)
    entries, table, trials = [], [], None
    for cls in cand:
        setup = _setup(current, cls, ns, L)
        free = setup[1]
        try:
            info_rec, idx, b = _block(info_fn, setup, cls, inflate)
        except (np.linalg.LinAlgError, ValueError) as e:
            say(f"identifiability of {cls.name}: not assessed ({e})")
            continue
        others = [(abs(c), _name(free[j])) for j, c in enumerate(b["corr"]) if j not in idx]
        confused = []
        for c, nm in sorted(others, reverse=True):
            if c >= rule("confused_min") and nm not in confused and len(confused) < 3:
                confused.append(nm)
        det = detection_size(cls.name, L)
        row = {"effect": cls.name, "named": cls.name in named, "correlation": round(b["R"], 3),
               "std": float(f"{b['sd']:.3g}"), "std_conditional": float(f"{b['sd_conditional']:.3g}"),
               "detection_size": float(f"{det:.3g}"), "unit": _unit(cls), "confused_with": confused}
        table.append(row)
        if not table[:-1]:
            say(IDENTIFIABILITY_LEGEND)
        say(identifiability_line(row, b["R"], _unit(cls) or _size_unit(cls), _size_unit(cls), fitter.ship.particulars))
        froude = getattr(fitter, "speed", 0.0) / math.sqrt(G * L)
        fl = floor_in_fit_unit(cls.name, least_floor(cls.name, getattr(fitter, "kind", ""), froude=froude), L)
        row["confounded"], reason, kind = verdict(b, det, fl, (weak or {}).get(cls.name), _unit(cls), _size_unit(cls))
        row["floor"], row["reason_kind"] = fl, kind
        if cls.name in named or reason is None:
            continue
        if trials is None:
            trials = _trial_segments(fitter, _trial_specs(fitter.recs, L), segment_s)
        text, res = _separation(info_fn, trials, setup, info_rec, idx, inflate, cls)
        entries.append({"effect": cls.name, "confused_with": confused or [_name(free[j]) for j in
                                                                           np.argsort(-np.abs(b["corr"]))
                                                                           if j not in idx][:1],
                        "correlation": round(b["R"], 3), "what_would_separate": text,
                        "reason": reason, "reason_kind": kind,
                        "std": row["std"], "std_conditional": row["std_conditional"], "detection_size": row["detection_size"],
                        "unit": row["unit"], "trials": [{"trial": lb, "std": float(f"{sd:.3g}")} for lb, sd in res]})
    return entries, table


def _block(info_fn, setup, cls, inflate: float):
    """(the records' information, the effect's indices among the free parameters, its
    :func:`block_confounding` under the inflated covariance) of one candidate's ``setup``."""
    effects, free, theta, s2 = setup
    info_rec = info_fn.records(effects, free, theta, s2)
    idx = [i for i, f in enumerate(free) if f.kind == "effect" and f.index == effects.index(cls)]
    return info_rec, idx, block_confounding(sym_inv(info_rec) * inflate ** 2, idx)


def verdict(b: dict, det: float, fl: float, weak_why: str | None, unit: str, det_unit: str) -> tuple:
    """Whether a candidate that was not named is reported ``not_identifiable``, and why (module
    docstring, "Rule").

    Parameters
    ----------
    b : dict
        Its :func:`block_confounding` (``sd``, ``sd_conditional``, ``R``, ``ratio``).
    det, fl : float
        Its :func:`detection_size` and calibrated floor (:func:`floor_in_fit_unit`), in ``det_unit``.
    weak_why : str or None
        The reason of evidence short of a name (:func:`trials.measured.diagnose.weak_evidence`).
    unit, det_unit : str
        The units of its fit parameter (``sd``) and of ``det`` and ``fl`` ("" for none).

    Returns
    -------
    (bool, str or None, str or None)
        ``confounded`` (the records could not show it for its confounding or its floor), the reason,
        the first that holds: :data:`STATISTICAL_REASON` (its std could not have shown ``det`` and
        confounding is why), the floor (the ship's own mismatch lends it more than ``det``), ``weak_why``,
        too little information (its std could not have shown ``det``, confounded or not); None: not
        reported; and that reason's kind (:data:`~trials.measured.diagnose.decision.REASON_KINDS`: "statistics",
        "floor", "evidence", "information"; None with it).
    """
    imprecise = bool(max(2.0, rule("z_threshold")) * b["sd"] > det)
    if imprecise and (b["R"] >= rule("r_confounded") or b["ratio"] >= rule("std_ratio_confounded")):
        return True, STATISTICAL_REASON, "statistics"
    if fl > det:
        return True, (f"the ship's own mismatch lends it up to {fl:.3g}{_sp(det_unit)} on such a record (calibrated "
                      f"floor), more than the {det:.3g}{_sp(det_unit)} to detect"), "floor"
    if weak_why:
        return False, weak_why, "evidence"
    if imprecise:
        return False, (f"the records hold too little information on it: sd {_fmt(b['sd'])}{_sp(unit)} "
                       f"({_fmt(b['sd_conditional'])}{_sp(unit)} with every other parameter fixed) could not have "
                       f"shown {det:.3g}{_sp(det_unit)}"), "information"
    return False, None, None


def _name(f) -> str:
    """A free parameter's name as a reader knows it: a hull or ship constant by name, an effect by the effect's."""
    return f.name.split(".")[0] if f.kind == "effect" else f.name


def not_identifiable_lines(entries) -> list[str]:
    """One console line per ``not_identifiable`` entry
    (:func:`trials.measured.diagnose.report.not_identifiable_line`, the one the console prints)."""
    from .report import not_identifiable_line

    return [not_identifiable_line(e) for e in entries]
