"""The TCU's filtered pedal for the shift schedule (``crates/tcsim-core/src/vehicle/shift_pedal.rs``,
docs/vehicle.md "Shift schedule pedal"): no gear hunting in a drive cycle, the full-pedal launch
unchanged (the kickdown passes the filter), bad filter constants refused in one line.

Hunting is a downshift undone by an upshift within :data:`REVERSAL_S`: the driver's pedal moves
with the trace's 1 Hz acceleration steps and, read raw by the schedule, shifted the gearbox back
and forth (US06's first 128 s: 21 upshifts, three reversals, before the filter).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tcsim.analysis.drive import Cycle, drive
from tcsim.io.cycle import bundled_cycle_path, read_cycle
from tcsim.models.vehicle import load_vehicle
from tcsim.simulation.launch import run_launch, select_models
from tcsim.simulation.scenarios import flip_flop

REPO = Path(__file__).resolve().parents[2]
BUNDLED = REPO / "python" / "tcsim" / "data" / "vehicles" / "midsize-awd-8at.toml"
MODELS = ["table", "hrovat-tobler", "quasi-dynamic"]
#: A downshift followed by an upshift within this time is a reversal (hunting), s.
REVERSAL_S = 3.0
#: Upshifts allowed beyond the fewest the trace needs (each trip's highest gear − 1).
SPARE_UPSHIFTS = 3


def _edited(tmp_path: Path, edit) -> Path:
    path = tmp_path / "veh.toml"
    path.write_text(edit(BUNDLED.read_text(encoding="utf-8")), encoding="utf-8")
    return path


def _unfiltered(text: str) -> str:
    """The bundled vehicle with the schedule reading the raw pedal (both time constants 0)."""
    return re.sub(r"(?m)^(shift_pedal_(rise|fall)_s) = .*$", r"\1 = 0.0", text)


def _us06_take_offs() -> Cycle:
    """US06's first 128 s: two hard take-offs, a stop between them, each trip from rest to rest."""
    c = read_cycle(bundled_cycle_path("us06"), "us06")
    keep = c.time_s <= 128
    return Cycle("us06[0:128]", c.source, c.time_s[keep], c.vehicle_speed_m_s[keep])


def _fewest_upshifts(frame: pd.DataFrame) -> int:
    """The upshifts the trips need: each trip (between standstills) its highest gear − its lowest."""
    stopped = (frame.vehicle_speed_m_s < 0.1).to_numpy()
    trip = np.cumsum(np.r_[0, stopped[1:] & ~stopped[:-1]])
    return int(sum(g.gear.max() - g.gear.min() for _, g in frame.groupby(trip)))


def _reversals(events: list[tuple[float, str, int]]) -> list[tuple[float, float]]:
    shifts = [(t, k) for t, k, _ in events if k in ("upshift-start", "downshift-start")]
    return [
        (a[0], b[0])
        for a, b in zip(shifts, shifts[1:], strict=False)
        if a[1] == "downshift-start" and b[1] == "upshift-start" and b[0] - a[0] < REVERSAL_S
    ]


def test_the_gearbox_does_not_hunt_on_the_us06_take_offs():
    result = drive(load_vehicle(), _us06_take_offs(), MODELS)
    for name, run in result.runs.items():
        upshifts = sum(k == "upshift-start" for _, k, _ in run.events)
        fewest = _fewest_upshifts(run.frame)
        assert fewest >= 12, (name, fewest)  # both take-offs reach 7th gear or higher
        assert upshifts <= fewest + SPARE_UPSHIFTS, (name, upshifts, fewest)
        assert _reversals(run.events) == [], name
        # tracking is not traded for it
        assert result.summary.set_index("model").loc[name].rms_speed_error_km_h < 1.0


def test_the_full_pedal_launch_is_the_same_with_and_without_the_filter(tmp_path):
    filtered = load_vehicle()
    assert "shift_pedal_fall_s = 3.0" in BUNDLED.read_text(encoding="utf-8")
    raw = load_vehicle(str(_edited(tmp_path, _unfiltered)))
    runs = [run_launch(v, flip_flop(), select_models(v, ["table"]))["table"] for v in (filtered, raw)]
    assert runs[0].events == runs[1].events
    np.testing.assert_array_equal(runs[0].frame.vehicle_speed_m_s, runs[1].frame.vehicle_speed_m_s)


@pytest.mark.parametrize(
    ("key", "value"),
    [("shift_pedal_rise_s", "-0.1"), ("shift_pedal_fall_s", "10.5"), ("shift_pedal_fall_s", "nan")],
)
def test_filter_time_constant_out_of_range_is_one_line_exit_2(cli, tmp_path, key, value):
    path = _edited(tmp_path, lambda text: re.sub(rf"(?m)^{key} = .*$", f"{key} = {value}", text))
    before = path.read_bytes()
    r = cli("launch", path.name, "--model", "table", "--out", "out", cwd=tmp_path)
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.code == 2, (r.code, r.stderr)
    assert len(lines) == 1 and lines[0].startswith(f"error: veh.toml: [gearbox].{key} = "), lines
    assert lines[0].endswith("expected a finite number at least 0 and at most 10"), lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["veh.toml"] and path.read_bytes() == before
