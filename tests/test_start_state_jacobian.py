"""The Jacobian columns of a record's start-state offsets (ekf.identify, kind "start") replay only the
record's first segment: every later segment restarts from its own state, so the offset cannot move it.
Checked against the forward difference of the whole residual vector, with segments, a stride, measured
wind loads read from the record's channels (an effect with per-sample context) and one record of a
single segment."""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import mmg
import mmg.effects as E
from ekf.identify import (FitOptions, Scales, Segmented, _SegmentFit, effect_parameters, free_parameters,
                          segment_resets, start_parameters)
from mmg.effects.base import Context
from mmg.model import pack
from mmg.replay import ReplayInputs, replay


def _records(ship, segment_s):
    pk = pack(ship)
    out = []
    for k, seg in enumerate(segment_s):
        t = np.arange(0.0, 40.0 + 1e-9, 0.1)
        delta = np.radians(15.0) * np.sign(np.sin(2 * np.pi * t / (18.0 + 4 * k)))
        inp = ReplayInputs(t=t, delta=np.convolve(delta, np.ones(5) / 5, mode="same"), n=np.full_like(t, 10.0))
        s = replay(pk, inp, [0.45, 0.0, 0.01 * k, 0.0, 0.0, 0.2 * k])
        rng = np.random.default_rng(k)
        meas = s + rng.normal(0.0, 0.003, s.shape)
        ch = {"wind_speed_rel": 2.0 + 0.5 * np.sin(t / 7.0), "wind_dir_rel": np.radians(40.0 + 30.0 * np.cos(t / 5.0))}
        ctx = Context(t=t, delta=inp.delta, n=inp.n, channels=ch, ship=ship)
        out.append(Segmented(f"rec{k}", meas, inp, segment_resets(t, seg), context=ctx))
    return out


@pytest.mark.parametrize("effects", [None, [E.get("wind")]])
def test_start_columns_equal_the_whole_residuals_difference(effects):
    ship = mmg.load_ship("esso_osaka_3m")
    if effects and getattr(ship, "wind", None) is None:
        pytest.skip("the 3 m config has no wind section")
    recs = _records(ship, (8.0, 13.0, np.inf))
    pk = pack(ship)
    free = free_parameters(pk, ship.hull.names, ["N_r", "Y_beta"]) + (effect_parameters(effects) if effects else [])
    free += start_parameters(np.tile([0.004, 0.004, 0.004, 0.0, 0.0, 0.004], (len(recs), 1)))
    sc = Scales(0.01, 0.01, 0.005, 0.01)
    with ThreadPoolExecutor(2) as pool:
        fit = _SegmentFit(pk, recs, free, sc, FitOptions(stride=3, effects=effects, ship=ship), pool)
        theta = np.array([f.prior if f.start is None else f.start for f in free], float)
        theta[[i for i, f in enumerate(free) if f.kind == "start"]] = 0.002     # off zero: a moved start
        J = fit.jac(theta)
        r0 = fit.resid(theta)
        h, steps = fit._steps(theta)
        for j, f in enumerate(free):
            if f.kind != "start":
                continue
            full = (fit.resid(steps[j]) - r0) / h[j]
            np.testing.assert_allclose(J[:, j], full, rtol=0, atol=1e-9 * max(1.0, np.abs(full).max()))
            assert np.abs(full[:-len(free)]).max() > 0          # the offset does move its record's first segment
