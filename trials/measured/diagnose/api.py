"""The entry points: :func:`diagnose` (the steps in order: records, baseline, search, verdicts, result)
and :func:`diagnose_each` (each record alone)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from mmg.errors import InputError
from mmg.model import G, pack
from mmg.ship import Ship

from .baseline import _ship_free, fit_baseline
from .decision import calibration, mean_heading, record_kind, typical_speed
from .fit import _Fitter
from .options import DiagnoseOptions
from .records import noise_level, prepare
from . import model_form
from .result import Diagnosis, _diagnosis
from .rules import rule, rules
from .search import _candidates, search
from .verdicts import verdicts

__all__ = ["diagnose", "diagnose_each"]


def _default_stride(recs, L: float) -> int:
    """Samples ``stride_spacing`` (the diagnosis rules) times sqrt(L/g) apart, at least every one."""
    dt = float(np.median(np.diff(recs[0].seg.inputs.t)))
    return max(1, int(round(rule("stride_spacing") * math.sqrt(L / G) / dt)))


def diagnose(ship: Ship, items, options: DiagnoseOptions | None = None, **kwargs) -> Diagnosis:
    """Diagnose the records ``items`` against ``ship`` (module docstring).

    Parameters
    ----------
    ship : Ship
    items : list of paths, TrialRecord or Prepared
    options : DiagnoseOptions, optional
        How to search; defaults when omitted.
    **kwargs
        Any :class:`DiagnoseOptions` field by name (``wind``, ``candidates``, ``segment_s``,
        ``stride``, ``max_nfev``, ``per_run``, ``ship_free``, ``say``, ``screen_nfev``), over
        ``options``.
    """
    import time

    import mmg.effects as E

    t0 = time.perf_counter()
    rules()                                     # a bad rules file: refused before any work
    o = DiagnoseOptions(**kwargs) if options is None else replace(options, **kwargs)
    say = o.say or (lambda m: None)
    calibration()                               # a bad calibration file: refused before any work
    form_rule = model_form.rules()
    recs = prepare(ship, items, wind=o.wind, segment_s=o.segment_s)
    if not recs:
        raise InputError("diagnose", "", "no record")
    if o.stride is None:
        o = replace(o, stride=_default_stride(recs, ship.particulars.L))
    noise = np.median(np.vstack([noise_level(r.seg.meas) for r in recs]), axis=0)
    cand, cand_log = _candidates(recs, list(o.candidates) if o.candidates is not None else E.names(), say)
    fitter = _first_fitter(ship, recs, o)
    d_config, base, kept, fitter = fit_baseline(fitter, noise, o, say)
    s = search(fitter, base, cand, o, say)
    cand_log = cand_log + [{"effect": c["effect"], "skipped": c["reason"]} for c in s.covered]
    current, named, ni, table = verdicts(s.fitter, s.current, s.named, s.fitted, s.covered, s.rounds, o, say)
    res = _diagnosis(s.fitter, (d_config, base, kept), (current, named, s.rounds), (s.fitted, cand_log), (ni, table),
                     noise)
    res, moved = model_form.reclassify(res, form_rule)                # a named effect whose fit stands for the model's form
    for ent in moved:
        say(f"{ent['effect']}: {ent['status']}, not named: {ent['reason']}")
    runs = diagnose_each(ship, recs, o, progress=o.say is not None) if o.per_run and len(recs) > 1 else []
    return replace(res, runs=runs, seconds=time.perf_counter() - t0)


def _first_fitter(ship: Ship, recs, o: DiagnoseOptions) -> _Fitter:
    """The fitter of the baseline's first fit: the ship's own parameters of the kind of record set
    (:func:`~.baseline._ship_free`, ``o.ship_free`` or the default ones), residual scales of 5 % of the
    records' median speed U (at least 0.05 sqrt(g L)) for u, v, 5 % of U / L for r, 2 deg for the
    heading and 5 % of L for the position, the records' mean heading and typical speed."""
    from ekf.identify import Scales

    L = ship.particulars.L
    packed = pack(ship)
    speed = typical_speed([r.seg.meas for r in recs])
    U = max(speed, 0.05 * math.sqrt(G * L))
    kind = record_kind([r.seg.inputs.delta for r in recs])
    sc0 = Scales(u=0.05 * U, v=0.05 * U, r=0.05 * U / L, psi=math.radians(2.0), pos=0.05 * L)
    return _Fitter(ship, packed, recs, sc0, o.stride, o.max_nfev, _ship_free(ship, packed, o.ship_free, kind, drift=False),
                   kind=kind, heading=mean_heading([r.seg.meas[:, 5] for r in recs]), speed=speed)


def _diagnose_one(task) -> "Diagnosis":
    ship, rec, o = task
    return diagnose(ship, [rec], o)


def diagnose_each(ship: Ship, items, options: DiagnoseOptions | None = None, progress: bool = False) -> list:
    """Each record diagnosed alone, in record order, spread by ``options.backend`` (serial, this
    machine's cores, or a dask cluster: :func:`trials.files.sweep.run_sweep`, one progress line per
    record).  Every diagnosis is deterministic, so the backend does not change a number.

    Parameters
    ----------
    ship : Ship
    items : list of paths, TrialRecord or Prepared
    options : DiagnoseOptions, optional
        How each is diagnosed (``per_run``, ``say``, ``client`` are not passed on).
    progress : bool
        One line per finished record on stderr.

    Returns
    -------
    list of Diagnosis
    """
    from ...files.sweep import run_sweep

    o = options or DiagnoseOptions()
    recs = prepare(ship, items, wind=o.wind, segment_s=o.segment_s)
    each = replace(o, per_run=False, say=None, backend="serial", client=None)
    return run_sweep(_diagnose_one, [(ship, r, each) for r in recs], backend=o.backend, client=o.client,
                     n_jobs=o.n_jobs, labels=[r.name for r in recs], progress=progress)
