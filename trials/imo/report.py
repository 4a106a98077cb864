"""The files of ``mmg imo``: ``imo.json`` (the criteria), ``imo.md`` (the report) and its figures."""
from __future__ import annotations

from pathlib import Path

from ..analysis.metrics import IMO_STANDARD
from .sampling import FAIL_PROBABILITY, PASS_PROBABILITY
from .standard import STOPPING

__all__ = ["write_report", "report_lines", "FIGURES"]

FIGURES = ("tracks.png", "zigzags.png", "stopping.png", "distributions.png")
"""The figures ``mmg imo`` writes (``distributions.png`` only with samples)."""


def _num(v, nd: int = 3) -> str:
    return "-" if v is None else f"{v:.{nd}g}" if abs(v) < 1e4 else f"{v:.4g}"


def _prob(p) -> str:
    return "-" if p is None else f"{p:.3f}"


def _interval(iv) -> str:
    return "-" if not iv else f"[{_num(iv[0])}, {_num(iv[1])}]"


def _table(res) -> list[str]:
    sampled = res.samples is not None
    head = ("| criterion | value | own parameters | 90 % interval | limit | probability | verdict |" if sampled
            else "| criterion | value | limit | verdict |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in res.rows():
        unit = f" {r['unit']}"
        if sampled:
            lines.append(f"| {r['name']} | {_num(r['value'])}{unit if r['value'] is not None else ''} | "
                         f"{_num(res.nominal.get(r['name']))} | {_interval(r['interval'])} | {r['limit']:.3g}{unit} | "
                         f"{_prob(r['probability'])} | {r['verdict']} |")
        else:
            lines.append(f"| {r['name']} | {_num(r['value'])}{unit if r['value'] is not None else ''} | "
                         f"{r['limit']:.3g}{unit} | {r['verdict']} |")
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


def report_lines(res) -> list[str]:
    """The lines of ``imo.md``: the criteria table, the rules, the notes, the convergence and the figures."""
    sampled = res.samples is not None
    lines = [f"# IMO manoeuvring standards: {res.ship}", "",
             f"Source of the criteria: {IMO_STANDARD}.", "",
             f"Approach speed V = {res.speed} ({res.u0:.4g} m/s); L = {res.L:g} m; L/V = {res.L_over_V:.3g} s "
             f"(it sets the 10/10 overshoot limits: 10 / 20 / 5 + L/(2V) deg and 25 / 40 / 17.5 + 0.75 L/V deg "
             f"for L/V below 10 s, from 30 s, between).  A criterion's side is that of the turn or of a zigzag's "
             f"first rudder order; the initial-turning track reach is the distance run to the 10/10 zigzag's second "
             f"execute (heading changed by 10 deg with 10 deg rudder).", ""]
    if sampled:
        pn = res.parameters
        lines += [f"Uncertainty: {res.n_samples} samples of {len(pn['names'])} parameters "
                  f"({', '.join(pn['names'])}) from their covariance (correlations kept; seed {pn['seed']}), every "
                  f"manoeuvre run per sample.  Value: the median of the samples ('own parameters': the ship's own "
                  f"values); interval: 5th to 95th percentile; probability: the share of samples meeting the limit "
                  f"(a sample whose manoeuvre does not give the figure counts as not meeting it).  Verdict: pass "
                  f"if the probability is >= {PASS_PROBABILITY:g}, fail if <= {FAIL_PROBABILITY:g}, "
                  f"undecided between.", ""]
    else:
        lines += ["No uncertainty (the ship's own parameters: `mmg imo --samples N` samples them from the "
                  "ship's covariance): value against limit, no interval or probability.", ""]
    stop = [n[len(STOPPING) + 2:] for n in res.notes if n.startswith(f"{STOPPING}: ")]
    lines += ["## Criteria", "", *_table(res), "", "Full-astern stopping test: " + " ".join(stop) + ".", ""]
    other = [n for n in res.notes if not n.startswith(STOPPING)]
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
