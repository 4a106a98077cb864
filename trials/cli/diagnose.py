"""``mmg diagnose``: name the effect the model is missing (:func:`trials.measured.diagnose.diagnose`)."""
from __future__ import annotations

import math
import sys
from pathlib import Path

from mmg.errors import InputError

from .common import _output_path, add_backend_options, backend_client, check_backend_options, release_notes


def cmd_diagnose(args) -> int:
    from contextlib import nullcontext

    from mmg.resources import ship_path
    from mmg.ship import load_ship

    from ..measured.diagnose import diagnose, prepare
    from ..measured.diagnose.rules import rules
    from ..files.output import StagedFile, StagedOutput, check_output_dir, check_output_file, dumps_json

    rules()                                              # a bad rules file (MMG_DIAGNOSE_RULES): refused first
    check_backend_options(args)
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
    release_notes()                                      # accepted: their notes, then the progress
    say = lambda m: print(m, file=sys.stderr, flush=True)  # noqa: E731
    with backend_client(args) as client:
        d = diagnose(ship, recs, wind=wind, per_run=len(recs) > 1, say=say,
                     backend=args.backend, client=client, n_jobs=args.jobs)
    text = dumps_json(d.to_json())
    ship_text = None
    if args.out_ship is not None:
        from ..measured.identify import ship_yaml

        note = (f"mmg diagnose over {len(recs)} record(s): named {', '.join(d.named) or 'nothing'}; "
                + "; ".join(f"{e} " + ", ".join(f"{k} = {v:.4g}" for k, v in p.items()) for e, p in d.parameters.items())
                + "".join(f"; {x['effect']} reported model_form_mismatch (fitted beside these coefficients, not "
                          f"written: {x['reason'].split(':')[0]})" for x in d.model_form_effects)
                + ". The named effects are in the effects: section, so mmg predict with this config replays these "
                  "records with them; a current, a rudder offset or a heading bias belongs to these records, not the "
                  "ship: for other trials move it to their trial config's effects: section")
        ship_text = ship_yaml(src, d.ship_fit_values, note)
        import yaml

        head, body = [], []
        for ln in ship_text.splitlines(keepends=True):
            (head if ln.startswith("#") and not body else body).append(ln)
        data = yaml.safe_load("".join(body))
        if d.parameters:
            eff = dict(data.get("effects") or {})
            for e, p in d.parameters.items():
                eff[e] = {k: float(f"{v:.6g}") for k, v in p.items() if math.isfinite(v)}
            if "wind" in eff and data.get("wind") is not None:
                for k in ("scale", "sway_factor", "yaw_factor"):  # the scale and shape are the effect's now
                    data["wind"].pop(k, None)
                data["wind"]["enabled"] = True             # (effects.wind with enabled: false is refused)
            data["effects"] = eff
        ship_text = "".join(head) + yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    with StagedFile(args.json) as tmp:         # the files first, then the console
        with StagedFile(args.out_ship) if args.out_ship is not None else nullcontext() as tship:
            with StagedOutput(args.plots) if args.plots is not None else nullcontext() as stage:
                if args.plots is not None:
                    from ..measured.diagnose.plots import diagnose_figure, diagnose_summary_figure

                    for i, r in enumerate(d.records):       # named after their files (unique: prepare)
                        diagnose_figure(d, i).savefig(stage.path(f"{r.name}.png"))
                    diagnose_summary_figure(d).savefig(stage.path("diagnosis_summary.png"))
            if tship is not None:
                tship.write_text(ship_text)
        tmp.write_text(text)
    for line in d.summary_lines():
        print(line)
    print(f"wrote {args.json}" + (f", {args.out_ship}" if args.out_ship is not None else "") +
          (f" and {len(d.records)} plot(s) and diagnosis_summary.png to {args.plots}" if args.plots is not None else ""))
    return 0


def add_parser(sub) -> None:
    """The diagnose subcommand of ``mmg`` (its options, help and function)."""
    p = sub.add_parser("diagnose", help="find where the model and the records disagree, name the missing effect "
                                        "(current, wind, rudder_offset, heading_bias, shallow_water) and show the gap shrink")
    p.add_argument("logs", nargs="+", metavar="LOG", help="FRT-DS-ESSO CSVs, project logs or truth files")
    p.add_argument("--ship", required=True, help="ship YAML or bundled name (esso_osaka_3m, esso_osaka, ...)")
    p.add_argument("--json", required=True, type=_output_path, help="write the diagnosis to this JSON file")
    p.add_argument("--plots", default=None, metavar="DIR", type=_output_path,
                   help="also one figure per record, DIR/<name>.png (<name>: the record's file name, as for predict), "
                        "and DIR/diagnosis_summary.png (manoeuvre, residuals, fitted values with 95 %% intervals)")
    p.add_argument("--out-ship", default=None, metavar="NEW.yaml", type=_output_path,
                   help="write the ship config with the fitted coefficients (and a named wind scale)")
    p.add_argument("--wind", choices=("on", "off"), default=None,
                   help="wind loads in the model from the start (default off: wind is then a candidate effect)")
    add_backend_options(p, "the per-record diagnoses of several logs (JSON runs)")
    p.set_defaults(func=cmd_diagnose)
