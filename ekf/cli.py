"""``mmg estimate``: hull derivatives from sea-trial logs with the augmented EKF (Rhee & Kim 1999).

    mmg estimate LOG_OR_TRIAL.yaml [...] --out DIR [--seed N] [--config FILE] [--set key=value]
    mmg estimate st35.yaml zz10.yaml zz20.yaml stype120.yaml --method output-error --out DIR

``--method output-error``: the joint EKF over all inputs, then the joint output-error fit of the
raw logs (:mod:`ekf.output_error`; zigzag/S-type reversal times as continuous nuisance
parameters); ``estimates.json`` then holds that one joint estimate per derivative (``estimate``,
``true``, ``error_pct``, plus ``std_error`` from (J^T W J)^-1 and ``ekf_start``), ``oe_fit.json``
the fit's chi2/dof and nuisances, and ``error_table.csv``/``.md`` the table (no figures).

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
        if getattr(args, "method", "ekf") == "output-error":
            return _run_output_error(datas, cfg, out)
        ests = [estimate(d, cfg) for d in datas]
        for e in ests:
            for w in e.warnings():
                print(f"warning: {w}", file=sys.stderr)
        if args.joint and len(datas) > 1:
            from .estimate import joint_estimate
            ests.append(joint_estimate(datas, cfg, name="joint"))
        rep = write_reports(ests, out, plots=not args.no_plots)
    return rep


def _run_output_error(datas, cfg, out) -> dict:
    import json

    from .estimate import error_table, estimates_json, to_markdown
    from .filter import DERIVATIVES
    from .output_error import OEEstimate, refine

    ekf, res = refine(datas, cfg, verbose=True)
    name = "output-error" if len(datas) == 1 else "output-error joint"
    est = OEEstimate(datas[0], res, name)
    js = estimates_json([est])
    for n in DERIVATIVES:
        js[n]["std_error"] = res.std_errors[n]
        if ekf is not None:
            js[n]["ekf_start"] = ekf[n]
    with open(out.path("estimates.json"), "w") as fh:
        json.dump(js, fh, indent=2)
    fit = {"method": "output-error", "trials": list(res.trials), "chi2_per_dof": res.chi2_per_dof,
           "cost": res.cost, "residuals": res.nres, "nfev": res.nfev, "seconds": res.seconds, "status": res.status,
           "nuisance": {t: {"v0": float(nu[0]), "psi0": float(nu[1]), "x0": float(nu[2]), "y0": float(nu[3]),
                            "reversal_times_s": [float(v) for v in nu[4:]]} for t, nu in zip(res.trials, res.nuisance)}}
    with open(out.path("oe_fit.json"), "w") as fh:
        json.dump(fit, fh, indent=2)
    tab = error_table([est])
    tab[f"{name} std err"] = [res.std_errors[n] for n in DERIVATIVES]
    if ekf is not None:
        tv = datas[0].true_values
        tab["EKF start"] = [ekf[n] for n in DERIVATIVES]
        if tv:
            tab["EKF start err(%)"] = [100.0 * abs(ekf[n] - tv[n]) / abs(tv[n]) for n in DERIVATIVES]
    tab.to_csv(out.path("error_table.csv"), index=False, float_format="%.6g")
    out.path("error_table.md").write_text(to_markdown(tab))
    print(f"output error over {', '.join(res.trials)}: chi2/dof {res.chi2_per_dof:.3f}, {res.seconds:.0f} s")
    return {"table": tab, "rms": {}, "method": "output-error"}


def _print(args, rep) -> None:
    tab = rep["table"]
    if rep.get("method") == "output-error":
        print(f"wrote {args.out}/estimates.json, oe_fit.json, error_table.csv/.md")
        print(tab.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        return
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
    p.add_argument("--method", choices=("ekf", "output-error"), default="ekf",
                   help="ekf: the augmented EKF per input (default); output-error: joint EKF then the joint "
                        "output-error fit of the raw logs over all inputs (ekf.output_error)")
    p.set_defaults(func=cmd_estimate)
