"""The main job: reproduce the papers on the default Esso Osaka configs.

:func:`reproduce` (``mmg reproduce --out DIR``) writes ``DIR/report.md`` and, beside it, every
file the report links to; it prints one progress line per section and returns the report's
path.  The report, in order:

1. the steady straight run (rpm beside the paper's 54.12 rpm, trim rudder, drift);
2. the Kijima formulas beside Table 2;
3. every default trial in ``configs/trials`` (log, truth, metrics, figures in DIR/trials/NAME);
4. the plausibility table: our ST35, ZZ10, ZZ20 against the IMO criteria and the
   3 m Esso Osaka model's measured turning metrics (computed here from the
   FRT-DS-ESSO files when :func:`trials.files.data.frt_folder` finds them);
5. step convergence and port/starboard symmetry checks;
6. the Nomoto models and their identification (Artyszuk 2018, Tables 1-8);
7. the EKF reproduction (Rhee & Kim 1999, Tables 9-10);
8. the sensitivity figures (Rhee & Kim Figs 2, 8-9, 12, 13, 14 and 28);
9. beyond the paper: the joint output-error estimate over the four trials;
   with ``full`` also the Monte Carlo of the EKF and of the output-error fit over
   20 noise seeds (about 20 minutes on 2 cores), the full extended Nomoto Table 8, and
   the Monte Carlo of the raw-log EKF beside the Cramer-Rao bounds (about 3 minutes).
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from mmg.integrate import CommandLaw
from mmg.kijima import compare
from mmg.resources import trial_path
from mmg.simulation import prepare, simulate
from mmg.units import DEG, KNOT

from ..analysis.metrics import imo_criteria, record_metrics, turning_metrics
from ..files.data import frt_folder
from ..files.output import StagedOutput, fmt, numerical_zeros, write_trial_outputs
from ..runs.run import run_trial
from ..runs.trial import load_trial

DEFAULT_TRIALS = ("st35", "zz10", "zz20", "stype60", "stype90", "stype120", "stype180", "sine", "sawtooth")

GLOSSARY = """## Symbols and terms

| symbol | meaning |
|---|---|
| L, B, T | ship length between perpendiculars, breadth, draught [m] |
| U, u, v, r | speed through the water, surge and sway velocity [m/s], yaw rate [rad/s] |
| beta | drift angle atan(-v/u) [rad], > 0 in a starboard turn |
| r' | non-dimensional yaw rate r L / U |
| Y_beta, N_r, ... | primed hull derivatives (forces on 1/2 rho L T U^2, moments on 1/2 rho L^2 T U^2) |
| Y_bb, N_bb | Y'_{beta\\|beta\\|}, N'_{beta\\|beta\\|}: coefficients of beta \\|beta\\| |
| Y_rr, N_rr | Y'_{r\\|r\\|}, N'_{r\\|r\\|}: coefficients of r' \\|r'\\| |
| Y_bbr, Y_brr, N_bbr, N_brr | coefficients of beta^2 r' and beta r'^2 |
| s' | non-dimensional time t U / L |
| ST35, ZZ10, ZZ20 | 35 deg turning circle; 10/10 and 20/20 deg zigzags |
| S-type 120 | Rhee & Kim's S-type trial switching at a heading change of 120 deg |
| advance, transfer, tactical D | IMO turning-circle measures, in ship lengths L |
| overshoot (OS) | heading beyond the switching heading after each rudder reversal of a zigzag [deg] |
| speed loss | 1 - U_end / U_0 over the turn |
| K, T (T1, T2, T3) | Nomoto gain [1/s] and time constants [s] (first / second order) |
| CRB | Cramer-Rao bound: the smallest standard deviation any unbiased estimator can reach |
| EKF | extended Kalman filter; "augmented": the derivatives are states |
| chi2/dof | weighted residual sum over its degrees of freedom (about 1 when the fit is noise-limited) |
"""


def progress(msg: str) -> None:
    """One progress line on stdout (not in the report)."""
    print(f"  {msg}", flush=True)


class Report:
    """The report being written: ``doc(text)`` appends a paragraph (a blank line joins the parts)."""

    def __init__(self):
        self.parts: list[str] = []

    def __call__(self, text: str = "") -> None:
        self.parts.append(str(text))

    def text(self) -> str:
        out = "\n".join(self.parts)
        while "\n\n\n" in out:
            out = out.replace("\n\n\n", "\n\n")
        return out.rstrip() + "\n"


def demote(md: str, levels: int = 1, drop_title: bool = False) -> str:
    """Markdown headings moved ``levels`` deeper (an embedded document's '#' becomes '##', ...)."""
    out = []
    for ln in md.splitlines():
        if ln.startswith("#"):
            if drop_title and ln.startswith("# "):
                continue
            ln = "#" * levels + ln
        out.append(ln)
    return "\n".join(out)


def table(rows, cols, headers=None) -> str:
    """A Markdown table of dict rows (numbers to 4 significant digits, numerical zeros of a column as 0
    (:func:`trials.files.output.numerical_zeros`), None as '-')."""
    headers = headers or cols
    columns = {c: numerical_zeros([r.get(c) for r in rows]) for c in cols}
    out = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(cols)]
    for i in range(len(rows)):
        cells = (columns[c][i] if isinstance(columns[c][i], str) else fmt(columns[c][i]) for c in cols)
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def straight_run_section(doc, ship):
    u0 = 10 * KNOT
    pk, eq = prepare(ship, u0)
    law = CommandLaw.schedule([0.0, 3000.0], [eq.delta, eq.delta])
    r = simulate(ship, law, 3000.0, 0.1, u0)
    free = simulate(ship, CommandLaw.schedule([0.0, 3000.0], [0.0, 0.0]), 3000.0, 0.1, u0, trim=False)
    doc("## 1. Steady straight run at 10 kn\n")
    doc(table([
        {"quantity": "approach rpm (solved)", "ours": eq.n * 60, "paper": 54.12},
        {"quantity": "trim rudder (deg, + starboard)", "ours": eq.delta / DEG, "paper": None},
        {"quantity": "drift angle beta (deg)", "ours": np.degrees(np.arctan(-eq.v / eq.u)), "paper": None},
        {"quantity": "K_Q scale to balance engine power", "ours": eq.K_Q_scale, "paper": None},
        {"quantity": "engine power P_0 (MW)", "ours": eq.power_W / 1e6, "paper": None},
        {"quantity": "trimmed: max |U - 10 kn| over 3000 s (kn)", "ours": float(np.max(np.abs(r.U - u0)) / KNOT), "paper": None},
        {"quantity": "trimmed: max |heading| over 3000 s (deg)", "ours": float(np.max(np.abs(r.psi)) / DEG), "paper": None},
        {"quantity": "rudder amidships, no trim: heading after 3000 s (deg)", "ours": float(free.psi[-1] / DEG), "paper": None},
        {"quantity": "rudder amidships, no trim: speed after 3000 s (kn)", "ours": float(free.U[-1] / KNOT), "paper": None},
    ], ["quantity", "ours", "paper"]))
    doc(f"\nThe paper prints two approach rpm for this one steady run: 54.12 (Table 4) and 54.21 (the filter's start, "
        f"Table 7). Ours, {eq.n * 60:.2f} rpm from balancing the surge equation (the paper's own recipe), is the "
        "second; the paper does not say why its two figures differ (0.17 %). The other rows have no value in the paper (round-off shows as 0).\n")


def kijima_section(doc, ship):
    doc("## 2. Kijima (1990) formulas vs Table 2\n")
    rows = compare(ship)
    doc(table(rows, ["coefficient", "kijima", "config", "difference_pct"],
                ["coefficient", "Kijima formula", "Table 2", "difference (%)"]))
    doc("\n" + kijima_note(rows) + "\n")


def printed_half_unit(v: float) -> float:
    """Half a unit in the last digit of ``v`` as a config prints it (its shortest repr): the rounding of a
    value the paper printed with those digits."""
    if v == 0 or not np.isfinite(v):
        return 0.0
    mant = repr(abs(float(v))).lower().split("e")[0]
    mant = mant.rstrip("0").rstrip(".") if "." in mant else mant
    digits = mant.replace(".", "").lstrip("0")
    exp = int(np.floor(np.log10(abs(v))))
    return 0.5 * 10.0 ** (exp - len(digits) + 1)


def kijima_note(rows) -> str:
    """Why the Kijima formulas and Table 2 differ: the rows within Table 2's rounding, and the others."""
    off = [r for r in rows if abs(r["kijima"] - r["config"]) > printed_half_unit(r["config"]) * (1 + 1e-9)]
    text = (f"{len(rows) - len(off)} of {len(rows)} differences are within half a unit of the last digit Table 2 "
            "prints: its rounding.")
    for r in off:
        if r["coefficient"] == "Y_r":
            text += (f" Y_r differs by {abs(r['kijima'] - r['config']):.2g}: it contains the added mass m_x', which the "
                     "paper does not print; the config's m_x' = 0.0200 rounds the 0.01998 that Table 2's Y_r implies.")
        else:
            text += f" {r['coefficient']} differs by {r['difference_pct']:.3g} %: not explained."
    return text


def trials_section(doc, out: Path):
    doc("## 3. Default trials\n")
    rows, runs = [], {}
    for name in DEFAULT_TRIALS:
        tr = load_trial(trial_path(name))
        run = run_trial(tr)
        with StagedOutput(out / "trials" / name) as stage:
            m = write_trial_outputs(run, stage)
        runs[name] = (run, m)
        rows.append({"trial": tr.name, **{k: m.get(k) for k in ("advance_L", "transfer_L", "tactical_diameter_L",
                     "steady_diameter_L", "speed_loss", "initial_turning_time_s", "period_s",
                     "final_heading_change_deg")},
                     "overshoots_deg": fmt(m.get("overshoots_deg", [])[:3], 1) if "overshoots_deg" in m else "-"})
    doc(table(rows, ["trial", "advance_L", "transfer_L", "tactical_diameter_L", "steady_diameter_L", "speed_loss",
                       "overshoots_deg", "initial_turning_time_s", "period_s", "final_heading_change_deg"],
                ["trial", "advance (L)", "transfer (L)", "tactical D (L)", "steady D (L)", "speed loss",
                 "overshoots 1-3 (deg)", "initial turning (s)", "period (s)", "heading change (deg)"]))
    doc("\nLogs, truth files, metrics.json and figures of each trial are in `trials/NAME/`: e.g. the ST35 "
        "[track](trials/st35/track.png) and [time histories](trials/st35/histories.png), the ZZ20 "
        "[track](trials/zz20/track.png) and [histories](trials/zz20/histories.png), the S-type 120 "
        "[track](trials/stype120/track.png).\n")
    return runs


def plausibility_section(doc, runs, ship):
    doc("## 4. Plausibility: IMO criteria and the 3 m model\n")
    L, U0 = ship.particulars.L, 10 * KNOT
    rows = imo_criteria(L, U0, runs["st35"][1], runs["zz10"][1], runs["zz20"][1])
    doc(table([{**r, "pass": "yes" if r["pass"] else ("no" if r["pass"] is False else "-")} for r in rows],
                ["criterion", "value", "limit", "pass"]))
    doc()
    st = runs["st35"][1]
    model_rows = [{"run": "ours, full scale, 10 kn, +35 deg", "U0": "10 kn", **{k: st.get(k) for k in
                   ("advance_L", "transfer_L", "tactical_diameter_L", "steady_diameter_L", "speed_loss")}}]
    frt = frt_folder()
    if frt is not None:
        # the three 35 deg turns at n = 10 rps (FRT-DS-ESSO README)
        for f in [frt / "turning" / f"turn_14-Sep-2020_{s}.csv" for s in ("13_39_32", "13_51_45", "14_16_04")]:
            from ..files.logio import read_record

            rec = read_record(f)
            m = record_metrics(rec, kind="turning", length=3.0)
            model_rows.append({"run": f"3 m model {f.stem} ({m['turn']})", "U0": f"{m['approach_speed_mps']:.2f} m/s",
                               **{k: m.get(k) for k in ("advance_L", "transfer_L", "tactical_diameter_L",
                                                         "steady_diameter_L", "speed_loss")}})
    else:
        doc("(FRT-DS-ESSO folder not found, see `MMG_FRT_DATA`: the 3 m model rows are left out)\n")
    doc(table(model_rows, ["run", "U0", "advance_L", "transfer_L", "tactical_diameter_L", "steady_diameter_L", "speed_loss"],
                ["run", "approach", "advance (L)", "transfer (L)", "tactical D (L)", "steady D (L)", "speed loss"]))
    doc("""
Expected differences: the 3 m model runs start from a still-accelerating approach at n = 10 rps
(Fn about 0.07, full-scale equivalent 7-9 kn) in an outdoor pond with wind, and at model-scale
Reynolds number (thicker boundary layer, larger wake fraction, relatively stronger propeller
slipstream on the rudder), which typically gives the model a tighter turn and a smaller advance than
the ship. Rhee & Kim's full-scale simulation uses Kijima's regression derivatives, not the
model's measured ones. No full-scale Crane (1979) numbers were available to us.
""")


def st35_variants_section(doc, ship):
    """ST35 heading change after 3000 s under the alternatives to the fact sheet's assumptions.

    Rhee & Kim chose t_f = 3000 s "to make the ship turn 560 deg"; this shows how far each
    unpublished constant moves ours.
    """
    from dataclasses import replace

    doc("### ST35: heading change after 3000 s (paper: 560 deg) under alternative assumptions\n")
    variants = [
        ("as configured (fact sheet)", ship),
        ("no wake change in the turn (C_wake = 0)", replace(ship, propeller=replace(ship.propeller, C_wake=0.0))),
        ("kappa = 0.5 (KVLCC2)", replace(ship, rudder=replace(ship.rudder, kappa=0.5))),
        ("l_R' = -0.71 (KVLCC2)", replace(ship, rudder=replace(ship.rudder, l_R_prime=-0.71))),
        ("k_zz = 0.27 L", replace(ship, mass=replace(ship.mass, I_zG_prime=0.01976))),
        ("constant rpm engine", replace(ship, engine=replace(ship.engine, mode="constant_rpm"))),
    ]
    rows = []
    law = CommandLaw.schedule([0.0, 3000.0], [35 * DEG] * 2)
    for label, sh in variants:
        r = simulate(sh, law, 3000.0, 0.1, 10 * KNOT)
        m = turning_metrics(r.t, r.x, r.y, r.psi, r.U, sh.particulars.L, t_execute=0.0)
        rows.append({"variant": label, "heading": float(r.psi[-1] / DEG), "TD": m["tactical_diameter_L"],
                     "U": float(r.U[-1] / r.U[0])})
    doc(table(rows, ["variant", "heading", "TD", "U"],
                ["variant", "heading change at 3000 s (deg)", "tactical D (L)", "final U / U0"]))
    h = [r["heading"] for r in rows]
    doc(f"\nRhee & Kim chose t_f = 3000 s \"to make the ship turn 560 deg\"; ours turns {h[0]:.0f} deg. The paper does "
        "not publish the constants varied here (wake change in the turn, flow-straightening kappa, rudder position "
        f"l_R', yaw inertia, engine model); each moves ours by {min(x - h[0] for x in h[1:]):+.0f} to "
        f"{max(x - h[0] for x in h[1:]):+.0f} deg, " + ("none to 560 deg: the rest of the difference is not explained "
        "by them (the paper's speed loss in the turn, which sets how far a slowing ship turns in 3000 s, is not "
        "published)." if min(abs(x - 560) for x in h) > 20 else "one of them to within 20 deg of 560 deg.") + "\n")


def checks_section(doc, ship):
    doc("## 5. Numerical checks\n")
    L = ship.particulars.L
    tds = []
    for dt in (0.2, 0.1, 0.05):
        r = simulate(ship, CommandLaw.schedule([0, 1500.0], [35 * DEG] * 2), 1500.0, dt, 10 * KNOT)
        tds.append(turning_metrics(r.t, r.x, r.y, r.psi, r.U, L, t_execute=0.0)["tactical_diameter_L"])
    sym = ship.with_hull({"Y_0": 0.0, "N_0": 0.0})
    a = simulate(sym, CommandLaw.schedule([0, 3000.0], [35 * DEG] * 2), 3000.0, 0.1, 10 * KNOT)
    b = simulate(sym, CommandLaw.schedule([0, 3000.0], [-35 * DEG] * 2), 3000.0, 0.1, 10 * KNOT)
    mirror = np.array([1, -1, -1, 1, -1, -1, -1, 1])
    rel = max(np.max(np.abs(a.states[:, j] - mirror[j] * b.states[:, j])) / (np.max(np.abs(a.states[:, j])) or 1)
              for j in range(8))
    doc(table([
        {"check": "tactical diameter, dt 0.2 / 0.1 / 0.05 s (L)", "value": " / ".join(f"{v:.7f}" for v in tds)},
        {"check": "relative change halving dt 0.1 -> 0.05 s", "value": f"{abs(tds[2] - tds[1]) / tds[2]:.2e}"},
        {"check": "port/starboard mirror (Y_0 = N_0 = 0), max relative difference", "value": f"{rel:.2e}"},
    ], ["check", "value"]))
    doc()


def nomoto_section(doc, out: Path, full: bool):
    from . import artyszuk

    doc("## 6. Nomoto models: Artyszuk (2018) Tables 1-8\n")
    if not full:
        doc("(the extended Table 8 without its output-error column and with 2 noise seeds: "
              "`mmg reproduce --full` or `mmg nomoto-paper` runs all of it, about 5 minutes)\n")
    t0 = time.perf_counter()
    tables = artyszuk.reproduce(fast=not full)
    artyszuk.write_tables(tables, out / "nomoto")
    for part in artyszuk.markdown_parts(tables, level=3):     # each table with its note on the paper
        doc(part)
    doc("(every table also as CSV in `nomoto/`)\n")
    progress(f"Nomoto tables {time.perf_counter() - t0:.1f} s")


def ekf_section(doc, out: Path, runs: dict) -> dict:
    from ..estimates.rhee_kim import reproduce_rhee_kim

    doc("## 7. EKF: Rhee & Kim (1999) Tables 9-10\n")
    t0 = time.perf_counter()
    keep = {}
    stems = {"ST35": "st35", "ZZ10": "zz10", "ZZ20": "zz20", "S-type 120": "stype120"}
    reproduce_rhee_kim(out / "ekf", verbose=False, runs={k: runs[s][0] for k, s in stems.items() if s in runs},
                       keep=keep)
    doc((out / "ekf" / "comparison.md").read_text())
    doc("\nOurs and the paper's errors differ because each is one draw of the measurement noise: the paper's noise "
        "sequence is not published (only its levels, Table 5), so a single run can only match in size, not value; "
        "section 10 of `mmg reproduce --full` gives the spread over 20 seeds to set them against.\n")
    doc("\nThe estimates, the Table-10 error table and the free-run check are in `ekf/` "
        "([estimates.json](ekf/estimates.json), [error_table.md](ekf/error_table.md), "
        "[free_run.json](ekf/free_run.json)); convergence figures, one per derivative, e.g. "
        "[Y_beta](ekf/convergence_Y_beta.png) and [N_r](ekf/convergence_N_r.png) (cf. Rhee & Kim Figs 15-26); "
        "recovered measurements against the truth (Figs 4-5): [ZZ20](ekf/preprocessing_ZZ20.png).\n")
    progress(f"EKF reproduction {time.perf_counter() - t0:.1f} s")
    return keep


def sensitivity_section(doc, out: Path):
    from ..planning.sensitivity_report import paper_figures

    doc("## 8. Derivative sensitivity: Rhee & Kim Figs 2, 8-9, 12, 13, 14, 28\n")
    t0 = time.perf_counter()
    cmp_ = out / "ekf" / "comparison.csv"
    paper_figures(out / "sensitivity", ekf_comparison=cmp_ if cmp_.exists() else None, verbose=False)
    doc(demote((out / "sensitivity" / "sensitivity_figures.md").read_text(), drop_title=True))
    doc("\nThe paper's Figs 2-14 are charts whose numbers it does not print: these tables are ours only, to set "
        "against its bars. The two Fig. 28 tables (ours; the same formula on the paper's Table 10) differ as the "
        "errors of section 7 do: one noise draw each, the paper's not published.\n")
    doc("\nFigures: [Fig. 2](sensitivity/fig02_conventional.png), [Figs 8-9](sensitivity/fig08_09_sine_sawtooth.png), "
        "[Fig. 12](sensitivity/fig12_stype.png), [Fig. 13](sensitivity/fig13_conventional_vs_stype120.png), "
        "[Fig. 14](sensitivity/fig14_sums.png), [Fig. 28](sensitivity/fig28_efficiency.png); CSVs beside them.\n")
    progress(f"sensitivity figures {time.perf_counter() - t0:.1f} s")


def best_estimator_section(doc, out: Path, full: bool, ekf: dict):
    from ekf.estimate import load_config

    from ..estimates.estimation import estimate_and_report, to_markdown

    doc("## 9. Beyond the paper: joint output-error estimate over ST35, ZZ10, ZZ20, S-type 120\n")
    doc("(the EKF of section 7 jointly over the four trials, then an output-error fit of the raw logs; "
          "one noise seed: the trial files' own)\n")
    t0 = time.perf_counter()
    cfg = load_config()
    datas = ekf["datas"]                                 # section 7's data (same trials, same seeds)
    joint = next(e for e in ekf["estimates"] if e.name == "joint")
    with StagedOutput(out / "best_estimator") as stage:
        rep = estimate_and_report(datas, cfg, stage, method="output-error", plots=False, verbose=False,
                                  n_jobs=2, ekf_start=joint.final)
    fit = rep["fit"]
    doc(f"Output-error fit over {', '.join(fit['trials'])}: chi2/dof {fit['chi2_per_dof']:.3f} "
        f"({fit['residuals']} residuals, {fit['nfev']} evaluations). Coefficients, standard errors from "
        f"(J^T W J)^-1 and the EKF start ([estimates.json](best_estimator/estimates.json), "
        f"[oe_fit.json](best_estimator/oe_fit.json)):\n")
    doc(to_markdown(rep["table"]))
    for w in rep["warnings"]:
        doc(f"Warning: {w}\n")
    progress(f"output-error estimate {time.perf_counter() - t0:.1f} s")
    if full:
        from ..estimates.montecarlo import log_filter_monte_carlo, monte_carlo, output_error_monte_carlo, summarise

        doc("## 10. Monte Carlo over 20 noise seeds: plain EKF per trial, and the joint output-error fit\n")
        monte_carlo(out / "ekf_montecarlo", 20, verbose=False)
        doc((out / "ekf_montecarlo" / "summary.md").read_text())
        output_error_monte_carlo(out / "oe_montecarlo", 20, verbose=False)
        summarise(out / "oe_montecarlo", ekf_summary=out / "ekf_montecarlo" / "summary.csv", verbose=False)
        doc((out / "oe_montecarlo" / "summary.md").read_text())
        from ..planning.sensitivity_report import crb_table

        doc("\n## 11. The raw-log EKF over 20 noise seeds beside the Cramer-Rao bound\n")
        log_filter_monte_carlo(out / "ekf_log_montecarlo", 20)
        (out / "crb_vs_mc").mkdir(exist_ok=True)
        crb_table(out / "ekf_log_montecarlo", out / "crb_vs_mc", verbose=False)
        doc((out / "crb_vs_mc" / "crb_vs_mc.txt").read_text() if (out / "crb_vs_mc" / "crb_vs_mc.txt").exists() else "")


class _Background:
    """A section run in a forked process beside the main one: its report parts come back through a pipe.

    The section writes its files under ``out`` itself (its own folder) and fills a :class:`Report` of its
    own; :meth:`parts` waits for it and returns that report's parts (or re-raises its exception).  The
    child starts with SIGINT blocked (a terminal's Ctrl-C reaches only the main process, which stops it)
    and SIGTERM at its default, so :meth:`stop` ends it at once; it leaves by ``os._exit`` whatever
    happens, never unwinding the main process's staging it inherited.  Start it before the main process
    creates worker pools (a forked copy of a loky executor would wait for workers it does not own), and
    give it no joblib process pool of its own (``os._exit`` skips the clean-up of its semaphores and
    memory-mapping folder).
    """

    def __init__(self, section):
        import multiprocessing as mp

        from ..files.output import children_ignore_sigint

        ctx = mp.get_context("fork")
        self._recv, send = ctx.Pipe(duplex=False)
        with children_ignore_sigint():
            self.proc = ctx.Process(target=_background_main, args=(section, send), daemon=True)
            self.proc.start()
        send.close()

    def parts(self) -> list[str]:
        try:
            ok, value = self._recv.recv()
        except EOFError:
            self.proc.join()
            raise RuntimeError(f"a report section's process ended without a result (exit {self.proc.exitcode})") from None
        self.proc.join()
        if not ok:
            raise value
        return value

    def stop(self) -> None:
        if self.proc.is_alive():
            self.proc.terminate()
        self.proc.join()


def _background_main(section, send) -> None:
    import signal
    import sys
    import traceback

    code = 1
    try:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        doc = Report()
        section(doc)
        send.send((True, doc.parts))
        code = 0
    except BaseException as e:                            # noqa: BLE001 - sent to the main process
        try:
            send.send((False, e))
        except Exception:                                  # an exception that does not pickle
            send.send((False, RuntimeError("".join(traceback.format_exception(e)).rstrip())))
    finally:
        sys.stdout.flush()
        os._exit(code)


def _sections_side_by_side(doc, out: Path, runs: dict, keep: dict, t0: float) -> None:
    """Sections 6-9 on both cores, their report parts in their places.

    The Nomoto tables need nothing of the others: a process of their own from the start.  The
    output-error fit needs the EKF's data and joint estimate: a process of its own once the EKF is done
    (its Jacobian on threads), while this one draws the sensitivity figures (joblib's workers; they come
    after the forks, so no child inherits a copy of their pool).
    """
    background = []
    try:
        nomoto = _Background(lambda d: nomoto_section(d, out, False))
        background.append(nomoto)
        ekf = Report()
        keep.update(ekf_section(ekf, out, runs))
        progress(f"EKF done ({time.perf_counter() - t0:.1f} s)")
        best = _Background(lambda d: best_estimator_section(d, out, False, keep))
        background.append(best)
        sens = Report()
        sensitivity_section(sens, out)
        progress(f"sensitivity done ({time.perf_counter() - t0:.1f} s)")
        parts = nomoto.parts() + ekf.parts + sens.parts + best.parts()
        progress(f"Nomoto and output error done ({time.perf_counter() - t0:.1f} s)")
    finally:
        for b in background:
            b.stop()
    for part in parts:
        doc(part)


def reproduce(out, full: bool = False) -> Path:
    """Run the main job into the folder ``out``; returns the path of ``report.md``.

    Parameters
    ----------
    out : str or Path
        Output folder (created); the report and every file it links to are written there.
    full : bool
        Also the Monte Carlo runs (about 25 minutes on 2 cores).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    doc = Report()
    t0 = time.perf_counter()
    ship = load_trial(trial_path("st35")).ship
    doc("# Esso Osaka MMG: paper reproduction\n")
    doc("Rhee & Kim (1999) and Artyszuk (2018) reproduced with this toolkit on its default configs "
        f"(`mmg reproduce{' --full' if full else ''}`). Our values stand beside the papers' wherever they print one.\n")
    doc(GLOSSARY)
    steps = [("straight run", lambda: straight_run_section(doc, ship)), ("Kijima", lambda: kijima_section(doc, ship))]
    for label, f in steps:
        f()
        progress(f"{label} done ({time.perf_counter() - t0:.1f} s)")
    runs = trials_section(doc, out)
    keep: dict = {}
    progress(f"default trials done ({time.perf_counter() - t0:.1f} s)")
    for label, f in [("plausibility", lambda: plausibility_section(doc, runs, ship)),
                     ("ST35 variants", lambda: st35_variants_section(doc, ship)),
                     ("numerical checks", lambda: checks_section(doc, ship))]:
        f()
        progress(f"{label} done ({time.perf_counter() - t0:.1f} s)")
    if full:                                   # the Monte Carlo runs take both cores themselves
        for label, f in [("Nomoto", lambda: nomoto_section(doc, out, full)),
                         ("EKF", lambda: keep.update(ekf_section(doc, out, runs))),
                         ("sensitivity", lambda: sensitivity_section(doc, out)),
                         ("output error", lambda: best_estimator_section(doc, out, full, keep))]:
            f()
            progress(f"{label} done ({time.perf_counter() - t0:.1f} s)")
    else:
        _sections_side_by_side(doc, out, runs, keep, t0)
    doc(f"\n---\nTotal {time.perf_counter() - t0:.1f} s.")
    path = out / "report.md"
    tmp = out / ".report.md.tmp"
    tmp.write_text(doc.text())
    os.replace(tmp, path)
    return path
