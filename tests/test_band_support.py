"""The support the prediction bands draw the ship in (:func:`trials.measured.draws.support_of`).

A candidate outside the fit's hard bounds is never replayed, and the band is numpy's quantiles of the
accepted candidates replayed here by hand (the bounds typed from :mod:`mmg.parameters`' table, the accepting
done here); a covariance wholly inside the support gives the untruncated band, draw for draw; every ship
replayed under an energy check gains no energy over the stated range, and the rejected ones are counted;
the ``state_range`` written by ``mmg identify`` is the training records' range; a bad one is refused naming
its field.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

import mmg
import trials.measured.bands as bands_mod
from mmg.dissipation import power_check, state_box
from mmg.errors import InputError
from mmg.model import pack
from mmg.replay import replay
from trials.measured.bands import prediction_bands

from .test_predict_bands import SHIP, SPREAD, _run

RANGE = {"u_mps": [0.2, 0.6], "v_mps": [-0.05, 0.05], "r_radps": [-0.08, 0.08]}


@pytest.fixture(scope="module")
def ship():
    return mmg.load_ship(SHIP)


def _candidates(mean, cov, std, n, seed, batches):
    """The documented streams in batches of ``n``: (ship candidates, run draws), paired by position."""
    rs, rp = np.random.default_rng(seed), np.random.default_rng([seed, 1])
    c = [rs.multivariate_normal(mean, cov, size=n, method="eigh") for _ in range(batches)]
    o = [rp.normal(0.0, 1.0, (n, len(std))) * std for _ in range(batches)]
    return np.concatenate(c), np.concatenate(o)


def _by_hand(ship, run, kappas, offs):
    """Headings [deg] of ``ship`` with each kappa, the first state offset by (u, r, psi) by hand."""
    out = []
    for kap, (du, dr, dpsi) in zip(kappas, offs):
        s = replace(ship, rudder=replace(ship.rudder, kappa=float(kap)))
        p = replay(pack(s), run.inputs, run.meas[0] + np.array([du, 0.0, dr, 0.0, 0.0, dpsi]))
        out.append(np.degrees(p[:, 5]))
    return np.array(out)


def _replayed_ships(monkeypatch):
    """Every ship :func:`prediction_bands` replays (the nominal one included), in a list."""
    seen, real = [], bands_mod.replay_record

    def spy(s, r):
        seen.append(s)
        return real(s, r)
    monkeypatch.setattr(bands_mod, "replay_record", spy)
    return seen


def test_a_draw_outside_the_fits_bounds_is_never_replayed(ship, monkeypatch):
    """kappa drawn at std 0.5 about 0.595: about a fifth of the normal lies outside the fit's bounds [0, 1]
    (:mod:`mmg.parameters`: kappa 0 to 1).  No ship with kappa outside them is replayed; the band is the
    quantiles of the first ``n`` in-bounds candidates replayed by hand, each with the run draw of its own
    candidate; the rejected are counted up to the ``n``-th accepted."""
    run = _run(ship, duration=30.0)
    n, seed, k0 = 40, 5, ship.rudder.kappa
    seen = _replayed_ships(monkeypatch)
    b = prediction_bands(ship, run, n, seed, covariance={"names": ["kappa"], "matrix": [[0.25]]},
                         run_spread=SPREAD, jobs=1, support="bounds")
    kap = [s.rudder.kappa for s in seen]
    assert len(kap) == n + 1 and all(0.0 <= x <= 1.0 for x in kap)
    cand, offs = _candidates([k0], [[0.25]], SPREAD["std"], n, seed, batches=3)
    inside = np.flatnonzero((cand[:, 0] >= 0.0) & (cand[:, 0] <= 1.0))[:n]
    assert len(inside) == n and b.draws == n
    assert b.rejected == inside[-1] + 1 - n > 3                          # the outside ones before the n-th inside
    heads = _by_hand(ship, run, cand[inside, 0], offs[inside])
    np.testing.assert_allclose(b.lo, np.quantile(heads, 0.05, axis=0), atol=1e-9)
    np.testing.assert_allclose(b.hi, np.quantile(heads, 0.95, axis=0), atol=1e-9)
    assert b.to_json()["rejected_draws"] == b.rejected
    assert any("rejected" in x and "outside the support" in x for x in b.notes)


def test_support_none_does_not_truncate_and_physical_is_the_default(ship, monkeypatch):
    """With ``support="none"`` the ship is drawn from the covariance's normal as it is: kappa outside the fit's
    bounds [0, 1] is replayed too, nothing is rejected, and the band is the first ``n`` draws' quantiles.
    Without ``support`` the draws are truncated as ``support="physical"`` truncates them."""
    run = _run(ship, duration=30.0)
    n, seed, k0 = 40, 5, ship.rudder.kappa
    cov = {"names": ["kappa"], "matrix": [[0.25]]}
    default = prediction_bands(ship, run, n, seed, covariance=cov, run_spread=SPREAD, jobs=1)
    physical = prediction_bands(ship, run, n, seed, covariance=cov, run_spread=SPREAD, jobs=1, support="physical")
    assert default.rejected == physical.rejected > 0
    np.testing.assert_array_equal(default.lo, physical.lo)
    seen = _replayed_ships(monkeypatch)
    b = prediction_bands(ship, run, n, seed, covariance=cov, run_spread=SPREAD, jobs=1, support="none")
    cand, offs = _candidates([k0], [[0.25]], SPREAD["std"], n, seed, batches=1)
    assert b.rejected == 0 and b.draws == n
    assert any(not 0.0 <= s.rudder.kappa <= 1.0 for s in seen)
    heads = _by_hand(ship, run, cand[:n, 0], offs[:n])
    np.testing.assert_allclose(b.lo, np.quantile(heads, 0.05, axis=0), atol=1e-9)
    np.testing.assert_allclose(b.hi, np.quantile(heads, 0.95, axis=0), atol=1e-9)
    with pytest.raises(InputError, match="support"):
        prediction_bands(ship, run, 2, seed, support="bound")


def test_a_covariance_inside_the_support_gives_the_untruncated_bands(ship):
    """kappa at std 0.02 (never near 0 or 1) and a state range the ship and such neighbours dissipate over:
    nothing is rejected, and the band is that of the untruncated normal's first ``n`` draws replayed by hand
    (and the same as without a state range)."""
    run = _run(ship, duration=30.0)
    n, seed = 30, 2
    cov = {"names": ["kappa"], "matrix": [[0.02 ** 2]], "state_range": RANGE}
    assert power_check(ship, *state_box(*(np.array(v) for v in RANGE.values()))).passes
    b = prediction_bands(ship, run, n, seed, covariance=cov, run_spread=SPREAD, jobs=2, support="physical")
    rows = np.random.default_rng(seed).multivariate_normal([ship.rudder.kappa], [[0.02 ** 2]], size=n, method="eigh")
    offs = np.random.default_rng([seed, 1]).normal(0.0, 1.0, (n, 3)) * SPREAD["std"]
    heads = _by_hand(ship, run, rows[:, 0], offs)
    assert b.rejected == 0 and b.draws == n
    np.testing.assert_allclose(b.lo, np.quantile(heads, 0.05, axis=0), atol=1e-9)
    np.testing.assert_allclose(b.hi, np.quantile(heads, 0.95, axis=0), atol=1e-9)
    plain = prediction_bands(ship, run, n, seed, covariance={k: cov[k] for k in ("names", "matrix")},
                             run_spread=SPREAD, jobs=1)
    np.testing.assert_array_equal(plain.lo, b.lo)
    np.testing.assert_array_equal(plain.hi, b.hi)


def test_ships_gaining_energy_over_the_state_range_are_not_replayed(ship, monkeypatch):
    """N_r drawn at std 0.08 about -0.054: on some draws it is positive enough (0.05: a yaw moment that feeds
    the yaw more than the resistance takes) for the ship to gain energy over the grid of the stated range.
    Every ship replayed gains none; the rejected are those the check fails, counted here up to the n-th
    accepted."""
    run = _run(ship, duration=20.0)
    n, seed = 30, 1
    cov = {"names": ["N_r"], "matrix": [[0.08 ** 2]], "state_range": RANGE}
    seen = _replayed_ships(monkeypatch)
    b = prediction_bands(ship, run, n, seed, covariance=cov, run_spread=SPREAD, jobs=1, support="physical")
    grid = state_box(*(np.array(v) for v in RANGE.values()))
    assert len(seen) == n + 1 and all(power_check(s, *grid).passes for s in seen)
    cand, _ = _candidates([ship.hull.value("N_r")], [[0.08 ** 2]], SPREAD["std"], n, seed, batches=4)
    ok = [power_check(ship.with_hull({"N_r": float(x)}), *grid).passes for x in cand[:, 0]]
    k = int(np.flatnonzero(ok)[n - 1])                 # the n-th accepted candidate
    assert b.rejected == k + 1 - n > 0
    assert max(s.hull.value("N_r") for s in seen) < 0.05        # a strongly yaw-feeding N_r is not among them


def test_the_training_records_state_range_spans_their_logged_states():
    from trials.measured.identify.covariance import training_state_range

    runs = [_run(mmg.load_ship(SHIP), duration=20.0, k=k, amp_deg=10.0 + 10 * k) for k in range(2)]
    m = np.concatenate([r.meas for r in runs])
    got = training_state_range(runs)
    for j, key in enumerate(("u_mps", "v_mps", "r_radps")):
        np.testing.assert_allclose(got[key], [m[:, j].min(), m[:, j].max()], rtol=1e-5)


def test_a_bad_state_range_is_refused_naming_its_field(tmp_path):
    from mmg.errors import InputError
    from mmg.resources import ship_path

    data = yaml.safe_load(Path(ship_path(SHIP)).read_text())
    s = mmg.load_ship(SHIP)
    data["covariance"] = {"names": ["N_r"], "units": ["1"], "values": [s.hull.value("N_r")], "matrix": [[1e-6]],
                          "state_range": {**RANGE, "v_mps": [0.1, -0.1]}}
    p = tmp_path / "ship.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(InputError, match="covariance.state_range.v_mps"):
        mmg.load_ship(p)
    data["covariance"]["state_range"]["v_mps"] = [-0.1, 0.1]
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    loaded = mmg.load_ship(p)
    assert loaded.covariance.state_range == ((0.2, 0.6), (-0.1, 0.1), (-0.08, 0.08))
    from trials.measured.draws import support_of

    sup = support_of(loaded, ["N_r"], loaded.covariance)              # the config's section, as mmg predict reads it
    assert sup.states is not None and np.max(sup.states[1]) == pytest.approx(0.1)


def test_the_energy_check_leaves_out_the_states_where_the_identified_ship_itself_gains_energy(ship):
    """An identified ship with N_r = +0.05 gains energy at some states of the range: the drawn ships are
    checked at the others alone (where it gains none), and the caveat says so."""
    from trials.measured.draws import support_of

    feeding = ship.with_hull({"N_r": 0.05})
    grid = state_box(*(np.array(v) for v in RANGE.values()))
    assert not power_check(feeding, *grid).passes
    sup = support_of(feeding, ["kappa"], {"names": ["kappa"], "matrix": [[1e-4]], "state_range": RANGE})
    assert 0 < len(sup.states[0]) < len(grid[0]) and power_check(feeding, *sup.states).passes
    assert "gains energy unpowered at the others" in sup.caveat
    assert sup.contains(feeding, [ship.rudder.kappa]) and not sup.contains(feeding, [1.2])   # kappa's bounds: 0 to 1
    plain = support_of(ship, ["kappa"], {"names": ["kappa"], "matrix": [[1e-4]], "state_range": RANGE})
    assert plain.caveat == "" and len(plain.states[0]) == len(grid[0])


def test_physical_without_a_state_range_says_the_energy_check_is_left_out(ship):
    """A covariance with no ``state_range``: the physical support can only be the fit's bounds, and its caveat
    (a band's note, shown whether or not a draw is rejected) says so; the bounds-only support has none."""
    from trials.measured.draws import support_of

    cov = {"names": ["kappa"], "matrix": [[1e-4]]}
    phys, plain = support_of(ship, ["kappa"], cov), support_of(ship, ["kappa"], cov, energy=False)
    assert phys.states is None and "state_range" in phys.caveat
    assert plain.caveat == ""
    np.testing.assert_array_equal([phys.lower[0], phys.upper[0]], [0.0, 1.0])     # kappa's range, mmg.parameters
