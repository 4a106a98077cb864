"""Do ``mmg imo``'s 90 % intervals cover the truth?  Synthetic identifications of a known ship, many seeds.

Per seed: a *true* ship (``esso_osaka_3m`` with every parameter ``mmg identify`` frees by default
multiplied by 1 + U(-0.15, 0.15), drawn from the seed); records of it made by the project's record
machinery (:func:`trials.measured.diagnose_records.synthetic_record`: closed-loop trial, replayed and
logged with uniform log noise of the development set's half-widths Froude-scaled to the 3 m model:
u, v 0.02 / sqrt(lambda) m/s, r 0.0002 sqrt(lambda) rad/s, x, y 0.5 / lambda m, psi 0.05 deg); the
ship identified from the config prior with :func:`trials.measured.identify.identify` as ``mmg
identify`` does (its default free set, stages, weighting and evaluation limit); :func:`trials.imo.imo`
with ``samples`` parameter draws from the fit's covariance (:func:`~trials.measured.identify.fit_covariance`,
what ``mmg identify`` writes into ship.yaml); the true ship's own criteria.  Counted: how often each
criterion's 90 % interval holds the true value.

Variants (the same seeds and draws' seed; no factor is tuned on them):

* ``written``: what ``mmg identify`` writes into ship.yaml
  (:func:`trials.measured.identify.identification_covariance`: the linearised posterior with the prior
  at its stated std and the data's information divided by the fit's residuals' correlation time tau,
  plus the delete-one-run jackknife over the records);
* ``run-jackknife``: the run-to-run part alone (:func:`trials.measured.identify.run_covariance`; with a
  seed's four records a rank-3 matrix: it leaves most directions to the prior);
* ``gauss-newton``: the fit's own Gauss-Newton covariance (:func:`~trials.measured.identify.fit_covariance`:
  what ``mmg identify`` wrote before);
* ``tau``: that covariance times the residuals' integrated autocorrelation time tau (samples, the mean
  over u, v, r, psi of each channel's median over the records; since the start-state fit, of the fit's own
  residuals at its stride, :attr:`~trials.measured.identify.Identification.tau`; before, of the identified
  model's open-loop residuals from the first sample at the full rate), i.e. the standard errors times sqrt(tau), as ``mmg diagnose`` inflates its own
  (:func:`trials.measured.diagnose._tau`): N residuals carry about N / tau independent ones;
* ``prior-stated``: the linearised posterior with the prior at its stated std.  :func:`ekf.identify._result`
  scales the whole inverse J^T J by the residual variance s^2, prior rows included, so a good fit
  (s^2 << 1 in the residual scales) shrinks the *prior's* std too, by s; here J^T J is split into the
  data part (J^T J - diag(1 / sigma_prior^2), reconstructed from the written covariance, s^2 and the
  priors) scaled by the data rows' own residual variance, plus the prior's information unscaled:
  cov = (J_d^T J_d / s_d^2 + diag(1 / sigma_prior^2))^-1;
* ``prior-stated-tau``: the same with the data part's variance times tau (the written covariance's
  posterior part alone);
* ``per-channel`` (added after seeds 0-39 showed the u, v, r residuals white, tau ~ 1, and the heading's
  correlated over the whole record, tau ~ 75 samples: the channel mean understates the heading's; judged
  on fresh seeds only): the posterior with each record's channel weighted by its own residual variance and
  correlation time, cov = (sum_kj J_kj^T J_kj / (s_kj^2 tau_kj) + diag(1 / sigma_prior^2))^-1, J_kj the
  open-loop replay's sensitivity of record k's channel j (u, v, r, psi) to the fitted parameters (forward
  differences at the identified values).

Every variant's covariance is the shared parameters' block (each record's start-state offsets, fitted as
nuisance parameters, marginalised out).  ``--initial-state sample`` identifies as before the start-state fit
(each replay from the raw first sample).

Usage: ``python bench/imo_coverage.py --seeds 24 --seed0 500 --samples 64 [--out bench_imo_coverage.json]``.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

SHIP = "esso_osaka_3m"
LAMBDA = 325.0 / 3.0
NOISE = (0.02 / math.sqrt(LAMBDA), 0.02 / math.sqrt(LAMBDA), 0.0002 * math.sqrt(LAMBDA), 0.5 / LAMBDA, 0.5 / LAMBDA,
         math.radians(0.05))
"""Uniform half-widths (u, v, r, x, y, psi) of the development set's log noise, Froude-scaled to 3 m."""
RECORDS = (("turning", 35.0, 60.0), ("turning", -35.0, 60.0), ("zigzag", 20.0, 70.0), ("zigzag", -10.0, 70.0))
"""(kind, rudder [deg], duration [s]) of each seed's records: short (60-70 s, about 110-130 sqrt(L/g))."""
PERTURB = 0.15
ALL_VARIANTS = ("written", "gauss-newton", "tau", "prior-stated", "prior-stated-tau", "per-channel", "run-jackknife")
VARIANTS = ALL_VARIANTS
"""The variants counted (``--variants``)."""
TRUTH = SHIP
"""``--truth``: the ship config the true ship is drawn around (``esso_osaka_3m_crossflow``: a model-form
mismatch, records of the cross-flow hull identified in the Kijima form)."""


def silent(*_a, **_k):
    return None


def true_ship(prior, seed: int):
    """The prior with each default-free parameter times 1 + U(-PERTURB, PERTURB) (hull, w_P0, rudder constants)."""
    from trials.imo.sampling import _ship_values
    from trials.measured.identify import DEFAULT_FREE, _free_names, ship_with_values

    names = [n for n in _free_names(prior, DEFAULT_FREE) if n != "wind_scale"]
    base = _ship_values(prior, names)
    f = 1.0 + np.random.default_rng([seed, 1]).uniform(-PERTURB, PERTURB, len(names))
    return ship_with_values(prior, dict(zip(names, base * f)))


EXACT_START = False
"""``--exact-start``: each record's first sample without its noise (an oracle experiment on the cause of the
under-coverage: the open-loop replay starts from the first measured sample, whose noise drifts the whole
record and is absorbed by the parameters; not ``mmg identify``'s procedure)."""


def records(prior, truth, seed: int, dt: float = 0.2):
    """The seed's records of ``truth`` as MeasuredRuns of ``prior`` (no wind, calm water)."""
    from trials.measured.diagnose_records import Manoeuvre, RecordNoise, synthetic_record
    from trials.measured.predict import measured_run

    out = []
    for k, (kind, rud, dur) in enumerate(RECORDS):
        man = Manoeuvre(kind, rudder_deg=rud, duration=dur, dt=dt)
        rec = synthetic_record(prior, man, truth_ship=truth, noise=RecordNoise(NOISE, "uniform", seed * 100 + k),
                               name=f"{kind}{rud:+g}")
        run = measured_run(prior, rec, wind=False)
        if EXACT_START:
            from dataclasses import replace

            clean = synthetic_record(prior, man, truth_ship=truth, noise=RecordNoise((0.0,) * 6, "uniform"),
                                     name="clean")
            m = run.meas.copy()
            m[0] = measured_run(prior, clean, wind=False).meas[0]
            run = replace(run, meas=m)
        out.append(run)
    return out


INITIAL_STATE = "fit"
"""``--initial-state``: :func:`trials.measured.identify.identify`'s ``initial_state``."""


def residual_tau(ident) -> float:
    """The fit's residuals' correlation time (:attr:`~trials.measured.identify.Identification.tau`); with
    ``--initial-state sample``, as before: the mean over u, v, r, psi of the median over the records of the
    open-loop residuals' (from the first sample, full rate) integrated autocorrelation time [samples]."""
    from trials.measured.diagnose import _tau

    if ident.initial_state == "fit":
        return float(ident.tau)
    taus = []
    for j in (0, 1, 2, 5):
        per = []
        for run in ident.runs:
            rep = ident.replay(run)
            d = rep.run.meas[:, j] - rep.pred[:, j]
            if j == 5:
                d = np.angle(np.exp(1j * d))
            per.append(_tau(d))
        taus.append(float(np.median(per)))
    return float(np.mean(taus))


def _psd(c: np.ndarray) -> np.ndarray:
    c = 0.5 * (c + c.T)
    w, v = np.linalg.eigh(c)
    return (v * np.clip(w, 0.0, None)) @ v.T


def covariances(fit, tau: float) -> dict:
    """The covariance of each variant (module docstring) from the fit (:class:`ekf.identify.IdentifyResult`)."""
    std = np.asarray(fit.std, float)
    cov = np.asarray(fit.corr, float) * np.outer(std, std)
    n, N = len(std), int(fit.n_residuals)
    s2 = 2.0 * fit.cost_final / max(N - n, 1)                   # ekf.identify._result's
    sig = np.array([f.sigma for f in fit.free], float)
    prior_ss = float(np.sum(((np.asarray(fit.theta) - np.array([f.prior for f in fit.free])) / sig) ** 2))
    sd2 = (2.0 * fit.cost_final - prior_ss) / max(N - 2 * n, 1)  # the data rows' own (N - n of them)
    P = np.diag(1.0 / sig ** 2)
    Ad = np.linalg.inv(cov) * s2 - P
    k = np.ix_(*(2 * [[i for i, f in enumerate(fit.free) if getattr(f, "record", None) is None]]))   # the shared block
    return {"gauss-newton": cov[k], "tau": cov[k] * tau, "prior-stated": _psd(np.linalg.inv(Ad / sd2 + P)[k]),
            "prior-stated-tau": _psd(np.linalg.inv(Ad / (sd2 * tau) + P)[k]), "s2": s2, "sd2": sd2}


def per_channel_covariance(ident) -> np.ndarray:
    """(sum_kj J_kj^T J_kj / (s_kj^2 tau_kj) + diag(1 / sigma^2))^-1 (module docstring, ``per-channel``)."""
    from trials.measured.diagnose import _tau
    from trials.measured.identify import ship_with_values

    fit = ident.fit
    shared = [f for f in fit.free if f.record is None]
    names = [f.name for f in shared]
    theta = np.array([v for f, v in zip(fit.free, fit.theta) if f.record is None], float)
    sig = np.array([f.sigma for f in shared], float)

    def preds(th):
        ship = ship_with_values(ident.initial, dict(zip(names, th)))
        return [_replay(ship, r) for r in ident.runs]

    base = preds(theta)
    h = 1e-4 * np.maximum(np.abs(theta), sig)
    cols = []
    for i in range(len(theta)):
        th = theta.copy()
        th[i] += h[i]
        cols.append([(p - b) / h[i] for p, b in zip(preds(th), base)])
    info = np.diag(1.0 / sig ** 2)
    for k, run in enumerate(ident.runs):
        d = run.meas - base[k]
        d[:, 5] = np.angle(np.exp(1j * d[:, 5]))
        for j in (0, 1, 2, 5):
            J = np.column_stack([cols[i][k][:, j] for i in range(len(theta))])
            ok = np.all(np.isfinite(J), axis=1) & np.isfinite(d[:, j])
            s2 = float(np.mean(d[ok, j] ** 2))
            if s2 > 0 and ok.any():
                info += J[ok].T @ J[ok] / (s2 * _tau(d[ok, j]))
    return _psd(np.linalg.inv(info))


def _replay(ship, run) -> np.ndarray:
    from trials.measured.predict import replay_record

    return replay_record(ship, run).pred


def serial(func, tasks):
    return [func(t) for t in tasks]


def one_seed(seed: int, samples: int) -> dict:
    """Identify one seed's records and count which intervals hold the truth, per variant."""
    import mmg
    from trials.imo import result as R
    from trials.measured.identify import fit_covariance, identification_covariance, identify

    t0 = time.perf_counter()
    prior = mmg.load_ship(SHIP)
    truth = true_ship(mmg.load_ship(TRUTH), seed)
    runs = records(prior, truth, seed)
    ident = identify(prior, runs, say=silent, initial_state=INITIAL_STATE)
    t_fit = time.perf_counter() - t0
    U = float(np.median(np.concatenate([np.hypot(r.meas[:, 0], r.meas[:, 1]) for r in runs[:1]])[:10]))
    speed = f"{0.09 * math.sqrt(9.80665 * prior.particulars.L):.6g} m/s"
    want = R.imo(truth, speed=speed, executor=serial).nominal
    cov = fit_covariance(ident.fit)
    tau = residual_tau(ident)
    out = {"seed": seed, "tau": tau, "initial_state": ident.initial_state, "fit_s": t_fit, "approach_U": U, "stages": [s["status"] for s in ident.stages],
           "truth": want, "variants": {}}
    if cov is None:
        out["error"] = "singular covariance"
        return out
    covs = covariances(ident.fit, tau)
    if "per-channel" in VARIANTS:
        covs["per-channel"] = per_channel_covariance(ident)
    written, post, runs_cov = identification_covariance(ident, parts=True)
    covs["written"] = np.asarray(written["matrix"], float)
    shared = [i for i, f in enumerate(ident.fit.free) if f.record is None]
    covs["run-jackknife"] = (_psd(runs_cov[np.ix_(shared, shared)]) if runs_cov is not None
                             else np.full_like(covs["written"], np.nan))
    out["s2"], out["sd2"] = covs["s2"], covs["sd2"]
    for v in VARIANTS:
        c = {**cov, "matrix": covs[v]}
        res = R.imo(ident.ship, speed=speed, samples=samples, cov=c, seed=seed, executor=serial)
        rows = {r["name"]: r["interval"] for r in res.rows() if r["interval"] is not None}
        out["variants"][v] = {k: {"interval": iv, "truth": want[k],
                                  "covered": bool(want[k] is not None and iv[0] is not None and iv[1] is not None
                                                  and iv[0] <= want[k] <= iv[1])} for k, iv in rows.items()}
    out["seconds"] = time.perf_counter() - t0
    return out


def summary(results: list[dict]) -> dict:
    """Per variant and criterion: coverage (share of seeds whose interval holds the truth), and overall."""
    out = {}
    for v in VARIANTS:
        per = {}
        for r in results:
            for k, d in r.get("variants", {}).get(v, {}).items():
                per.setdefault(k, []).append(d["covered"])
        allc = [x for xs in per.values() for x in xs]
        out[v] = {"per_criterion": {k: float(np.mean(xs)) for k, xs in per.items()},
                  "overall": float(np.mean(allc)) if allc else None, "n": len(next(iter(per.values()), []))}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=24)
    ap.add_argument("--seed0", type=int, default=0)
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--out", default=None, help="JSON of every seed's figures")
    ap.add_argument("--exact-start", action="store_true",
                    help="each record's first sample without its noise (an oracle experiment on the cause)")
    ap.add_argument("--initial-state", default="fit", choices=("fit", "sample"),
                    help="identify's initial_state: each record's start state fitted (default) or its raw first sample")
    ap.add_argument("--truth", default=SHIP, help="ship config the true ships are drawn around (default the prior's; "
                                                  "esso_osaka_3m_crossflow: a model-form mismatch)")
    ap.add_argument("--variants", nargs="+", default=list(ALL_VARIANTS), choices=ALL_VARIANTS,
                    help="the covariances to count (each costs one sampled IMO run per seed)")
    a = ap.parse_args(argv)
    global EXACT_START, INITIAL_STATE, TRUTH, VARIANTS
    EXACT_START, INITIAL_STATE, TRUTH, VARIANTS = a.exact_start, a.initial_state, a.truth, tuple(a.variants)
    results = []
    t0 = time.perf_counter()
    for s in range(a.seed0, a.seed0 + a.seeds):
        r = one_seed(s, a.samples)
        results.append(r)
        cov = {v: sum(d["covered"] for d in r["variants"].get(v, {}).values()) for v in VARIANTS}
        print(f"seed {s}: {r.get('seconds', 0):.0f} s (fit {r['fit_s']:.0f} s), tau {r['tau']:.1f}, covered "
              + ", ".join(f"{v} {cov[v]}/{len(r['variants'].get(v, {}))}" for v in VARIANTS)
              + (f"  {r['error']}" if "error" in r else ""), flush=True)
        if a.out:
            Path(a.out).write_text(json.dumps({"results": results, "summary": summary(results)}, indent=1))
    sm = summary(results)
    print(f"\n{len(results)} seeds, {a.samples} samples each, {time.perf_counter() - t0:.0f} s")
    names = list(next(iter(sm.values()))["per_criterion"])
    print(f"{'criterion':42s} " + " ".join(f"{v:>13s}" for v in VARIANTS))
    for k in names:
        print(f"{k:42s} " + " ".join(f"{sm[v]['per_criterion'].get(k, float('nan')):13.2f}" for v in VARIANTS))
    print(f"{'overall':42s} " + " ".join(f"{sm[v]['overall']:13.3f}" for v in VARIANTS))
    return 0


if __name__ == "__main__":
    sys.exit(main())
