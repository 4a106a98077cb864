"""``mmg identify``: identify a ship model from measured records (:func:`trials.measured.identify.identify`)."""
from __future__ import annotations

import sys
import time
from pathlib import Path

from mmg.errors import InputError

from .common import (_finite_positive, _output_path, _positive_int, _whole, add_backend_options, backend_client,
                     check_backend_options, release_notes)


def _check_free(ship, names) -> None:
    """Refuse (one line, exit 2) a --free name that is neither a hull coefficient of ``ship`` nor a constant."""
    from ekf.identify import SHIP_CONSTANTS

    known = set(ship.hull.names) | set(SHIP_CONSTANTS) | {"hull", "hull-except-constants"}
    for n in names:
        if n not in known:
            raise InputError("--free", n, f"not a hull coefficient of {ship.name} nor one of "
                                          f"hull, hull-except-constants, {', '.join(SHIP_CONSTANTS)}")


def _hull_choice(args):
    """The candidate hull forms of ``--hull`` (None without it); refusals in one line, exit 2."""
    if args.hull is None:
        if args.inner_folds is not None:
            raise InputError("--inner-folds", str(args.inner_folds), "needs --hull auto")
        return None
    from ..measured.nested import HULL_FORMS, hull_candidates

    if args.hull != "auto" and args.inner_folds is not None:
        raise InputError("--inner-folds", str(args.inner_folds), "needs --hull auto (nothing to choose)")
    forms = tuple(HULL_FORMS) if args.hull == "auto" else (args.hull,)
    return hull_candidates(args.ship, forms)


def _auto_hull(args, cands, runs, initial, folds, wind, kw, t0):
    """--hull auto: (ship, its config path, the nested cross-validation or None).  Without --cv the choice
    is an inner cross-validation on all the training records; with --cv K the K-fold cross-validation is
    nested (each fold's choice made on its training records) and the final form is chosen as without."""
    from ..measured.nested import nested_cross_validate, select_candidate

    common = dict(kw, wind=wind)
    args.inner_folds = args.inner_folds or 3
    say = (lambda m: print(m, file=sys.stderr, flush=True))
    from ..measured.nested import check_choosable

    try:                                       # a training set too small to choose on: refused before any fit
        check_choosable(cands, runs, args.inner_folds, folds, args.folds_by)
    except ValueError as e:
        raise InputError("--hull", "auto", f"{e} (a record and its cut copies count once)") from None
    with backend_client(args) as client:
        if folds:
            say(f"nested cross-validation: {folds} outer folds, the hull form chosen in each by "
                f"{args.inner_folds} inner folds ({time.perf_counter() - t0:.0f} s)")
            nested = nested_cross_validate(cands, runs, folds=folds, inner_folds=args.inner_folds, initial=initial,
                                           folds_by=args.folds_by, backend=args.backend, client=client,
                                           n_jobs=args.jobs, **common)
        else:
            nested = None
        say(f"choosing the hull form by a {args.inner_folds}-fold cross-validation on the {len(runs)} training "
            f"records ({time.perf_counter() - t0:.0f} s)")
        sel = select_candidate(cands, runs, folds=args.inner_folds, initial=initial, folds_by=args.folds_by,
                               backend=args.backend, client=client, n_jobs=args.jobs, **common)
    for ln in sel.lines():
        say(f"  {ln}")
    print(f"hull form: {sel.choice} (inner {sel.folds}-fold cross-validation on the training records)")
    chosen = cands[sel.choice].ship
    return chosen, cands[sel.choice].path, (nested, sel)


def _nested_as_cv(nested) -> list:
    """The nested cross-validation's kept-out records in :func:`trials.measured.identify.cross_validate`'s
    form (the report's cross-validation table)."""
    res, _ = nested
    if res is None:
        return None
    return [{"name": r["name"], "fold": r["fold"], "initial": r["scaled"], "identified": r["identified"],
             "ship": r["ship"], "values": r["values"], "choice": r["choice"]} for r in res.records]


def _print_nested(nested, out: Path) -> None:
    """--hull auto: the choices (each fold's with --cv) and the nested summary, on stdout."""
    res, _ = nested
    if res is None:
        return
    for f in res.folds:
        print(f"fold {f['fold']}: chose {f['choice']} ("
              + "; ".join(f"{c} {t['mean_heading_rms_deg']:.2f} deg, {t['diverged']} diverged"
                          for c, t in f["inner"].items()) + ")")
    s = res.summary()
    print(f"nested cross-validation: mean heading RMS {s['mean_scaled']:.2f} deg (initial) -> "
          f"{s['mean_identified']:.2f} deg (identified), ratio {s['ratio']:.2f}, better on {s['better']} of {s['n']}; "
          f"{len(s['diverged'])} diverged replay(s)")
    for name, who, d in s["diverged"]:
        print(f"  diverged: {name} ({who}) at t = {d['t_s']:.1f} s, last finite state "
              + ("none" if d["last_state"] is None else
                 ", ".join(f"{k} {v:.3g}" for k, v in d["last_state"].items())))
    print(f"wrote {out / 'nested_cv.json'} (per kept-out record, the scores of both models and each fold's choice)")


def _ships(args):
    """(the prior's YAML path, the prior, the --hull candidates or None, the ship scored against or None),
    every refusal before any record is read."""
    from mmg.resources import ship_path
    from mmg.ship import load_ship

    src = ship_path(args.ship)
    ship = load_ship(src)
    cands = _hull_choice(args)                     # refused before any record is read
    if cands is not None and len(cands) == 1:      # --hull kijima|crossflow: that form is the prior
        (only,) = cands.values()
        src, ship = only.path, only.ship
    if args.free:
        _check_free(ship, args.free)
        for c in (cands or {}).values():
            _check_free(c.ship, args.free)
    initial = load_ship(ship_path(args.initial)) if args.initial else None
    if initial is None and cands is not None and ship.name != load_ship(ship_path(args.ship)).name:
        initial = load_ship(ship_path(args.ship))  # scored against the --ship given, whatever form is fitted
    if initial is not None:                # the same ship's particulars, before any record is read
        from ..files.shipcheck import check_same_ship

        check_same_ship(ship, initial)
    return src, ship, cands, initial


def _fit_options(args, default_max_nfev: int) -> dict:
    """:func:`~trials.measured.identify.identify`'s keywords from the command line."""
    kw = {"record_weighting": args.weighting} if args.weighting else {}
    kw["max_nfev"] = args.max_nfev or default_max_nfev
    if args.velocity_weight is not None:
        kw["velocity_weight"] = args.velocity_weight
    if args.free:
        kw["free"] = tuple(args.free)
    if args.initial_state:
        kw["initial_state"] = args.initial_state
    return kw


def _print_outcome(ident, runs, out: Path, nested, t0: float) -> None:
    """The closing lines: the fit's figures, what was written, notes and warnings."""
    import numpy as np

    a = np.mean([x["heading_rms_deg"] for x in ident.scores(model="initial")])
    b = np.mean([x["heading_rms_deg"] for x in ident.scores()])
    from ..measured.identify import free_parameter_text

    print(f"identified {free_parameter_text(ident.fit)} over {len(runs)} records in {time.perf_counter() - t0:.0f} s: "
          f"mean heading RMS {a:.2f} deg (initial) -> {b:.2f} deg (identified)")
    print(f"wrote {out / 'ship.yaml'} and {out / 'report.md'}")
    if nested is not None:
        _print_nested(nested, out)
    for st in ident.stages:
        if st["status"] == 0:
            print(f"note: {st['description'].split(':')[0]} stopped at its evaluation limit ({st['max_nfev']}) before "
                  f"converging; --max-nfev raises it", file=sys.stderr)
    for w in ident.physical_check().warnings():
        print(f"warning: {w}", file=sys.stderr)
    from ..measured.identify import identification_summary

    warn = identification_summary(ident)["warnings"]
    if warn:
        print(f"warning: {len(warn)} finding(s) on where the identified values should not be read as the ship's "
              f"physics or the fit not as finished (sign changes, bounds, no convergence, training replays worse "
              f"than the initial model's, physical checks): {out / 'report.md'}, 'Warnings', and the "
              f"identification: section of {out / 'ship.yaml'} (mmg imo reads it)", file=sys.stderr)


def _records(args, ship, wind):
    """(the training records, the test records or None): an unusable record is skipped with one line;
    an option none of whose records is usable is refused, saying why."""
    import logging

    from ..files.output import record_labels
    from ..measured.identify import load_runs

    names = record_labels(args.train + (args.test or []))   # training and test records told apart together
    skipped: list = []

    def note(msg):                          # held until every record is read (a refusal: one line)
        skipped.append(msg)
        logging.getLogger("trials.cli.identify").warning(msg)

    def why(first: int = 0) -> str:         # the refusal of an option none of whose records is usable says why
        return f"no usable record ({'; '.join(skipped[first:])})" if skipped[first:] else "no usable record"

    runs = load_runs(ship, args.train, wind=wind, names=names[:len(args.train)], say=note)   # an unusable one: one line, skipped
    if not runs:
        raise InputError("--train", "", why().replace("record", "training record", 1))
    first_test = len(skipped)
    tests = (load_runs(ship, args.test, wind=wind, names=names[len(args.train):], say=note)   # a bad one: one line, before any progress line
             if args.test else None)
    if args.test and not tests:
        raise InputError("--test", "", why(first_test))
    return runs, tests


def cmd_identify(args) -> int:
    from mmg.resources import ship_path
    from mmg.ship import load_ship

    from ..measured.identify import DEFAULT_MAX_NFEV, cross_validate, cv_folds, identify, write_identification
    from ..files.output import StagedOutput, check_output_dir

    check_backend_options(args)
    check_output_dir(args.out)
    for log in args.train + (args.test or []):
        if not Path(log).is_file():
            raise InputError(log, "", "file not found" if not Path(log).exists() else "is not a regular file")
    src, ship, cands, initial = _ships(args)
    wind = None if args.wind is None else args.wind == "on"
    t0 = time.perf_counter()
    runs, tests = _records(args, ship, wind)
    release_notes()
    print(f"training on {len(runs)} record{'' if len(runs) == 1 else 's'}", file=sys.stderr, flush=True)
    if args.cv:                                          # refused or narrowed before any fit
        try:
            folds = cv_folds(runs, args.cv)
        except ValueError as e:
            raise InputError("--cv", "", f"{e} (a record and its cut copies count once)") from None
        if folds < args.cv:
            print(f"note: --cv {args.cv}: {folds} independent records, so {folds} folds (each kept out once)",
                  file=sys.stderr, flush=True)

    shown = [None]

    def progress(k, cost, stage):            # a header per fit stage, then its iterations labelled by it
        if stage != shown[0]:
            shown[0] = stage
            print(f"{stage}; at most {kw['max_nfev']} evaluations", file=sys.stderr, flush=True)
        print(f"  {stage.split(':')[0]}, iteration {k}: cost {cost:.5g} ({time.perf_counter() - t0:.0f} s)",
              file=sys.stderr, flush=True)

    kw = _fit_options(args, DEFAULT_MAX_NFEV)
    nested = None
    if cands is not None and len(cands) > 1:          # --hull auto: the form chosen by an inner CV
        ship, src, nested = _auto_hull(args, cands, runs, initial, folds if args.cv else None, wind, kw, t0)
        if initial is None:
            initial = load_ship(ship_path(args.ship))
    ident = identify(ship, runs, wind=wind, progress=progress, initial=initial, **kw)
    cv = None
    if nested is not None:
        cv = _nested_as_cv(nested)
    elif args.cv:
        with backend_client(args) as client:
            cv = cross_validate(ship, runs, folds=folds, wind=wind, initial=initial, folds_by=args.folds_by, **kw,
                                backend=args.backend, client=client, n_jobs=args.jobs,
                                progress=lambda k, n: print(f"cross-validation fold {k}/{n} "
                                                            f"({time.perf_counter() - t0:.0f} s)",
                                                            file=sys.stderr, flush=True))
    with StagedOutput(args.out) as stage:
        write_identification(ident, src, stage.dir, cv, tests)
        if nested is not None and nested[0] is not None:
            import json

            (stage.dir / "nested_cv.json").write_text(json.dumps(nested[0].to_json(), indent=1) + "\n")
    _print_outcome(ident, runs, Path(args.out), nested, t0)
    return 0


def add_parser(sub) -> None:
    """The identify subcommand of ``mmg`` (its options, help and function)."""
    p = sub.add_parser("identify", help="identify hull coefficients and model-scale constants jointly over measured "
                                        "records (segment-wise output error); writes DIR/ship.yaml (with its "
                                        "identification: section, the fit's warnings) and DIR/report.md")
    p.add_argument("--ship", required=True, help="initial ship YAML or bundled name (the prior)")
    p.add_argument("--train", required=True, nargs="+", metavar="LOG", help="training records")
    p.add_argument("--out", required=True, metavar="DIR", type=_output_path, help="output folder")
    p.add_argument("--wind", choices=("on", "off"), default=None,
                   help="wind loads from the measured relative wind (default: as the ship config says)")
    p.add_argument("--initial", default=None, metavar="SHIP",
                   help="the model the identified one is compared with in the report (default: --ship); e.g. "
                        "--ship esso_osaka_3m_crossflow --initial esso_osaka_3m fits the cross-flow form of the "
                        "Kijima ship and scores it against the Kijima one")
    p.add_argument("--cv", type=_whole(2, "--cv"), default=None, metavar="FOLDS",
                   help="also cross-validate in FOLDS folds (each record kept out once) and report it")
    p.add_argument("--test", nargs="+", default=None, metavar="LOG",
                   help="records never trained on, predicted with the initial and the identified model in the report")
    p.add_argument("--weighting", choices=("samples", "equal", "relative"), default=None,
                   help="how each training record counts in the fit: samples (every sample alike: long records count "
                        "more), equal (every record alike), relative (every record alike relative to its own misfit); "
                        "default trials.measured.identify.DEFAULT_WEIGHTING")
    p.add_argument("--free", nargs="+", default=None, metavar="NAME",
                   help="the parameters to fit: hull coefficient names, 'hull' (all of them), 'hull-except-constants', "
                        "w_P0, epsilon, kappa, gamma_R_pos, gamma_R_neg, l_R_prime, rudder_offset, wind_scale, "
                        "wind_sway_factor, wind_yaw_factor, Y_P_astern, m_x, m_y, "
                        "J_z (default trials.measured.identify.DEFAULT_FREE)")
    p.add_argument("--velocity-weight", type=_finite_positive, default=None, metavar="W",
                   help="factor on the u, v, r residuals beside the heading's (default 1; 0.1: their squares weigh a "
                        "hundredth, so the fit follows the heading; docs/identify_cv.md)")
    p.add_argument("--initial-state", choices=("fit", "sample"), default=None,     # identify.INITIAL_STATES (test)
                   help="where each record's replay starts in the fit: 'fit' (default: offsets on the first sample's "
                        "u, v, r and heading fitted as the record's own nuisance, so one noisy sample does not drift a "
                        "whole replay; the written covariance then covers the truth: docs/imo.md) or 'sample' (the "
                        "first sample as logged, the fit with no start-state nuisance)")
    p.add_argument("--max-nfev", type=_positive_int, default=None, metavar="N",
                   help="most evaluations of the residuals in each fit stage (segment-wise, then whole-record; "
                        "default trials.measured.identify.DEFAULT_MAX_NFEV); a stage that reaches it stops unconverged, "
                        "and the report and a note say so")
    p.add_argument("--folds-by", choices=("order", "revolutions", "manoeuvre"), default="order",
                   help="with --cv: deal the records into folds in the order given, stratified by their propeller "
                        "revolutions, or by manoeuvre (astern, zigzag, port or starboard turn, then revolutions); "
                        "a record and its cut copies always share a fold")
    p.add_argument("--hull", choices=("auto", "kijima", "crossflow"), default=None,
                   help="the hull form fitted: kijima (--ship's bundled Kijima config) or crossflow (its "
                        "'_crossflow' config); auto: chosen by an inner cross-validation on the --train records "
                        "(lowest held-out mean heading RMS; --inner-folds), reported; with --cv the cross-validation "
                        "is nested (the choice made inside each training set; default: --ship as given)")
    p.add_argument("--inner-folds", type=_whole(2, "--inner-folds"), default=None, metavar="FOLDS",
                   help="with --hull auto: folds of the inner cross-validation that chooses the form (default 3)")
    add_backend_options(p, "the cross-validation folds (--cv) and the --hull auto choice")
    p.set_defaults(func=cmd_identify)
