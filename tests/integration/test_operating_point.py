"""The backward operating point (issue 12, item 2): ``tcsim.operating_point`` and ``tcsim operating-point``.

Every expectation comes from the forward model (``tcsim.steady_state``) or from the table by hand,
never from the backward call itself."""

from __future__ import annotations

import math
import os
import signal
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import tcsim
from interrupts import interrupt
from tcsim.errors import InputError, TcsimWarning
from tcsim.io.results import non_finite_columns
from tcsim.models.converter import bundled_names, load_converter
from tcsim.models.operating_point import COLUMNS

CASES = [(name, model) for name in bundled_names() for model in load_converter(name).models]
WP = 2000 * math.pi / 30  # rad/s
#: Speed ratios of the grid: drive (0 … 0.95) and coast (1.05 … 2).
DRIVE_SR = np.linspace(0.0, 0.95, 20)
COAST_SR = np.array([1.05, 1.2, 1.5, 2.0])


def _forward(conv, model, wp, wt) -> pd.DataFrame:
    with np.errstate(divide="ignore", invalid="ignore"):
        return tcsim.steady_state(conv, model, wp, wt)


def _round_trip(conv, model, wp: np.ndarray, wt: np.ndarray, *reasons: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Forward at (wp, wt), backward from its delivered torque, forward again at the pump speeds found;
    asserts every point's reason is one of ``reasons`` (default ``ok``) and the torque comes back to
    1e-9 of the torques there."""
    fwd = _forward(conv, model, wp, wt)
    t = fwd["turbine_torque_nm"].to_numpy()
    back = tcsim.operating_point(conv, wt, t, model=model)
    allowed = back["reason"].isin(reasons or ("ok",))
    assert allowed.all(), back[~allowed]
    again = _forward(conv, model, back["pump_speed_rad_s"].to_numpy(), wt)
    scale = np.maximum(np.abs(t), np.abs(again["pump_torque_nm"].to_numpy()))
    np.testing.assert_array_less(np.abs(again["turbine_torque_nm"].to_numpy() - t), 1e-9 * scale + 1e-300)
    np.testing.assert_array_equal(back["pump_torque_nm"], again["pump_torque_nm"])
    return fwd, back


@pytest.mark.filterwarnings("ignore::tcsim.errors.TcsimWarning")
@pytest.mark.parametrize(("name", "model"), CASES)
@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["forward", "reversed"])
def test_drive_round_trips_to_the_pump_speed(name, model, sign):
    conv = load_converter(name)
    wp = np.full(DRIVE_SR.shape, sign * WP)
    # reversed, the mirror image of drive: with a table only the pump turned backwards gives it (values
    # given); Hrovat & Tobler reversed gives torques a forward pump gives too (28 kN·m at 2000 rpm)
    reasons = ("ok",) if sign > 0 else ("pump-backwards",) if model != "hrovat-tobler" else ("ok", "pump-backwards")
    _, back = _round_trip(conv, model, wp, DRIVE_SR * wp, *reasons)
    ok = (back["reason"] == "ok").to_numpy()
    assert (back["pump_speed_rad_s"][ok] >= 0).all() and (back["pump_speed_rad_s"][~ok] < 0).all()
    if model == "hrovat-tobler" and sign < 0:
        # Hrovat & Tobler is not odd in the speeds: with both reversed several pump speeds give the
        # torque (the torque round trip above holds; the rule picks another root)
        return
    np.testing.assert_allclose(back["pump_speed_rad_s"], wp, rtol=1e-9, atol=0)
    # the ratios are the forward model's
    np.testing.assert_allclose(back["speed_ratio"], DRIVE_SR, rtol=1e-9, atol=1e-15)


@pytest.mark.filterwarnings("ignore::tcsim.errors.TcsimWarning")
@pytest.mark.parametrize(("name", "model"), CASES)
def test_coast_round_trips_to_the_lowest_pump_speed(name, model):
    conv = load_converter(name)
    wp = np.concatenate([np.full(COAST_SR.shape, WP), np.full(COAST_SR.shape, -WP)])
    wt = np.concatenate([COAST_SR, COAST_SR]) * wp
    fwd, back = _round_trip(conv, model, wp, wt, "ok", "pump-backwards")
    assert (fwd["turbine_torque_nm"].to_numpy() * wt < 0).all()  # coast: the turbine is driven
    found = back["pump_speed_rad_s"].to_numpy()
    n = COAST_SR.size
    # the pump turns forwards, never faster than the grid's own point (the lowest such root)
    assert (back["reason"][:n] == "ok").all(), back
    assert (found[:n] > 0).all() and (found[:n] <= wp[:n] * (1 + 1e-9)).all(), back
    # the turbine turning backwards with a positive torque is a vehicle rolling back: a pump turning
    # forwards holds it where it can (ok); where the torque is below what the converter takes with the
    # pump at rest, only the mirror image gives it, the pump turned backwards (no faster than the grid's)
    forwards = (back["reason"][n:] == "ok").to_numpy()
    assert (found[n:][forwards] >= 0).all(), back
    backwards = found[n:][~forwards]
    assert (backwards < 0).all() and (backwards >= wp[n:][~forwards] * (1 + 1e-9)).all(), back


def test_the_table_closed_form_gives_the_hand_values():
    conv = load_converter("li-sunden-2016")
    # SR 0.5 at ω_p = 200 rad/s: T = TR·CF·ω_p² with Table C.1's row (1.43, 3.017e-3)
    t = 1.43 * 3.017e-3 * 200.0**2
    df = tcsim.operating_point(conv, [100.0, 0.0], [t, 300.0])
    np.testing.assert_allclose(df["pump_speed_rad_s"], [200.0, math.sqrt(300.0 / (2.14 * 3.272e-3))], rtol=1e-12)
    np.testing.assert_allclose(df["pump_torque_nm"], [3.017e-3 * 200.0**2, 300.0 / 2.14], rtol=1e-12)
    np.testing.assert_allclose(df["efficiency"], [0.5 * 1.43, 0.0], atol=1e-12)
    assert df["reason"].tolist() == ["ok", "ok"]
    # the quasi-dynamic model's steady state is its table
    qd = tcsim.operating_point(conv, [100.0, 0.0], [t, 300.0], model="quasi-dynamic")
    pd.testing.assert_frame_equal(df, qd)


def test_invalid_points_are_flagged_and_no_nan_comes_without_a_reason():
    conv = load_converter("li-sunden-2016")
    stall = 3.272e-3 * 100.0**2  # coast torque CF(0)·ω_t² with the pump at rest, turbine at 100 rad/s
    # then: the mirror of drive (both negative: the engine turned backwards), overflow, rolling back in drive
    wt = [np.nan, 100.0, 0.0, 100.0, 100.0, 100.0, -100.0, 1e-160, -20.0, 0.0]
    t = [1.0, np.inf, 0.0, 172.0, -0.5 * stall, -3.0 * stall, -172.0, 1e300, 100.0, -50.0]
    with pytest.warns(TcsimWarning, match="the operating points"):  # the coast point is in the mirror extension
        df = tcsim.operating_point(conv, wt, t, pump_speed_limit_rad_s=150.0)
    assert df["reason"].tolist() == [
        "non-finite-input",
        "non-finite-input",
        "at-rest",
        "above-pump-speed-limit",
        "ok",
        "pump-backwards",
        "pump-backwards",
        "overflow",
        "ok",
        "pump-backwards",
    ]
    assert df["valid"].tolist() == [False, False, True, False, True, False, False, False, True, False]
    # values are given where a steady state exists, NaN only with a reason that says there is none
    assert df.loc[3, "pump_speed_rad_s"] > 150.0 and df.loc[5, "pump_speed_rad_s"] < -100.0
    assert df.loc[8, "pump_speed_rad_s"] > 20.0 and df.loc[9, "pump_speed_rad_s"] < 0.0
    numbers = df[["pump_speed_rad_s", "pump_torque_nm", "speed_ratio", "torque_ratio", "efficiency"]]
    nan_rows = numbers.isna().any(axis=1)
    assert set(df.loc[nan_rows, "reason"]) <= {"non-finite-input", "at-rest", "overflow"}
    assert df.loc[2, "pump_speed_rad_s"] == 0.0 and df.loc[2, "pump_torque_nm"] == 0.0


def test_a_power_gives_the_torque_p_over_omega():
    conv = load_converter("li-sunden-2016")
    by_power = tcsim.operating_point(conv, [100.0, 0.0, -50.0], turbine_power_w=[2e4, 1e3, 5e3])
    by_torque = tcsim.operating_point(conv, [100.0, -50.0], [200.0, -100.0])
    assert by_power["turbine_torque_nm"].tolist()[::2] == [200.0, -100.0]
    pd.testing.assert_frame_equal(by_power.iloc[[0, 2]].reset_index(drop=True), by_torque)
    assert by_power.loc[1, "reason"] == "power-at-standstill" and not by_power.loc[1, "valid"]


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"model": "vecto"}, "model"),
        ({"pump_speed_limit_rad_s": 0.0}, "pump_speed_limit_rad_s"),
        ({"pump_speed_limit_rad_s": float("nan")}, "pump_speed_limit_rad_s"),
        ({"turbine_power_w": [1.0]}, "turbine_power_w"),  # with a torque too: named as the one too many
    ],
)
def test_api_refuses_bad_arguments(kwargs, field):
    with pytest.raises(InputError) as e:
        tcsim.operating_point("li-sunden-2016", [100.0], [50.0], **kwargs)
    assert (e.value.source, e.value.field) == ("argument", field)


def test_a_load_not_given_asks_for_one():
    """A trial: ``operating_point(C, [100])`` said ``turbine_torque_nm = 'neither': expected either
    … not both``."""
    with pytest.raises(InputError) as e:
        tcsim.operating_point("li-sunden-2016", [100.0])
    assert (e.value.field, e.value.value) == ("turbine_torque_nm", None)
    assert "not both" not in e.value.expected and "turbine_power_w" in e.value.expected


def test_api_refuses_text_and_shapes_that_do_not_broadcast():
    with pytest.raises(InputError, match="turbine_torque_nm"):
        tcsim.operating_point("li-sunden-2016", [100.0, 200.0], [1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="turbine_speed_rad_s"):
        tcsim.operating_point("li-sunden-2016", ["fast"], [1.0])


# ---------------------------------------------------------------------------------------------
# the command line


def _points(tmp_path: Path, text: str, name: str = "points.csv") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_cli_writes_the_operating_points(cli, tmp_path):
    points = _points(tmp_path, "turbine_speed_rad_s,turbine_torque_nm\n100,172\n0,300\n150,-20\n")
    r = cli("operating-point", "li-sunden-2016", points, "--out", tmp_path / "o", "--pump-speed-limit-rpm", "1800")
    assert r.code == 0, r.stderr
    df = pd.read_csv(tmp_path / "o" / "operating_points.csv")
    assert list(df.columns) == list(COLUMNS)
    limit = 1800 * math.pi / 30
    api = tcsim.operating_point("li-sunden-2016", [100, 0, 150], [172, 300, -20], pump_speed_limit_rad_s=limit)
    np.testing.assert_allclose(df["pump_speed_rad_s"], api["pump_speed_rad_s"], rtol=1e-15)
    assert df["reason"].tolist() == api["reason"].tolist()
    assert "3 operating points written" in r.stdout + r.stderr


def test_flagged_points_are_written_without_an_overflow_warning(cli, tmp_path):
    """A flagged point's empty values are explained by its reason; a valid point with a non-finite
    value would still be warned about (the writer's check, io.results.non_finite_columns)."""
    points = _points(tmp_path, "turbine_speed_rad_s,turbine_torque_nm\n100,50\n1e200,1e300\n")
    r = cli("operating-point", "li-sunden-2016", points, "--out", tmp_path / "o", "--allow-implausible")
    assert r.code == 0, r.stderr
    df = pd.read_csv(tmp_path / "o" / "operating_points.csv")
    assert df["reason"].tolist() == ["ok", "overflow"] and df["pump_speed_rad_s"].isna().tolist() == [False, True]
    assert "non-finite" not in r.stdout + r.stderr, r.stderr
    assert non_finite_columns(df) == {}
    df.loc[1, "valid"] = True  # the same NaN in a point called valid is reported
    assert non_finite_columns(df) == {"pump_speed_rad_s": 1, "pump_torque_nm": 1}


def test_cli_reads_powers_from_parquet_and_other_models(cli, tmp_path):
    p = tmp_path / "points.parquet"
    pd.DataFrame({"turbine_speed_rad_s": [100.0, 0.0], "turbine_power_w": [2e4, 5.0]}).to_parquet(p)
    r = cli("operating-point", "li-sunden-2016", p, "--model", "hrovat-tobler", "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    df = pd.read_csv(tmp_path / "o" / "operating_points.csv")
    assert df["turbine_torque_nm"][0] == 200.0 and df["reason"].tolist() == ["ok", "power-at-standstill"]
    assert "1 flagged (1 power-at-standstill)" in r.stdout + r.stderr


def test_cli_reads_speeds_in_rpm_and_runs_implausible_values_only_when_allowed(cli, tmp_path):
    rad_s = _points(tmp_path, "turbine_speed_rad_s,turbine_torque_nm\n100,172\n150,-20\n", "rad_s.csv")
    rpm = _points(
        tmp_path,
        f"turbine_speed_rpm,turbine_torque_nm\n{100 * 30 / math.pi!r},172\n{150 * 30 / math.pi!r},-20\n",
        "rpm.csv",
    )
    for p, out in ((rad_s, "a"), (rpm, "b")):
        assert cli("operating-point", "li-sunden-2016", p, "--out", tmp_path / out).code == 0
    a, b = (pd.read_csv(tmp_path / o / "operating_points.csv") for o in "ab")
    np.testing.assert_allclose(b["pump_speed_rad_s"], a["pump_speed_rad_s"], rtol=1e-12)
    wrong = _points(tmp_path, "turbine_speed_rad_s,turbine_torque_nm\n1500,200\n", "wrong.csv")
    r = cli("operating-point", "li-sunden-2016", wrong, "--out", tmp_path / "c", "--allow-implausible")
    assert r.code == 0 and "turbine_speed_rad_s = 1500 is outside the plausible" in r.stderr, r.stderr


BAD = [
    ("turbine_torque_nm\n1\n", "points.csv", [], "turbine_speed_rad_s / turbine_speed_rpm = 'missing'"),
    ("turbine_speed_rad_s,turbine_speed_rpm,turbine_torque_nm\n1,2,3\n", "points.csv", [], "_rpm = 'both'"),
    # rpm under a rad/s name, a torque in N·mm: refused by the plausibility ranges (trial: "ok" points)
    ("turbine_speed_rad_s,turbine_torque_nm\n100,200\n1500,200\n", "points.csv", [], "1500 rad/s at row 2"),
    ("turbine_speed_rad_s,turbine_torque_nm\n100,2e5\n", "points.csv", [], "turbine_torque_nm = 200000 N·m at row 1"),
    ("turbine_speed_rad_s\n1\n", "points.csv", [], "turbine_torque_nm / turbine_power_w = 'missing'"),
    ("turbine_speed_rad_s,turbine_torque_nm,turbine_power_w\n1,2,3\n", "points.csv", [], "= 'both'"),
    ("turbine_speed_rad_s,turbine_torque_nm\n1,abc\n", "points.csv", [], "turbine_torque_nm = \"'abc' at row 1\""),
    ("turbine_speed_rad_s,turbine_torque_nm\n1,\n", "points.csv", [], "turbine_torque_nm = 'NaN at row 1'"),
    ("turbine_speed_rad_s,turbine_torque_nm\n", "points.csv", [], "(rows) = 0"),
    ("turbine_speed_rad_s,turbine_torque_nm\n1,2\n", "points.txt", [], "(extension) = '.txt'"),
    ("turbine_speed_rad_s,turbine_torque_nm\n1,2\n", "points.csv", ["--model", "vecto"], "--model = 'vecto'"),
    ("turbine_speed_rad_s,turbine_torque_nm\n1,2\n", "points.csv", ["--pump-speed-limit-rpm", "-5"], "-5"),
]


@pytest.mark.parametrize(("text", "name", "extra", "message"), BAD, ids=[m for *_, m in BAD])
def test_cli_bad_input_exits_2_with_one_line_and_writes_nothing(cli, tmp_path, text, name, extra, message):
    points = _points(tmp_path, text, name)
    before = points.read_bytes()
    r = cli("operating-point", "li-sunden-2016", points, "--out", tmp_path / "o", *extra)
    assert r.code == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], r.stderr
    assert not (tmp_path / "o").exists()
    assert points.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == [name]


@pytest.mark.subprocess
def test_an_interrupted_run_leaves_nothing(tmp_path):
    """SIGINT while the output is being written: exit 130, one line, no output and no staging folder."""
    data = tmp_path / "data"
    data.mkdir()
    n = 400_000
    rng = np.random.default_rng(12)
    points = data / "points.parquet"
    frame = {"turbine_speed_rad_s": rng.uniform(0, 300, n), "turbine_torque_nm": rng.uniform(-50, 400, n)}
    pd.DataFrame(frame).to_parquet(points)
    work = tmp_path / "work"
    work.mkdir()
    r = interrupt(["operating-point", "li-sunden-2016", str(points), "--out", "o"], signal.SIGINT, "writing", work)
    err = r.stderr
    assert r.returncode == 130, err
    lines = [line for line in err.strip().splitlines() if not line.startswith("warning: ")]  # the mirror's
    assert lines == ["interrupted (SIGINT): nothing written"], err
    assert os.listdir(work) == []
