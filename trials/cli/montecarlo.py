"""``mmg montecarlo``, ``mmg log-filter`` and ``mmg output-error``: the estimators' Monte Carlo over noise
seeds (:mod:`trials.estimates.montecarlo`)."""
from __future__ import annotations

from pathlib import Path

from mmg.errors import InputError

from .common import _output_path, _positive_int, _seed, backend_client, check_backend_options, quantity


def cmd_montecarlo(args) -> int:
    from ..estimates.montecarlo import group_table, monte_carlo
    from ..files.output import StagedOutput, check_output_dir

    if args.summarise_only:              # reads only
        import pandas as pd

        summary = Path(args.out) / "summary.csv"
        if not summary.is_file():
            raise InputError(str(summary), "", "file not found (mmg montecarlo OUT writes it)")
        print("\n".join(group_table(pd.read_csv(summary))))
        return 0
    check_backend_options(args)
    check_output_dir(args.out, "OUT")
    with backend_client(args), StagedOutput(args.out) as stage:
        monte_carlo(stage.dir, n_seeds=args.seeds, n_jobs=args.jobs, first_seed=args.first_seed, config=args.config,
                    backend=args.backend)
    return 0


def cmd_log_filter(args) -> int:
    from ..estimates.montecarlo import log_filter_monte_carlo
    from ..files.output import StagedOutput, check_output_dir

    check_backend_options(args)
    check_output_dir(args.out, "OUT")
    sigma = args.sigma_tau if args.sigma_tau is not None else (1e-4 if args.true_rudder else 0.15)
    with backend_client(args), StagedOutput(args.out) as stage:
        runs = log_filter_monte_carlo(stage.dir, n_seeds=args.seeds, trials=args.trials, n_jobs=args.jobs,
                                      sigma_tau=sigma, first_seed=args.first_seed,
                                      rudder="true" if args.true_rudder else "rebuilt", config=args.config,
                                      backend=args.backend)
    print(runs_line(runs, Path(args.out) / "runs.csv"))
    return 0


def runs_line(runs, path) -> str:
    """The console's line of a Monte Carlo that writes runs alone: how many runs of how many trials, and how
    many diverged (a run with a ``diverged`` message), so a run that failed is not silent."""
    n = len(runs)
    bad = int(runs["diverged"].fillna("").astype(str).str.strip().ne("").sum()) if "diverged" in runs else 0
    trials = runs["trial"].nunique() if "trial" in runs else 0
    return (f"wrote {path}: {n} run(s) of {trials} trial(s), {bad} diverged (each row: the final estimates and "
            f"their % errors; no summary table)")


def cmd_output_error(args) -> int:
    import shutil

    from ..estimates.montecarlo import PAPER_TRIALS, output_error_monte_carlo, summarise
    from ..files.output import StagedOutput, check_output_dir

    for t in args.trials:
        if t not in PAPER_TRIALS:
            raise InputError("--trials", t, f"not one of {', '.join(PAPER_TRIALS)}")
    runs = Path(args.out) / "runs.csv"
    if args.summarise_only and not runs.is_file():
        raise InputError(str(runs), "", "file not found (mmg output-error OUT writes it)")
    check_backend_options(args)
    check_output_dir(args.out, "OUT")
    ekf_summary = args.ekf_summary
    with backend_client(args), StagedOutput(args.out) as stage:
        if args.summarise_only:          # the summary from a copy of runs.csv, moved in with it
            shutil.copy2(runs, stage.path("runs.csv"))
            summarise(stage.dir, tuple(args.trials), args.rudder, ekf_summary)
        else:
            output_error_monte_carlo(stage.dir, args.seeds, tuple(args.trials), n_jobs=args.jobs,
                                     first_seed=args.first_seed, rudder=args.rudder, ekf_summary=ekf_summary,
                                     config=args.config, backend=args.backend)
    return 0


def add_parser(sub) -> None:
    """The montecarlo, log-filter and output-error subcommands of ``mmg`` (its options, help and function)."""
    def mc_common(p, what, files="runs.csv, summary.csv/.md"):
        p.add_argument("out", type=_output_path, help=f"output folder ({files})")
        p.add_argument("--seeds", type=_positive_int, default=20, help="noise seeds per trial (default 20)")
        p.add_argument("--first-seed", type=_seed, default=1000, help="noise seed of the first run of each trial")
        p.add_argument("--jobs", type=_positive_int, default=2, help="workers (default 2)")
        p.add_argument("--config", default=None, help=f"estimation YAML for the {what}")
        p.add_argument("--backend", choices=("serial", "loky", "dask"), default="loky",
                       help="where the seeds run: serial, loky (local processes, default) or dask (--scheduler's "
                            "cluster, or a local one of --jobs workers; optional extra mmg-toolkit[dask])")
        p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="with --backend dask: a running dask scheduler (tcp://host:8786)")

    p = sub.add_parser("montecarlo", help="Monte Carlo of the paper EKF over noise seeds (ST35, ZZ10, ZZ20, S-type 120)")
    mc_common(p, "EKF")
    p.add_argument("--summarise-only", action="store_true", help="print the group table of OUT/summary.csv, no runs")
    p.set_defaults(func=cmd_montecarlo)

    p = sub.add_parser("log-filter", help="Monte Carlo of the EKF on the raw 5 s log (near the Cramer-Rao bound)")
    mc_common(p, "raw-log EKF", "runs.csv")
    p.add_argument("--trials", nargs="*", default=None,
                   help="trial names (default ST35 ZZ10 ZZ20 'S-type 120') or turning/zigzag/S-type trial YAMLs")
    p.add_argument("--sigma-tau", type=quantity("time", "s", 0.0, lo_open=True), default=None,
                   help="prior std of each rudder movement's timing with its unit ('0.15 s'), a bare number in s "
                        "(default 0.15 s, or 1e-4 s with --true-rudder)")
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
