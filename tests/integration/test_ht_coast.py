"""Hrovat & Tobler in coast: a tip-out launch with the lock-up held open (issue 11).

Pedal 1 → 0 at 6 s on the bundled sedan with its lock-up never engaging: once the vehicle drives
the turbine faster than the engine, the flow reverses (a ``flow-zero`` event with the flow
direction −1 after it) and the pump torque opposes the engine's rotation (engine braking through
the converter), with both bundled H&T geometries (docs/models.md, "Steady state in every
quadrant"); the fluid loss stays non-negative.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from tcsim.io.scenario import read_scenario
from tcsim.models.dynamic import dynamic_model
from tcsim.models.vehicle import load_vehicle
from tcsim.simulation.launch import run_launch

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def tip_out_files(tmp_path):
    t = np.round(np.arange(0.0, 12.0 + 1e-9, 0.1), 3)
    pedal = np.interp(t, [0.0, 6.0, 6.2, 12.0], [1.0, 1.0, 0.0, 0.0])
    scenario = tmp_path / "tip_out.csv"
    rows = "".join(f"{a},{b:.4f},0\n" for a, b in zip(t, pedal))
    scenario.write_text("time_s,accelerator_pedal,brake_pedal\n" + rows)
    text = (REPO / "python" / "tcsim" / "data" / "vehicles" / "midsize-awd-8at.toml").read_text()
    for key in ("engage_speed_zero_pedal_m_s", "engage_speed_full_pedal_m_s"):
        line = next(ln for ln in text.splitlines() if ln.startswith(f"{key} ="))
        text = text.replace(line, f"{key} = 1000.0")  # the lock-up never engages
    # the shift schedule reads the raw pedal: the tip-out upshifts to top gear at once and the coast
    # from 9 s is in one gear (the TCU filter's later coast upshifts: tests/integration/test_shift_pedal.py)
    text = re.sub(r"(?m)^(shift_pedal_(rise|fall)_s) = .*$", r"\1 = 0.0", text)
    return tmp_path, text, scenario


@pytest.mark.parametrize("converter", ["li-sunden-2016", "li-sunden-2016-fitted"])
def test_tip_out_with_the_lockup_open_brakes_the_engine_through_the_converter(tip_out_files, converter):
    folder, text, scenario = tip_out_files
    line = next(ln for ln in text.splitlines() if ln.startswith("converter ="))
    vehicle_file = folder / "vehicle.toml"
    vehicle_file.write_text(text.replace(line, f'converter = "{converter}"'))
    vehicle = load_vehicle(vehicle_file)
    run = run_launch(vehicle, read_scenario(scenario), [dynamic_model(vehicle.converter, "hrovat-tobler")])
    df, events = run["hrovat-tobler"].frame, run["hrovat-tobler"].events
    assert (df["lockup_state"] == 0).all()
    reversals = [e for e in events if e[1] == "flow-zero"]
    assert reversals, events
    late = df[df["time_s"] >= 9.0]
    assert (late["speed_ratio"] > 1.0).all() and (late["flow_m3_s"] < 0.0).all()
    # engine braking: the pump torque opposes the pump's rotation, and the vehicle slows down
    assert (late["pump_torque_nm"] * late["pump_speed_rad_s"] < 0.0).all()
    assert late["pump_torque_nm"].max() < -10.0, late["pump_torque_nm"].max()
    assert late["vehicle_speed_m_s"].iloc[-1] < late["vehicle_speed_m_s"].iloc[0]
    assert (df["fluid_loss_power_w"] >= -1e-9).all()
