"""``bench/bench_diagnose.py --mismatch``: mmg diagnose on full-scale trials of ships that are not its model.

Records: the development set's trials (:data:`trials.measured.mismatch.TRIALS`: 35 deg turns to
starboard and port, 10/10, 15/15, 20/20 zigzags; 10 kn, constant revolutions, 1 s, uniform noise
of the set's half-widths) of members of the mismatch family (:mod:`trials.measured.mismatch`:
hull +-10 % linear, +-25 % nonlinear, a quarter with the cross-flow hull form, rudder and propeller
+-15 %, added masses +-10 %, wind loads +-30 %; ``--wind-curve harmonic`` or ``mixed``: all or half
of the members' wind loads on a loaded tanker's measured curve instead of the model's regression,
:mod:`trials.measured.wind_curves`), each diagnosed alone as a user would
(``diagnose(load_ship(ship_path(SHIP)), [record])``, SHIP ``--ship``, default ``esso_osaka``; a
model-scale config such as ``kvlcc2_l7`` sails the same full-scale trials Froude-scaled to it,
:func:`trials.measured.mismatch.froude_scaled`; sizes stay full-scale in the tables).  Clean records give the false-alarm
rate; records with one effect (current, wind, heading bias, rudder offset, at several sizes, random
direction or sign, random member and trial) the detection rate.  The JSON keeps every record's
candidate statistics per round (``rounds``), to calibrate the naming decision on the clean ones.
"""
from __future__ import annotations

import functools
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

KINDS = ("turn35", "turn35p", "zz10", "zz15", "zz20")

PAIRS = {"turn_pair": ("turn35", "turn35p")}
"""Trials of several records diagnosed together (``--trials turn_pair``): a 35 deg turn to each
side by the same member, with one shared effect (the IMO set of turning circles; record kind
``turn_pair`` of :func:`trials.measured.decision.record_kind`).  Not among the default trials."""

SIZES = {
    "current": ("speed_mps", "m/s", [0.05, 0.1, 0.15, 0.25]),
    "wind": ("speed_mps", "m/s", [6.0, 10.0, 15.0]),
    "heading_bias": ("bias_deg", "deg", [0.5, 1.0, 1.5]),
    "rudder_offset": ("offset_deg", "deg", [0.5, 1.0, 1.5]),
}
"""Per effect: the size's name, its unit and the sizes tried (full scale, 10 kn approach)."""

FAMILY_SIZE = 40
"""Members drawn per family seed; clean record i sails member i mod this, effect records a random one."""

WIDE_SIZES = {
    "current": ("speed_mps", "m/s", [0.15, 0.25]),
    "wind": ("speed_mps", "m/s", [8.0, 10.0, 15.0, 20.0, 25.0]),
    "heading_bias": ("bias_deg", "deg", [1.0, 1.5]),
    "rudder_offset": ("offset_deg", "deg", [1.0, 1.5]),
}
"""``--wide``: the sizes per effect alone (at or above the sizes the acceptance figures are for, and
winds from 8 to 25 m/s)."""

WIDE_BESIDE_WIND = (15.0, 20.0, 25.0)
"""``--wide``: true wind speeds [m/s] of the records with a wind beside another effect
(``wind+current``, ``wind+heading_bias``, ``wind+rudder_offset``; the other effect at one of its
:data:`WIDE_SIZES`, drawn)."""

WIDE_SPEEDS_KN = (6.0, 15.0)
"""``--wide``: approach speeds [kn], uniform per record."""

SPEED_BANDS_KN = ((6.0, 9.0), (9.0, 12.0), (12.0, 15.0))
"""The approach-speed classes of the per-class table [kn] (a band holds its lower end; the last, both)."""

ACCEPT = {"current": 0.15, "wind": 10.0, "heading_bias": 1.0, "rudder_offset": 1.0}
"""The smallest size whose detection the per-class table counts (the sizes the detection figures are stated for)."""


SHIP = "esso_osaka"
"""The config diagnosed (and the family drawn around) unless ``--ship`` names another."""


@functools.lru_cache(maxsize=4)
def _family(seed0: int, ship: str = SHIP, wind_curve: str = "fujiwara"):
    import mmg
    from trials.measured.mismatch import MismatchSpec, mismatch_family

    return mismatch_family(mmg.load_ship(mmg.ship_path(ship)), FAMILY_SIZE, seed0, MismatchSpec(wind_curve=wind_curve))


def jobs(nclean: int, seeds: int, effects, seed0: int, trials=None) -> list[dict]:
    """The records to make and diagnose: ``nclean`` clean ones (member i, trial i mod 5), then per
    effect, size and seed one with that effect (member, trial, direction or sign drawn from the seeds)."""
    kinds = list(trials or KINDS)
    out = [{"id": f"clean_{i}", "effect": None, "size": 0.0, "member": i % FAMILY_SIZE, "trial": kinds[i % len(kinds)],
            "spec": {}, "true_wind": (0.0, 0.0), "seed": seed0 + i} for i in range(nclean)]
    for ie, eff in enumerate(effects):
        for isz, size in enumerate(SIZES[eff][2]):
            for s in range(seeds):
                rng = np.random.default_rng([seed0, ie, isz, s])
                job = {"id": f"{eff}_{size:g}_{s}", "effect": eff, "size": size,
                       "member": int(rng.integers(FAMILY_SIZE)), "trial": kinds[int(rng.integers(len(kinds)))],
                       "true_wind": (0.0, 0.0), "seed": seed0 + 10000 * (ie + 1) + 100 * isz + s}
                sign = float(rng.choice([-1.0, 1.0]))
                direction = float(rng.uniform(0.0, 360.0))
                if eff == "current":
                    job["spec"] = {"current": {"speed_mps": size, "direction_deg": direction}}
                elif eff == "wind":
                    job["spec"] = {"wind": {}}
                    job["true_wind"] = (size, math.radians(direction))
                elif eff == "heading_bias":
                    job["spec"] = {"heading_bias": {"bias_deg": sign * size}}
                else:
                    job["spec"] = {"rudder_offset": {"offset_deg": sign * size}}
                out.append(job)
    return out


def _wide_trial(rng, manoeuvre: str, hand: str) -> str:
    """A :data:`~trials.measured.mismatch.TRIALS` key of that manoeuvre and hand, its size drawn."""
    size = int(rng.choice([10, 15, 20] if manoeuvre == "zigzag" else [15, 20, 25, 30, 35]))
    return f"{'zz' if manoeuvre == 'zigzag' else 'turn'}{size}{'p' if hand == 'port' else ''}"


def _effect_spec(eff: str, size: float, rng) -> tuple[dict, tuple]:
    """One effect's spec (mmg.effects) and true wind of that size, its direction or sign drawn."""
    sign = float(rng.choice([-1.0, 1.0]))
    direction = float(rng.uniform(0.0, 360.0))
    if eff == "current":
        return {"current": {"speed_mps": size, "direction_deg": direction}}, (0.0, 0.0)
    if eff == "wind":
        return {"wind": {}}, (size, math.radians(direction))
    if eff == "heading_bias":
        return {"heading_bias": {"bias_deg": sign * size}}, (0.0, 0.0)
    return {"rudder_offset": {"offset_deg": sign * size}}, (0.0, 0.0)


def wide_jobs(nclean: int, seeds: int, effects, seed0: int) -> list[dict]:
    """The wider draw (``--wide``): every record's hand, manoeuvre (turn 15-35 deg or zigzag 10/10 to
    20/20) and approach speed (uniform in :data:`WIDE_SPEEDS_KN`) drawn.  Clean records cycle the four
    (hand, manoeuvre) classes; effect records draw both (a rudder offset: zigzags only, since on one
    turn an offset is reported ``not_identifiable`` by design); each effect alone at its
    :data:`WIDE_SIZES`, and a wind of :data:`WIDE_BESIDE_WIND` beside each other effect in ``effects``."""
    hands, mans = ("starboard", "port"), ("turn", "zigzag")

    def job(key, jid, effect, size, i, eff_list, wind=None):
        rng = np.random.default_rng([seed0, 7919] + key)
        if effect is None:
            hand, man = hands[i % 2], mans[(i // 2) % 2]
        else:
            hand = hands[int(rng.integers(2))]
            man = "zigzag" if "rudder_offset" in eff_list else mans[int(rng.integers(2))]
        spec, tw = {}, (0.0, 0.0)
        for e in eff_list:
            sz = wind if (e == "wind" and wind is not None) else (
                size if len(eff_list) == 1 else float(rng.choice(WIDE_SIZES[e][2])))
            sp, w = _effect_spec(e, sz, rng)
            spec.update(sp)
            tw = w if e == "wind" else tw
        return {"id": jid, "effect": effect, "size": size, "member": int(rng.integers(FAMILY_SIZE)) if effect else i % FAMILY_SIZE,
                "trial": _wide_trial(rng, man, hand), "speed_kn": round(float(rng.uniform(*WIDE_SPEEDS_KN)), 2),
                "spec": spec, "true_wind": tw, "seed": seed0 + 100000 * key[0] + 1000 * key[1] + key[2] + 7}

    out = [job([0, 0, i], f"clean_{i}", None, 0.0, i, []) for i in range(nclean)]
    for ie, eff in enumerate(effects):
        for isz, size in enumerate(WIDE_SIZES[eff][2]):
            out += [job([ie + 1, isz, s], f"{eff}_{size:g}_{s}", eff, size, s, [eff]) for s in range(seeds)]
        if eff == "wind" or "wind" not in effects:
            continue
        for iw, w in enumerate(WIDE_BESIDE_WIND):
            out += [job([ie + 11, iw, s], f"wind+{eff}_{w:g}_{s}", f"wind+{eff}", w, s, ["wind", eff], wind=w)
                    for s in range(seeds)]
    clean, eff_jobs = out[:nclean], out[nclean:]            # interleaved: a run cut short still holds both
    step = max(1, math.ceil(nclean / max(len(eff_jobs), 1)))
    mixed = []
    for k in range(max(len(clean), len(eff_jobs) * step)):
        mixed += clean[k:k + 1]
        if k % step == step - 1 and k // step < len(eff_jobs):
            mixed.append(eff_jobs[k // step])
    return mixed + eff_jobs[len(mixed) - len(clean):]


def mirrored(job: dict) -> dict:
    """The port <-> starboard twin of a job: the trial of the other hand (``zz10`` <-> ``zz10p``), the true
    wind's and the current's directions mirrored about the approach course (north: d -> -d), the offset's
    and the bias's signs flipped; the same member, speed and noise seed, id ``<id>_mirror``.  The member's
    own asymmetries (gamma_R of either sign, the cross-flow hull) are not mirrored: a twin is the same ship
    run the other way in the mirrored sea."""
    import copy

    m = copy.deepcopy(job)
    t = job["trial"]
    m["trial"] = t if t in PAIRS else t[:-1] if t.endswith("p") else t + "p"       # a pair holds both hands
    m["id"] = f"{job['id']}_mirror"
    spec = m["spec"]
    if "current" in spec:
        spec["current"]["direction_deg"] = (-float(spec["current"]["direction_deg"])) % 360.0
    for eff, key in (("heading_bias", "bias_deg"), ("rudder_offset", "offset_deg")):
        if eff in spec:
            spec[eff][key] = -float(spec[eff][key])
    speed, frm = job["true_wind"]
    m["true_wind"] = (speed, (-frm) % (2.0 * math.pi) if speed else frm)
    return m


def true_effects(r: dict) -> set:
    """The effects a record was made with (``"wind+current"``: both)."""
    return set(r["effect"].split("+")) if r["effect"] else set()


def run_one(job: dict, seed0: int) -> dict:
    """Make the job's record, diagnose it with the bundled config as a user would, return the row."""
    import mmg
    from trials.measured.diagnose import diagnose
    from trials.measured.mismatch import TrialConditions, trial_records

    ship = job.get("ship", SHIP)
    config = mmg.load_ship(mmg.ship_path(ship))
    member, factors = _family(seed0, ship, job.get("wind_curve", "fujiwara"))[job["member"]]
    sea = TrialConditions(job["spec"], job["true_wind"], job.get("speed_kn", 10.0))
    recs = [trial_records(config, member, t, sea, seed=job["seed"] + 1000003 * k,
                          name=f"{job['id']}_{t}" if k else job["id"],
                          wind_curve=factors.get("wind_curve"))
            for k, t in enumerate(PAIRS.get(job["trial"], (job["trial"],)))]
    rec = recs[0]
    t0 = time.perf_counter()
    extra = {"max_nfev": job["max_nfev"]} if job.get("max_nfev") is not None else {}
    d = diagnose(config, recs, candidate_start=job.get("candidate_start", "config"), **extra)
    js = d.to_json()
    truth = {k: dict(v) for k, v in rec.meta["effects"].items()}          # as the record holds them (fit units)
    if "wind" in truth:
        w = rec.meta["effects"]["wind"]
        truth["wind"] = {"speed_mps": w["true_speed_mps"], "from_deg": w["true_from_deg"], **member.wind.values(),
                         **({"curve": factors["wind_curve"]} if "wind_curve" in factors else {})}
    return {**{k: job[k] for k in ("id", "seed", "member", "trial", "effect", "size")},
            "speed_kn": job.get("speed_kn", 10.0), "ship": ship, "froude_scale": config.froude_scale,
            "family_seed": seed0, "factors": factors, "truth": truth, "named": list(d.named),
            "parameters": d.parameters, "not_identifiable": [n["effect"] for n in d.not_identifiable],
            "not_identifiable_reasons": {n["effect"]: n.get("reason") for n in d.not_identifiable},
            "not_identifiable_kinds": {n["effect"]: n.get("reason_kind") for n in d.not_identifiable},
            "not_identifiable_correlation": {n["effect"]: n.get("correlation") for n in d.not_identifiable},
            "model_form": {x["effect"]: {"reason": x["reason"], "parameters": x.get("parameters", {})}
                           for x in d.model_form_effects},
            "unexplained": bool(d.unexplained), "rounds": js["rounds"], "duration_s": float(sum(r.t[-1] for r in recs)),
            "rms_after": js["rms_after"], "rms_before": js["rms_before"], "rms_config": js["rms_config"],
            "speed_mps": float(np.median(np.hypot(rec.u, rec.v))), "L_m": float(config.particulars.L),
            "seconds": round(time.perf_counter() - t0, 1)}


def _execute(todo: list, seed0: int, njobs: int, save) -> list:
    rows = []

    def done(row):
        rows.append(row)
        save(rows)
        print(f"[{len(rows)}/{len(todo)}] {row['id']} {row['trial']} member {row['member']} "
              f"({row['factors']['hull_form']}): named {row['named']} "
              f"{'not identifiable ' + str(row['not_identifiable']) + ' ' if row['not_identifiable'] else ''}"
              f"{row['seconds']:.0f} s", file=sys.stderr, flush=True)

    if njobs <= 1:
        for job in todo:
            done(run_one(job, seed0))
    else:
        with ProcessPoolExecutor(njobs) as ex:
            for fut in as_completed([ex.submit(run_one, job, seed0) for job in todo]):
                done(fut.result())
    order = {j["id"]: i for i, j in enumerate(todo)}
    return sorted(rows, key=lambda r: order[r["id"]])


def _rate(rows, pred) -> tuple[int, int]:
    return sum(bool(pred(r)) for r in rows), len(rows)


def _pct(k: int, n: int) -> str:
    return f"{k}/{n} ({100 * k / n:.0f} %)" if n else "-"


def summarise(rows: list) -> dict:
    """Print and return the false-alarm rate, detection (zigzag / turn), exact naming."""
    clean = [r for r in rows if r["effect"] is None]
    fa = _rate(clean, lambda r: r["named"])
    print(f"\nfalse alarms: {_pct(*fa)} clean records named an effect")
    for r in clean:
        if r["named"]:
            print(f"  {r['id']} {r['trial']} ({r['factors']['hull_form']}): {r['named']} {r['parameters']}")
    print(f"\n{'effect':14s} {'size':>9s} {'zigzag det':>12s} {'turn det':>12s} {'exact':>12s} {'not ident (turn)':>17s} {'silent':>10s}")
    table = {"false_alarms": list(fa), "detection": {}}
    for eff, (par, unit, sizes) in SIZES.items():
        er = [r for r in rows if r["effect"] == eff]
        if not er:
            continue
        table["detection"][eff] = []
        present = sorted({r["size"] for r in er})
        for size in (sizes if set(present) <= set(sizes) else present):
            sr = [r for r in er if r["size"] == size]
            zz = [r for r in sr if r["trial"].startswith("zz")]
            tu = [r for r in sr if r["trial"].startswith("turn")]
            hit = lambda r, e=eff: e in r["named"]  # noqa: E731
            dz, dt = _rate(zz, hit), _rate(tu, hit)
            ex = _rate(sr, lambda r, e=eff: set(r["named"]) == {e})
            ni = _rate(tu, lambda r, e=eff: e not in r["named"] and e in r["not_identifiable"])
            silent = _rate(sr, lambda r, e=eff: e not in r["named"] and e not in r["not_identifiable"])
            print(f"{eff:14s} {size:6g} {unit:3s} {_pct(*dz):>12s} {_pct(*dt):>12s} {_pct(*ex):>12s} {_pct(*ni):>17s} "
                  f"{_pct(*silent):>10s}")
            table["detection"][eff].append({"size": size, "zigzag": list(dz), "turn": list(dt), "exact": list(ex),
                                            "turn_not_identifiable": list(ni), "silent": list(silent)})
    allr = _rate(rows, lambda r: set(r["named"]) == true_effects(r))
    print(f"\nexact (named set == true set) over all records: {_pct(*allr)}")
    table["exact"] = list(allr)
    table["exact_by_hand"] = exact_by_hand(rows)
    print("exact by hand of the first rudder, records with an effect (with a wind beside another) / clean: "
          + "; ".join(f"{h} {_pct(*v['effect'])} ({_pct(*v['wind_beside'])}) / {_pct(*v['clean'])}"
                      for h, v in table["exact_by_hand"].items()))
    table["model_form"] = model_form_lines(rows)
    table["per_trial"] = _per_trial(rows)
    table["reasons"] = _reason_counts(rows)
    table["classes"] = class_table(rows)
    return table


def model_form_lines(rows: list) -> dict:
    """Print and return the records where an effect was reported ``model_form_mismatch`` (fitted, kept in the
    model, not named: :mod:`trials.measured.diagnose.model_form`): on clean records, and on records with an
    effect, whether it was the true one (a row without a ``model_form`` field counts as none)."""
    mf = [r for r in rows if r.get("model_form")]
    clean = [r for r in mf if r["effect"] is None]
    true = [r for r in mf if r["effect"] is not None and set(r["model_form"]) & true_effects(r)]
    print(f"\nreported model_form_mismatch: {len(mf)}/{len(rows)} records ({len(clean)} clean; the true effect on "
          f"{len(true)} of the {len(mf) - len(clean)} others)")
    for r in mf:
        print(f"  {r['id']} {r['trial']}: named {r['named']}, model_form_mismatch {sorted(r['model_form'])}")
    return {"records": len(mf), "clean": len(clean), "true_effect": len(true), "ids": [r["id"] for r in mf]}


def exact_by_hand(rows: list) -> dict:
    """``{hand: {"effect": (k, n), "wind_beside": (k, n), "clean": (k, n)}}``: records named exactly, per hand of
    the first rudder (:func:`record_class`), counted once each: those with an effect, those with a wind
    beside another effect, the clean ones."""
    out = {}
    for r in rows:
        d = out.setdefault(record_class(r)[0], {"effect": [0, 0], "wind_beside": [0, 0], "clean": [0, 0]})
        true = true_effects(r)
        keys = ["effect", "wind_beside"] if "wind" in true and len(true) > 1 else ["effect"] if true else ["clean"]
        for k in keys:
            d[k][0] += set(r["named"]) == true
            d[k][1] += 1
    return {h: {k: tuple(v) for k, v in d.items()} for h, d in sorted(out.items())}


def record_class(r: dict) -> tuple[str, str, str]:
    """(hand of the first rudder, manoeuvre, approach-speed band) of a record row."""
    from trials.measured.mismatch import trial_hand

    trial = PAIRS.get(r["trial"], (r["trial"],))[0]
    hand = "pair" if r["trial"] in PAIRS else trial_hand(trial)
    v = float(r.get("speed_kn", 10.0))
    band = next((f"{lo:g}-{hi:g} kn" for lo, hi in SPEED_BANDS_KN if lo <= v < hi or (hi == SPEED_BANDS_KN[-1][1] and v == hi)),
                f"{v:g} kn")
    return hand, "zigzag" if trial.startswith("zz") else "turn", band


def true_sizes(r: dict) -> dict:
    """{effect: size} of a record's truth at full scale (current and wind [m/s], bias and offset [deg],
    magnitudes): a model-scale record's speeds (``froude_scale`` lambda > 1) times sqrt(lambda)."""
    key = {"current": "speed_mps", "wind": "speed_mps", "heading_bias": "bias_deg", "rudder_offset": "offset_deg"}
    speed = math.sqrt(float(r.get("froude_scale", 1.0)))
    return {e: abs(float(v[key[e]])) * (speed if key[e] == "speed_mps" else 1.0)
            for e, v in r["truth"].items() if e in key}


def class_figures(rows: list) -> dict:
    """The acceptance figures of a set of records: false alarms on the clean ones, detection of each
    effect at or above its :data:`ACCEPT` size (a rudder offset: zigzags only; an effect beside a wind
    counts), and the wind records with nothing named but their true effects: each ``[k, n]``."""
    out = {"false_alarms": list(_rate([r for r in rows if r["effect"] is None], lambda r: r["named"]))}
    for eff, floor in ACCEPT.items():
        sel = [r for r in rows if true_sizes(r).get(eff, 0.0) >= floor - 1e-12
               and (eff != "rudder_offset" or record_class(r)[1] == "zigzag")]
        out[eff] = list(_rate(sel, lambda r, e=eff: e in r["named"]))
    out["wind_no_spurious"] = list(_rate([r for r in rows if "wind" in true_effects(r)],
                                         lambda r: set(r["named"]) <= true_effects(r)))
    return out


def class_table(rows: list) -> dict:
    """Print and return :func:`class_figures` per class (hand, manoeuvre, speed band), per hand, per
    manoeuvre, per hand and manoeuvre, per speed band, and over all records."""
    cls = {id(r): record_class(r) for r in rows}
    groups = {}
    for r in rows:
        h, m, b = cls[id(r)]
        for key in ((h, m, b), (h, m, "all"), (h, "all", "all"), ("all", m, "all"), ("all", "all", b)):
            groups.setdefault(key, []).append(r)
    groups[("all", "all", "all")] = list(rows)
    cols = ["false_alarms"] + list(ACCEPT) + ["wind_no_spurious"]
    head = ["clean: false alarms", "current>=0.15 m/s", "wind>=10 m/s", "bias>=1 deg", "offset>=1 deg (zz)",
            "wind: no spurious"]
    print("\nper class (hand of the first rudder, manoeuvre, approach speed): k/n records")
    print(f"{'hand':10s} {'manoeuvre':9s} {'speed':9s} " + " ".join(f"{h:>20s}" for h in head))
    order = lambda k: tuple((x == "all", x) for x in k)  # noqa: E731
    table = {}
    for key in sorted(groups, key=order):
        fig = class_figures(groups[key])
        table[" / ".join(key)] = fig
        print(f"{key[0]:10s} {key[1]:9s} {key[2]:9s} " + " ".join(f"{_pct(*fig[c]):>20s}" for c in cols))
    return table


def _per_trial(rows) -> dict:
    """Print and return per trial: false alarms on its clean records, its effect records whose effect
    was named, and those named exactly."""
    out = {}
    print(f"\n{'trial':9s} {'false alarms':>14s} {'effect named':>14s} {'exact':>14s}")
    for trial in sorted({r["trial"] for r in rows}):
        tr = [r for r in rows if r["trial"] == trial]
        fa = _rate([r for r in tr if r["effect"] is None], lambda r: r["named"])
        hit = _rate([r for r in tr if r["effect"]], lambda r: r["effect"] in r["named"])
        ex = _rate(tr, lambda r: set(r["named"]) == ({r["effect"]} if r["effect"] else set()))
        print(f"{trial:9s} {_pct(*fa):>14s} {_pct(*hit):>14s} {_pct(*ex):>14s}")
        out[trial] = {"false_alarms": list(fa), "effect_named": list(hit), "exact": list(ex)}
    return out


_OLD_RUN_PHRASES = (("statistics", "its standard error"), ("floor", "mismatch lends"), ("evidence", "(a name needs"),
                    ("information", "too little information"))
"""For runs stored before each entry kept its ``reason_kind``
(:data:`trials.measured.decision.REASON_KINDS`): the kind by a phrase of the reason's text."""


def _reason_kind(r: dict, eff: str, text) -> str:
    """The kind of record ``r``'s entry for ``eff``: as stored, else (an older run) by its text."""
    kind = (r.get("not_identifiable_kinds") or {}).get(eff)
    return kind or next((k for k, phrase in _OLD_RUN_PHRASES if phrase in str(text or "")), "other")


def _reason_counts(rows) -> dict:
    """Print and return the ``not_identifiable`` entries by kind of reason: on clean records, on records
    with an effect for that effect, and for another effect (runs that stored the reasons only)."""
    out = {w: {} for w in ("clean", "true effect", "other effect")}
    for r in rows:
        for eff, why in (r.get("not_identifiable_reasons") or {}).items():
            w = "clean" if r["effect"] is None else "true effect" if eff == r["effect"] else "other effect"
            k = _reason_kind(r, eff, why)
            out[w][k] = out[w].get(k, 0) + 1
    if any(out.values()):
        print("not_identifiable entries by reason: " + "; ".join(
            f"{w} {', '.join(f'{k} {n}' for k, n in sorted(c.items())) or '-'}" for w, c in out.items()))
    return out


def summarise_files(paths) -> dict:
    """:func:`summarise` of the records of runs already made, pooled; each record's ``not_identifiable``
    completed by :func:`trials.measured.diagnose.weak_evidence` over its stored rounds (a run made
    before that rule reported such candidates; the naming itself does not depend on it)."""
    from trials.measured.diagnose import weak_evidence

    rows, n_added = [], 0
    for p in paths:
        for r in json.loads(Path(p).read_text())["records"]:
            added = [e for e in weak_evidence(r["rounds"]) if e not in r["named"] and e not in r["not_identifiable"]]
            rows.append({**r, "not_identifiable": list(r["not_identifiable"]) + added})
            n_added += bool(added) and r["effect"] is None
    print(f"{len(rows)} records of {len(paths)} run(s): {', '.join(Path(p).name for p in paths)}")
    clean = [r for r in rows if r["effect"] is None]
    print(f"clean records with a not_identifiable entry added here by the evidence rule (not in the run's own "
          f"list): {n_added} of {len(clean)}")
    return summarise(rows)


def plot(table: dict, path: Path, title: str) -> None:
    """Detection rate against size per effect, zigzag and turn lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    det = table["detection"]
    if not det:
        return
    fig, axs = plt.subplots(1, len(det), figsize=(3.6 * len(det), 3.4), layout="constrained", squeeze=False)
    for ax, (eff, rows) in zip(axs[0], det.items()):
        par, unit, _ = SIZES[eff]
        for key, style, lab in (("zigzag", "o-", "zigzag: named"), ("turn", "s--", "35° turn: named")):
            pts = [(r["size"], r[key][0] / r[key][1]) for r in rows if r[key][1]]
            if pts:
                ax.plot(*zip(*pts), style, label=f"{lab}")
        pts = [(r["size"], r["turn_not_identifiable"][0] / r["turn_not_identifiable"][1]) for r in rows
               if r.get("turn_not_identifiable", (0, 0))[1]]
        if pts and any(y > 0 for _, y in pts):
            ax.plot(*zip(*pts), "^:", label="turn: reported not identifiable")
        ax.set_ylim(-0.05, 1.05)
        what = {"current": "current speed", "wind": "true wind speed"}.get(eff, eff.replace("_", " "))
        ax.set_xlabel(f"{what} [{unit}]")
        ax.set_ylabel("share of records [-]")
        ax.set_title(eff.replace("_", " "), fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fa = table["false_alarms"]
    fig.suptitle(f"{title}; false alarms {fa[0]}/{fa[1]} clean records", fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main_mismatch(a) -> None:
    """The ``--mismatch`` mode of bench/bench_diagnose.py (options parsed there)."""
    import mmg
    from mmg.errors import InputError

    try:
        mmg.load_ship(mmg.ship_path(a.ship))
    except InputError as e:
        print(f"--ship: {e}", file=sys.stderr)
        raise SystemExit(2) from None
    nclean = 4 if a.quick and a.clean is None else (a.clean if a.clean is not None else 40)
    seeds = 1 if a.quick else a.seeds
    effects = a.effects if a.effects is not None else (["current", "wind"] if a.quick else list(SIZES))
    effects = [] if effects == ["none"] else effects           # --effects none: clean records only
    unknown = set(effects) - set(SIZES)
    if unknown:
        raise SystemExit(f"--mismatch: unknown effects {sorted(unknown)}; have {list(SIZES)}")
    out = REPO / "bench" / "out"
    out.mkdir(exist_ok=True)
    bad = set(a.trials or ()) - set(KINDS) - set(PAIRS)
    if bad:
        raise SystemExit(f"--mismatch: unknown trials {sorted(bad)}; have {list(KINDS) + list(PAIRS)}")
    todo = (wide_jobs(nclean, seeds, effects, a.seed0) if getattr(a, "wide", False)
            else jobs(nclean, seeds, effects, a.seed0, a.trials))
    if a.only:                                   # the same records as a full run of these options, by id
        todo = [j for j in todo if j["id"] in set(a.only)]
    if getattr(a, "mirror", False):
        todo = [mirrored(j) for j in todo]
    curve = getattr(a, "wind_curve", "fujiwara")
    todo = [{**j, "candidate_start": a.candidate_start, "max_nfev": a.max_nfev, "ship": a.ship, "wind_curve": curve}
            for j in todo]
    tag = a.tag + ("_mirror" if getattr(a, "mirror", False) else "")      # twins never overwrite their draw
    path = out / f"diagnose_mismatch{tag}.json"
    wide = getattr(a, "wide", False)
    head = {"ship": a.ship, "family_seed": a.seed0, "family_size": FAMILY_SIZE, "clean": nclean, "seeds": seeds,
            "effects": effects, "sizes": {e: (WIDE_SIZES if wide else SIZES)[e] for e in effects}, "wide": wide,
            "wind_curve": curve, "mirror": bool(getattr(a, "mirror", False))}
    save = lambda rows: path.write_text(json.dumps({**head, "records": rows}, indent=1, default=float))  # noqa: E731
    t0 = time.perf_counter()
    nc = sum(j["effect"] is None for j in todo)
    print(f"mismatch bench on {a.ship}: {len(todo)} records ({nc} clean, {len(todo) - nc} with an effect), family seed "
          f"{a.seed0}, {a.jobs} job(s)", flush=True)
    rows = _execute(todo, a.seed0, a.jobs, save)
    table = summarise(rows)
    save(rows)
    path.write_text(json.dumps({**head, "summary": table, "records": rows}, indent=1, default=float))
    png = out / f"diagnose_detection_mismatch{tag}.png"
    plot(table, png, f"mmg diagnose on the {a.ship} mismatch family (seed {a.seed0}, {seeds} seed(s)/size)")
    print(f"wrote {path} and {png}; {time.perf_counter() - t0:.0f} s wall")
