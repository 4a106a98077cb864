"""The saved figures are readable (tests/figure_checks.py): every legend on the canvas, no text on another,
the data filling a fair share of the canvas; every distribution panel says what its lines are."""
from __future__ import annotations

import matplotlib
import pytest

import mmg

from .figure_checks import check_figure
from .test_imo import serial
from .test_track_figures import _replayed, turn, zigzag

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def imo_res():
    """The full-scale Esso Osaka's IMO manoeuvres with 2 samples of N_r (5 % standard deviation)."""
    ship = mmg.load_ship("esso_osaka")
    nr = ship.hull.value("N_r")
    return mmg.imo(ship, samples=2, cov={"names": ["N_r"], "values": [nr], "matrix": [[(0.05 * nr) ** 2]]},
                   executor=serial, seed=1)


@pytest.mark.parametrize("make", [zigzag, turn], ids=["zigzag", "turn"])
def test_predict_figure_readable(make):
    """A long zigzag (its track across the top) and a turn (beside the histories)."""
    from trials.measured.predict_plots import replay_figure

    check_figure(replay_figure(_replayed(make)[0], pyplot=False), min_data_share=0.3)


def test_distributions_figure_readable_and_every_panel_names_its_limit(imo_res):
    from trials.imo.plots import distributions_figure

    fig = distributions_figure(imo_res, pyplot=False)
    check_figure(fig, min_data_share=0.2)
    for ax, c in zip(fig.axes, imo_res.criteria):
        lg = ax.get_legend()
        assert lg is not None, f"panel {c.name!r} has no legend"
        assert f"limit {c.limit:.3g} {c.unit}" in [t.get_text() for t in lg.get_texts()], c.name


def test_stopping_figure_readable(imo_res):
    from trials.imo.plots import stopping_figure

    check_figure(stopping_figure(imo_res, pyplot=False), min_data_share=0.3)


def test_diagnose_figure_readable():
    from types import SimpleNamespace as NS

    from trials.measured.diagnose_plots import diagnose_figure

    rep, meas, pred = _replayed(turn)
    rec = NS(name="rec", seg=NS(inputs=NS(t=rep.run.t), meas=meas))
    check_figure(diagnose_figure(NS(records=[rec], pred_before=[pred], pred_after=[0.5 * (meas + pred)],
                                    named=["wind"]), 0), min_data_share=0.2)


def test_stopping_figure_keeps_a_long_ship_name_on_the_canvas(imo_res):
    """An identified model's name and a speed in m/s (as `mmg imo DIR/ship.yaml --speed '0.49 m/s'` titles it):
    no title cut by the canvas's edge."""
    import dataclasses

    from trials.imo.plots import stopping_figure

    res = dataclasses.replace(imo_res, ship="Esso Osaka 3 m model (identified)", speed="0.49 m/s")
    check_figure(stopping_figure(res, pyplot=False), min_data_share=0.3)


def test_diagnose_figure_draws_no_residual_for_a_channel_not_logged():
    """A record without sway velocity (v left out of the fit): its panel says so and draws no line (not a flat
    zero residual that reads as a perfect fit); the other panels keep their two lines."""
    from types import SimpleNamespace as NS

    from trials.measured.diagnose_plots import diagnose_figure

    rep, meas, pred = _replayed(turn)
    rec = NS(name="rec", seg=NS(inputs=NS(t=rep.run.t), meas=meas), absent={"v": {"column": "", "compared_instead": ""}})
    fig = diagnose_figure(NS(records=[rec], pred_before=[pred], pred_after=[0.5 * (meas + pred)], named=["wind"]), 0)
    v_ax = next(ax for ax in fig.axes if ax.get_ylabel() == "v [m/s]")
    assert v_ax.get_lines() == [] and any("v not logged" in t.get_text() for t in v_ax.texts)
    u_ax = next(ax for ax in fig.axes if ax.get_ylabel() == "u [m/s]")
    assert len(u_ax.get_lines()) == 2
    check_figure(fig, min_data_share=0.2)
