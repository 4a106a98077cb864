"""``mmg estimate``: hull coefficients from logs or trials (:func:`trials.estimates.estimation.estimate_and_report`)."""
from __future__ import annotations

import math
import sys

from .common import _listing, _output_path, _seed


def _aot_deferred(when: bool):
    """mmg._aot.build_deferred() when ``when``, else nothing."""
    from contextlib import nullcontext

    from mmg import _aot

    return _aot.build_deferred() if when else nullcontext()


PREPROCESSING_UNITS = {"u": (1.0, "m/s"), "v": (1.0, "m/s"), "r": (180 / math.pi, "deg/s"),
                       "delta": (180 / math.pi, "deg"), "n": (1.0, "rps")}
"""Factor from SI and unit of each channel of ``preprocessing_rms.json`` on the console."""


def preprocessing_rms_text(name: str, rms: dict) -> str:
    """The console line of a trial's preprocessing RMS ({channel: RMS in SI}), each with its unit."""
    parts = []
    for k, v in rms.items():
        f, unit = PREPROCESSING_UNITS.get(k, (1.0, "(SI)"))
        parts.append(f"{k} {f * v:.3g} {unit}")
    return f"  preprocessing RMS {name} (recovered - true): " + ", ".join(parts)


def cmd_estimate(args) -> int:
    from ekf.estimate import load_config

    from ..estimates.estimation import estimate_and_report, load_inputs
    from ..files.output import StagedOutput, check_output_dir

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
        print(preprocessing_rms_text(n, r))
    cols = [c for c in tab.columns if c in ("coeff", "real") or c.endswith("final") or c.endswith("err(%)")]
    print(tab[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    return 0


def add_parser(sub) -> None:
    """The estimate subcommand of ``mmg`` (its options, help and function)."""
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
