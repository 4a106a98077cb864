"""``mmg reproduce``: the main job, the papers reproduced (:func:`trials.papers.reproduce.reproduce`)."""
from __future__ import annotations

from .common import _output_path


def cmd_reproduce(args) -> int:
    from ..files.output import StagedOutput, check_output_dir
    from ..papers.reproduce import reproduce

    check_output_dir(args.out)
    with StagedOutput(args.out) as stage:         # the whole report or nothing
        rep = stage.final(reproduce(stage.dir, full=args.full))
    print(f"report: {rep}")
    return 0


def add_parser(sub) -> None:
    """The reproduce subcommand of ``mmg`` (its options, help and function)."""
    p = sub.add_parser("reproduce", help="the main job: reproduce the papers on the default Esso Osaka configs")
    p.add_argument("--out", default="out", type=_output_path, help="output folder (default: out)")
    p.add_argument("--full", action="store_true",
                   help="also the Monte Carlo runs (EKF and output error, 20 seeds) and the full Nomoto Table 8 (~25 min)")
    p.set_defaults(func=cmd_reproduce)
