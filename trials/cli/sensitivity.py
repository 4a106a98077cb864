"""``mmg sensitivity``: sensitivities, Cramer-Rao bounds, trial design (:mod:`trials.planning.sensitivity_report`)."""
from __future__ import annotations

import time
from pathlib import Path

from mmg.errors import InputError

from .common import _output_path, _positive_int, _rudder_timing, backend_client, check_backend_options


def cmd_sensitivity(args) -> int:
    from contextlib import ExitStack

    from ..planning import sensitivity_report as sr
    from ..files.output import StagedOutput, check_output_dir

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
    check_backend_options(args)
    t0 = time.perf_counter()
    with backend_client(args):
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
    print(f"wrote {args.out} ({time.perf_counter() - t0:.1f} s)")
    return 0


def add_parser(sub) -> None:
    """The sensitivity subcommand of ``mmg`` (its options, help and function)."""
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
                   help="with --crb-vs-mc or --design: prior std (a time, '0.15 s'; a bare number in s) of the "
                        "per-movement rudder-timing nuisances of the "
                        "second log bound (default 0.15, the raw-log EKF's; 'inf' no prior; 'none' leaves that bound out)")
    p.add_argument("--design", action="store_true", help="trial-design search (S-type psi_S, zigzag angles)")
    p.add_argument("--backend", choices=["serial", "loky", "threads", "dask"], default="loky",
                   help="parallel backend of the sweeps (dask: --scheduler's cluster or a local one; optional extra)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="with --backend dask: a running dask scheduler (tcp://host:8786); default a local cluster")
    p.add_argument("--jobs", type=_positive_int, default=None, help="workers (default: all cores)")
    p.set_defaults(func=cmd_sensitivity)
