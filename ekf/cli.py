"""``mmg estimate``: hull derivatives from sea-trial logs with the augmented EKF (Rhee & Kim 1999).

    mmg estimate LOG_OR_TRIAL.yaml [...] --out DIR [--seed N] [--config FILE] [--set key=value]

Each input is a project log (``log.csv``) or a trial YAML (simulated first with the noise
seed ``--seed``; the truth is then known).  Writes ``estimates.json``, ``error_table.csv``
and ``.md`` (Table 10 layout), ``final_estimates.csv``, ``convergence_<name>.png`` (all
trials on one figure per derivative) and, when the truth is known, the preprocessing
comparison figures and their RMS.  Bad input: one line, exit 2; a diverging filter: one
line naming the trial and the time, exit 3, nothing written.
"""
from __future__ import annotations

import sys
from pathlib import Path

from mmg.errors import InputError


def _is_trial_yaml(path: str) -> bool:
    return Path(path).suffix.lower() in (".yaml", ".yml")


def cmd_estimate(args) -> int:
    from trials.cli import StagedOutput

    from .estimate import data_from_log, data_from_trial, estimate, load_config, write_reports
    from .filter import FilterDivergence

    cfg = load_config(args.config, args.set or ())
    if args.truth and len(args.inputs) != 1:
        raise InputError("--truth", "", "give --truth with a single log only")
    try:
        rep = _run(args, cfg, StagedOutput, data_from_log, data_from_trial, estimate, write_reports)
    except FilterDivergence as e:
        print(f"error: {e}", file=sys.stderr)
        return 3
    _print(args, rep)
    return 0


def _run(args, cfg, StagedOutput, data_from_log, data_from_trial, estimate, write_reports):
    with StagedOutput(args.out) as out:
        datas = []
        for i, path in enumerate(args.inputs):
            if not Path(path).exists():
                raise InputError(path, "", "file not found")
            if _is_trial_yaml(path):
                wd = out.path(f"trials/{i}_{Path(path).stem}/x").parent
                datas.append(data_from_trial(path, cfg, seed=args.seed, workdir=wd))
            else:
                datas.append(data_from_log(path, cfg, ship_path=args.ship, truth_path=args.truth))
        names = [d.name for d in datas]
        if len(set(names)) != len(names):
            raise InputError(args.inputs[0], "trial", f"two inputs have the same trial name ({names})")
        ests = [estimate(d, cfg) for d in datas]
        if args.joint and len(datas) > 1:
            from .estimate import joint_estimate
            ests.append(joint_estimate(datas, cfg, name="joint"))
        rep = write_reports(ests, out, plots=not args.no_plots)
    return rep


def _print(args, rep) -> None:
    tab = rep["table"]
    with_pct = [c for c in tab.columns if c.endswith("err(%)")]
    print(f"wrote {args.out}/estimates.json, error_table.csv/.md, convergence_*.png")
    if rep["rms"]:
        for n, r in rep["rms"].items():
            print(f"  preprocessing RMS {n}: " + ", ".join(f"{k} {v:.3g}" for k, v in r.items()))
    cols = ["coeff", "real"] + [c for c in tab.columns if c.endswith("final")] + with_pct
    print(tab[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))


def register(subparsers) -> None:
    p = subparsers.add_parser("estimate", help="estimate the 12 hull derivatives from trial logs (augmented EKF, Rhee & Kim)")
    p.add_argument("inputs", nargs="+", metavar="LOG_OR_TRIAL.yaml",
                   help="project logs (log.csv) or trial YAMLs (simulated first)")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--seed", type=int, default=None, help="noise seed for simulated trials (default: the trial's)")
    p.add_argument("--config", default=None, help="estimation YAML overriding configs/estimation/rhee_kim.yaml")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override one config value, e.g. initial.scale=1.5 or R.ZZ20.u=0.1 (repeatable)")
    p.add_argument("--ship", default=None, help="ship YAML for logs (default: configs/ships/esso_osaka.yaml)")
    p.add_argument("--truth", default=None, help="truth.csv of a simulated log (enables true values and errors)")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    p.add_argument("--joint", action="store_true",
                   help="also one joint estimate running through all inputs in turn (column 'joint')")
    p.set_defaults(func=cmd_estimate)
