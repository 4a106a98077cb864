"""The hostile-input review's findings, each as a class (V1-V3, V5, V6, M1, M2; V4 in
test_output_apart.py): valid records never refused, wrong units or ships refused in one line."""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from mmg.errors import InputError
from mmg.ship import load_ship
from trials.files import shipcheck as sc
from trials.files.logio import read_record

from .conftest import CONFIGS, FRT, REPO, needs_frt

DEV = REPO.parent / "shared" / "data" / "diagnose-dev" / "data"
needs_dev = pytest.mark.skipif(not DEV.is_dir(), reason="diagnose-dev data absent")


def _scaled(src: Path, dst: Path, col: str, factor: float) -> Path:
    df = pd.read_csv(src)
    df[col] = df[col] * factor
    df.to_csv(dst, index=False)
    return dst


# --------------------------------------------------------------------------- V3: propeller tip speed


@needs_dev
@pytest.mark.parametrize("factor, unit", [(60.0, "rpm"), (2 * np.pi, "rad/s")])
def test_full_scale_propeller_speed_in_another_unit_refused(tmp_path, factor, unit):
    """A full-scale record with n in rpm (52 "rps": under the reader's 100 rps cap) or rad/s is refused
    by the tip speed pi n D of the ship's propeller, naming the likely unit; every command checks so."""
    esso = load_ship(CONFIGS / "ships" / "esso_osaka.yaml")
    for src in sorted(DEV.glob("*.csv"))[:3]:
        p = _scaled(src, tmp_path / src.name, "n_prop [rps]", factor)
        with pytest.raises(sc.ShipMismatch, match=f"tip speed.*{unit}") as e:
            sc.read_for_ship(p, esso)
        assert e.value.field == "n_prop [rps]"          # the column, by its exact header
        with pytest.raises(sc.ShipMismatch, match=unit):       # a length only (mmg metrics --length 325)
            sc.read_for_ship(p, 325.0)


@needs_dev
@needs_frt()
def test_valid_propeller_speeds_accepted():
    """Every real record with its own ship: tip speed inside the bound (margins: bench/ship_check_margins.py)."""
    esso, m3 = load_ship(CONFIGS / "ships" / "esso_osaka.yaml"), load_ship(CONFIGS / "ships" / "esso_osaka_3m.yaml")
    for files, ship in ((sorted(DEV.glob("*.csv")), esso), (sorted(FRT.glob("*/*.csv")), m3)):
        for p in files:
            s = sc.read_for_ship(p, ship)
            assert sc.tip_speed(s.n[np.isfinite(s.n)].max() if s.n is not None else 0, ship.propeller.D) < sc.TIP_SPEED_MAX


def test_tip_speed_message_names_unit():
    with pytest.raises(sc.ShipMismatch, match=r"rpm\? \(600 rpm = 10 rps"):
        sc.check_tip_speed(600.0, 3.0 / 35, "r.csv", "the 3 m model")
    sc.check_tip_speed(17.95, 0.1427, "r.csv", "KVLCC2 L7")        # the MMG-2015 model: 8 m/s


# --------------------------------------------------------------------------- V1: steps with a tolerance


@needs_frt()
@pytest.mark.parametrize("step", [0.02, 0.05, 1.0])
def test_frt_record_resampled_to_the_range_ends_accepted(tmp_path, step):
    """A valid record resampled to 50 Hz (its median step 0.0199999999999996 s) or to the other ends of
    the accepted range is read, not refused as beyond the range."""
    src = sorted((FRT / "zigzag").glob("*.csv"))[0]
    df = pd.read_csv(src).dropna(how="all")
    t0 = df["t [s]"].to_numpy()
    t = t0[0] + np.arange(int((t0[-1] - t0[0]) / step)) * step
    t = np.round(t0[0] + np.cumsum(np.r_[0, np.full(len(t) - 1, step)]), 12) if step == 1.0 else t
    out = pd.DataFrame({c: np.interp(t, t0, df[c].to_numpy()) for c in df.columns})
    out["t [s]"] = t
    p = tmp_path / "resampled.csv"
    out.to_csv(p, index=False)
    rec = read_record(p)
    assert abs(np.median(np.diff(rec.t)) - step) < 1e-9


# --------------------------------------------------------------------------- V2: a second ship option


@needs_frt()
@pytest.mark.parametrize("ship, initial", [("esso_osaka_3m", "esso_osaka"), ("esso_osaka", "esso_osaka_3m"),
                                           ("esso_osaka_3m_crossflow", "kvlcc2_l7")])
def test_identify_initial_of_another_ship_refused(tmp_path, capsys, ship, initial):
    """--initial with other particulars than --ship: one line naming both, before any record is read."""
    from trials.cli import main

    rec = sorted((FRT / "zigzag").glob("*.csv"))[0]
    assert main(["identify", "--ship", ship, "--initial", initial, "--train", str(rec),
                 "--out", str(tmp_path / "o"), "--max-nfev", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --initial: particulars."), err
    assert load_ship(ship).name in err[0] and load_ship(initial).name in err[0]
    assert not (tmp_path / "o").exists()


def test_identify_library_refuses_initial_of_another_ship():
    from trials.measured.identify import identify

    with pytest.raises(sc.ShipMismatch, match="particulars.L"):
        identify(load_ship("esso_osaka_3m"), [], initial=load_ship("esso_osaka"))
    sc.check_same_ship(load_ship("esso_osaka_3m_crossflow"), load_ship("esso_osaka_3m"))   # one ship, two forms


# --------------------------------------------------------------------------- V5: turning circles below 1 L


@needs_frt()
def test_turn_with_a_wrong_length_refused(capsys):
    """A real 3 m model turn read with L = 7 m or more turns on circles under 1 L: refused, one line, the figure;
    with its own length (3 m) every FRT-DS-ESSO turn is accepted (bench/turn_diameter_margins.py: margins >= 1.87)."""
    from trials.analysis.metrics import MIN_TURN_DIAMETER_L, record_metrics
    from trials.cli import main

    turns = sorted((FRT / "turning").glob("*.csv"))
    for p in turns:
        m = record_metrics(read_record(p, length_m=3.0), kind="turning", length=3.0)
        assert min(m["tactical_diameter_L"], m["steady_diameter_L"]) >= MIN_TURN_DIAMETER_L
    for L in ("20", "12"):
        assert main(["metrics", "--length", L, str(turns[0])]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "not this ship's length?" in err[0] and " L (" in err[0], err
    with pytest.raises(InputError, match="diameter"):
        record_metrics(read_record(turns[0], length_m=20.0), kind="turning", length=20.0)


# --------------------------------------------------------------------------- V6: constant-rpm approach rpm


@pytest.mark.parametrize("rpm, ok", [("3000 rpm", False), ("1500 rpm", False), ("300 rpm", False),
                                     ("17.95 rps", True), ("711 rpm", True), ("solve", True)])
def test_constant_rpm_approach_within_a_factor_2(rpm, ok):
    """The KVLCC2 model (constant rpm) at 1.179 m/s: its straight run needs 711 rpm (11.85 rps); the published
    MMG-2015 17.95 rps (factor 1.51) is accepted, 3000 rpm (which runs the ship up to 3.58 m/s) refused."""
    import yaml

    from trials.runs.trial import trial_from_dict

    data = yaml.safe_load((CONFIGS / "trials" / "kvlcc2_zz20.yaml").read_text())
    data["approach"]["rpm"] = rpm
    if ok:
        trial_from_dict(data, "t.yaml", base=CONFIGS / "trials")
    else:
        with pytest.raises(InputError, match=r"approach.rpm: .* times the rpm of the straight run.*711"):
            trial_from_dict(data, "t.yaml", base=CONFIGS / "trials")


# --------------------------------------------------------------------------- M1, M2: a refusal is one line


def _wind_nan(src: Path, dst: Path, rows=None) -> Path:
    df = pd.read_csv(src)
    cols = ["wind_velo_relative_mid [m/s]", "wind_dir_relative_mid [rad]"]
    df[cols] = df[cols].astype(float)
    df.loc[df.index if rows is None else rows, cols] = np.nan
    df.to_csv(dst, index=False)
    return dst


@needs_frt()
def test_wind_nan_throughout_is_no_wind(tmp_path, capsys):
    """Relative-wind columns NaN in every row: as if absent (the same one 'wind skipped' note, accepted);
    partly NaN with the wind used: refused, and stderr holds only the error line (no reader notes first)."""
    from trials.cli import main

    src = sorted((FRT / "zigzag").glob("*.csv"))[0]
    p = _wind_nan(src, tmp_path / "nan.csv")
    rec = read_record(p)
    assert rec.wind_speed_rel is None and rec.wind_dir_rel is None
    assert main(["predict", "--ship", "esso_osaka_3m", "--json", str(tmp_path / "a.json"), str(p)]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert [ln for ln in err if "wind" in ln] == [f"{p}: wind skipped: the record has no wind_speed_rel / "
                                                  "wind_dir_rel channels"], err
    q = _wind_nan(src, tmp_path / "part.csv", rows=slice(100, 200))
    assert main(["predict", "--ship", "esso_osaka_3m", "--json", str(tmp_path / "b.json"), str(q)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "wind_velo_relative_mid" in err[0], err
    assert not (tmp_path / "b.json").exists()


@needs_frt()
@needs_dev
def test_identify_refuses_a_test_record_before_any_progress(tmp_path, capsys):
    """--test of another ship: exit 2 with the one error line, not 'training on 1 record' first."""
    from trials.cli import main

    train = sorted((FRT / "zigzag").glob("*.csv"))[0]
    test = sorted(DEV.glob("*.csv"))[0]
    assert main(["identify", "--ship", "esso_osaka_3m", "--train", str(train), "--test", str(test),
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {test}"), err
