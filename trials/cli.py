"""The ``mmg`` command: one entry point, one argument and exit-code convention.

Every subcommand is a thin layer over public library functions (named in its help):
parse, call, print.  Exit status: 0 done; 2 bad input (one line on stderr naming the file
or option and the field; nothing written) or bad arguments; 3 a diverging filter; 130 / 143
interrupted by SIGINT / SIGTERM (one line, nothing left behind).  Library code never calls
:func:`main`.

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
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from pathlib import Path

from mmg.errors import InputError

METRIC_KEYS = ["trial", "kind", "approach_speed_kn", "approach_rpm", "trim_rudder_deg", "advance_L", "transfer_L",
               "tactical_diameter_L", "steady_diameter_L", "speed_loss", "overshoots_deg", "initial_turning_time_s",
               "period_s", "final_heading_change_deg"]


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (``error: mmg estimate: argument --seed: ...``), exit 2."""

    def error(self, message):
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


class Interrupted(Exception):
    """SIGTERM arrived (SIGINT arrives as KeyboardInterrupt)."""


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("mmg-toolkit")
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {v}")
    return v


def _seed(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < 0:
        raise argparse.ArgumentTypeError(f"a noise seed must be 0 or more, got {v}")
    return v


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
    from .output import StagedOutput, write_trial_outputs
    from .run import run_trial
    from .trial import load_trial

    trial = load_trial(args.config)
    run = run_trial(trial)
    with StagedOutput(args.out) as stage:
        m = write_trial_outputs(run, stage, show=args.show)
    print(f"{trial.name}: wrote log.csv, truth.csv, metrics.json, track.png, histories.png to {args.out}")
    print_metrics(m)
    if not run.result.completed:
        print(f"warning: {trial.name} stopped early at t = {run.result.t[-1]:g} s (speed collapsed)", file=sys.stderr)
    return 0


def cmd_metrics(args) -> int:
    import numpy as np

    from .logio import read_record
    from .metrics import record_metrics
    from .output import StagedOutput, dump_json

    rec = read_record(args.log)
    ang = None if args.zigzag_angle is None else np.radians(args.zigzag_angle)
    m = record_metrics(rec, args.kind, args.length, ang)
    print(f"{rec.name} ({m['kind']}, {rec.source})")
    print_metrics(m)
    if args.json:
        with StagedOutput(Path(args.json).parent or ".") as stage:
            dump_json(m, stage.path(Path(args.json).name))
    return 0


def cmd_reproduce(args) -> int:
    from .reproduce import reproduce

    rep = reproduce(args.out, full=args.full)
    print(f"report: {rep}")
    return 0


# --------------------------------------------------------------------------- Nomoto


def cmd_nomoto(args) -> int:
    from .nomoto_report import identify_log, report, write_identification

    ident, note = identify_log(args.log, args.length, args.speed, output_error=not args.no_output_error)
    if note:
        print(note)
    print(report(ident))
    if args.json:
        write_identification(ident, args.json)
        print(f"wrote {args.json} and {Path(args.json).with_suffix('.png')}")
    return 0


def cmd_nomoto_paper(args) -> int:
    import pandas as pd

    from . import artyszuk as a

    tables = a.reproduce(fast=args.fast)
    with pd.option_context("display.width", 200, "display.max_columns", 40, "display.float_format", "{:.5g}".format):
        for key, title in a.TITLES.items():
            print(f"\n{title}")
            print(tables[key].to_string(index=False))
            note = tables.get("notes", {}).get(key)
            if note:
                print(f"note: {note}")
    paths = a.write_tables(tables, args.out)
    print(f"\nwrote {len(paths)} files to {args.out}")
    return 0


# --------------------------------------------------------------------------- estimate


def cmd_estimate(args) -> int:
    from ekf.estimate import load_config

    from .estimation import estimate_and_report, load_inputs
    from .output import StagedOutput

    cfg = load_config(args.config, args.set or ())
    datas = load_inputs(args.inputs, cfg, seed=args.seed, ship=args.ship, truth=args.truth)
    with StagedOutput(args.out) as out:
        rep = estimate_and_report(datas, cfg, out, joint=args.joint, plots=not args.no_plots, method=args.method)
    for w in rep["warnings"]:
        print(f"warning: {w}", file=sys.stderr)
    tab = rep["table"]
    if rep["method"] == "output-error":
        print(f"wrote {args.out}/estimates.json, oe_fit.json, error_table.csv/.md, free_run.json")
        print(tab.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        return 0
    figs = ", convergence_*.png" if rep["figures"] else ""
    print(f"wrote {args.out}/estimates.json, error_table.csv/.md, final_estimates.csv{figs}")
    for n, r in rep["rms"].items():
        print(f"  preprocessing RMS {n}: " + ", ".join(f"{k} {v:.3g}" for k, v in r.items()))
    cols = [c for c in tab.columns if c in ("coeff", "real") or c.endswith("final") or c.endswith("err(%)")]
    print(tab[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    return 0


# --------------------------------------------------------------------------- sensitivity


def cmd_sensitivity(args) -> int:
    from . import sensitivity_report as sr
    from .output import StagedOutput

    modes = [bool(args.trials), args.paper_figures, args.crb_vs_mc is not None, args.design]
    if sum(modes) != 1:
        raise InputError("mmg sensitivity", "arguments", "give trial YAMLs, or exactly one of --paper-figures, "
                                                          "--crb-vs-mc DIR, --design")
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
        cluster = LocalCluster(n_workers=args.jobs or 2, processes=True, threads_per_worker=1)
        client = Client(cluster)
    try:
        with StagedOutput(args.out) as stage:
            if args.trials:
                sr.trial_sensitivities(args.trials, stage, fisher_bounds=args.fisher, backend=args.backend,
                                       n_jobs=args.jobs)
            elif args.paper_figures:
                sr.paper_figures(stage, args.ekf_comparison, backend=args.backend, n_jobs=args.jobs)
            elif args.crb_vs_mc is not None:
                sr.crb_table(args.crb_vs_mc, stage, n_seeds=args.mc_seeds, rudder_timing=args.rudder_timing)
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

    if args.summarise_only:
        import pandas as pd

        print("\n".join(group_table(pd.read_csv(Path(args.out) / "summary.csv"))))
        return 0
    monte_carlo(args.out, n_seeds=args.seeds, n_jobs=args.jobs, first_seed=args.first_seed, config=args.config)
    return 0


def cmd_log_filter(args) -> int:
    from .montecarlo import log_filter_monte_carlo

    sigma = args.sigma_tau if args.sigma_tau is not None else (1e-4 if args.true_rudder else 0.15)
    log_filter_monte_carlo(args.out, n_seeds=args.seeds, trials=args.trials, n_jobs=args.jobs, sigma_tau=sigma,
                           first_seed=args.first_seed, rudder="true" if args.true_rudder else "rebuilt",
                           config=args.config)
    return 0


def cmd_output_error(args) -> int:
    from .montecarlo import PAPER_TRIALS, output_error_monte_carlo, summarise

    for t in args.trials:
        if t not in PAPER_TRIALS:
            raise InputError("--trials", t, f"not one of {', '.join(PAPER_TRIALS)}")
    if args.summarise_only:
        summarise(args.out, tuple(args.trials), args.rudder, args.ekf_summary)
    else:
        output_error_monte_carlo(args.out, args.seeds, tuple(args.trials), n_jobs=args.jobs, first_seed=args.first_seed,
                                 rudder=args.rudder, ekf_summary=args.ekf_summary, config=args.config)
    return 0


# --------------------------------------------------------------------------- parser


def build_parser() -> argparse.ArgumentParser:
    """The ``mmg`` argument parser (every subcommand)."""
    ap = _Parser(prog="mmg", description="MMG ship manoeuvring: simulate, analyse, identify.")
    ap.add_argument("--version", action="version", version=f"mmg-toolkit {_version()}")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)

    p = sub.add_parser("simulate", help="simulate a trial from its YAML config")
    p.add_argument("config", help="trial YAML (configs/trials/*.yaml) or a bundled trial name (st35, zz20, ...)")
    p.add_argument("--out", required=True, help="output folder (log.csv, truth.csv, metrics.json, PNGs)")
    p.add_argument("--show", action="store_true", help="also show the figures on screen")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("metrics", help="manoeuvre metrics from a log (project log, truth file or FRT-DS-ESSO CSV)")
    p.add_argument("log")
    p.add_argument("--kind", choices=["turning", "zigzag", "stype"], help="override the manoeuvre kind")
    p.add_argument("--length", type=_finite_positive, help="ship length L [m] when the log does not say")
    p.add_argument("--zigzag-angle", type=_finite_positive,
                   help="switching heading [deg] for a zigzag log without rudder")
    p.add_argument("--json", help="also write the metrics to this JSON file")
    p.set_defaults(func=cmd_metrics)

    p = sub.add_parser("reproduce", help="the main job: reproduce the papers on the default Esso Osaka configs")
    p.add_argument("--out", default="out", help="output folder (default: out)")
    p.add_argument("--full", action="store_true",
                   help="also the Monte Carlo runs (EKF and output error, 20 seeds) and the full Nomoto Table 8 (~25 min)")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser("nomoto", help="identify 1st/2nd-order Nomoto K, T (T1, T2, T3) from a zigzag log")
    p.add_argument("log", help="zigzag record (project log/truth CSV or FRT-DS-ESSO CSV)")
    p.add_argument("--length", type=float, required=True, help="ship length L [m]")
    p.add_argument("--speed", type=float, help="speed U [m/s] for s' = tU/L (default: mean approach speed)")
    p.add_argument("--json", help="write results to this JSON file (plot PNG next to it)")
    p.add_argument("--no-output-error", action="store_true", help="skip the output-error fit")
    p.set_defaults(func=cmd_nomoto)

    p = sub.add_parser("nomoto-paper", help="reproduce Artyszuk (2018) Tables 1-8 (CSV + Markdown)")
    p.add_argument("--out", default="out/nomoto-paper", help="output folder")
    p.add_argument("--fast", action="store_true", help="skip the output-error fits of the extended Table 8")
    p.set_defaults(func=cmd_nomoto_paper)

    p = sub.add_parser("estimate", help="estimate the ship's sway/yaw hull coefficients from trial logs (augmented EKF)")
    p.add_argument("inputs", nargs="+", metavar="LOG_OR_TRIAL.yaml",
                   help="project logs (log.csv) or trial YAMLs / bundled trial names (simulated first)")
    p.add_argument("--out", required=True, help="output folder")
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

    p = sub.add_parser("sensitivity", help="derivative sensitivities (Rhee & Kim eqs. 21-22), Fisher information, "
                                           "trial design")
    p.add_argument("trials", nargs="*", help="trial YAMLs to compare (their sensitivities are normalised together)")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--paper-figures", action="store_true", help="Rhee & Kim Figs 2, 8-9, 12, 13, 14 and 28 in one go")
    p.add_argument("--ekf-comparison", help="comparison.csv of the EKF reproduction for Fig. 28 (default: run it)")
    p.add_argument("--fisher", action="store_true", help="also write the Cramer-Rao bounds of the given trials")
    p.add_argument("--crb-vs-mc", metavar="MC_DIR", nargs="+",
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

    def mc_common(p, what):
        p.add_argument("out", help="output folder (runs.csv, summary.csv/.md)")
        p.add_argument("--seeds", type=_positive_int, default=20, help="noise seeds per trial (default 20)")
        p.add_argument("--first-seed", type=_seed, default=1000, help="noise seed of the first run of each trial")
        p.add_argument("--jobs", type=_positive_int, default=2, help="workers (default 2)")
        p.add_argument("--config", default=None, help=f"estimation YAML for the {what}")

    p = sub.add_parser("montecarlo", help="Monte Carlo of the paper EKF over noise seeds (ST35, ZZ10, ZZ20, S-type 120)")
    mc_common(p, "EKF")
    p.add_argument("--summarise-only", action="store_true", help="print the group table of OUT/summary.csv, no runs")
    p.set_defaults(func=cmd_montecarlo)

    p = sub.add_parser("log-filter", help="Monte Carlo of the EKF on the raw 5 s log (near the Cramer-Rao bound)")
    mc_common(p, "raw-log EKF")
    p.add_argument("--trials", nargs="*", default=None,
                   help="trial names (default ST35 ZZ10 ZZ20 'S-type 120') or turning/zigzag/S-type trial YAMLs")
    p.add_argument("--sigma-tau", type=_finite_positive, default=None,
                   help="prior std [s] of each rudder movement's timing (default 0.15, or 1e-4 with --true-rudder)")
    p.add_argument("--true-rudder", action="store_true",
                   help="give the filter the truth file's rudder instead of the rebuilt one (a check against the CRB "
                        "with the rudder known)")
    p.set_defaults(func=cmd_log_filter)

    p = sub.add_parser("output-error", help="Monte Carlo of the joint output-error fit (EKF start) over noise seeds")
    mc_common(p, "EKF start and the fit")
    p.add_argument("--trials", nargs="+", default=["ST35", "ZZ10", "ZZ20", "S-type 120"],
                   help="trial names (ST35 ZZ10 ZZ20 'S-type 120')")
    p.add_argument("--rudder", choices=("ramp", "law", "reconstructed"), default="ramp")
    p.add_argument("--ekf-summary", default=None,
                   help="summary.csv of 'mmg montecarlo' (per-trial EKF) to show beside the table")
    p.add_argument("--summarise-only", action="store_true", help="rewrite the table from OUT/runs.csv, no runs")
    p.set_defaults(func=cmd_output_error)
    return ap


def _on_sigterm(signum, frame):
    raise Interrupted()


def main(argv=None) -> int:
    """Run the ``mmg`` command; returns the exit status (see the module docstring)."""
    ap = build_parser()
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:            # --help, --version (0) and bad arguments (2, one usage line)
        return int(e.code or 0)
    if not getattr(args, "show", False):
        os.environ.setdefault("MPLBACKEND", "Agg")   # files only; no display needed (cheap: nothing imported)
    old = signal.signal(signal.SIGTERM, _on_sigterm) if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, None) else None
    try:
        return int(args.func(args) or 0)
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except Interrupted:
        print("interrupted", file=sys.stderr)
        return 143
    except Exception as e:  # a diverging filter is a result, not a crash
        from ekf.filter import FilterDivergence

        if isinstance(e, FilterDivergence):
            print(f"error: {e}", file=sys.stderr)
            return 3
        raise
    finally:
        if old is not None:
            signal.signal(signal.SIGTERM, old)


if __name__ == "__main__":
    sys.exit(main())
