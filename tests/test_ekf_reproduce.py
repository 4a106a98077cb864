"""Slow: the full Rhee & Kim reproduction (four 3000 s trials and the joint estimate)."""
from __future__ import annotations

import pytest


@pytest.mark.slow
def test_reproduce_rhee_kim(tmp_path):
    from trials.estimates.rhee_kim import reproduce_rhee_kim

    df = reproduce_rhee_kim(tmp_path, plots=False, verbose=False)
    assert set(df.trial) == {"ST35", "ZZ10", "ZZ20", "S-type 120", "joint"}
    lin = df[(df.trial == "ZZ20") & df.coeff.isin(["Y_beta", "Y_r", "N_beta", "N_r"])]
    assert (lin.our_err_pct < 3.0).all()
    assert (tmp_path / "comparison.md").exists() and (tmp_path / "estimates.json").exists()
