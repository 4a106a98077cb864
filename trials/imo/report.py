"""The files of ``mmg imo``: ``imo.json`` (the criteria), ``imo.md`` (the report) and its figures."""
from __future__ import annotations

from pathlib import Path

from ..analysis.metrics import IMO_STANDARD
from .sampling import FAIL_PROBABILITY, PASS_PROBABILITY
from .standard import STOPPING, speed_label

__all__ = ["write_report", "report_lines", "interval_text", "FIGURES"]

FIGURES = ("tracks.png", "zigzags.png", "stopping.png", "distributions.png")
"""The figures ``mmg imo`` writes (``distributions.png`` only with samples)."""


def _num(v, nd: int = 3) -> str:
    return "-" if v is None else f"{v:.{nd}g}" if abs(v) < 1e4 else f"{v:.4g}"


def _prob(p) -> str:
    return "-" if p is None else f"{p:.3f}"


def _interval(iv) -> str:
    return "-" if not iv else f"[{_end(iv[0])}, {_end(iv[1])}]"


def _end(v) -> str:
    """An interval's end: None is a percentile among the samples that gave no figure (at +inf)."""
    return "unbounded" if v is None else _num(v)


def interval_text(iv, unit: str) -> str:
    """A criterion's 90 % interval on the console, with its unit: ``[2.18, 3.5] L``; an end among the samples
    that gave no figure is ``unbounded``; "-" without an interval."""
    return "-" if not iv else f"{_interval(iv)} {unit}"


def _table(res) -> list[str]:
    sampled = res.samples is not None
    head = ("| criterion | value | own parameters | 90 % interval | limit | probability | verdict |" if sampled
            else "| criterion | value | limit | verdict |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in res.rows():
        unit = f" {r['unit']}"
        if "note" in r:
            r = {**r, "verdict": f"{r['verdict']} (identification)"}
        if sampled:
            lines.append(f"| {r['name']} | {_num(r['value'])}{unit if r['value'] is not None else ''} | "
                         f"{_num(res.nominal.get(r['name']))} | {_interval(r['interval'])} | {r['limit']:.3g}{unit} | "
                         f"{_prob(r['probability'])} | {r['verdict']} |")
        else:
            lines.append(f"| {r['name']} | {_num(r['value'])}{unit if r['value'] is not None else ''} | "
                         f"{r['limit']:.3g}{unit} | {r['verdict']} |")
    return lines


def _warnings(res) -> list[str]:
    """The warnings block near the top of ``imo.md``: the identification's (its ship.yaml's
    ``identification:`` section), what that does to the verdicts, and this check's own."""
    d = res.doubts
    lines = []
    if d.warnings or d.reason:
        lines += ["## Warnings of the identification", "",
                  "From the ship's identification: section (mmg identify's account of the fit it was made by):", ""]
        lines += [f"- {w}" for w in d.warnings] or ["- none listed"]
        lines.append("")
        if d.reason:
            lines += [f"**Verdicts: {d.reason}.** A criterion its values would pass is reported 'undecided "
                      f"(identification)' below; a fail stands.", ""]
    if res.own_warnings:
        lines += ["## Warnings of this check", ""] + [f"- {w}" for w in res.own_warnings] + [""]
    return lines


def _convergence(res) -> list[str]:
    lines = ["## Convergence with the number of samples", "",
             "Each criterion's probability of meeting its limit and 90 % interval from the first N/8, N/4, N/2 "
             "and all N samples: when the last columns agree to the digits that matter, N is enough.", ""]
    ns = [c["n"] for c in res.convergence(res.criteria[0].name)]
    lines.append("| criterion | " + " | ".join(f"P (N = {n})" for n in ns) + " | " +
                 " | ".join(f"interval (N = {n})" for n in ns) + " |")
    lines.append("|---|" + "---|" * (2 * len(ns)))
    for c in res.criteria:
        conv = res.convergence(c.name)
        lines.append(f"| {c.name} | " + " | ".join(_prob(x["probability"]) for x in conv) + " | " +
                     " | ".join(_interval(x["interval"]) for x in conv) + " |")
    return lines


_EFFECT_SOURCES = {
    "friction": "(1 + k)(C_FM - C_FS) S/(L T) added to the resistance coefficient (ITTC-1957 line; ITTC 7.5-02-03-01.4 "
                "2.4.1); std on the correction",
    "wake": "w_S = (t + 0.04) + (w_M - t - 0.04)((1 + k) C_FS + dC_F)/((1 + k) C_FM) (ITTC 7.5-02-03-01.4 2.4.3); std "
            "on the correction",
    "epsilon": "(1 - w_R)/(1 - w_P) with the rudder's wake scaled by the same formula; std on the value",
    "kappa": "transferred; the loading itself is the full-scale propeller's and engine's; std on the value"}


def _scaling(res) -> list[str]:
    sc = res.scaling
    lines = ["## From the model to the ship", "",
             f"Froude-scaled from {sc['model']} to {sc['ship']} (trials.imo.scaling): lambda = {sc['lambda']:.4g}, model "
             f"speed {sc['u_model']:.4g} m/s (the ship's {sc['u_ship']:.4g} m/s / sqrt(lambda)).  From the model: the "
             f"primed hull coefficients, w_P0, epsilon, kappa, gamma_R, l_R', the primed added masses; from the ship's "
             f"config: geometry, mass, propeller, engine, steering, rudder geometry.  Re {sc['re_model']:.3g} (model) "
             f"and {sc['re_ship']:.3g} (ship), ITTC-1957 C_F {sc['cf_model']:.5f} and {sc['cf_ship']:.5f}, "
             f"1 + k = {sc['form_factor']:g}, dC_F = {sc['delta_CF']:g}, t = {sc['t_model']:.3f}.", "",
             "| scale effect | quantity | model | ship | relative std | formula |", "|---|---|---|---|---|---|"]
    for k, (q, m, s) in sc["corrections"].items():
        lines.append(f"| {k} | {q} | {m:.4g} | {s:.4g} | {sc['rel_std'][k]:g} | {_EFFECT_SOURCES[k]} |")
    widths = res.interval_widths()
    if widths:
        lines += ["", "The 90 % intervals' widths with all the uncertainty and with the identified covariance only "
                  "(the same model draws, the scale-effect corrections fixed at their nominal values): the share the "
                  "scaling assumptions add.", "",
                  "| criterion | width | width, identified only | from the scaling |", "|---|---|---|---|"]
        for w in widths:
            share = "-" if w["scaling_share"] is None else f"{100 * w['scaling_share']:.0f} %"
            lines.append(f"| {w['name']} | {_num(w['width'])} {w['unit']} | {_num(w['width_identified'])} {w['unit']} "
                         f"| {share} |")
    return lines + [""]


def report_lines(res) -> list[str]:
    """The lines of ``imo.md``: the warnings (:func:`_warnings`), the criteria table, the rules, the notes,
    the convergence and the figures."""
    sampled = res.samples is not None
    lines = [f"# IMO manoeuvring standards: {res.ship}", "",
             f"Source of the criteria: {IMO_STANDARD}.", "",
             f"Approach speed V = {speed_label(res.speed, res.u0)}; L = {res.L:g} m; L/V = {res.L_over_V:.3g} s "
             f"(it sets the 10/10 overshoot limits: 10 / 20 / 5 + L/(2V) deg and 25 / 40 / 17.5 + 0.75 L/V deg "
             f"for L/V below 10 s, from 30 s, between).  A criterion's side is that of the turn or of a zigzag's "
             f"first rudder order; the initial-turning track reach is the distance run to the 10/10 zigzag's second "
             f"execute (heading changed by 10 deg with 10 deg rudder).", ""]
    lines += _warnings(res)
    if sampled:
        pn = res.parameters
        src = pn.get("model", pn)
        what = (f"{len(src['names'])} parameters ({', '.join(src['names']) or 'none'}) from their covariance"
                if src["names"] else "no parameters (no covariance)")
        if "model" in pn:
            what = (f"the model's {what} and the {len(pn['scale_effects'][0])} scale-effect corrections (below), "
                    f"written into the full-scale ship as {len(pn['names'])} parameters")
        lines += [f"Uncertainty: {res.n_samples} samples of {what} (correlations kept; seed {pn['seed']}), every "
                  f"manoeuvre run per sample.  Value: the median of the samples ('own parameters': the ship's own "
                  f"values); interval: 5th to 95th percentile; probability: the share of samples meeting the limit "
                  f"(a sample whose manoeuvre does not give the figure counts as not meeting it).  Verdict: pass "
                  f"if the probability is >= {PASS_PROBABILITY:g}, fail if <= {FAIL_PROBABILITY:g}, "
                  f"undecided between.", ""]
    else:
        lines += ["No uncertainty (the ship's own parameters: `mmg imo --samples N` samples them from the "
                  "ship's covariance): value against limit, no interval or probability.", ""]
    stop = [n[len(STOPPING) + 2:] for n in res.notes if n.startswith(f"{STOPPING}: ")]
    if res.scaling is not None:
        lines += _scaling(res)
    lines += ["## Criteria", "", *_table(res), "", "Full-astern stopping test: " + " ".join(stop) + ".", ""]
    other = [n for n in res.notes if not n.startswith(STOPPING) and n not in res.own_warnings]
    if other:
        lines += ["## Notes", ""] + [f"- {n}" for n in other] + [""]
    if sampled:
        lines += _convergence(res) + [""]
    lines += ["## Figures", "", "- [turning circles with ship outlines](tracks.png)" +
              (" (with the samples' smallest, median and largest tactical diameter)" if sampled else ""),
              "- [zigzag heading and rudder histories](zigzags.png)",
              "- [full-astern stopping track with ship outlines, speed and revolutions](stopping.png)"]
    if sampled:
        lines.append("- [distributions of the sampled criteria with their limits](distributions.png)")
    return lines


def write_report(res, out_dir) -> list[str]:
    """Write ``imo.json``, ``imo.md`` and the figures of ``res`` into ``out_dir``; returns the names written."""
    out = Path(out_dir)
    res.to_json(out / "imo.json")
    (out / "imo.md").write_text("\n".join(report_lines(res)) + "\n")
    names = ["imo.json", "imo.md"]
    kinds = ["tracks", "zigzags", "stopping"] + (["distributions"] if res.samples is not None else [])
    for k in kinds:
        fig = res.plot(k, pyplot=False)
        fig.savefig(out / f"{k}.png", dpi=110)
        names.append(f"{k}.png")
    return names
