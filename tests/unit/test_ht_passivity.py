"""Passivity of the Hrovat & Tobler steady state in every quadrant (issue 11; docs/models.md).

At every steady state the converter absorbs power, ``T_p·ω_p + T_t·ω_t + T_s·ω_s ≥ 0`` with the
external torques of docs/physics.md §2 (the ``turbine_torque_nm`` column is the delivered torque
``−T_t``), for every sign of the speeds and speed ratios up to ±5, and the one-way clutch is
respected: locked means ``ω_s = 0`` and ``T_s ≥ 0``, free-wheeling ``ω_s ≥ 0`` and ``T_s = 0``.
Random points (hypothesis, profile ``ci``) through the public steady API.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tcsim import hrovat_tobler_steady_state, load_converter, simulate
from tcsim.models.drives import Speeds

CONVERTERS = ("li-sunden-2016", "li-sunden-2016-fitted")
GEOMETRY = {name: load_converter(name).core_geometry() for name in CONVERTERS}

speed = st.floats(min_value=-1000.0, max_value=1000.0, allow_nan=False)
ratio = st.floats(min_value=-5.0, max_value=5.0, allow_nan=False)


def absorbed_power_w(out: dict[str, np.ndarray], wp: np.ndarray, wt: np.ndarray) -> np.ndarray:
    """``T_p ω_p + T_t ω_t + T_s ω_s`` in W, external torques (turbine: minus the delivered torque)."""
    return (
        out["pump_torque_nm"] * wp - out["turbine_torque_nm"] * wt + out["stator_torque_nm"] * out["stator_speed_rad_s"]
    )


def check_passive(name: str, wp: np.ndarray, wt: np.ndarray) -> dict[str, np.ndarray]:
    out = hrovat_tobler_steady_state(GEOMETRY[name], wp, wt)
    scale = 840.0 * 0.0144 * 0.12 * (np.abs(wp) + np.abs(wt)) ** 3 + 1e-300
    power = absorbed_power_w(out, wp, wt)
    assert np.all(power >= -1e-12 * scale), (name, wp[power < 0], wt[power < 0], power[power < 0])
    mode = out["stator_mode"]
    locked, free = mode == 0, mode == 1
    assert np.all(out["stator_speed_rad_s"][locked] == 0.0) and np.all(out["stator_torque_nm"][locked] >= 0.0)
    assert np.all(out["stator_speed_rad_s"][free] >= 0.0) and np.all(out["stator_torque_nm"][free] == 0.0)
    assert np.all(mode >= 0), "every finite operating point has a steady state"
    return out


@pytest.mark.parametrize("name", CONVERTERS)
@given(wp=speed, sr=ratio)
def test_steady_states_are_passive_at_random_points(name, wp, sr):
    check_passive(name, np.array([wp, 0.0, wp]), np.array([sr * wp, wp, sr]))


@pytest.mark.parametrize("name", CONVERTERS)
def test_steady_states_are_passive_on_a_grid_and_coast_brakes_the_pump(name):
    w = np.array([-400.0, -209.4, -50.0, -1.0, 0.0, 1e-9, 1.0, 50.0, 209.4, 400.0])
    wp, wt = (a.ravel() for a in np.meshgrid(w, w))
    check_passive(name, wp, wt)
    # sustained overrun at 2000 rpm: reverse flow, the pump torque opposes the pump's rotation
    sr = np.array([1.2, 2.0, 3.0, 5.0])
    out = check_passive(name, np.full(sr.shape, 209.44), 209.44 * sr)
    assert np.all(out["flow_m3_s"] < 0.0) and np.all(out["pump_torque_nm"] < 0.0), out


def test_the_closed_form_coast_state_is_the_transients_where_the_flow_could_start_either_way():
    """Fitted geometry (shock coefficients below 1), SR 1.037: at rest F_Q(0⁺) > 0 > F_Q(0⁻); the
    forward direction has no flowing steady state, the reverse free-wheeling one is returned, and a
    transient run held there from it stays on it (no event)."""
    conv = load_converter("li-sunden-2016-fitted")
    wp, wt = 178.0, 1.037 * 178.0
    out = hrovat_tobler_steady_state(conv.core_geometry(), np.array([wp]), np.array([wt]))
    assert out["stator_mode"][0] == 1 and out["flow_m3_s"][0] < 0.0 and out["pump_torque_nm"][0] < 0.0
    drive = Speeds(time_s=[0.0, 3.0], pump_speed_rad_s=[wp, wp], turbine_speed_rad_s=[wt, wt])
    run = simulate(conv, drive, "hrovat-tobler", times_s=np.linspace(0.0, 3.0, 31))
    assert not run.events
    last = run.frame().iloc[-1]
    assert last["flow_m3_s"] == pytest.approx(out["flow_m3_s"][0], rel=1e-6)
    assert last["pump_torque_nm"] == pytest.approx(out["pump_torque_nm"][0], rel=1e-6)
