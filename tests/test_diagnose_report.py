"""What mmg diagnose tells a user (an answer a user can trust): each named effect's value
with a 95 % interval (checked against a Monte Carlo of the fitted normal, computed here), the evidence
of the round that named it, console lines with units and three significant figures (no raw dict), the
unexplained residual in units, the summary figure, and a zigzag's track that is not a strip."""
from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from dataclasses import replace
from types import SimpleNamespace as NS

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")


# --------------------------------------------------------------------------- interval maths


def _mc_polar(n, e, cov, k=400_000, seed=0):
    """Monte Carlo of the (north, east) normal: speeds and bearings [deg] unwrapped about the fitted one."""
    rng = np.random.default_rng(seed)
    p = rng.multivariate_normal([n, e], cov, size=k)
    s = np.hypot(p[:, 0], p[:, 1])
    b0 = math.degrees(math.atan2(e, n))
    b = (np.degrees(np.arctan2(p[:, 1], p[:, 0])) - b0 + 180.0) % 360.0 - 180.0 + b0
    return s, b


@pytest.mark.parametrize("n, e, sn, se, rho", [
    (-0.126, 0.217, 0.007, 0.006, 0.0),        # 0.251 m/s towards 120 deg, round
    (0.30, -0.05, 0.012, 0.004, 0.6),          # elongated and tilted
    (0.20, -0.004, 0.010, 0.015, -0.5),        # just west of north: the arc crosses north
])
def test_current_interval_matches_monte_carlo(n, e, sn, se, rho):
    from mmg.effects.current import Current
    from trials.measured.diagnose_report import effect_intervals

    cov = np.array([[sn * sn, rho * sn * se], [rho * sn * se, se * se]])
    iv = effect_intervals(Current, [n, e], cov)
    s, b = _mc_polar(n, e, cov)
    s_lo, s_hi = np.percentile(s, [2.5, 97.5])
    b_lo, b_hi = np.percentile(b, [2.5, 97.5])
    lo, hi = iv["speed_mps"]
    w = s_hi - s_lo
    assert abs(lo - s_lo) < 0.04 * w and abs(hi - s_hi) < 0.04 * w, (iv, s_lo, s_hi)
    d_lo, d_hi = iv["direction_deg"]
    assert 0.0 <= d_lo < 360.0 and 0.0 <= d_hi < 360.0                 # within [0, 360): an arc lo -> hi
    wd = b_hi - b_lo
    assert abs((d_lo - b_lo + 180) % 360 - 180) < 0.04 * wd, (d_lo, b_lo % 360)
    assert abs((d_hi - b_hi + 180) % 360 - 180) < 0.04 * wd, (d_hi, b_hi % 360)
    # the direction is where the current sets towards: the middle of the arc is the fitted bearing
    mid = (d_lo + ((d_hi - d_lo) % 360.0) / 2.0) % 360.0
    assert abs((mid - math.degrees(math.atan2(e, n)) + 180) % 360 - 180) < 0.1 * wd


def test_current_near_zero_any_direction_and_speed_from_zero():
    """The origin inside the ellipse: direction 'any', speed interval from 0 (never negative); it still
    covers the speeds of the fitted normal."""
    from mmg.effects.current import Current
    from trials.measured.diagnose_report import effect_intervals

    cov = np.diag([0.03 ** 2, 0.02 ** 2])
    iv = effect_intervals(Current, [0.02, -0.01], cov)
    assert iv["direction_deg"] == "any"
    lo, hi = iv["speed_mps"]
    s, _ = _mc_polar(0.02, -0.01, cov)
    assert lo == 0.0 and np.mean(s <= hi) >= 0.95
    # far from zero the same code gives a direction arc, never 'any'
    assert effect_intervals(Current, [0.3, 0.0], cov)["direction_deg"] != "any"


def test_scalar_intervals_bounds_and_monotone_map():
    """A parameter fitted as itself: value +- 1.96 sd, clipped to its bounds; shallow water fitted as
    T/H and reported as H/T: the T/H interval mapped (1/x), deep water (inf) where T/H reaches 0."""
    from mmg.effects import get
    from trials.measured.diagnose_report import effect_intervals

    ro = get("rudder_offset")
    hi_bound = ro.parameters[0].upper
    iv = effect_intervals(ro, [1.2], [[0.25 ** 2]])["offset_deg"]
    assert iv == pytest.approx([1.2 - 1.959964 * 0.25, 1.2 + 1.959964 * 0.25], rel=1e-6)
    iv = effect_intervals(ro, [hi_bound - 0.1], [[1.0]])["offset_deg"]
    assert iv[1] == hi_bound and iv[0] == pytest.approx(hi_bound - 0.1 - 1.959964, rel=1e-6)
    sw = get("shallow_water")
    iv = effect_intervals(sw, [0.4], [[0.05 ** 2]])["depth_to_draft"]
    assert iv == pytest.approx([1 / (0.4 + 1.959964 * 0.05), 1 / (0.4 - 1.959964 * 0.05)], rel=1e-6)
    iv = effect_intervals(sw, [0.1], [[0.1 ** 2]])["depth_to_draft"]
    assert iv[0] == pytest.approx(1 / (0.1 + 1.959964 * 0.1), rel=1e-6) and iv[1] == math.inf


def test_evidence_from_the_round_that_named_it():
    from trials.measured.diagnose_report import effect_evidence

    rounds = [{"round": 1, "candidates": [
        {"effect": "current", "delta_bic": 412.0, "z": 18.3, "clears_threshold": True},
        {"effect": "rudder_offset", "delta_bic": 31.0, "z": 4.0, "clears_threshold": True},
        {"effect": "heading_bias", "delta_bic": 2.0, "z": 0.5, "clears_threshold": False}]},
        {"round": 2, "candidates": [
            {"effect": "rudder_offset", "delta_bic": 25.5, "z": 3.6, "clears_threshold": True},
            {"effect": "heading_bias", "delta_bic": 1.0, "z": 0.2, "clears_threshold": False}]},
        {"round": 3, "candidates": [{"effect": "heading_bias", "delta_bic": 0.5, "z": 0.1, "clears_threshold": False}]}]
    ev = effect_evidence(["current", "rudder_offset"], rounds)
    assert (ev["current"]["delta_bic"], ev["current"]["z"]) == (412.0, 18.3)
    assert ev["current"]["false_alarm_probability"] is None      # rounds without a kind: not calibrated
    assert (ev["rudder_offset"]["delta_bic"], ev["rudder_offset"]["z"]) == (25.5, 3.6)


# --------------------------------------------------------------------------- console text


_NUM = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?:e[+-]?\d+)?")


def _sig_digits(tok: str) -> int:
    mant = tok.lstrip("-").split("e")[0]
    if "." in mant:
        return len(mant.replace(".", "").lstrip("0"))
    return len(mant.lstrip("0").rstrip("0")) or 1


def _check_plain(lines):
    """No raw dict or list, no number with more than 3 significant figures."""
    for ln in lines:
        assert "{" not in ln and "}" not in ln and "[0." not in ln, ln
        for tok in _NUM.findall(ln):
            assert _sig_digits(tok) <= 3, (tok, ln)


@pytest.fixture(scope="module")
def ship():
    from mmg.ship import load_ship

    return load_ship("esso_osaka_3m")


@pytest.fixture(scope="module")
def current_record(ship):
    from trials.measured.diagnose import Manoeuvre, RecordNoise, synthetic_record

    return synthetic_record(ship, Manoeuvre("zigzag", duration=60.0),
                            {"current": {"speed_mps": 0.15, "direction_deg": 200.0}}, noise=RecordNoise(seed=3),
                            name="zz")


@pytest.fixture(scope="module")
def diag_and_console(ship, current_record):
    from trials.measured.diagnose import diagnose

    said = []
    return diagnose(ship, [current_record], say=said.append), said


@pytest.fixture(scope="module")
def diag(diag_and_console):
    return diag_and_console[0]


def test_console_rounds_have_headers_and_sizes_their_si_value(diag_and_console, ship):
    """Each search round opens with its header; R, sd and detection size have a legend before the first
    identifiability line and units; a size in sqrt(gL) has m/s beside it, one in T/H the depth in m."""
    d, said = diag_and_console
    heads = [i for i, ln in enumerate(said) if ln.startswith("round ")]
    assert said[heads[0]] == "round 1: candidates against the ship alone"
    assert len(heads) == len(d.rounds) >= 2 and said[heads[1]] == "round 2: after naming current"
    assert all(said[i + 1].startswith("  ") for i in heads)              # the round's candidates follow it
    ident = [i for i, ln in enumerate(said) if ln.startswith("identifiability of ")]
    legend = [i for i, ln in enumerate(said) if "R, the multiple correlation" in ln]
    assert len(legend) == 1 and legend[0] < ident[0] and "standard error" in said[legend[0]]
    cur = next(ln for ln in said if ln.startswith("identifiability of current"))
    assert re.search(r"sd [0-9.e-]+ m/s \(alone [0-9.e-]+ m/s\), detection size [0-9.e-]+ m/s", cur)
    g = 9.80665
    for ln in said:
        for v, ms in re.findall(r"([0-9.e-]+) sqrt\(gL\) = ([0-9.e-]+) m/s", ln):
            assert float(ms) == pytest.approx(float(v) * math.sqrt(g * ship.particulars.L), rel=0.01)
        for v, h in re.findall(r"([0-9.e-]+) T/H, H = ([0-9.e-]+) m", ln):
            assert float(h) == pytest.approx(ship.particulars.T / float(v), rel=0.01)
        assert not re.search(r"sqrt\(gL\)(?! = [0-9.e-]+ m/s)", ln), ln
        assert not re.search(r"(size|floor) [0-9.e-]+ T/H(?!, H = [0-9.e-]+ m|, H infinite)", ln), ln
    assert any("T/H, H = " in ln for ln in said) and any("sqrt(gL) = " in ln for ln in said)


def test_json_has_intervals_evidence_and_the_new_keys(diag):
    j = json.loads(json.dumps(diag.to_json()))
    assert j["named_effects"] == ["current"]
    lo, hi = j["intervals_95"]["current"]["speed_mps"]
    assert 0.0 <= lo <= j["parameters"]["current"]["speed_mps"] <= hi
    ev = j["evidence"]["current"]
    assert ev["delta_bic"] > 20 and ev["z"] > 3 and "false_alarm_probability" in ev
    assert all({"effect", "confused_with", "correlation", "what_would_separate"} <= set(e)
               and e["effect"] != "current" for e in j["not_identifiable"])          # never the named one
    assert j["model_form_mismatch"] == {}


def test_summary_lines_units_three_figures(diag):
    lines = diag.summary_lines()
    _check_plain(lines)
    v = diag.parameters["current"]
    first = lines[0]
    assert first.startswith("current") and "m/s towards" in first and "deg" in first and "95 %" in first
    assert f"{v['speed_mps']:.3g}" in first and "dBIC" in first and " z " in first and "false-alarm p" in first
    assert any("dBIC:" in ln and "z:" in ln and "20" in ln for ln in lines)              # the legend
    table = [ln for ln in lines if ln.strip().startswith(("u [m/s]", "v [m/s]", "r [deg/s]", "heading [deg]",
                                                           "position [m]"))]
    assert len(table) == 5


def test_summary_lines_nothing_named_and_not_identifiable(diag):
    d = replace(diag, named=[], parameters={}, intervals_95={}, evidence={}, unexplained=False,
                not_identifiable=[{"effect": "rudder_offset", "confused_with": ["N_r", "Y_r"], "correlation": 0.9712345,
                                   "what_would_separate": "a port turn beside the starboard one"}])
    lines = d.summary_lines()
    _check_plain(lines)
    assert "nothing named" in lines
    assert ("rudder_offset: not identifiable from these records (correlation 0.971 with N_r, Y_r): "
            "a port turn beside the starboard one") in lines
    assert not any(ln.startswith("unexplained") for ln in lines)


def test_unexplained_in_units_not_a_ratio_to_a_zero_noise():
    """A v residual of 0.083 m/s on a record without noise: said in m/s, not as 10^13 x its noise."""
    from trials.measured.diagnose import _describe

    n = 400
    t = np.arange(n) * 1.0
    meas = np.zeros((n, 6))
    meas[:, 0], meas[:, 5] = 5.0, 0.3 * np.sin(t / 50.0)
    diffs = np.zeros((n, 6))
    diffs[:, 1] = 0.083 * np.where(np.arange(n) % 2, 1.0, -1.0)   # RMS 0.083 m/s
    rec = NS(seg=NS(meas=meas, inputs=NS(delta=np.zeros(n)), context=None))
    noise = np.array([1e-3, 1e-15, 1e-5, 0.1, 0.1, 1e-4])
    flag, desc, _ = _describe([rec], [diffs], noise, None)
    assert flag
    assert "v residual 0.0830 m/s RMS" in desc, desc
    assert "x its noise" not in desc
    _check_plain([desc])


# --------------------------------------------------------------------------- the CLI and the figures


def test_cli_prints_summary_and_writes_figures(tmp_path, ship, current_record):
    from trials.measured.diagnose import write_frt_csv

    p = tmp_path / "zz.csv"
    write_frt_csv(current_record, p)
    r = subprocess.run([sys.executable, "-m", "trials.cli", "diagnose", "--ship", "esso_osaka_3m", str(p),
                        "--json", str(tmp_path / "d.json"), "--plots", str(tmp_path / "plots")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = r.stdout.splitlines()
    assert out[0].startswith("current") and "m/s towards" in out[0] and "95 %" in out[0]
    _check_plain([ln for ln in out if not ln.startswith("wrote")])
    _check_plain(r.stderr.splitlines())                       # the progress lines too
    for name in ("zz.png", "diagnosis_summary.png"):
        f = tmp_path / "plots" / name
        head = f.read_bytes()[:24]
        w, h = int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
        assert head[:8] == b"\x89PNG\r\n\x1a\n" and f.stat().st_size > 30_000 and w >= 800 and 0.4 < h / w < 1.5, (name, w, h)


def _render(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    fig.canvas.draw()


def test_summary_figure_panels(diag):
    from trials.measured.diagnose_plots import diagnose_summary_figure

    fig = diagnose_summary_figure(diag)
    _render(fig)
    titles = [a.get_title() for a in fig.axes]
    assert any("95 %" in t and "speed" in t for t in titles) and any("95 %" in t and "direction" in t for t in titles)
    labels = [a.get_ylabel() for a in fig.axes]
    for lab in ("rudder [deg]", "heading [deg]", "u [m/s]", "v [m/s]", "r [deg/s]", "distance [m]"):
        assert lab in labels
    legends = [t.get_text() for a in fig.axes if a.get_legend() for t in a.get_legend().get_texts()]
    assert any("after (current)" in t and "m/s" in t for t in legends)
    fig = diagnose_summary_figure(replace(diag, named=[], parameters={}, intervals_95={}, evidence={}))
    _render(fig)
    assert any("nothing named" in t.get_text() for a in fig.axes for t in a.texts)


def test_zigzag_track_not_a_strip():
    """A 3500 s zigzag, 35 km along and 1 km across: the track panel shows its cross-track shape over
    more than 150 pixels (to scale it is a 30-pixel strip), the start shown, the legend off the data."""
    from trials.measured.diagnose_plots import diagnose_figure

    t = np.arange(0.0, 3500.0, 1.0)
    north = 10.0 * t
    east = 500.0 * np.sin(2 * np.pi * t / 780.0)
    meas = np.zeros((len(t), 6))
    meas[:, 0], meas[:, 3], meas[:, 4] = 10.0, north, east
    before, after = meas.copy(), meas.copy()
    before[:, 4] += 30.0 * np.sin(t / 300.0)
    rec = NS(name="zz", seg=NS(inputs=NS(t=t), meas=meas))
    fig = diagnose_figure(NS(records=[rec], pred_before=[before], pred_after=[after], named=["current"]), 0)
    _render(fig)
    ax = next(a for a in fig.axes if "track" in a.get_title())
    box = ax.get_window_extent()
    line = next(ln for ln in ax.get_lines() if ln.get_label() == "logged")
    xy = ax.transData.transform(np.column_stack(line.get_data()))
    assert box.height > 150 and np.ptp(xy[:, 1]) > 150 and np.ptp(xy[:, 1]) > 0.5 * box.height, (box, np.ptp(xy[:, 1]))
    inside = (xy[:, 0] >= box.x0 - 1) & (xy[:, 0] <= box.x1 + 1) & (xy[:, 1] >= box.y0 - 1) & (xy[:, 1] <= box.y1 + 1)
    assert inside.all()                                        # all of it, start included
    lg = ax.get_legend().get_window_extent()
    assert not ((xy[:, 0] > lg.x0) & (xy[:, 0] < lg.x1) & (xy[:, 1] > lg.y0) & (xy[:, 1] < lg.y1)).any()
    assert "m" in ax.get_xlabel() and "m" in ax.get_ylabel()


def test_negative_interval_reads_as_a_range():
    from trials.measured.diagnose_report import effect_line

    ln = effect_line("heading_bias", {"bias_deg": -1.5234}, {"bias_deg": [-1.6234, -1.4234]},
                     {"delta_bic": 61.04, "z": 30.2, "false_alarm_probability": 0.0031})
    assert "bias -1.52 deg" in ln and "-1.62 to -1.42 deg" in ln and "false-alarm p 0.00310" in ln
    _check_plain([ln])


# --------------------------------------------------------------------------- tables that never run together


def _cells(line):
    return re.split(r"\s{2,}", line.strip())


@pytest.mark.parametrize("ev", [{"delta_bic": 886.0, "z": 62.0, "false_alarm_probability": 0.00671},
                                {"delta_bic": -1.234e+300, "z": -9.87e-300, "false_alarm_probability": 1e-300}],
                         ids=["reported", "extreme"])
def test_evidence_panel_and_rms_table_keep_columns_apart(ev):
    """The figure's evidence table and the console's RMS table: every cell stays a cell (two spaces at least
    between columns) for any value, the extreme ones included; the parameter panel's title names the effect in
    words ("heading bias = -2.00 deg"), not the parameter's key."""
    from matplotlib.figure import Figure

    from trials.measured.diagnose_plots import _evidence_lines, _interval_panels
    from trials.measured.diagnose_report import fmt3, summary_lines

    rms = {"u": 1.5e+300, "v": -2.5e-300, "r": 123456.0, "heading": 0.00671, "position": None}
    diag = NS(named=["heading_bias"], evidence={"heading_bias": ev}, not_identifiable=[],
              parameters={"heading_bias": {"bias_deg": -2.0}}, intervals_95={"heading_bias": {"bias_deg": [-2.5, -1.5]}},
              rounds=[], unexplained=False, model_form_mismatch={}, straight_runs=[], runs=[], absent_channels=[],
              rms_config=rms, rms_before=rms, rms_after=rms)
    lines = _evidence_lines(diag)
    assert _cells(lines[0]) == ["effect", "dBIC", "z", "p"]
    assert _cells(lines[1]) == ["heading_bias", fmt3(ev["delta_bic"]), fmt3(ev["z"]), fmt3(ev["false_alarm_probability"])]
    text = summary_lines(diag)
    head = next(i for i, ln in enumerate(text) if ln.startswith("residual RMS"))
    assert _cells(text[head]) == ["residual RMS (replay - log)", "config", "ship fitted", "+ named"]
    for c, ln in zip(rms, text[head + 1:head + 6]):
        assert _cells(ln)[1:] == [fmt3(rms[c])] * 3, ln
    fig = Figure()
    _interval_panels(fig, fig.add_gridspec(7, 1), 0, diag)
    titles = [ax.get_title() for ax in fig.axes]
    assert any(t.startswith("heading bias = -2.00 deg") for t in titles), titles
    assert not any("bias_deg" in t for t in titles)
