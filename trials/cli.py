"""The ``mmg`` command: one entry point, one argument and exit-code convention.

Every subcommand is a thin layer over public library functions (named in its help):
parse, call, print.  Exit status: 0 done; 2 bad input (one line on stderr naming the file
or option and the field; nothing written) or bad arguments; 3 a diverging filter; 130 / 143
interrupted by SIGINT / SIGTERM (one line, nothing left behind).  Library code never calls
:func:`main`.

Outputs: every command that writes checks its target first (``--out`` a folder that exists
or can be created, ``--json`` a file whose folder can be written; :func:`trials.output.check_output_dir`,
:func:`trials.output.check_output_file`) and refuses an unusable one in one line before any
computation; it then writes through :class:`trials.output.StagedOutput` (a staging folder
inside the target, moved in at the end), so an error, a full disk, a read-only filesystem,
SIGINT or SIGTERM leaves nothing behind: no staging folder, no partial file, no folder it
created.  A write failure (no space, read-only, no permission) is one line naming the path,
exit 2.  An empty path for any output option is refused when the arguments are read
(:func:`_output_path`).  An existing folder is written into (a command re-run into its own
folder replaces its own files); when it holds files this run did not write (an earlier run's,
another command's) one ``note:`` line on stderr names them after the run
(:func:`trials.output.others_note`).  Inputs are named after their files in printed lines and
outputs (:func:`trials.output.record_labels`).

Console output: a reader that leaves early (``mmg ... | head``) costs only the lines it did not
read: stdout and stderr are wrapped (:class:`_ReaderGone`) so that a closed pipe sends the rest
of the console output to ``os.devnull``; the run goes on, writes every file and exits with its
own status (no SIGPIPE, no BrokenPipeError).

Subcommands
-----------
simulate      a trial from its YAML                    (:func:`trials.run.run_trial`)
metrics       turning/zigzag metrics of any record      (:func:`trials.metrics.record_metrics`)
reproduce     the main job: the papers reproduced       (:func:`trials.reproduce.reproduce`)
nomoto        Nomoto K, T from a zigzag record          (:func:`trials.nomoto_report.identify_log`)
nomoto-paper  Artyszuk (2018) Tables 1-8                (:func:`trials.artyszuk.reproduce`)
estimate      hull coefficients from logs or trials     (:func:`trials.estimation.estimate_and_report`)
sensitivity   sensitivities, CRB, trial design          (:mod:`trials.sensitivity_report`)
montecarlo    EKF Monte Carlo over noise seeds          (:func:`trials.montecarlo.monte_carlo`)
log-filter    raw-log EKF Monte Carlo                   (:func:`trials.montecarlo.log_filter_monte_carlo`)
output-error  joint output-error Monte Carlo            (:func:`trials.montecarlo.output_error_monte_carlo`)
identify      identify a ship model from records        (:func:`trials.identify.identify`)
predict       replay records against their own inputs   (:func:`trials.predict.predict`)
diagnose      name the effect the model is missing      (:func:`trials.diagnose.diagnose`)
"""
from __future__ import annotations

import argparse
import errno
import math
import os
import signal
import sys
import time
from contextlib import contextmanager
from pathlib import Path

from mmg.errors import InputError

METRIC_KEYS = ["trial", "kind", "execute_s", "approach_speed_mps", "rudder_deg", "approach_speed_kn", "approach_rpm", "trim_rudder_deg", "advance_L", "transfer_L",
               "tactical_diameter_L", "steady_diameter_L", "speed_loss", "overshoots_deg", "initial_turning_time_s",
               "period_s", "final_heading_change_deg"]


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (``error: mmg estimate: argument --seed: ...``), exit 2."""

    def error(self, message):
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


class Interrupted(BaseException):
    """SIGTERM arrived (SIGINT arrives as KeyboardInterrupt).

    A BaseException, like KeyboardInterrupt, so that library code catching ``Exception`` does
    not swallow it; ``with`` blocks (the output staging) clean up as it passes."""


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("mmg-toolkit")
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


def _whole(minimum: int, what: str):
    """An argparse type: a whole number of at least ``minimum``; the error names ``what`` it is."""
    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if v < minimum:
            raise argparse.ArgumentTypeError(f"{what} must be {minimum} or more, got {v}")
        return v
    return parse


_positive_int = _whole(1, "it")
_seed = _whole(0, "a noise seed")


def _output_path(text: str) -> str:
    """An argparse type for every output option (a folder or file written): an empty path is refused
    (it would otherwise mean "no output" to a command whose option is optional)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"empty path {text!r}: give a file or folder name")
    return text


def _finite_positive(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not (v > 0 and v < float("inf")):
        raise argparse.ArgumentTypeError(f"expected a positive finite number, got {text!r}")
    return v


def _rudder_timing(text: str) -> float | None:
    """--rudder-timing: a prior std [s] > 0, 'inf' (no prior) or 'none' (no timing nuisances)."""
    if text.strip().lower() == "none":
        return None
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not v > 0:
        raise argparse.ArgumentTypeError(f"expected a prior std in seconds > 0, 'inf' or 'none', got {text!r}")
    return v


def print_metrics(m: dict, out=None) -> None:
    """The main metrics of a trial or record, one per line."""
    from .output import fmt

    out = out or sys.stdout
    for k in METRIC_KEYS:
        if k in m:
            print(f"  {k:26s} {fmt(m[k])}", file=out)


# --------------------------------------------------------------------------- simulate, metrics, reproduce


def cmd_simulate(args) -> int:
    from .output import StagedOutput, check_output_dir, write_trial_outputs
    from .run import run_trial
    from .trial import load_trial

    check_output_dir(args.out)
    trial = load_trial(args.config)
    with StagedOutput(args.out) as stage:
        run = run_trial(trial)
        m = write_trial_outputs(run, stage, show=args.show)
    print(f"{trial.name}: wrote log.csv, truth.csv, metrics.json, track.png, histories.png to {args.out}")
    print_metrics(m)
    if not run.result.completed:
        print(f"warning: {trial.name} stopped early at t = {run.result.t[-1]:g} s (speed collapsed)", file=sys.stderr)
    return 0


def cmd_metrics(args) -> int:
    import numpy as np

    from .logio import read_record, require_finite
    from .metrics import record_metrics
    from .output import check_output_file, dump_json
    from .records import CHANNELS

    if args.json is not None:
        check_output_file(args.json)
    from .shipcheck import check_record_ship, read_for_ship

    if args.length is not None:
        rec = read_for_ship(args.log, args.length)
    else:                    # the header's length, or the FRT-DS-ESSO layout's 3 m model
        rec = read_record(args.log)
        length = rec.meta.get("length_m")
        if isinstance(length, (int, float)) and length > 0:          # none at all: record_metrics says so
            assumed = "model the FRT-DS-ESSO layout assumes when no --length is given"
            check_record_ship(rec, float(length), name=assumed if rec.meta.get("format") == "frt-ds-esso" else None)
    require_finite(rec, CHANNELS, "mmg metrics")      # the track, heading, speeds, rudder, rpm; not the wind
    ang = None if args.zigzag_angle is None else np.radians(args.zigzag_angle)
    m = record_metrics(rec, args.kind, args.length, ang)
    if args.json is not None:
        dump_json(m, args.json)               # first (a temporary file beside it, renamed), then the console
    print(f"{rec.name} ({m['kind']}, {rec.source})")
    print_metrics(m)
    for note in m.get("notes", []):
        print(f"note: {note}", file=sys.stderr)
    return 0


def cmd_reproduce(args) -> int:
    from .output import StagedOutput, check_output_dir
    from .reproduce import reproduce

    check_output_dir(args.out)
    with StagedOutput(args.out) as stage:         # the whole report or nothing
        rep = stage.final(reproduce(stage.dir, full=args.full))
    print(f"report: {rep}")
    return 0


# --------------------------------------------------------------------------- Nomoto


def cmd_nomoto(args) -> int:
    from contextlib import nullcontext

    from .nomoto_report import identify_log, report, write_identification
    from .output import StagedOutput, check_output_file

    if args.json is not None:
        if Path(args.json).suffix.lower() == ".png":
            raise InputError("--json", args.json, "ends in .png, the name of the plot written beside it")
        check_output_file(args.json, also=[Path(args.json).with_suffix(".png")])
    # the JSON's folder staged for the JSON and its plot only: what else it holds is not this run's business
    with StagedOutput(Path(args.json).parent, report=False) if args.json is not None else nullcontext() as stage:
        ident, note = identify_log(args.log, args.length, args.speed, output_error=not args.no_output_error)
        if args.json is not None:
            write_identification(ident, stage.path(Path(args.json).name))
    if note:                                     # the files are in place: now the console
        print(note)
    print(report(ident))
    if args.json is not None:
        print(f"wrote {args.json} and {Path(args.json).with_suffix('.png')}")
    return 0


def cmd_nomoto_paper(args) -> int:
    import pandas as pd

    from . import artyszuk as a
    from .output import StagedOutput, check_output_dir

    check_output_dir(args.out)
    with StagedOutput(args.out) as stage:
        tables = a.reproduce(fast=args.fast)
        paths = a.write_tables(tables, stage.dir)
    with pd.option_context("display.width", 200, "display.max_columns", 40, "display.float_format", "{:.5g}".format):
        for key, title in a.TITLES.items():
            print(f"\n{title}")
            print(a.printable(tables[key])[0].to_string(index=False))     # as artyszuk_tables.md: no empty column
            note = tables.get("notes", {}).get(key)
            if note:
                print(f"note: {note}")
    print(f"\nwrote {len(paths)} files to {args.out}")
    return 0


# --------------------------------------------------------------------------- estimate


def _aot_deferred(when: bool):
    """mmg._aot.build_deferred() when ``when``, else nothing."""
    from contextlib import nullcontext

    from mmg import _aot

    return _aot.build_deferred() if when else nullcontext()


def cmd_estimate(args) -> int:
    from ekf.estimate import load_config

    from .estimation import estimate_and_report, load_inputs
    from .output import StagedOutput, check_output_dir

    from .warmup import compiling_in_background, filter_cache_cold, warm_filter_parts, warm_jacobian_real_parts

    check_output_dir(args.out)
    cfg = load_config(args.config, args.set or ())
    # a cold numba cache: the filter's Jacobian compiles on the second core while this one simulates
    # the inputs (with the JIT's kernel: cheaper to compile than the simulator's module) and compiles
    # the pass's other parts; the pass then loads them all, while the second core builds the
    # simulator's module from the JIT's code (mmg._aot) for the next command
    cold = args.method == "ekf" and filter_cache_cold()
    with StagedOutput(args.out) as out, compiling_in_background("jacobian", "aot", when=cold) as compiled, \
            _aot_deferred(cold):
        datas = load_inputs(args.inputs, cfg, seed=args.seed, ship=args.ship, truth=args.truth)
        if cold:
            warm_jacobian_real_parts()             # the child's, before it needs them
            warm_filter_parts()
        compiled("jacobian")
        rep = estimate_and_report(datas, cfg, out, joint=args.joint, plots=not args.no_plots, method=args.method)
    for w in rep["warnings"]:
        print(f"warning: {w}", file=sys.stderr)
    tab = rep["table"]
    print(f"wrote {_listing(out.written)} to {args.out}")   # the files actually written (no PNG with --no-plots)
    if rep["method"] == "output-error":
        print(tab.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        return 0
    for n, r in rep["rms"].items():
        print(f"  preprocessing RMS {n}: " + ", ".join(f"{k} {v:.3g}" for k, v in r.items()))
    cols = [c for c in tab.columns if c in ("coeff", "real") or c.endswith("final") or c.endswith("err(%)")]
    print(tab[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    return 0


# --------------------------------------------------------------------------- sensitivity


def cmd_sensitivity(args) -> int:
    from contextlib import ExitStack

    from . import sensitivity_report as sr
    from .output import StagedOutput, check_output_dir

    modes = [bool(args.trials), args.paper_figures, args.crb_vs_mc is not None, args.design]
    if sum(modes) != 1:
        raise InputError("mmg sensitivity", "arguments", "give trial YAMLs, or exactly one of --paper-figures, "
                                                          "--crb-vs-mc DIR, --design")
    check_output_dir(args.out)
    # a single --crb-vs-mc folder without runs.csv is where the Monte Carlo is run (written): staged too
    mc_run_dir = (args.crb_vs_mc[0] if args.crb_vs_mc and len(args.crb_vs_mc) == 1
                  and not (Path(args.crb_vs_mc[0]) / "runs.csv").exists() else None)
    if mc_run_dir is not None:
        check_output_dir(mc_run_dir, "--crb-vs-mc")
    if args.ekf_comparison is not None:
        sr.read_comparison(args.ekf_comparison)
    for p in args.trials:
        if not Path(p).is_file():
            raise InputError(p, "", "file not found")
    if args.backend == "dask":
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise InputError("--backend", "dask", "needs the optional extra: pip install 'mmg-toolkit[dask]'") from None
    t0 = time.perf_counter()
    cluster = client = None
    if args.backend == "dask":
        from .output import children_ignore_sigint

        with children_ignore_sigint():     # a terminal's Ctrl-C reaches this process only, which closes them
            cluster = LocalCluster(n_workers=args.jobs or 2, processes=True, threads_per_worker=1)
            client = Client(cluster)
    try:
        with ExitStack() as stack:
            stage = stack.enter_context(StagedOutput(args.out))
            if args.trials:
                sr.trial_sensitivities(args.trials, stage, fisher_bounds=args.fisher, backend=args.backend,
                                       n_jobs=args.jobs)
            elif args.paper_figures:
                sr.paper_figures(stage, args.ekf_comparison, backend=args.backend, n_jobs=args.jobs)
            elif args.crb_vs_mc is not None:
                mc = args.crb_vs_mc if mc_run_dir is None else stack.enter_context(StagedOutput(mc_run_dir)).dir
                sr.crb_table(mc, stage, n_seeds=args.mc_seeds, rudder_timing=args.rudder_timing)
            else:
                sr.design(stage, backend=args.backend, n_jobs=args.jobs, rudder_timing=args.rudder_timing)
    finally:
        if client is not None:
            client.close()
            cluster.close()
    print(f"wrote {args.out} ({time.perf_counter() - t0:.1f} s)")
    return 0


# --------------------------------------------------------------------------- Monte Carlo


def cmd_montecarlo(args) -> int:
    from .montecarlo import group_table, monte_carlo
    from .output import StagedOutput, check_output_dir

    if args.summarise_only:              # reads only
        import pandas as pd

        summary = Path(args.out) / "summary.csv"
        if not summary.is_file():
            raise InputError(str(summary), "", "file not found (mmg montecarlo OUT writes it)")
        print("\n".join(group_table(pd.read_csv(summary))))
        return 0
    check_output_dir(args.out, "OUT")
    with StagedOutput(args.out) as stage:
        monte_carlo(stage.dir, n_seeds=args.seeds, n_jobs=args.jobs, first_seed=args.first_seed, config=args.config)
    return 0


def cmd_log_filter(args) -> int:
    from .montecarlo import log_filter_monte_carlo
    from .output import StagedOutput, check_output_dir

    check_output_dir(args.out, "OUT")
    sigma = args.sigma_tau if args.sigma_tau is not None else (1e-4 if args.true_rudder else 0.15)
    with StagedOutput(args.out) as stage:
        log_filter_monte_carlo(stage.dir, n_seeds=args.seeds, trials=args.trials, n_jobs=args.jobs, sigma_tau=sigma,
                               first_seed=args.first_seed, rudder="true" if args.true_rudder else "rebuilt",
                               config=args.config)
    return 0


def cmd_output_error(args) -> int:
    import shutil

    from .montecarlo import PAPER_TRIALS, output_error_monte_carlo, summarise
    from .output import StagedOutput, check_output_dir

    for t in args.trials:
        if t not in PAPER_TRIALS:
            raise InputError("--trials", t, f"not one of {', '.join(PAPER_TRIALS)}")
    runs = Path(args.out) / "runs.csv"
    if args.summarise_only and not runs.is_file():
        raise InputError(str(runs), "", "file not found (mmg output-error OUT writes it)")
    check_output_dir(args.out, "OUT")
    ekf_summary = args.ekf_summary
    with StagedOutput(args.out) as stage:
        if args.summarise_only:          # the summary from a copy of runs.csv, moved in with it
            shutil.copy2(runs, stage.path("runs.csv"))
            summarise(stage.dir, tuple(args.trials), args.rudder, ekf_summary)
        else:
            output_error_monte_carlo(stage.dir, args.seeds, tuple(args.trials), n_jobs=args.jobs,
                                     first_seed=args.first_seed, rudder=args.rudder, ekf_summary=ekf_summary,
                                     config=args.config)
    return 0


# --------------------------------------------------------------------------- predict


def cmd_predict(args) -> int:
    from contextlib import nullcontext

    from mmg.ship import load_ship

    from .output import StagedFile, StagedOutput, check_output_dir, check_output_file, dumps_json
    from .predict import predict

    check_output_file(args.json)
    if args.plots is not None:
        check_output_dir(args.plots, "--plots")
    for log in args.logs:                  # every record there before the first is replayed
        if not Path(log).is_file():
            raise InputError(log, "", "file not found" if not Path(log).exists() else "is not a regular file")
    ship = load_ship(args.ship)
    wind = None if args.wind is None else args.wind == "on"

    def progress(i, n, name):
        print(f"replayed {i}/{n}: {name}", file=sys.stderr, flush=True)

    pred = predict(ship, args.logs, start=args.start, wind=wind, progress=progress)   # runs named after their files
    text = dumps_json(pred.to_json())
    names = [f"{r.run.name}.png" for r in pred.runs]
    with StagedFile(args.json) as tmp:     # the files first (renamed last, after the plots), then the console
        with StagedOutput(args.plots) if args.plots is not None else nullcontext() as stage:
            for r, name in zip(pred.runs, names if args.plots is not None else ()):
                r.plot(pyplot=False).savefig(stage.path(name))
        tmp.write_text(text)
    for r in pred.runs:
        s = r.scores()
        if r.diverged_at is not None:      # NaN scores (null in the JSON): say where and why
            print(f"{r.run.name}: the replay diverged at t = {r.diverged_at:.1f} s (the predicted state is not "
                  f"finite from there; scores null), wind {r.run.wind}")
            continue
        print(f"{r.run.name}: heading {s['heading_rms_deg']:.4g} deg RMS, yaw rate {s['yaw_rate_rms_degps']:.4g} deg/s RMS, "
              f"speed {s['speed_rms_mps']:.4g} m/s RMS, final position {s['final_position_error_m']:.4g} m "
              f"({s['final_position_error_L']:.4g} L), wind {r.run.wind}")
    if len(pred.runs) > 1:                 # the figure a comparison of two configs quotes
        sc = [r.scores() for r in pred.runs if r.diverged_at is None]
        mean = lambda k: sum(x[k] for x in sc) / len(sc)  # noqa: E731
        left = len(pred.runs) - len(sc)
        if sc:
            print(f"mean over {len(sc)} runs{f' ({left} diverged, left out)' if left else ''}: heading "
                  f"{mean('heading_rms_deg'):.4g} deg RMS, final position {mean('final_position_error_L'):.4g} L")
    print(f"wrote {args.json}" + (f" and {len(names)} plot{'s' if len(names) != 1 else ''} to {args.plots}"
                                  if args.plots is not None else ""))
    return 0


def _check_free(ship, names) -> None:
    """Refuse (one line, exit 2) a --free name that is neither a hull coefficient of ``ship`` nor a constant."""
    from ekf.identify import SHIP_CONSTANTS

    known = set(ship.hull.names) | set(SHIP_CONSTANTS) | {"hull", "hull-except-constants"}
    for n in names:
        if n not in known:
            raise InputError("--free", n, f"not a hull coefficient of {ship.name} nor one of "
                                          f"hull, hull-except-constants, {', '.join(SHIP_CONSTANTS)}")


def cmd_identify(args) -> int:
    import numpy as np

    from mmg.resources import ship_path
    from mmg.ship import load_ship

    from .identify import DEFAULT_MAX_NFEV, cross_validate, cv_folds, identify, load_runs, write_identification
    from .output import StagedOutput, check_output_dir, record_labels

    check_output_dir(args.out)
    for log in args.train + (args.test or []):
        if not Path(log).is_file():
            raise InputError(log, "", "file not found" if not Path(log).exists() else "is not a regular file")
    src = ship_path(args.ship)
    ship = load_ship(src)
    if args.free:
        _check_free(ship, args.free)
    wind = None if args.wind is None else args.wind == "on"
    t0 = time.perf_counter()
    names = record_labels(args.train + (args.test or []))   # training and test records told apart together
    runs = load_runs(ship, args.train, wind=wind, names=names[:len(args.train)])   # an unusable one: one line, skipped
    if not runs:
        raise InputError("--train", "", "no usable training record")
    print(f"training on {len(runs)} record{'' if len(runs) == 1 else 's'}", file=sys.stderr, flush=True)
    if args.cv:                                          # refused or narrowed before any fit
        try:
            folds = cv_folds(runs, args.cv)
        except ValueError as e:
            raise InputError("--cv", "", f"{e} (a record and its cut copies count once)") from None
        if folds < args.cv:
            print(f"note: --cv {args.cv}: {folds} independent records, so {folds} folds (each kept out once)",
                  file=sys.stderr, flush=True)
    tests = (load_runs(ship, args.test, wind=wind, names=names[len(args.train):])   # a bad one: one line, before the fit
             if args.test else None)
    if args.test and not tests:
        raise InputError("--test", "", "no usable record")

    shown = [None]

    def progress(k, cost, stage):            # a header per fit stage, then its iterations labelled by it
        if stage != shown[0]:
            shown[0] = stage
            print(f"{stage}; at most {kw['max_nfev']} evaluations", file=sys.stderr, flush=True)
        print(f"  {stage.split(':')[0]}, iteration {k}: cost {cost:.5g} ({time.perf_counter() - t0:.0f} s)",
              file=sys.stderr, flush=True)

    initial = load_ship(ship_path(args.initial)) if args.initial else None
    kw = {"record_weighting": args.weighting} if args.weighting else {}
    kw["max_nfev"] = args.max_nfev or DEFAULT_MAX_NFEV
    if args.velocity_weight is not None:
        kw["velocity_weight"] = args.velocity_weight
    if args.free:
        kw["free"] = tuple(args.free)
    ident = identify(ship, runs, wind=wind, progress=progress, initial=initial, **kw)
    cv = None
    if args.cv:
        cv = cross_validate(ship, runs, folds=folds, wind=wind, initial=initial, folds_by=args.folds_by, **kw,
                            progress=lambda k, n: print(f"cross-validation fold {k}/{n} ({time.perf_counter() - t0:.0f} s)",
                                                        file=sys.stderr, flush=True))
    with StagedOutput(args.out) as stage:
        write_identification(ident, src, stage.dir, cv, tests)
    a = np.mean([x["heading_rms_deg"] for x in ident.scores(model="initial")])
    b = np.mean([x["heading_rms_deg"] for x in ident.scores()])
    print(f"identified {len(ident.fit.free)} parameters over {len(runs)} records in {time.perf_counter() - t0:.0f} s: "
          f"mean heading RMS {a:.2f} deg (initial) -> {b:.2f} deg (identified)")
    print(f"wrote {Path(args.out) / 'ship.yaml'} and {Path(args.out) / 'report.md'}")
    for st in ident.stages:
        if st["status"] == 0:
            print(f"note: {st['description'].split(':')[0]} stopped at its evaluation limit ({st['max_nfev']}) before "
                  f"converging; --max-nfev raises it", file=sys.stderr)
    warn = ident.fit.warnings()
    if warn:
        print(f"warning: {len(warn)} finding(s) on where the identified values should not be read as the ship's "
              f"physics (sign changes, bounds, no convergence): {Path(args.out) / 'report.md'}, 'Warnings'",
              file=sys.stderr)
    return 0


# --------------------------------------------------------------------------- diagnose


def cmd_diagnose(args) -> int:
    from contextlib import nullcontext

    from mmg.resources import ship_path
    from mmg.ship import load_ship

    from .diagnose import diagnose, prepare
    from .output import StagedFile, StagedOutput, check_output_dir, check_output_file, dumps_json

    check_output_file(args.json)
    if args.plots is not None:
        check_output_dir(args.plots, "--plots")
    if args.out_ship is not None:
        check_output_file(args.out_ship, "--out-ship")
    for log in args.logs:
        if not Path(log).is_file():
            raise InputError(log, "", "file not found" if not Path(log).exists() else "is not a regular file")
    src = ship_path(args.ship)
    ship = load_ship(src)
    wind = False if args.wind is None else args.wind == "on"
    recs = prepare(ship, args.logs, wind=wind)           # every record read (a bad one: one line) first
    say = lambda m: print(m, file=sys.stderr, flush=True)  # noqa: E731
    d = diagnose(ship, recs, wind=wind, per_run=len(recs) > 1, say=say)
    text = dumps_json(d.to_json())
    ship_text = None
    if args.out_ship is not None:
        from .identify import ship_yaml

        note = (f"mmg diagnose over {len(recs)} record(s): named {', '.join(d.named) or 'nothing'}; "
                + "; ".join(f"{e} " + ", ".join(f"{k} = {v:.4g}" for k, v in p.items()) for e, p in d.parameters.items())
                + ". The named effects are in the effects: section, so mmg predict with this config replays these "
                  "records with them; a current, a rudder offset or a heading bias belongs to these records, not the "
                  "ship: for other trials move it to their trial config's effects: section")
        ship_text = ship_yaml(src, d.ship_values, note)
        import yaml

        head, body = [], []
        for ln in ship_text.splitlines(keepends=True):
            (head if ln.startswith("#") and not body else body).append(ln)
        data = yaml.safe_load("".join(body))
        for k, v in d.ship_values.items():            # the fitted added masses (ship_yaml writes the hull)
            if k.endswith("_prime") and k in data.get("mass", {}):
                data["mass"][k] = float(f"{v:.6g}")
        if d.parameters:
            eff = dict(data.get("effects") or {})
            for e, p in d.parameters.items():
                eff[e] = {k: float(f"{v:.6g}") for k, v in p.items() if math.isfinite(v)}
            if "wind" in eff and data.get("wind") is not None:
                data["wind"].pop("scale", None)            # the scale is the effect's now
                data["wind"]["enabled"] = True             # (effects.wind with enabled: false is refused)
            data["effects"] = eff
        ship_text = "".join(head) + yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    with StagedFile(args.json) as tmp:         # the files first, then the console
        with StagedFile(args.out_ship) if args.out_ship is not None else nullcontext() as tship:
            with StagedOutput(args.plots) if args.plots is not None else nullcontext() as stage:
                if args.plots is not None:
                    from .diagnose_plots import diagnose_figure

                    for i, r in enumerate(d.records):       # named after their files (unique: prepare)
                        diagnose_figure(d, i).savefig(stage.path(f"{r.name}.png"))
            if tship is not None:
                tship.write_text(ship_text)
        tmp.write_text(text)
    b, a = d.rms_before, d.rms_after
    print(f"named: {', '.join(d.named) or 'nothing'}" + "".join(
        f"; {e} " + ", ".join(f"{k} {v:.4g} +- {d.standard_errors[e][k]:.2g}" for k, v in p.items())
        for e, p in d.parameters.items()))
    print("residual RMS before -> after: " + ", ".join(f"{c} {b[c]:.3g} -> {a[c]:.3g}" for c in b))
    if d.unexplained:
        print(f"unexplained: {d.unexplained_description}")
    print(f"wrote {args.json}" + (f", {args.out_ship}" if args.out_ship is not None else "") +
          (f" and {len(d.records)} plot(s) to {args.plots}" if args.plots is not None else ""))
    return 0


# --------------------------------------------------------------------------- parser


def build_parser() -> argparse.ArgumentParser:
    """The ``mmg`` argument parser (every subcommand)."""
    ap = _Parser(prog="mmg", description="MMG ship manoeuvring: simulate, analyse, identify.")
    ap.add_argument("--version", action="version", version=f"mmg-toolkit {_version()}")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)

    for add in (_add_simulate, _add_metrics, _add_reproduce, _add_nomoto, _add_nomoto_paper, _add_estimate,
                _add_sensitivity, _add_montecarlo, _add_log_filter, _add_output_error, _add_predict, _add_identify,
                _add_diagnose):
        add(sub)
    return ap


def _mc_common(p, what) -> None:
    """The arguments the Monte Carlo commands share."""
    p.add_argument("out", type=_output_path, help="output folder (runs.csv, summary.csv/.md)")
    p.add_argument("--seeds", type=_positive_int, default=20, help="noise seeds per trial (default 20)")
    p.add_argument("--first-seed", type=_seed, default=1000, help="noise seed of the first run of each trial")
    p.add_argument("--jobs", type=_positive_int, default=2, help="workers (default 2)")
    p.add_argument("--config", default=None, help=f"estimation YAML for the {what}")


def _add_simulate(sub) -> None:
    """``mmg simulate``'s arguments."""
    p = sub.add_parser("simulate", help="simulate a trial from its YAML config")
    p.add_argument("config", help="trial YAML (configs/trials/*.yaml) or a bundled trial name (st35, zz20, ...)")
    p.add_argument("--out", required=True, type=_output_path,
                   help="output folder (log.csv, truth.csv, metrics.json, PNGs)")
    p.add_argument("--show", action="store_true", help="also show the figures on screen")
    p.set_defaults(func=cmd_simulate)


def _add_metrics(sub) -> None:
    """``mmg metrics``'s arguments."""
    p = sub.add_parser("metrics", help="manoeuvre metrics from a log (project log, truth file or FRT-DS-ESSO CSV)")
    p.add_argument("log")
    p.add_argument("--kind", choices=["turning", "zigzag", "stype"], help="override the manoeuvre kind")
    p.add_argument("--length", type=_finite_positive, help="ship length L [m] when the log does not say")
    p.add_argument("--zigzag-angle", type=_finite_positive,
                   help="switching heading [deg] for a zigzag log without rudder")
    p.add_argument("--json", type=_output_path, help="also write the metrics to this JSON file")
    p.set_defaults(func=cmd_metrics)


def _add_reproduce(sub) -> None:
    """``mmg reproduce``'s arguments."""
    p = sub.add_parser("reproduce", help="the main job: reproduce the papers on the default Esso Osaka configs")
    p.add_argument("--out", default="out", type=_output_path, help="output folder (default: out)")
    p.add_argument("--full", action="store_true",
                   help="also the Monte Carlo runs (EKF and output error, 20 seeds) and the full Nomoto Table 8 (~25 min)")
    p.set_defaults(func=cmd_reproduce)


def _add_nomoto(sub) -> None:
    """``mmg nomoto``'s arguments."""
    p = sub.add_parser("nomoto", help="identify 1st/2nd-order Nomoto K, T (T1, T2, T3) from a zigzag log")
    p.add_argument("log", help="zigzag record (project log/truth CSV or FRT-DS-ESSO CSV)")
    p.add_argument("--length", type=float, required=True, help="ship length L [m]")
    p.add_argument("--speed", type=float, help="speed U [m/s] for s' = tU/L (default: mean approach speed)")
    p.add_argument("--json", type=_output_path, help="write results to this JSON file (plot PNG next to it)")
    p.add_argument("--no-output-error", action="store_true", help="skip the output-error fit")
    p.set_defaults(func=cmd_nomoto)


def _add_nomoto_paper(sub) -> None:
    """``mmg nomoto-paper``'s arguments."""
    p = sub.add_parser("nomoto-paper", help="reproduce Artyszuk (2018) Tables 1-8 (CSV + Markdown)")
    p.add_argument("--out", default="out/nomoto-paper", type=_output_path, help="output folder")
    p.add_argument("--fast", action="store_true", help="skip the output-error fits of the extended Table 8")
    p.set_defaults(func=cmd_nomoto_paper)


def _add_estimate(sub) -> None:
    """``mmg estimate``'s arguments."""
    p = sub.add_parser("estimate", help="estimate the ship's sway/yaw hull coefficients from trial logs (augmented EKF)")
    p.add_argument("inputs", nargs="+", metavar="LOG_OR_TRIAL.yaml",
                   help="project logs (log.csv) or trial YAMLs / bundled trial names (simulated first)")
    p.add_argument("--out", required=True, type=_output_path, help="output folder")
    p.add_argument("--seed", type=_seed, default=None, help="noise seed for simulated trials (default: the trial's)")
    p.add_argument("--config", default=None, help="estimation YAML overriding the bundled configs/estimation/rhee_kim.yaml")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override one config value, e.g. initial.scale=1.5 or R.ZZ20.u=0.1 (repeatable)")
    p.add_argument("--ship", default=None,
                   help="ship YAML or bundled name for logs (default: the log header's ship file, else esso_osaka)")
    p.add_argument("--truth", default=None, help="truth.csv of a simulated log (enables true values and errors)")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    p.add_argument("--joint", action="store_true",
                   help="also one joint estimate running through all inputs in turn (column 'joint')")
    p.add_argument("--method", choices=("ekf", "output-error"), default="ekf",
                   help="ekf: the augmented EKF per input (default); output-error: joint EKF then the joint "
                        "output-error fit of the raw logs over all inputs")
    p.set_defaults(func=cmd_estimate)


def _add_sensitivity(sub) -> None:
    """``mmg sensitivity``'s arguments."""
    p = sub.add_parser("sensitivity", help="derivative sensitivities (Rhee & Kim eqs. 21-22), Fisher information, "
                                           "trial design")
    p.add_argument("trials", nargs="*", help="trial YAMLs to compare (their sensitivities are normalised together)")
    p.add_argument("--out", required=True, type=_output_path, help="output folder")
    p.add_argument("--paper-figures", action="store_true", help="Rhee & Kim Figs 2, 8-9, 12, 13, 14 and 28 in one go")
    p.add_argument("--ekf-comparison", help="comparison.csv of the EKF reproduction for Fig. 28 (default: run it)")
    p.add_argument("--fisher", action="store_true", help="also write the Cramer-Rao bounds of the given trials")
    p.add_argument("--crb-vs-mc", metavar="MC_DIR", nargs="+", type=_output_path,
                   help="CRB vs the EKF Monte Carlo in MC_DIR (runs.csv; run there when a single folder is missing); "
                        "several folders are pooled per trial")
    p.add_argument("--mc-seeds", type=_positive_int, default=20, help="seeds per trial when the Monte Carlo must be run")
    p.add_argument("--rudder-timing", type=_rudder_timing, default=0.15, metavar="SIGMA_S",
                   help="with --crb-vs-mc or --design: prior std [s] of the per-movement rudder-timing nuisances of the "
                        "second log bound (default 0.15, the raw-log EKF's; 'inf' no prior; 'none' leaves that bound out)")
    p.add_argument("--design", action="store_true", help="trial-design search (S-type psi_S, zigzag angles)")
    p.add_argument("--backend", choices=["serial", "loky", "threads", "dask"], default="loky",
                   help="parallel backend of the sweeps (dask: a local distributed cluster; optional extra)")
    p.add_argument("--jobs", type=_positive_int, default=None, help="workers (default: all cores)")
    p.set_defaults(func=cmd_sensitivity)


def _add_montecarlo(sub) -> None:
    """``mmg montecarlo``'s arguments."""
    p = sub.add_parser("montecarlo", help="Monte Carlo of the paper EKF over noise seeds (ST35, ZZ10, ZZ20, S-type 120)")
    _mc_common(p, "EKF")
    p.add_argument("--summarise-only", action="store_true", help="print the group table of OUT/summary.csv, no runs")
    p.set_defaults(func=cmd_montecarlo)


def _add_log_filter(sub) -> None:
    """``mmg log-filter``'s arguments."""
    p = sub.add_parser("log-filter", help="Monte Carlo of the EKF on the raw 5 s log (near the Cramer-Rao bound)")
    _mc_common(p, "raw-log EKF")
    p.add_argument("--trials", nargs="*", default=None,
                   help="trial names (default ST35 ZZ10 ZZ20 'S-type 120') or turning/zigzag/S-type trial YAMLs")
    p.add_argument("--sigma-tau", type=_finite_positive, default=None,
                   help="prior std [s] of each rudder movement's timing (default 0.15, or 1e-4 with --true-rudder)")
    p.add_argument("--true-rudder", action="store_true",
                   help="give the filter the truth file's rudder instead of the rebuilt one (a check against the CRB "
                        "with the rudder known)")
    p.set_defaults(func=cmd_log_filter)


def _add_output_error(sub) -> None:
    """``mmg output-error``'s arguments."""
    p = sub.add_parser("output-error", help="Monte Carlo of the joint output-error fit (EKF start) over noise seeds")
    _mc_common(p, "EKF start and the fit")
    p.add_argument("--trials", nargs="+", default=["ST35", "ZZ10", "ZZ20", "S-type 120"],
                   help="trial names (ST35 ZZ10 ZZ20 'S-type 120')")
    p.add_argument("--rudder", choices=("ramp", "law", "reconstructed"), default="ramp")
    p.add_argument("--ekf-summary", default=None,
                   help="summary.csv of 'mmg montecarlo' (per-trial EKF) to show beside the table")
    p.add_argument("--summarise-only", action="store_true", help="rewrite the table from OUT/runs.csv, no runs")
    p.set_defaults(func=cmd_output_error)


def _add_predict(sub) -> None:
    """``mmg predict``'s arguments."""
    p = sub.add_parser("predict", help="replay records open-loop against their own rudder and propeller history: "
                                       "heading, yaw-rate, speed RMS and final position error per run")
    p.add_argument("logs", nargs="+", metavar="LOG", help="FRT-DS-ESSO CSVs, project logs or truth files")
    p.add_argument("--ship", required=True, help="ship YAML or bundled name (esso_osaka_3m, esso_osaka, ...)")
    p.add_argument("--json", required=True, type=_output_path, help="write the scores of every run to this JSON file")
    p.add_argument("--plots", default=None, metavar="DIR", type=_output_path,
                   help="also one figure per run, DIR/<name>.png (<name>: the record's file name; two files of one "
                        "name told apart by their folders, DIR/<folder>/<name>.png)")
    p.add_argument("--start", type=float, default=None, metavar="S",
                   help="start time [s] of every replay (default: each record's first sample)")
    p.add_argument("--wind", choices=("on", "off"), default=None,
                   help="wind loads from the measured relative wind (default: as the ship config says)")
    p.set_defaults(func=cmd_predict)


def _add_identify(sub) -> None:
    """``mmg identify``'s arguments."""
    p = sub.add_parser("identify", help="identify hull coefficients and model-scale constants jointly over measured "
                                        "records (segment-wise output error); writes DIR/ship.yaml and DIR/report.md")
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
                        "default trials.identify.DEFAULT_WEIGHTING")
    p.add_argument("--free", nargs="+", default=None, metavar="NAME",
                   help="the parameters to fit: hull coefficient names, 'hull' (all of them), 'hull-except-constants', "
                        "w_P0, epsilon, kappa, gamma_R_pos, gamma_R_neg, l_R_prime, rudder_offset, wind_scale, m_x, m_y, "
                        "J_z (default trials.identify.DEFAULT_FREE)")
    p.add_argument("--velocity-weight", type=_finite_positive, default=None, metavar="W",
                   help="factor on the u, v, r residuals beside the heading's (default 1; 0.1: their squares weigh a "
                        "hundredth, so the fit follows the heading; docs/identify_cv.md)")
    p.add_argument("--max-nfev", type=_positive_int, default=None, metavar="N",
                   help="most evaluations of the residuals in each fit stage (segment-wise, then whole-record; "
                        "default trials.identify.DEFAULT_MAX_NFEV); a stage that reaches it stops unconverged, "
                        "and the report and a note say so")
    p.add_argument("--folds-by", choices=("order", "revolutions"), default="order",
                   help="with --cv: deal the records into folds in the order given or stratified by their propeller "
                        "revolutions (a record and its cut copies always share a fold)")
    p.set_defaults(func=cmd_identify)


def _add_diagnose(sub) -> None:
    """``mmg diagnose``'s arguments."""
    p = sub.add_parser("diagnose", help="find where the model and the records disagree, name the missing effect "
                                        "(current, wind, rudder_offset, heading_bias, shallow_water) and show the gap shrink")
    p.add_argument("logs", nargs="+", metavar="LOG", help="FRT-DS-ESSO CSVs, project logs or truth files")
    p.add_argument("--ship", required=True, help="ship YAML or bundled name (esso_osaka_3m, esso_osaka, ...)")
    p.add_argument("--json", required=True, type=_output_path, help="write the diagnosis to this JSON file")
    p.add_argument("--plots", default=None, metavar="DIR", type=_output_path,
                   help="also one figure per record, DIR/<name>.png (<name>: the record's file name, as for predict)")
    p.add_argument("--out-ship", default=None, metavar="NEW.yaml", type=_output_path,
                   help="write the ship config with the fitted coefficients (and a named wind scale)")
    p.add_argument("--wind", choices=("on", "off"), default=None,
                   help="wind loads in the model from the start (default off: wind is then a candidate effect)")
    p.set_defaults(func=cmd_diagnose)


def _listing(names) -> str:
    """File names for a 'wrote ...' line; 3 or more of one pattern (convergence_*.png) as one."""
    groups: dict = {}
    for n in names:
        stem, suffix = os.path.splitext(n)
        key = (stem.split("_", 1)[0] + "_*" if "_" in stem else stem, suffix)
        groups.setdefault(key, []).append(n)
    out = []
    for (pat, suffix), ns in groups.items():
        out += [f"{pat}{suffix} ({len(ns)})"] if len(ns) >= 3 else ns
    return ", ".join(out) or "nothing"


_signal_state = {"signum": None, "unwinding": False}


def _on_signal(signum, frame):
    """SIGINT -> KeyboardInterrupt, SIGTERM -> Interrupted.  While that exception unwinds (and the
    staging cleans up) a further signal is ignored, so the clean-up is never cut short."""
    if _signal_state["unwinding"]:
        return
    _signal_state.update(signum=signum, unwinding=True)
    import logging
    import warnings

    # from here on only "interrupted": no joblib "tasks executed but not used" warning, no logged
    # "exception calling callback" of a worker pool being shut down
    warnings.simplefilter("ignore")
    logging.disable(logging.CRITICAL)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Interrupted()


def _unraisable(u, _default=sys.unraisablehook):
    """The interrupt's exception raised where Python cannot propagate it (a weakref callback, a
    ``__del__``: "Exception ignored in ...") is not lost: the signal is sent again, so it is
    raised at the next ordinary line instead; other unraisable exceptions as usual."""
    if (u.exc_type is not None and issubclass(u.exc_type, (Interrupted, KeyboardInterrupt))
            and _signal_state["signum"] is not None):
        import threading

        _signal_state["unwinding"] = False
        # sent a moment later, from another thread: sent here, its handler would run (and raise) in this hook
        t = threading.Timer(0.02, os.kill, (os.getpid(), _signal_state["signum"]))
        t.daemon = True
        t.start()
        return
    _default(u)


def _install_handlers() -> dict:
    """Our handler for SIGINT and SIGTERM where they have their default one (main thread only);
    returns the old handlers to restore."""
    import logging
    import threading

    old = {}
    _signal_state.update(signum=None, unwinding=False)
    if threading.current_thread() is not threading.main_thread():
        return old
    old["logging"] = logging.root.manager.disable      # _on_signal silences logging: put back after main()
    defaults = {signal.SIGINT: (signal.default_int_handler,), signal.SIGTERM: (signal.SIG_DFL, None)}
    for sig, dflt in defaults.items():
        if signal.getsignal(sig) in dflt:
            old[sig] = signal.signal(sig, _on_signal)
    if signal.SIGINT in old or signal.SIGTERM in old:
        old["unraisablehook"] = sys.unraisablehook
        sys.unraisablehook = lambda u, _d=sys.unraisablehook: _unraisable(u, _d)
    return old


class _ReaderGone:
    """A console stream (stdout, stderr) that outlives its reader: when the pipe it writes to is
    closed (``mmg ... | head``: EPIPE, a BrokenPipeError with SIGPIPE ignored, as Python has it),
    its file descriptor is pointed at ``os.devnull`` and the write counts as done, so the run goes
    on and writes its files, and the exit status is its own.  Everything else is the stream's."""

    def __init__(self, stream):
        self._stream = stream
        self.gone = False

    def _closed(self) -> None:
        self.gone = True
        try:
            fd = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(fd, self._stream.fileno())       # the buffered rest, and any later flush, go there
            finally:
                os.close(fd)
        except (OSError, ValueError, AttributeError):
            pass

    def _guarded(self, call, *a):
        if self.gone:
            try:
                return call(*a)                          # to os.devnull now (or a stream without a descriptor)
            except (BrokenPipeError, ValueError, OSError):
                return None
        try:
            return call(*a)
        except BrokenPipeError:
            self._closed()
        except OSError as e:
            if e.errno != errno.EPIPE:
                raise
            self._closed()
        return None

    def write(self, text):
        self._guarded(self._stream.write, text)
        return len(text)

    def writelines(self, lines):
        self._guarded(self._stream.writelines, lines)

    def flush(self):
        self._guarded(self._stream.flush)

    def __getattr__(self, name):
        return getattr(self._stream, name)


@contextmanager
def _console_outlives_reader():
    """sys.stdout and sys.stderr wrapped in :class:`_ReaderGone` for the block (flushed and put back after)."""
    old = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = (_ReaderGone(x) if x is not None else x for x in old)
    try:
        yield
    finally:
        for x in (sys.stdout, sys.stderr):
            if isinstance(x, _ReaderGone):
                x.flush()
        sys.stdout, sys.stderr = old


def _interrupted(code: int) -> int:
    print("interrupted", file=sys.stderr)
    return code


def main(argv=None) -> int:
    """Run the ``mmg`` command; returns the exit status (see the module docstring)."""
    import warnings

    old = _install_handlers()          # first: an early signal is already one line, 130 / 143
    try:
        with warnings.catch_warnings(), _console_outlives_reader():   # _on_signal silences warnings: only for this run
            try:
                return _run(argv)
            except KeyboardInterrupt:      # a signal during the last lines of _run's own handling
                return _interrupted(130)
            except Interrupted:
                return _interrupted(143)
    finally:
        hook = old.pop("unraisablehook", None)
        level = old.pop("logging", None)
        for sig, h in old.items():
            signal.signal(sig, h)
        if hook is not None:
            sys.unraisablehook = hook
        if level is not None:
            import logging

            logging.disable(level)
        if argv is None and signal.SIGINT in old and _is_command_line():
            # the run is over (its outputs are in place or gone): a Ctrl-C while Python shuts down
            # (joining the worker pool's threads) would only print a KeyboardInterrupt traceback
            signal.signal(signal.SIGINT, signal.SIG_IGN)


def _is_command_line() -> bool:
    """This process is the ``mmg`` command (console script or ``python -m trials.cli``)."""
    main_mod = sys.modules.get("__main__")
    spec = getattr(main_mod, "__spec__", None)
    return Path(sys.argv[0]).name in ("mmg", "mmg.exe") or (spec is not None and spec.name == "trials.cli")


def _run(argv) -> int:
    ap = build_parser()
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:            # --help, --version (0) and bad arguments (2, one usage line)
        return int(e.code or 0)
    if not getattr(args, "show", False):
        os.environ.setdefault("MPLBACKEND", "Agg")   # files only; no display needed (cheap: nothing imported)
    from .output import collect_commits, others_note

    try:
        with collect_commits() as committed:
            code = int(args.func(args) or 0)
        for stage in committed:            # the folders written into: what they hold that this run did not write
            note = others_note(stage)
            if note:
                print(note, file=sys.stderr)
        return code
    except (Exception, KeyboardInterrupt, Interrupted) as e:
        code = _interrupt_code(e)
        if code:
            return _interrupted(code)
        if isinstance(e, InputError):
            print(f"error: {e}", file=sys.stderr)
            return 2
        if isinstance(e, OSError) and e.errno in _WRITE_ERRNOS():
            # writing (or reading) a file failed: no space, read-only filesystem, no permission
            from .output import write_error

            print(f"error: {write_error(e) if e.errno in _FULL_OR_READ_ONLY else _os_error_line(e)}", file=sys.stderr)
            return 2
        from ekf.filter import FilterDivergence

        if isinstance(e, FilterDivergence):   # a diverging filter is a result, not a crash
            print(f"error: {e}", file=sys.stderr)
            return 3
        raise


def _interrupt_code(e: BaseException) -> int:
    """130 / 143 when ``e`` is, or was caused by, the interrupt (numba, for one, turns an exception
    raised in a callback into a SystemError), or when any error follows a signal; else 0."""
    seen, x = set(), e
    while x is not None and id(x) not in seen:
        if isinstance(x, KeyboardInterrupt):
            return 130
        if isinstance(x, Interrupted):
            return 143
        seen.add(id(x))
        x = x.__cause__ or x.__context__
    if _signal_state["unwinding"] and _signal_state["signum"] is not None:
        return 130 if _signal_state["signum"] == signal.SIGINT else 143
    return 0


def _WRITE_ERRNOS():
    from .output import WRITE_ERRNOS

    return WRITE_ERRNOS


_FULL_OR_READ_ONLY = {getattr(errno, n) for n in ("ENOSPC", "EROFS", "EDQUOT", "EFBIG") if hasattr(errno, n)}


def _os_error_line(e: OSError) -> str:
    return f"{e.filename or '?'}: {e.strerror or e}"


if __name__ == "__main__":
    sys.exit(main())
