"""What a user reads: error messages that say what to do with the command line that exists, speeds in the
ship's own scale, counts and units said the same way everywhere."""
from __future__ import annotations

import math
import re

import pytest

from mmg.errors import InputError
from mmg.resources import ship_path
from mmg.ship import load_ship

KNOT = 1852.0 / 3600.0


# ----------------------------------------------------------------- mmg imo


def test_no_covariance_says_what_to_do_on_the_command_line():
    from trials.measured.draws import parameter_covariance

    with pytest.raises(InputError) as e:
        parameter_covariance(load_ship(ship_path("esso_osaka")))
    msg = e.value.message
    assert "none was given" not in msg                 # no other way to give one exists on the command line
    assert "mmg identify" in msg and "DIR/ship.yaml" in msg and "--samples" in msg


def test_example_speed_is_in_the_ships_own_scale():
    from trials.imo.standard import approach_speed, example_speed

    model = load_ship(ship_path("esso_osaka_3m"))      # a 3 m model of the 325 m ship
    ms = float(re.search(r"'([0-9.]+) m/s'", example_speed(model)).group(1))
    assert ms == pytest.approx(10 * KNOT / math.sqrt(325.0 / 3.0), rel=0.02)     # 0.494 m/s, Froude-scaled
    with pytest.raises(InputError) as e:
        approach_speed(model)                          # no bundled trial gives its speed
    assert "e.g. '10 kn'" not in e.value.message and f"'{ms:.2g} m/s'" in e.value.message
    ship = load_ship(ship_path("esso_osaka"))          # no full_scale: section: Froude number 0.1
    ms = float(re.search(r"'([0-9.]+) m/s'", example_speed(ship)).group(1))
    assert ms == pytest.approx(0.1 * math.sqrt(9.80665 * 325.0), rel=0.02)


@pytest.mark.parametrize("given, u0, expected", [
    ("0.5 m/s", 0.5, "0.5 m/s"),
    ("0.5m/s", 0.5, "0.5m/s"),
    ("10 kn", 10 * KNOT, "10 kn (5.144 m/s)"),
    ("2 knots", 2 * KNOT, "2 knots (1.029 m/s)"),
])
def test_speed_said_once_or_in_another_unit(given, u0, expected):
    from trials.imo.standard import speed_label

    assert speed_label(given, u0) == expected


# ----------------------------------------------------------------- mmg identify


@pytest.mark.parametrize("kinds, expected", [
    (["hull"] * 22 + ["start"] * 12, "22 model parameters and 12 start-state offsets (34 in all)"),
    (["hull"] * 3 + ["wind_scale"], "4 model parameters"),
    (["hull", "start"], "1 model parameter and 1 start-state offset (2 in all)"),
])
def test_free_parameters_counted_in_words(kinds, expected):
    from types import SimpleNamespace

    from trials.measured.identify import free_parameter_text

    fit = SimpleNamespace(free=[SimpleNamespace(name=f"p{i}", kind=k) for i, k in enumerate(kinds)])
    assert free_parameter_text(fit) == expected


# ----------------------------------------------------------------- mmg diagnose


def test_sizes_relative_to_the_ship_said_in_si():
    from trials.measured.diagnose_report import size_in_si, size_with_unit

    L, T = 3.0, 0.2
    assert size_in_si(0.1, "sqrt(gL)", L, T) == f"{0.1 * math.sqrt(9.80665 * 3.0):.3g} m/s"      # 0.542 m/s
    assert size_with_unit(0.1, "sqrt(gL)", L, T) == "0.100 sqrt(gL) = 0.542 m/s"
    assert size_with_unit(0.5, "T/H", L, T) == "0.500 T/H, H = 0.400 m"                           # H = T / (T/H)
    assert size_with_unit(0.0, "T/H", L, T) == "0 T/H, H infinite"
    assert size_with_unit(0.738, "deg", L, T) == "0.738 deg" and size_in_si(1.0, "deg", L, T) == ""


def test_round_headers():
    from trials.measured.diagnose_report import round_header

    assert round_header(1, []) == "round 1: candidates against the ship alone"
    assert round_header(3, ["current", "rudder_offset"]) == "round 3: after naming current, rudder_offset"


def test_identifiability_line_has_units_and_the_depth():
    from types import SimpleNamespace

    from trials.measured.identifiability import identifiability_line

    row = {"effect": "shallow_water", "std": 0.0074, "std_conditional": 0.00108, "detection_size": 0.5,
           "confused_with": ["m_y", "J_z"]}
    line = identifiability_line(row, 0.989, "T/H", "T/H", SimpleNamespace(L=3.0, T=0.2))
    assert line == ("identifiability of shallow_water: R 0.989, sd 0.0074 T/H (alone 0.00108 T/H), "
                    "detection size 0.500 T/H, H = 0.400 m, with m_y, J_z")
