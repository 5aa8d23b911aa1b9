"""``tcsim drive`` (issue 14, item 6): the driver follows US06, UDDS and WLTC 3b with every model,
the energy balance closes, coasting brakes the engine, and bad traces are refused in one line.

The whole cycles with all three models take about 2 CPU-minutes (docs/drive.md has their
numbers), so the acceptance runs all three models on segments of each cycle that start and end at
rest (the hard US06 take-offs, the first UDDS hill, WLTC's extra-high phase) and one whole cycle,
WLTC 3b, with the table model.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from tcsim.analysis.drive import BUNDLED_CYCLES, SUMMARY_COLUMNS, Cycle, drive
from tcsim.errors import TcsimWarning
from tcsim.io.cycle import bundled_cycle_path, read_cycle
from tcsim.models.vehicle import load_vehicle

#: (cycle, start, end) of the segments, s: each starts and ends at rest.
SEGMENTS = [("us06", 0, 128), ("udds", 0, 125), ("wltc-3b", 1452, 1800)]
MODELS = ["table", "hrovat-tobler", "quasi-dynamic"]


def segment(name: str, start: float, end: float) -> Cycle:
    c = read_cycle(bundled_cycle_path(name), name)
    keep = (c.time_s >= start) & (c.time_s <= end)
    assert c.vehicle_speed_m_s[keep][0] == 0.0 and c.vehicle_speed_m_s[keep][-1] == 0.0
    return Cycle(f"{name}[{start}:{end}]", c.source, c.time_s[keep] - start, c.vehicle_speed_m_s[keep])


@pytest.fixture(scope="module")
def vehicle():
    return load_vehicle()


@pytest.fixture(scope="module")
def segment_runs(vehicle):
    return {seg: drive(vehicle, segment(*seg), MODELS) for seg in SEGMENTS}


@pytest.fixture(scope="module")
def wltc(vehicle):
    return drive(vehicle, read_cycle(bundled_cycle_path("wltc-3b"), "wltc-3b"), ["table"])


def check_acceptance(summary: pd.DataFrame) -> None:
    for _, row in summary.iterrows():
        assert row.rms_speed_error_km_h < 1.0, row.to_dict()
        assert abs(row.energy_residual) < 1e-4, row.to_dict()


def test_every_model_follows_the_cycle_segments_and_the_energy_balances(segment_runs):
    for seg, result in segment_runs.items():
        assert list(result.summary.model) == MODELS, seg
        check_acceptance(result.summary)


def test_whole_wltc_is_followed_and_the_energy_balances(wltc):
    check_acceptance(wltc.summary)
    f = wltc.runs["table"].frame
    # the vehicle stands at every stop of the trace, held by the brake, and the lock-up locks
    assert f.vehicle_speed_m_s.iloc[-1] == pytest.approx(0.0, abs=1e-3)
    assert (f.lockup_state == 2).any() and (f.gear == 8).any()


def coasting(f: pd.DataFrame) -> pd.DataFrame:
    """Samples with the accelerator released, rolling faster than 5 m/s, not shifting."""
    return f[(f.accelerator_pedal == 0.0) & (f.vehicle_speed_m_s > 5.0) & (f.shifting == 0)]


def test_the_table_models_reaching_the_overrun_extension_share_one_warning(vehicle):
    # fresh-eyes trial: `tcsim drive` on the bundled defaults printed the same warning once per model
    with pytest.warns(TcsimWarning) as caught:
        drive(vehicle, read_cycle(bundled_cycle_path("us06"), "us06"), ["table", "quasi-dynamic"])
    overrun = [str(w.message) for w in caught if "overrun" in str(w.message)]
    assert len(overrun) == 1, overrun
    assert "the drive runs 'table' and 'quasi-dynamic' reached SR 1." in overrun[0], overrun[0]


def test_coasting_brakes_the_engine_through_the_converter_and_the_lockup(wltc, segment_runs):
    runs = [wltc.runs["table"], *segment_runs[SEGMENTS[0]].runs.values()]
    for run in runs:
        coast = coasting(run.frame)
        assert len(coast) > 50
        # the engine absorbs power: its net crank torque opposes its rotation
        assert (coast.engine_torque_nm < 0).mean() > 0.9
    f = coasting(wltc.runs["table"].frame)
    open_ = f[f.lockup_state == 0]
    locked = f[f.lockup_state == 2]
    # open converter: the turbine drives the pump (SR > 1), the pump torque is negative
    assert len(open_) > 20 and (open_.speed_ratio > 1.0).mean() > 0.9, open_.speed_ratio.describe()
    assert (open_.pump_torque_nm < 0).mean() > 0.9
    assert len(locked) > 20
    assert wltc.summary.engine_braking_kj.iloc[0] > 0.0


def test_losses_are_booked_and_heat_is_converter_plus_lockup(wltc):
    s = wltc.summary.iloc[0]
    assert list(wltc.summary.columns) == list(SUMMARY_COLUMNS)
    assert s.converter_loss_kj > 0 and s.brake_energy_kj > 0 and s.lockup_loss_kj >= 0
    assert s.heat_to_fluid_kj == pytest.approx(s.converter_loss_kj + s.lockup_loss_kj, rel=1e-12)
    assert s.distance_km == pytest.approx(23.2, abs=0.3)  # WLTC class 3b: 23.27 km


@pytest.fixture
def trace_csv(tmp_path):
    """A short user trace on a 4 % climb: stand, accelerate to 40 km/h, brake to rest."""
    t = np.arange(0.0, 31.0)
    v = np.interp(t, [0, 2, 12, 20, 28, 30], [0, 0, 11.1, 11.1, 0, 0])
    p = tmp_path / "hill.csv"
    pd.DataFrame({"time_s": t, "vehicle_speed_m_s": v, "grade_percent": 4.0}).to_csv(p, index=False)
    return p


def test_cli_drive_writes_every_output_for_a_user_trace(cli, tmp_path, trace_csv):
    out = tmp_path / "out"
    r = cli("drive", "--cycle", trace_csv, "--model", "table", "--model", "hrovat-tobler", "--out", out)
    assert r.code == 0, (r.stdout, r.stderr)
    names = {p.name for p in out.iterdir()}
    expected = {"table.csv", "hrovat-tobler.csv", "summary.csv", "events.csv", "cycle.csv", "speed.png", "losses.png"}
    assert expected <= names
    s = pd.read_csv(out / "summary.csv")
    assert list(s.columns) == list(SUMMARY_COLUMNS) and list(s.model) == ["table", "hrovat-tobler"]
    assert (s.rms_speed_error_km_h < 1.0).all() and (s.energy_residual.abs() < 1e-4).all()
    f = pd.read_csv(out / "table.csv")
    assert (f.grade_percent == 4.0).all()


def test_bundled_cycles_are_listed_in_help_and_carry_their_sources(cli):
    r = cli("drive", "--help")
    for name in BUNDLED_CYCLES:
        assert name in r.stdout
        assert bundled_cycle_path(name).read_text().startswith("# ")
        assert "Source:" in bundled_cycle_path(name).read_text().splitlines()[1]


BAD_TRACES = [
    ("empty", "", "(file)", "empty"),
    ("header only", "time_s,vehicle_speed_m_s\n", "time_s", "0 rows"),
    ("missing column", "time_s,speed\n0,0\n1,1\n", "vehicle_speed_m_s", "missing"),
    ("time not increasing", "time_s,vehicle_speed_m_s\n0,0\n2,1\n1,2\n", "time_s", "1 at row 3 after 2"),
    ("NaN speed", "time_s,vehicle_speed_m_s\n0,0\n1,\n2,1\n", "vehicle_speed_m_s", "NaN"),
    ("text", "time_s,vehicle_speed_m_s\n0,0\n1,fast\n", "vehicle_speed_m_s", "fast"),
    ("negative speed", "time_s,vehicle_speed_m_s\n0,0\n1,-1\n", "vehicle_speed_m_s", "-1 at row 2 (time_s 1)"),
    ("not at rest", "time_s,vehicle_speed_m_s\n0,5\n1,5\n", "vehicle_speed_m_s", "5 at row 1 (time_s 0)"),
    (
        "steep grade",
        "time_s,vehicle_speed_m_s,grade_percent\n0,0,0\n1,1,45\n",
        "grade_percent",
        "45 at row 2 (time_s 1)",
    ),
]


@pytest.mark.parametrize(("case", "text", "field", "value"), BAD_TRACES, ids=[c[0] for c in BAD_TRACES])
def test_bad_trace_is_one_line_naming_file_field_and_value(cli, tmp_path, case, text, field, value):
    path = tmp_path / "trace.csv"
    path.write_text(text)
    before = path.read_bytes()
    out = tmp_path / "out"
    r = cli("drive", "--cycle", path, "--model", "table", "--out", out)
    assert r.code == 2, (case, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert lines[0].startswith(f"error: {path}: {field} = "), lines[0]
    assert value in lines[0] and ": expected " in lines[0], lines[0]
    assert not out.exists() and path.read_bytes() == before


def test_unknown_cycle_name_is_refused(cli, tmp_path):
    r = cli("drive", "--cycle", "wltc_3b", "--out", tmp_path / "out")
    assert r.code == 2
    assert (
        r.stderr.strip()
        == "error: command line: --cycle = 'wltc_3b': expected one of us06, udds, hwfet, wltc-3b or a trace file"
    )


def test_a_trace_in_km_h_under_the_m_s_name_is_warned_of_and_runs(tmp_path, cli):
    """The first 199 s of UDDS in km/h under ``vehicle_speed_m_s`` (63 km/h read as 63 m/s: within
    the speed limit) ran with only a speed-error warning; its acceleration is now warned of first."""
    c = read_cycle(bundled_cycle_path("udds"), "udds")
    n = int(np.argmax(c.vehicle_speed_m_s * 3.6 > 65.0))
    trace = tmp_path / "wrong.csv"
    pd.DataFrame({"time_s": c.time_s[:n], "vehicle_speed_m_s": c.vehicle_speed_m_s[:n] * 3.6}).to_csv(
        trace, index=False
    )
    r = cli("drive", "--cycle", trace, "--model", "table", "--no-plots", "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    first = r.stderr.strip().splitlines()[0]
    assert first.startswith(f"warning: {trace}: vehicle_speed_m_s's change per second from row 164 (time_s 163) = 5.31")
    assert "a trace in km/h read as m/s" in first


def test_a_trace_in_km_h_is_read_as_its_m_s_twin(tmp_path, cli):
    # fresh-eyes trial: drive cycles are published in km/h and a trace file took m/s only
    t = np.arange(0.0, 31.0)
    kmh = np.concatenate([np.linspace(0.0, 45.0, 16), np.linspace(45.0, 0.0, 15)])
    pd.DataFrame({"time_s": t, "vehicle_speed_km_h": kmh}).to_csv(tmp_path / "kmh.csv", index=False)
    pd.DataFrame({"time_s": t, "vehicle_speed_m_s": kmh / 3.6}).to_csv(tmp_path / "ms.csv", index=False)
    a, b = read_cycle(tmp_path / "kmh.csv"), read_cycle(tmp_path / "ms.csv")
    assert a.speed_column == "vehicle_speed_km_h" and b.speed_column == "vehicle_speed_m_s"
    np.testing.assert_array_equal(a.vehicle_speed_m_s, b.vehicle_speed_m_s)
    # a speed beyond the range is named in the file's column and unit
    fast = pd.DataFrame({"time_s": t, "vehicle_speed_km_h": kmh * 7.0})
    fast.to_csv(tmp_path / "fast.csv", index=False)
    r = cli("drive", "--cycle", tmp_path / "fast.csv", "--out", tmp_path / "o")
    lines = r.stderr.strip().splitlines()
    assert r.code == 2 and len(lines) == 1, r.stderr
    assert lines[0].startswith(f"error: {tmp_path / 'fast.csv'}: vehicle_speed_km_h = '252 at row 13 (time_s 12)': ")
    assert lines[0].endswith("(in m/s: the file's km/h ÷ 3.6)")
    pd.DataFrame({"time_s": t, "vehicle_speed_m_s": kmh / 3.6, "vehicle_speed_km_h": kmh}).to_csv(
        tmp_path / "both.csv", index=False
    )
    r = cli("drive", "--cycle", tmp_path / "both.csv", "--out", tmp_path / "o")
    assert r.code == 2 and "vehicle_speed_km_h = 'given too': expected one speed column" in r.stderr
