"""Issue 11, the edges of the speed range: a replay from standstill (pump at exactly 0 rad/s, tiny
first turbine speeds), the launch outputs replayed, ``simulate(times_s)`` integrating from the
drive's start, the vectorised ``tcsim.steady_state`` and ``characterise --speed-ratio``."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import tcsim
from tcsim import transient
from tcsim.cli import main
from tcsim.errors import InputError
from tcsim.models.steady import MAX_SWEEP_POINTS, speed_ratio_sweep

MODELS = ["table", "hrovat-tobler", "quasi-dynamic"]
CONVERTER = "li-sunden-2016"


def run_cli(*args: object) -> int:
    return main([str(a) for a in args])


# ---------------------------------------------------------------------------------------------
# standstill


def start_stop(tmp_path: Path, turbine: str) -> Path:
    """The start-stop rig test (§3.4) as drive (b): the pump ramps 0 → 200 rad/s in 1 s from exactly
    0, the turbine held at rest or following at 30 % of the pump speed."""
    t = np.round(np.arange(1501) * 1e-3, 12)
    wp = np.clip(t, 0.0, 1.0) * 200.0
    wt = np.zeros_like(t) if turbine == "held" else 0.3 * wp
    path = tmp_path / f"start_stop_{turbine}.csv"
    pd.DataFrame({"time_s": t, "pump_speed_rad_s": wp, "turbine_speed_rad_s": wt}).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("turbine", ["held", "free"])
@pytest.mark.parametrize("model", MODELS)
def test_start_stop_replay_from_a_pump_at_rest(tmp_path, model, turbine):
    """Refused before issue 11 (``initial pump_speed_rad_s = 0: expected a finite, non-zero pump
    speed``, exit 2). At rest the fluid transfers no torque; the run stays finite and the pump
    torque grows with the pump speed."""
    out = tmp_path / "out"
    meas = start_stop(tmp_path, turbine)
    assert run_cli("replay", CONVERTER, meas, "--drive", "speeds", "--model", model, "--out", out) == 0
    df = pd.read_csv(out / f"{model}.csv")
    assert df["pump_speed_rad_s"].iloc[0] == 0.0
    for torque in ("pump_transferred_torque_nm", "turbine_transferred_torque_nm"):
        assert df[torque].iloc[0] == pytest.approx(0.0, abs=1e-9)  # the rest is the inertias' I·ω̇
    physical = [c for c in df.columns if c.endswith(("_rad_s", "_nm", "_m3_s", "_w", "_j"))]
    assert np.isfinite(df[physical].to_numpy()).all()
    at_1s = df.loc[df["time_s"] == 1.0, "pump_torque_nm"].iloc[0]
    at_half = df.loc[df["time_s"] == 0.5, "pump_torque_nm"].iloc[0]
    assert at_1s > at_half > 0.0


@pytest.mark.parametrize("model", MODELS)
def test_pump_torque_drive_from_rest(model):
    """Drive (a) with zero pump torque and the turbine at rest starts at rest (ω_p = 0), then the
    pump speeds up under the torque step."""
    t = np.round(np.arange(1001) * 1e-3, 12)
    tp = np.where(t < 0.1, 0.0, 40.0)
    r = tcsim.simulate(CONVERTER, transient.PumpTorqueTurbineSpeed(t, tp, 0.0 * t), model)
    assert r["pump_speed_rad_s"][0] == 0.0
    assert np.isfinite(r["pump_speed_rad_s"]).all() and r["pump_speed_rad_s"][-1] > 50.0


def initial_pump_speed(model: str, turbine_speed_rad_s: float) -> float:
    t = np.round(np.arange(201) * 1e-3, 12)
    drive = transient.PumpTorqueTurbineSpeed(t, 40.0 + 0.0 * t, turbine_speed_rad_s + 10.0 * t)
    return float(tcsim.simulate(CONVERTER, drive, model, times_s=t[:2])["pump_speed_rad_s"][0])


@pytest.mark.parametrize("model", MODELS)
def test_tiny_first_turbine_speeds_start_continuously(model):
    """A first turbine speed of 1e-13 … 1e-9 rad/s was refused before issue 11 (``initial
    pump_torque_nm = 40: expected a pump torque the converter can absorb``, exit 2). The steady
    initial pump speed is continuous at ω_t → 0: the stall value, to 1e-8 relative (a turbine speed
    of 1e-9 rad/s moves the speed ratio by 1e-11, the pump speed by far less)."""
    at_rest = initial_pump_speed(model, 0.0)
    assert 50.0 < at_rest < 500.0
    for wt in (1e-13, 1e-11, 1e-9):
        assert initial_pump_speed(model, wt) == pytest.approx(at_rest, rel=1e-8)


# ---------------------------------------------------------------------------------------------
# launch outputs replayed

#: What the replay of a launch output must reproduce, and why it cannot reproduce it exactly: the
#: launch integrates the vehicle, the replay prescribes the launch's turbine speed sampled every
#: 10 ms, interpolated linearly between the samples, with its derivative smoothed over 40 ms (the
#: turbine inertia torque differs where the turbine accelerates quickly). Measured on the bundled
#: vehicle, first gear with the lock-up open (0–7.5 s): pump speed relative RMS 0.8e-5–1.2e-5, turbine
#: torque NRMSE 1.9e-4–2.3e-4 for the three models; a wrong converter or initial state gives percent
#: (the H&T replay on li-sunden-2016 instead of the vehicle's fitted geometry: 2.2e-2).
LAUNCH_PUMP_SPEED_REL_RMS = 1e-3
LAUNCH_TURBINE_TORQUE_NRMSE = 2e-3
BUNDLED_VEHICLE = Path(tcsim.__file__).parent / "data" / "vehicles" / "midsize-awd-8at.toml"


@pytest.fixture(scope="module")
def launch_dir(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("launch") / "results"
    assert run_cli("launch", "--out", out) == 0
    return out


@pytest.mark.parametrize("model", MODELS)
def test_launch_results_replay(launch_dir, tmp_path, model):
    """``tcsim launch`` writes ``results/<model>.csv``; each replays with ``tcsim replay`` (the
    Hrovat & Tobler one was refused before issue 11: its first turbine speed is 1.3e-13 rad/s). While
    the lock-up clutch is open and before the first gear shift, the replay (drive (a): the launch's
    pump torque and turbine speed in) reproduces the launch's pump speed and turbine torque."""
    out = tmp_path / "replay"
    converter = tomllib.loads(BUNDLED_VEHICLE.read_text(encoding="utf-8"))["converter"]
    assert run_cli("replay", converter, launch_dir / f"{model}.csv", "--model", model, "--out", out) == 0
    launch = pd.read_csv(launch_dir / f"{model}.csv")
    replayed = pd.read_csv(out / f"{model}.csv")
    assert np.allclose(replayed["time_s"], launch["time_s"])
    open_ = (launch["lockup_state"] == 0) & (launch["shifting"] == 0) & (launch["gear"] == launch["gear"].iloc[0])
    first = np.flatnonzero(~open_.to_numpy())
    n = first[0] if first.size else len(launch)
    assert n > 100
    wp_l, wp_r = launch["pump_speed_rad_s"][:n], replayed["pump_speed_rad_s"][:n]
    rel_rms = np.sqrt(np.mean((wp_r - wp_l) ** 2)) / np.sqrt(np.mean(wp_l**2))
    assert rel_rms < LAUNCH_PUMP_SPEED_REL_RMS
    tt_l, tt_r = launch["turbine_torque_nm"][:n], replayed["turbine_torque_nm"][:n]
    nrmse = np.sqrt(np.mean((tt_r - tt_l) ** 2)) / (tt_l.max() - tt_l.min())
    assert nrmse < LAUNCH_TURBINE_TORQUE_NRMSE


# ---------------------------------------------------------------------------------------------
# simulate(times_s)

#: Agreement of a run sampled from 2 s with the full run ending at the same time: the solver's steps
#: do not depend on the output times in between (samples are interpolated within the steps), so the
#: values agree to round-off (measured: identical). A different last output time changes the last
#: steps and leaves differences of the solver's tolerance (measured 1.5e-9 relative at rtol 1e-6).
LATE_START_RTOL = 1e-12


@pytest.mark.parametrize("model", MODELS)
def test_simulate_with_a_later_first_sample_integrates_from_the_drive_start(model):
    """Before issue 11 ``times_s`` starting at 2 s restarted the take-off at rest at 2 s (H&T pump
    speed at 2 s: 291 rad/s instead of 345.4)."""
    drive = transient.isolated_takeoff()
    times = np.round(np.arange(1001) * 0.01, 12)
    full = tcsim.simulate(CONVERTER, drive, model, times_s=times)
    later = times[200:][::-1][::7][::-1]  # from 2.05 s to the end, 10 s
    late = tcsim.simulate(CONVERTER, drive, model, times_s=later)
    at = np.searchsorted(times, later)
    for column in ("pump_speed_rad_s", "turbine_speed_rad_s", "pump_torque_nm", "turbine_torque_nm"):
        np.testing.assert_allclose(late[column], full[column][at], rtol=LATE_START_RTOL, atol=0.0)
    assert np.array_equal(late["time_s"], later)


@pytest.mark.parametrize(
    ("times", "field"),
    [
        ([-1.0, 1.0], "times_s[0]"),
        ([1.0, 1e9], "times_s[1]"),
        ([1.0, np.nan], "times_s[1]"),
        ([1e-7, 1.0], "times_s[0]"),
    ],
)
def test_simulate_times_outside_the_drive_are_input_errors(times, field):
    with pytest.raises(InputError) as e:
        tcsim.simulate(CONVERTER, transient.isolated_takeoff(), "table", times_s=times)
    assert e.value.field == field and e.value.source == "argument"


# ---------------------------------------------------------------------------------------------
# tcsim.steady_state


@pytest.mark.parametrize("model", MODELS)
def test_steady_state_has_the_characteristic_columns_and_agrees_with_characterise(model):
    ref = tcsim.characterise(CONVERTER, model=model)
    df = tcsim.steady_state(CONVERTER, model, ref["pump_speed_rad_s"], ref["turbine_speed_rad_s"])
    assert list(df.columns) == list(ref.columns) and len(df) == len(ref)
    numeric = [c for c in ref.columns if ref[c].dtype.kind == "f"]
    np.testing.assert_allclose(df[numeric].to_numpy(), ref[numeric].to_numpy(), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("model", MODELS)
def test_steady_state_broadcasts_any_sign_and_marks_points_without_a_steady_state(model):
    """One row per broadcast point (C order). Every quadrant is defined, the pump at rest included:
    there the turbine drives the fluid, so a turning turbine is braked (delivered torque against its
    rotation) and the pump at rest takes no power; both at rest is zero torque. A point whose torques
    overflow is a NaN row: ``no-steady-state`` for Hrovat & Tobler, ``extrapolated`` false for a table."""
    wp = np.array([[-300.0], [0.0], [150.0], [400.0], [1e200]])
    wt = np.array([-100.0, 0.0, 100.0, 600.0])
    df = tcsim.steady_state(CONVERTER, model, wp, wt)
    assert len(df) == 20
    np.testing.assert_array_equal(df["pump_speed_rad_s"], np.repeat(wp[:, 0], 4))
    np.testing.assert_array_equal(df["turbine_speed_rad_s"], np.tile(wt, 5))
    torques = df[["pump_torque_nm", "turbine_torque_nm", "stator_torque_nm"]].to_numpy()
    solved = np.isfinite(torques).all(axis=1)
    assert (solved | np.isnan(torques).all(axis=1)).all()
    assert solved[:16].all() and not solved[16:].any()  # every sign, the pump at rest; 1e200 rad/s overflows
    at_rest = df.iloc[4:8]
    np.testing.assert_array_equal(at_rest["pump_torque_nm"].iloc[1], 0.0)  # both at rest
    turning = at_rest.drop(at_rest.index[1])
    assert (turning["turbine_torque_nm"] * turning["turbine_speed_rad_s"] < 0).all(), turning
    if model == "hrovat-tobler":
        assert (df["stator_mode"][~solved] == "no-steady-state").all()
        assert (df["stator_mode"][solved] != "no-steady-state").all()
    else:
        assert not df["extrapolated"][~solved].any()


@pytest.mark.parametrize(
    ("wp", "wt", "field"),
    [
        ([100.0, np.nan], 0.0, "pump_speed_rad_s[1]"),
        (100.0, [[0.0, 1.0], [np.inf, 2.0]], "turbine_speed_rad_s[1, 0]"),
        ([1.0, 2.0], [1.0, 2.0, 3.0], "turbine_speed_rad_s"),
        ("fast", 0.0, "pump_speed_rad_s"),
        # scalars too (a scalar NaN gave a row of NaN: argwhere of a 0-d array finds nothing)
        (np.nan, 100.0, "pump_speed_rad_s"),
        (100.0, -np.inf, "turbine_speed_rad_s"),
    ],
)
def test_steady_state_input_errors_name_the_argument_and_index(wp, wt, field):
    with pytest.raises(InputError) as e:
        tcsim.steady_state(CONVERTER, "table", wp, wt)
    assert e.value.field == field and e.value.source == "argument"


def test_steady_state_unknown_model():
    with pytest.raises(InputError) as e:
        tcsim.steady_state(CONVERTER, "magic", 100.0, 0.0)
    assert e.value.field == "model"


# ---------------------------------------------------------------------------------------------
# characterise --speed-ratio


def characterised(tmp_path: Path, model: str, sweep: str) -> pd.DataFrame:
    out = tmp_path / "out"
    assert run_cli("characterise", CONVERTER, "--model", model, f"--speed-ratio={sweep}", "--out", out) == 0
    assert (out / "tr_cf.png").is_file() or any(out.glob("*.png"))
    return pd.read_csv(out / "characteristic.csv")


@pytest.mark.parametrize("model", ["table", "quasi-dynamic"])
def test_characterise_sweep_of_the_table_range_gives_the_table(tmp_path, model):
    df = characterised(tmp_path, model, "0:1:0.05")
    table = tcsim.load_converter(CONVERTER).characteristic
    assert list(df.columns) == list(tcsim.characterise(CONVERTER, model=model).columns)
    assert np.all(np.diff(df["speed_ratio"]) > 0)
    assert len(df) == len(np.union1d(np.round(np.arange(21) * 0.05, 12), table.speed_ratio))
    knots = df.set_index("speed_ratio").loc[table.speed_ratio]
    np.testing.assert_allclose(knots["torque_ratio"], table.torque_ratio, rtol=1e-12)
    np.testing.assert_allclose(knots["capacity_factor_nm_s2"], table.capacity_factor_nm_s2, rtol=1e-12)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("sweep", ["-1:0:0.1", "0:5:0.1", "-2:3:0.25"])
def test_characterise_sweeps_beyond_0_to_1(tmp_path, capsys, model, sweep):
    """Negative SR and SR up to 5 run for the table models (plots included); for Hrovat & Tobler a
    point outside the core's solved range is one error naming ``--speed-ratio`` (exit 2) until the
    core covers it, and runs afterwards."""
    out = tmp_path / "out"
    code = run_cli("characterise", CONVERTER, "--model", model, f"--speed-ratio={sweep}", "--out", out)
    if code == 2:
        assert model == "hrovat-tobler"
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("error: command line: --speed-ratio = ") and not out.exists()
        return
    assert code == 0
    df = pd.read_csv(out / "characteristic.csv")
    lo, hi, _ = (float(x) for x in sweep.split(":"))
    assert df["speed_ratio"].iloc[0] == lo and df["speed_ratio"].iloc[-1] == hi
    assert np.all(np.diff(df["speed_ratio"]) > 0)
    np.testing.assert_allclose(df["efficiency"], df["speed_ratio"] * df["torque_ratio"], rtol=1e-12)
    k = df["k_factor_rpm_per_sqrt_nm"]
    assert np.isnan(k[df["capacity_factor_nm_s2"] < 0]).all()


def test_characterise_overrun_rows_write_without_a_warning(tmp_path, capsys):
    """A table's own coast rows (negative CF) give a NaN K-factor by definition, and CF = 0 an
    infinite one: neither is an overflow (before issue 11 the writer warned ``non-finite values …
    in k_factor_rpm_per_sqrt_nm (40)``, the NaN of a column whose name ends in ``_nm``)."""
    table = Path(__file__).resolve().parents[1] / "data" / "converters" / "jambe_trami_9at.csv"
    out = tmp_path / "out"
    assert run_cli("characterise", table, "--speed-ratio=0:3:0.05", "--out", out) == 0
    assert "warning" not in capsys.readouterr().err
    df = pd.read_csv(out / "characteristic.csv")
    negative = df["capacity_factor_nm_s2"] < 0
    assert negative.sum() > 10 and df["k_factor_rpm_per_sqrt_nm"][negative].isna().all()


@pytest.mark.parametrize(
    "sweep",
    ["0:1", "a:b:c", "0:1:0", "0:1:-0.1", "1:0:0.1", "0:nan:0.1", "0:101:1", "-0.5:1e3:0.1", "0:10:1e-5"],
)
def test_speed_ratio_sweep_refusals(sweep):
    with pytest.raises(InputError) as e:
        speed_ratio_sweep(sweep)
    assert e.value.field == "--speed-ratio" and e.value.value == sweep and e.value.source == "command line"


def test_speed_ratio_sweep_grid():
    np.testing.assert_allclose(speed_ratio_sweep("0:1:0.01"), np.linspace(0.0, 1.0, 101), atol=1e-15)
    assert speed_ratio_sweep("0:1:0.3").tolist()[-1] == pytest.approx(0.9)
    assert len(speed_ratio_sweep(f"0:1:{1 / (MAX_SWEEP_POINTS - 1)!r}")) == MAX_SWEEP_POINTS


@pytest.mark.parametrize("model", ["table", "quasi-dynamic"])
def test_a_sweep_keeps_the_table_points_past_its_last_step(tmp_path, model):
    """conventions.md: the table's speed ratios in [MIN, MAX] are added, also those past the grid's
    last step (``0:1:0.7`` has the grid 0, 0.7; it dropped the table's 0.8–1)."""
    df = characterised(tmp_path, model, "0:1:0.7")
    table = tcsim.load_converter(CONVERTER).characteristic.speed_ratio
    assert df["speed_ratio"].tolist() == np.union1d([0.0, 0.7], table[(table >= 0) & (table <= 1)]).tolist()


@pytest.mark.parametrize("model", MODELS)
def test_default_sweeps_hold_no_near_duplicates(model):
    """The default sweep merges a grid point within 1e-9 of a step into the table point (or the
    coupling point) it stands for: the table's sweep had 0.7 and 0.7000000000000001 as two rows."""
    sr = tcsim.characterise(CONVERTER, model=model)["speed_ratio"].to_numpy()
    step = (sr[-1] - sr[0]) / 100
    assert np.diff(sr).min() > 1e-6 * step
    table = tcsim.load_converter(CONVERTER).characteristic.speed_ratio
    if model != "hrovat-tobler":
        assert np.isin(table, sr).all()
