"""Reproduction of Artyszuk (2018), Tables 1-8, with the paper's values beside ours.

The ``PAPER_*`` constants are the numbers *printed in the paper* (for
comparison only); every "ours" column is computed here from the models of
eqs. (24)/(25) (``configs/nomoto/artyszuk_eq24.yaml``, ``artyszuk_eq25.yaml``) or,
for the tables that take the paper's rounded inputs (2 from 1, 4 from 3, 6
from 5, 7, 8), by running :func:`trials.analysis.nomoto.four_point` on those inputs.

Beyond the paper, :func:`table8_robust` repeats the Table 8 perturbations on a
whole simulated record and adds heading noise, comparing the four-point
method with the least-squares (eq. 15 integrated twice) and output-error fits.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd

from mmg.resources import config_path
from trials.analysis import nomoto as nm

PI18 = np.pi / 18.0
POINTS = ("CR1", "OS1", "CR2", "OS2")
DELTA_SIGN = {"CR1": 1.0, "OS1": -1.0, "CR2": -1.0, "OS2": 1.0}  # eq. (18), fourth column

# ---- the paper's printed numbers (comparison only) ------------------------------
#            s'      eps'      omega'   Delta     psi[rad]  psi[deg]
PAPER_TABLE1 = {
    "CR1": (1.857, 0.06522, 0.17240, 0.28617, 0.17453, 10.0),
    "OS1": (3.352, -0.09620, 0.0, 0.17701, 0.32594, 18.675),
    "CR2": (7.015, -0.05652, -0.25500, -0.46231, -0.17453, -10.0),
    "OS2": (9.305, 0.08246, 0.0, -0.21439, -0.46824, -26.828),
}
PAPER_TABLE3 = {
    "CR1": (2.287, 0.07037, 0.16247, 0.36121, 0.17453, 10.0),
    "OS1": (4.719, -0.08714, 0.0, 0.08852, 0.43252, 24.782),
    "CR2": (8.704, -0.05804, -0.28537, -0.60700, -0.17453, -10.0),
    "OS2": (12.180, 0.08714, 0.0, -0.15209, -0.74676, -42.786),
}
PAPER_TABLE5 = {
    "CR1": (2.0, -0.00674, 0.14176, 0.32262, 0.17453, 10.0),
    "OS1": (3.6, -0.16082, 0.0, 0.14915, 0.31254, 17.907),
    "CR2": (6.2, 0.07979, -0.24937, -0.30464, -0.17453, -10.0),
    "OS2": (8.0, 0.17470, 0.0, -0.09626, -0.43634, -25.000),
}
PAPER_TABLE2 = {"K": 4.8537, "T1": 10.3747, "T2": 0.2750, "T3": 0.9534}
PAPER_TABLE4 = {"K": 4.9447, "T1": 9.9023, "T2": -2.2113, "T3": -2.2050}
PAPER_TABLE6 = {"K": -0.194, "T1": np.nan, "T2": np.nan, "T3": 28.748}
PAPER_TABLE7 = {  # W, Wx1..Wx4 for Tables 1, 3, 5
    "table1": (2.584e-05, 7.371e-05, 2.752e-04, -1.254e-04, -1.196e-04),
    "table3": (6.233e-07, -1.365e-05, 4.794e-06, -3.082e-06, 6.796e-06),
    "table5": (-2.001e-04, -1.636e-03, -1.117e-03, -3.881e-05, 1.116e-03),
}
PAPER_CLASSICAL = {"K": 2.06, "T": 3.35}  # text after Table 8 (from Artyszuk 2016)

# Table 8 rows: label, {channel: {point: factor}} and the paper's K, T1, T2, T3
_E, _W, _P = "eps", "omega", "psi"


def _row(label, spec, K, T1, T2, T3):
    return (label, spec, (K, T1, T2, T3))


def _all(ch_pts, f):
    d = {}
    for ch, pts in ch_pts:
        d.setdefault(ch, {}).update({p: f for p in pts})
    return d


_EPS4 = (_E, POINTS)
_OM2 = (_W, ("CR1", "CR2"))
_PSI2 = (_P, ("OS1", "OS2"))
PAPER_TABLE8 = [
    _row("reference (Table 2)", {}, 4.854, 10.375, 0.275, 0.953),
    _row("eps' CR1 +10%", {_E: {"CR1": 1.1}}, 5.612, 12.479, 0.394, 1.164),
    _row("eps' CR1 -10%", {_E: {"CR1": 0.9}}, 4.544, 9.531, 0.211, 0.847),
    _row("eps' OS1 +10%", {_E: {"OS1": 1.1}}, 4.846, 10.346, 0.161, 0.837),
    _row("eps' OS1 -10%", {_E: {"OS1": 0.9}}, 4.902, 10.558, 0.944, 1.641),
    _row("eps' CR2 +10%", {_E: {"CR2": 1.1}}, 4.647, 9.758, 0.235, 0.884),
    _row("eps' CR2 -10%", {_E: {"CR2": 0.9}}, 5.196, 11.404, 0.332, 1.056),
    _row("eps' OS2 +10%", {_E: {"OS2": 1.1}}, 4.553, 9.721, 0.524, 1.220),
    _row("eps' OS2 -10%", {_E: {"OS2": 0.9}}, 4.971, 10.621, 0.187, 0.858),
    _row("omega' CR1 +10%", {_W: {"CR1": 1.1}}, -17.402, 1.038, -55.613, 2.950),
    _row("omega' CR1 +5%", {_W: {"CR1": 1.05}}, 10.250, 25.783, 0.680, 1.775),
    _row("omega' CR1 -10%", {_W: {"CR1": 0.9}}, 2.875, 5.327, -0.476, -0.121),
    _row("omega' CR1 -5%", {_W: {"CR1": 0.95}}, 3.494, 6.791, -0.125, 0.346),
    _row("omega' CR2 +10%", {_W: {"CR2": 1.1}}, 2.961, 5.092, -0.451, -0.044),
    _row("omega' CR2 +5%", {_W: {"CR2": 1.05}}, 3.536, 6.576, -0.112, 0.371),
    _row("omega' CR2 -10%", {_W: {"CR2": 0.9}}, -9.862, 1.003, -37.087, 3.283),
    _row("omega' CR2 -5%", {_W: {"CR2": 0.95}}, 11.015, 29.554, 0.664, 1.827),
    _row("psi OS1 +10%", {_P: {"OS1": 1.1}}, 4.870, 10.434, 0.505, 1.189),
    _row("psi OS1 -10%", {_P: {"OS1": 0.9}}, 4.837, 10.318, 0.042, 0.716),
    _row("psi OS2 +10%", {_P: {"OS2": 1.1}}, 5.189, 11.069, 0.032, 0.692),
    _row("psi OS2 -10%", {_P: {"OS2": 0.9}}, 4.519, 9.643, 0.555, 1.253),
    _row("all 8 {eps', omega', psi} +10%", _all([_EPS4, _OM2, _PSI2], 1.1), 5.205, 10.106, 0.250, 0.913),
    _row("all 8 {eps', omega', psi} -10%", _all([_EPS4, _OM2, _PSI2], 0.9), 4.502, 10.705, 0.304, 1.000),
    _row("all 4 {eps'} +10%", _all([_EPS4], 1.1), 4.854, 10.400, 0.249, 0.953),
    _row("all 4 {eps'} -10%", _all([_EPS4], 0.9), 4.854, 10.343, 0.306, 0.953),
    _row("all 6 {eps', omega'} +10%", _all([_EPS4, _OM2], 1.1), 4.854, 9.406, 0.276, 0.953),
    _row("all 6 {eps', omega'} -10%", _all([_EPS4, _OM2], 0.9), 4.854, 11.559, 0.274, 0.953),
    _row("all 2 {omega'} +10%", _all([_OM2], 1.1), 4.854, 9.377, 0.304, 0.953),
    _row("all 2 {omega'} -10%", _all([_OM2], 0.9), 4.854, 11.587, 0.246, 0.953),
    _row("all 4 {omega', psi} +10%", _all([_OM2, _PSI2], 1.1), 5.205, 10.080, 0.275, 0.913),
    _row("all 4 {omega', psi} -10%", _all([_OM2, _PSI2], 0.9), 4.502, 10.736, 0.273, 1.000),
]


# ---- helpers ------------------------------------------------------------------------
def paper_points(table: dict) -> nm.ZigzagPoints:
    """A paper input table (1, 3 or 5) as :class:`ZigzagPoints`.

    The rudder column and the counter-rudder headings are the nominal +-pi/18 of
    eq. (18); the other values are the paper's rounded numbers.

    Parameters
    ----------
    table : dict
        One of ``PAPER_TABLE1``, ``PAPER_TABLE3``, ``PAPER_TABLE5``.
    """
    rows = []
    for p in POINTS:
        s, e, w, D, psi, _ = table[p]
        if p.startswith("CR"):
            psi = np.sign(psi) * PI18
        rows.append({"s": s, "eps": e, "omega": w, "Delta": D, "delta": DELTA_SIGN[p] * PI18, "psi": psi})
    return nm.ZigzagPoints.from_rows(POINTS, rows)


def simulate_config(name: str, **overrides) -> nm.ZigzagSimulation:
    """Simulate the zigzag of a ``configs/nomoto/<name>.yaml`` file.

    Parameters
    ----------
    name : str
        Config stem, e.g. ``"artyszuk_eq24"``, or a path to a YAML file.
    **overrides
        Replace zigzag settings (delta0_deg, psi0_deg, rudder_rate_deg_per_L, s_max, ds).
    """
    path = Path(name) if str(name).endswith(".yaml") else config_path("nomoto", f"{name}.yaml")
    model = nm.load_model(path)
    z = nm.zigzag_spec(path)
    z.update(overrides)
    return nm.simulate_zigzag(model, z["delta0_deg"], z["psi0_deg"], z["rudder_rate_deg_per_L"], z["s_max"], z["ds"])


def _pct(ours, ref):
    return 100.0 * (ours - ref) / ref if (np.isfinite(ref) and ref != 0) else np.nan


# ---- Tables 1/3: simulated inputs -----------------------------------------------
def table_inputs(sim: nm.ZigzagSimulation, paper: dict) -> pd.DataFrame:
    """Tables 1/3: s', eps', omega', Delta, psi at CR1, OS1, CR2, OS2, ours vs paper.

    Parameters
    ----------
    sim : ZigzagSimulation
        Our simulation of eq. (24) or (25).
    paper : dict
        ``PAPER_TABLE1`` or ``PAPER_TABLE3``.
    """
    pts = sim.points(2)
    rows = []
    for i, p in enumerate(POINTS):
        ps, pe, pw, pD, prad, pdeg = paper[p]
        ours = {"s'": pts.s[i], "eps'": pts.eps[i], "omega'": pts.omega[i], "Delta": pts.Delta[i],
                "psi [deg]": np.degrees(pts.psi[i])}
        ref = {"s'": ps, "eps'": pe, "omega'": pw, "Delta": pD, "psi [deg]": pdeg}
        row = {"point": p}
        for k in ours:
            row[f"{k} ours"] = ours[k]
            row[f"{k} paper"] = ref[k]
        row["s' diff %"] = _pct(ours["s'"], ps)
        row["psi diff %"] = _pct(ours["psi [deg]"], pdeg)
        rows.append(row)
    return pd.DataFrame(rows)


# ---- Tables 2/4/6: four-point output ----------------------------------------------
def table_params(results: dict, paper: dict, true: dict | None = None) -> pd.DataFrame:
    """Parameter table: rows K, T1, T2, T3, T2/T1, T3/T2; one column per result plus the paper.

    Parameters
    ----------
    results : dict
        {column label: FourPointResult or NomotoModel-like with K, T1, T2, T3}.
    paper : dict
        The paper's K, T1, T2, T3.
    true : dict, optional
        The generating model's K, T1, T2, T3 (adds "% vs true" columns).
    """
    def vals(r):
        K, T1, T2, T3 = (r["K"], r["T1"], r["T2"], r["T3"]) if isinstance(r, dict) else (r.K, r.T1, r.T2, r.T3)
        return {"K": K, "T1": T1, "T2": T2, "T3": T3, "T2/T1": T2 / T1, "T3/T2": T3 / T2}

    cols = {"paper": vals(paper)}
    cols.update({k: vals(v) for k, v in results.items()})
    df = pd.DataFrame(cols)
    if true is not None:
        tv = vals(true)
        df.insert(0, "true", pd.Series(tv))
        for k in ["paper"] + list(results):
            df[f"{k} % vs true"] = [_pct(df.loc[i, k], tv[i]) for i in df.index]
    df.index.name = "parameter"
    return df.reset_index()


def table7(results: dict) -> pd.DataFrame:
    """Table 7: determinants W, W_x1..W_x4, ours vs paper.

    Parameters
    ----------
    results : dict
        {"table1"|"table3"|"table5": FourPointResult} computed from the paper's inputs.
    """
    names = ["W (main)", "W_x1", "W_x2", "W_x3", "W_x4"]
    out = {"determinant": names}
    for key, r in results.items():
        out[f"{key} ours"] = [r.W, *r.Wx]
        out[f"{key} paper"] = list(PAPER_TABLE7[key])
    return pd.DataFrame(out)


def table8(points: nm.ZigzagPoints, true: dict) -> pd.DataFrame:
    """Table 8: four-point results for the paper's input perturbations.

    Parameters
    ----------
    points : ZigzagPoints
        Reference inputs (the paper's Table 1).
    true : dict
        eq. (24) parameters for the % columns.
    """
    rows = []
    for label, spec, (pK, pT1, pT2, pT3) in PAPER_TABLE8:
        r = nm.four_point(points.scaled(**spec))
        row = {"variation": label}
        for k, ours, pap in (("K", r.K, pK), ("T1", r.T1, pT1), ("T2", r.T2, pT2), ("T3", r.T3, pT3)):
            row[f"{k} ours"] = ours
            row[f"{k} paper"] = pap
            row[f"{k} % ours"] = _pct(ours, true[k])
        rows.append(row)
    return pd.DataFrame(rows)


# ---- beyond the paper: Table 8 on a whole record ----------------------------------
def _window_scale(z: nm.ZigzagData, spec: dict, half_width: float) -> nm.ZigzagData:
    """Scale channels by factors in windows |s' - s'_point| <= half_width around named points."""
    at = {"CR1": z.s_cr[0], "OS1": z.s_os[0], "CR2": z.s_cr[1], "OS2": z.s_os[1]}
    # half_width 0: the one sample nearest to the point
    near = {p: np.abs(z.s - v) <= max(half_width, np.min(np.abs(z.s - v))) for p, v in at.items()}
    kw = {}
    for ch, pts in spec.items():
        arr = getattr(z, ch).copy()
        for p, f in pts.items():
            arr[near[p]] *= f
        kw[ch] = arr
        if ch == "psi" and z.psi_raw is not None:  # the fits read the raw heading
            raw = kw.get("psi_raw", z.psi_raw.copy())
            for p, f in pts.items():
                raw[near[p]] *= f
            kw["psi_raw"] = raw
    return dataclasses.replace(z, **kw)


def sim_record(sim: nm.ZigzagSimulation, ds: float = 0.01, L: float = 100.0, U: float = 5.0,
               heading_noise_deg: float = 0.0, heading_only: bool = False, seed: int = 0):
    """A TrialRecord sampled every ``ds`` from a simulation, optionally with white heading noise.

    Parameters
    ----------
    sim : ZigzagSimulation
        Source simulation (fine grid).
    ds : float
        Sampling step in s' [-] (0.01 = 0.2 s for L = 100 m, U = 5 m/s).
    L, U : float
        Ship length [m] and speed [m/s] given to the record.
    heading_noise_deg : float
        Standard deviation of Gaussian heading noise [deg].
    heading_only : bool
        Drop the yaw-rate channel (derivatives then come from the heading).
    seed : int
        Random seed.
    """
    step = max(1, int(round(ds / (sim.s[1] - sim.s[0]))))
    rec = sim.to_record(L, U)
    idx = np.arange(0, len(rec.t), step)
    rng = np.random.default_rng(seed)
    psi = rec.psi[idx] + np.radians(heading_noise_deg) * rng.standard_normal(len(idx))
    return dataclasses.replace(rec, t=rec.t[idx], psi=psi, r=None if heading_only else rec.r[idx],
                               delta=rec.delta[idx], U=rec.U[idx])


def table8_robust(sim: nm.ZigzagSimulation, true: dict, half_width: float = 0.5, noise_deg: float = 0.05,
                  n_seeds: int = 5, output_error: bool = True, rows: list | None = None) -> pd.DataFrame:
    """Table 8 perturbations applied to a whole simulated record; four-point vs least squares vs output error.

    Each Table 8 variation "channel X at point P by f" multiplies channel X over
    the samples within ``half_width`` ship lengths of P (so it is a local bias
    lasting one ship length, not a single sample); the four-point method sees
    exactly the paper's perturbation at P.  Then ``n_seeds`` records with white
    heading noise (std ``noise_deg``) and heading only (omega', eps' from the
    smoothing spline) are identified by all three methods (mean and worst error).

    Parameters
    ----------
    sim : ZigzagSimulation
        Noise-free 2nd-order simulation (eq. 24).
    true : dict
        True K, T1, T2, T3.
    half_width : float
        Perturbation window half-width [-].
    noise_deg : float
        Heading noise std [deg].
    n_seeds : int
        Noisy realisations.
    output_error : bool
        Include the output-error fit (about a second per row).
    rows : list, optional
        Subset of Table 8 labels (default all).
    """
    L, U = 100.0, 5.0
    z0 = nm.zigzag_data(sim_record(sim), L, U)
    out = []

    def add(label, fp, ls, oe):
        row = {"variation": label}
        for meth, r in (("four-point", fp), ("least squares", ls), ("output error", oe)):
            for k in ("K", "T1", "T2", "T3"):
                row[f"{k} % {meth}"] = np.nan if r is None else _pct(getattr(r, k), true[k])
        out.append(row)

    for label, spec, _ in PAPER_TABLE8:
        if rows is not None and label not in rows:
            continue
        z = _window_scale(z0, spec, half_width) if spec else z0
        fp = nm.four_point(z0.points(2).scaled(**spec))
        ls = nm.fit_least_squares(z)
        oe = nm.fit_output_error(z) if output_error else None
        add(label, fp, ls, oe)
    if n_seeds <= 0:
        return pd.DataFrame(out)
    # heading noise, heading only
    res = {"four-point": [], "least squares": [], "output error": []}
    for seed in range(n_seeds):
        z = nm.zigzag_data(sim_record(sim, heading_noise_deg=noise_deg, heading_only=True, seed=seed), L, U)
        res["four-point"].append(nm.four_point(z.points(2)))
        res["least squares"].append(nm.fit_least_squares(z))
        if output_error:
            res["output error"].append(nm.fit_output_error(z))
    for agg, fn in (("mean", np.nanmean), ("worst", lambda a: a[np.nanargmax(np.abs(a))])):
        row = {"variation": f"heading noise {noise_deg} deg, heading only, {n_seeds} seeds ({agg})"}
        for meth, rs in res.items():
            for k in ("K", "T1", "T2", "T3"):
                v = np.array([_pct(getattr(r, k), true[k]) for r in rs]) if rs else np.array([np.nan])
                row[f"{k} % {meth}"] = fn(v) if np.isfinite(v).any() else np.nan
        out.append(row)
    return pd.DataFrame(out)


# ---- all tables ---------------------------------------------------------------------
def reproduce(fast: bool = False) -> dict:
    """All reproduced tables as DataFrames keyed "table1" ... "table8", "table8_robust", "classical".

    Parameters
    ----------
    fast : bool
        Skip the output-error fits in ``table8_robust`` and use 2 noise seeds.
    """
    sim2 = simulate_config("artyszuk_eq24")
    sim1 = simulate_config("artyszuk_eq25")
    m24, m25 = sim2.model, sim1.model
    true24 = {"K": m24.K, "T1": m24.T1, "T2": m24.T2, "T3": m24.T3}
    true25 = {"K": m25.K, "T1": m25.T1, "T2": np.nan, "T3": np.nan}
    p1, p3, p5 = paper_points(PAPER_TABLE1), paper_points(PAPER_TABLE3), paper_points(PAPER_TABLE5)
    f1, f3, f5 = nm.four_point(p1), nm.four_point(p3), nm.four_point(p5)
    out = {
        "table1": table_inputs(sim2, PAPER_TABLE1),
        "table2": table_params({"ours from paper Table 1": f1,
                                "ours from our simulation": nm.four_point(sim2.points())},
                               PAPER_TABLE2, true24),
        "table3": table_inputs(sim1, PAPER_TABLE3),
        "table4": table_params({"ours from paper Table 3": f3,
                                "ours from our simulation": nm.four_point(sim1.points())},
                               PAPER_TABLE4, true25),
        "table5": pd.DataFrame([{"point": p, **dict(zip(["s'", "eps'", "omega'", "Delta", "psi [rad]", "psi [deg]"],
                                                      PAPER_TABLE5[p]))} for p in POINTS]),
        "table6": table_params({"ours from paper Table 5": f5}, PAPER_TABLE6),
        "table7": table7({"table1": f1, "table3": f3, "table5": f5}),
        "table8": table8(p1, true24),
    }
    cl = nm.classical_first_order(sim2, n_half=3)
    cdf = cl.to_pandas()
    cdf["half_cycle"] = cdf["half_cycle"].astype(object)
    cdf.loc[len(cdf)] = {"half_cycle": "mean", "K": cl.K, "T_cr": cl.T, "K_os": cl.K_os, "T_os": cl.T_os,
                         "T_zero": float(np.nanmean(cdf["T_zero"]))}
    cdf.loc[len(cdf)] = {"half_cycle": "paper (Artyszuk 2016)", "K": PAPER_CLASSICAL["K"], "T_cr": PAPER_CLASSICAL["T"]}
    out["classical"] = cdf
    out["table8_robust"] = table8_robust(sim2, true24, output_error=not fast, n_seeds=2 if fast else 5)
    psi_rows = [r[0] for r in PAPER_TABLE8 if "psi" in r[1] or not r[1]]
    out["table8_robust_point"] = table8_robust(sim2, true24, half_width=0.0, output_error=not fast, n_seeds=0,
                                               rows=psi_rows)
    out["notes"] = {
        "table1": inputs_note(sim2, PAPER_TABLE1),
        "table2": params_note(out["table2"], "Table 1", "eq. (24)"),
        "table3": inputs_note(sim1, PAPER_TABLE3),
        "table4": table4_note(out["table4"], nm.four_point(sim1.points())),
        "table6": table6_note(f5),
        "table7": table7_note(out["table7"]),
        "table8": table8_note(out["table8"]),
        "classical": classical_note(cdf),
        "table8_robust_empty": ("the output-error fits (about 5 minutes) are not run here: `mmg nomoto-paper` "
                                "(without --fast) or `mmg reproduce --full` runs them" if fast else "no fit returned a value"),
        "table4_ours_from_simulation": nm.four_point(sim1.points()).note(),
    }
    out["notes"]["table8_robust_point_empty"] = out["notes"]["table8_robust_empty"]
    return out


# ---- the notes under the tables: every disagreement with the paper explained ------------------------
def _rel(a, b) -> float:
    return abs(a - b) / abs(b) * 100.0 if b != 0 else np.nan


def inputs_note(sim: nm.ZigzagSimulation, paper: dict) -> str:
    """Why our Table 1 / 3 differs from the paper's: where the paper's points lie and what moves with them."""
    pts = sim.points(2)
    worst = {}
    for k, arr, j in (("eps", pts.eps, 1), ("Delta", pts.Delta, 3)):
        d = [(_rel(arr[i], paper[p][j]), p) for i, p in enumerate(POINTS) if paper[p][j] != 0]
        worst[k] = max(d)
    ds = max(abs(pts.s[i] - paper[p][0]) for i, p in enumerate(POINTS))
    psi_cr1 = np.degrees(sim.state_at(paper["CR1"][0])["psi"])
    return (f"The paper's points lie up to {ds:.4f} L from ours (at the paper's CR1, s' = {paper['CR1'][0]}, our heading "
            f"is {psi_cr1:.3f} deg, not 10): the paper integrated its model with a step of 0.002 and interpolated to "
            "0.001, ours is exact between the rudder's corners. The values that change fastest at a point move "
            f"with its abscissa: eps' at a counter-rudder (up to {worst['eps'][0]:.2g} % at "
            f"{worst['eps'][1]}: the rudder starts to move there, and eps' turns sharply) and "
            f"Delta after one (up to {worst['Delta'][0]:.2g} % at {worst['Delta'][1]}: the integral of the rudder "
            "depends on when it reversed). omega' is 0 at an overshoot by definition (ours to round-off); the psi of a "
            "counter-rudder is the nominal 10 deg in both.")


def params_note(df: pd.DataFrame, source: str, model: str) -> str:
    """Why the paper's four-point output and ours from its printed input differ (Tables 2)."""
    col = f"ours from paper {source}"
    d = max(_rel(a, b) for a, b in zip(df[col], df["paper"]) if np.isfinite(a) and np.isfinite(b))
    return (f"The paper's output and ours from its {source} differ by at most {d:.2g} %: the paper solved eq. (18) "
            f"with its unrounded points, {source} prints them rounded to 4-5 digits. Both miss {model} by 1-8 % "
            "(T2 most: a small difference of large numbers) because of that rounding, as the paper says in its "
            f"Discussion; from our unrounded points (last columns) the four-point method returns {model} to round-off.")


def table4_note(df: pd.DataFrame, ours_sim) -> str:
    """Why T2 and T3 of Table 4 differ (indeterminate for first-order data)."""
    kt = df[df["parameter"].isin(["K", "T1"])]
    d = max(_rel(a, b) for a, b in zip(kt["ours from paper Table 3"], kt["paper"]))
    t2 = df.set_index("parameter")
    note = (f"K and T1 (= T) agree with the paper's within {d:.2g} % (its unrounded inputs, as in Table 2). "
            "T2 and T3 are indeterminate for first-order data: such data need only T2 = T3, whatever their value "
            "(eq. 26 and the paper's text), so the T2, T3 printed are set by the inputs' rounding, not by the ship: "
            f"the paper's {t2.loc['T2', 'paper']:.4g} and ours {t2.loc['T2', 'ours from paper Table 3']:.4g} from the "
            f"same rounded Table 3 differ, while T3/T2 is about 1 in every column.")
    return note + (f" Ours from our simulation: {ours_sim.note()}." if ours_sim.note() else "")


def table6_note(f5) -> str:
    """The sign of T3 in Table 6: the paper's own Table 7 gives a negative T3."""
    W, _, _, Wx3, Wx4 = PAPER_TABLE7["table5"]
    x3, x4 = Wx3 / W, Wx4 / W
    return (f"T3: ours is negative, the paper prints +{PAPER_TABLE6['T3']}. The sign is not a convention: by eqs. (16) "
            f"and (23), x3 = -K and x4 = -K T3, so T3 = x4 / x3, and the paper's own Table 7 determinants give "
            f"x3 = W_x3 / W = {x3:.4g} (K = {-x3:.3g}, as it prints) and x4 = W_x4 / W = {x4:.4g}, so T3 = "
            f"{x4 / x3:.5g}: negative, of the paper's magnitude. The paper's +{PAPER_TABLE6['T3']} is, to the rounding "
            "of those determinants, x4 / K = -x4 / x3: most likely the minus of K = -x3 was dropped in that division "
            "(or |T3| printed). "
            f"Our magnitude differs from {abs(x4 / x3):.5g} by the rounding of the inputs (Table 5 prints the "
            "smoothing's output to 5 digits; see Table 7). The \"1.0\" the paper prints as T1's % is a leftover of "
            "Table 4: it has no T1. " + (f5.note() + "." if f5.note() else ""))


def table7_note(df: pd.DataFrame) -> str:
    """Why our determinants differ from the paper's."""
    d = {k: max(_rel(a, b) for a, b in zip(df[f"{k} ours"], df[f"{k} paper"])) for k in ("table1", "table3", "table5")}
    return (f"Ours from the paper's rounded inputs, the paper's from its unrounded ones: they differ by at most "
            f"{d['table1']:.2g} % (Table 1 case) and {d['table5']:.2g} % (Table 5 case), but {d['table3']:.2g} % in "
            "the Table 3 case: first-order data make eq. (18) nearly singular (W = 6e-7 against 2.6e-5), each "
            "determinant a small difference of large products, which the fifth-digit rounding of the inputs moves "
            "by a few per cent.")


def table8_note(df: pd.DataFrame) -> str:
    """Why our Table 8 differs from the paper's."""
    worst = (0.0, "", "")
    for k in ("K", "T1", "T2", "T3"):
        for lab, a, b in zip(df["variation"], df[f"{k} ours"], df[f"{k} paper"]):
            r = _rel(a, b)
            if np.isfinite(r) and abs(a - b) > 0.0005 and r > worst[0]:       # beyond the paper's 3 decimals
                worst = (r, k, lab)
    return (f"Ours from the paper's Table 1 as printed, the paper's from its unrounded points: beyond the paper's "
            f"3 decimals they differ by at most {worst[0]:.2g} % ({worst[1]}, \"{worst[2]}\"), most where the "
            "method breaks down (omega' +-10 %: eq. 18 is nearly singular there and amplifies the inputs' "
            "rounding). \"% ours\" is against eq. (24), like the paper's % columns (not repeated here).")


def classical_note(cdf: pd.DataFrame) -> str:
    """Why our classical K, T differ from the paper's quoted 2.06, 3.35."""
    hc = cdf[cdf["half_cycle"].apply(lambda v: isinstance(v, (int, np.integer)))]
    ks = pd.concat([hc["K"], hc["K_os"]]).astype(float)
    ts = pd.concat([hc["T_zero"], hc["T_cr"], hc["T_os"]]).astype(float)
    inside = (ks.min() <= PAPER_CLASSICAL["K"] <= ks.max()) and (ts.min() <= PAPER_CLASSICAL["T"] <= ts.max())
    return (f"The paper's K = {PAPER_CLASSICAL['K']}, T = {PAPER_CLASSICAL['T']} come from Artyszuk (2016), whose "
            "half-cycles and T formula (eq. 11 at the zero crossing or eq. 12 at the counter-rudder) the 2018 paper "
            f"does not give; ours range over {ks.min():.3g}-{ks.max():.3g} (K) and {ts.min():.3g}-{ts.max():.3g} (T) "
            "across the half-cycles and formulas, " + ("which contains the paper's values." if inside else
                                                        "which does NOT contain the paper's values: unexplained."))


PCT_ATOL = 1e-9
"""A percentage column's numerical zero [%]: a relative error of 1e-11 is round-off of an exact 0."""


def printable(df: pd.DataFrame) -> tuple[pd.DataFrame, list]:
    """The table as printed: columns without a single value (all NaN) left out, numerical zeros
    exact (:func:`trials.files.output.numerical_zeros`, per column; a "%" column also below ``PCT_ATOL``).

    Returns
    -------
    (DataFrame, list of str)
        The printed table and the names of the columns left out.
    """
    from ..files.output import numerical_zeros

    empty = [c for c in df.columns if pd.api.types.is_numeric_dtype(df[c]) and not np.isfinite(
        pd.to_numeric(df[c], errors="coerce").to_numpy(dtype=float)).any()]
    out = df.drop(columns=empty)
    for c in out.columns:
        if pd.api.types.is_float_dtype(out[c]):
            out[c] = numerical_zeros(out[c].tolist(), atol=PCT_ATOL if "%" in str(c) else 0.0).astype(float)
    return out, empty


PCT_DECIMALS = 1
"""Decimals of a per-cent column (a name with " % "): an error of a few hundredths of a per cent is 0.0."""
UNUSABLE_PCT = 100.0
"""A per-cent error beyond which a method has not identified the parameter at all (:func:`unusable_note`)."""


def to_markdown(df: pd.DataFrame, floatfmt: str = "{:.5g}") -> str:
    """A DataFrame as a GitHub Markdown table (no extra dependency), as :func:`printable` leaves it:
    all-NaN columns left out (say why beside the table), numerical zeros printed as 0, NaN as n/a; a
    per-cent column (" % " in its name) with :data:`PCT_DECIMALS` decimals, no more precision than it has."""
    df, _ = printable(df)
    cols = list(df.columns)
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for _, r in df.iterrows():
        lines.append("| " + " | ".join(_cell(r[c], c, floatfmt) for c in cols) + " |")
    return "\n".join(lines)


def _cell(v, col: str, floatfmt: str = "{:.5g}") -> str:
    """One printed cell of column ``col``: NaN as n/a, a per-cent column (" % " in its name) with
    :data:`PCT_DECIMALS` decimals, other numbers with ``floatfmt`` (a numerical zero as 0)."""
    if isinstance(v, (float, np.floating)):
        if not np.isfinite(v):
            return "n/a"
        if " % " in col:
            return f"{v:.{PCT_DECIMALS}f}"
        return "0" if v == 0 else floatfmt.format(v)
    return str(v)


def to_text(df: pd.DataFrame, floatfmt: str = "{:.5g}") -> str:
    """A DataFrame as a console table with the cells of :func:`to_markdown` (columns that cannot run
    together, :func:`trials.files.tables.text_table`)."""
    from ..files.tables import text_table

    df, _ = printable(df)
    cols = [str(c) for c in df.columns]
    rows = [[_cell(r[c], str(c), floatfmt) for c in df.columns] for _, r in df.iterrows()]
    return "\n".join(text_table(cols, rows, align=">" * len(cols)))


def text_parts(tables: dict) -> list:
    """The console's lines of ``mmg nomoto-paper``: each table of :func:`reproduce` under its title, the
    note naming its unusable errors (:func:`unusable_note`) and its own note, as :func:`markdown_parts`."""
    notes = tables.get("notes", {})
    out = []
    for key, title in TITLES.items():
        if key not in tables:
            continue
        out += ["", title, to_text(tables[key])]
        out += [f"note: {n}" for n in (unusable_note(tables[key]), notes.get(key)) if n]
    return out


def unusable_note(df: pd.DataFrame) -> str:
    """One sentence naming the per-cent errors beyond +-:data:`UNUSABLE_PCT` (the column and the rows' first
    cell): there the method has not identified the parameter, whatever the digits say; "" where none is."""
    cols = [c for c in df.columns if " % " in c]
    bad = []
    for c in cols:
        rows = [str(r.iloc[0]) for _, r in df.iterrows() if np.isfinite(r[c]) and abs(r[c]) > UNUSABLE_PCT]
        if rows:
            bad.append(f"{c} on {', '.join(rows)}")
    if not bad:
        return ""
    return (f"Errors beyond +-{UNUSABLE_PCT:g} % (the method did not identify the parameter there; such a fit is "
            f"unusable, not merely inaccurate): {'; '.join(bad)}.")


def markdown_parts(tables: dict, level: int = 2) -> list:
    """Each table of :func:`reproduce` under its title (``level`` '#'), the columns left out named, and
    its note (every disagreement with the paper explained where it stands): the Markdown of
    ``mmg nomoto-paper`` and of section 6 of ``mmg reproduce``."""
    notes = tables.get("notes", {})
    md = []
    for key, title in TITLES.items():
        if key not in tables:
            continue
        md += [f"{'#' * level} {title}\n", to_markdown(tables[key]), ""]
        if unusable_note(tables[key]):
            md += [unusable_note(tables[key]) + "\n"]
        _, empty = printable(tables[key])
        if empty:
            why = notes.get(f"{key}_empty", "no value in any row")
            md += [f"Columns left out (no value in any row): {', '.join(empty)}; {why}\n"]
        if notes.get(key):
            md += [f"Note: {notes[key]}\n"]
    return md


TITLES = {
    "table1": "Table 1. Simulated input, 2nd order (eq. 24): ours vs paper",
    "table2": "Table 2. Four-point output, 2nd order",
    "table3": "Table 3. Simulated input, 1st order (eq. 25): ours vs paper",
    "table4": "Table 4. Four-point output, 1st order (T1 = T; T2, T3 indeterminate)",
    "table5": "Table 5. Real (smoothed) input, chemical tanker (paper's values, input only)",
    "table6": "Table 6. Four-point output, chemical tanker",
    "table7": "Table 7. Determinants of eq. (18)",
    "table8": "Table 8. Four-point output for perturbed Table 1 inputs",
    "classical": "Classical 1st-order K, T (Nomoto 1960) on the 2nd-order record (paper: K = 2.06, T = 3.35)",
    "table8_robust": "Table 8 extended: % error vs eq. (24), four-point vs least squares vs output error "
                     "(record perturbed over +-0.5 L around the point; then heading noise)",
    "table8_robust_point": "Table 8 extended, literal: only the sample at the point perturbed "
                           "(rows that perturb psi; eps'/omega' rows do not enter the whole-record fits)",
}


def write_tables(tables: dict, out_dir) -> list:
    """Write each table as CSV and all of them into one Markdown file; return the paths.

    Parameters
    ----------
    tables : dict
        From :func:`reproduce`.
    out_dir : str or Path
        Output folder (created).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for key in TITLES:
        if key not in tables:
            continue
        p = out_dir / f"{key}.csv"
        tables[key].to_csv(p, index=False)
        paths.append(p)
    md = ["# Artyszuk (2018) tables reproduced\n", *markdown_parts(tables)]
    p = out_dir / "artyszuk_tables.md"
    p.write_text("\n".join(md))
    paths.append(p)
    return paths
