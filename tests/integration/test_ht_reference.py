"""Hrovat & Tobler steady states in every quadrant against a plain reference (issue 11).

``ht_reference.py`` was written by a second engineer without reading tcsim's core: the forward
equations straight from the thesis (eqs 2.12–2.25), the reverse-flow form of docs/physics.md §8 derived
again from the angular-momentum balance, and the steady states found by scanning the net head over
both flow directions and refining every sign change (not the core's closed-form quadratics), with the
one-way clutch rule: locked while the holding torque T_s ≥ 0, else free-wheeling with ω_s ≥ 0, else
held at Q = 0. The core must find the same state at every speed ratio, every sign of the pump speed
included, and the same torques to the reference's root-finding accuracy.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import tcsim
from tcsim.models.converter import load_converter
from tcsim.models.drives import Speeds
from tcsim.simulation.transient import simulate

sys.path.insert(0, str(Path(__file__).resolve().parent))
import ht_reference as ref  # noqa: E402

PUMP_RAD_S = 209.44
# drive, roll-back, the coupling point, the fold of the free-wheeling branch (0.99233), the no-flow
# band, the start of reverse flow with a free stator (1.0084) and with the stator at rest (1.0303), coast
SPEED_RATIOS = [-3.0, -1.0, -0.3, 0.0, 0.4, 0.9, 0.95, 0.99, 0.992, 0.995, 1.0, 1.005, 1.01, 1.02, 1.03, 1.05]
SPEED_RATIOS += [1.2, 1.5, 2.0, 3.0, 5.0]
MODES = {"locked": "locked", "free": "free-wheeling", "held": "no-flow"}


@pytest.fixture(scope="module")
def core_states():
    conv = load_converter("li-sunden-2016")  # the Appendix D geometry
    sr = np.array(SPEED_RATIOS)
    out = {}
    for sign in (1.0, -1.0):
        wp = np.full(sr.shape, sign * PUMP_RAD_S)
        out[sign] = tcsim.steady_state(conv, "hrovat-tobler", wp, sr * wp)
    return out


def _agrees(row, state, scale) -> bool:
    """Whether the core's row is the reference's steady state ``state`` (mode, flow, torques, and
    the stator's torque when locked or its speed when free-wheeling)."""
    close = lambda a, b, floor: abs(a - b) <= 1e-7 * abs(b) + floor  # noqa: E731
    ok = row["stator_mode"] == MODES[state["mode"]] and close(row["flow_m3_s"], state["Q"], 1e-12)
    ok = ok and close(row["pump_torque_nm"], state["T_p"], 1e-9 * scale)
    ok = ok and close(row["turbine_torque_nm"], state["T_t_delivered"], 1e-9 * scale)
    if state["mode"] == "locked":
        ok = ok and close(row["stator_torque_nm"], state["T_s"], 1e-9 * scale)
    if state["mode"] == "free":
        ok = ok and close(row["stator_speed_rad_s"], state["w_s"], 1e-9)
    return bool(ok)


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["pump-forward", "pump-reversed"])
@pytest.mark.parametrize("i", range(len(SPEED_RATIOS)), ids=[f"SR{s:g}" for s in SPEED_RATIOS])
def test_core_steady_state_is_the_reference_one(core_states, sign, i):
    """Where the reference finds one admissible state (or none: held), the core's is that one. With
    the pump reversed (both speeds negative) the locked stator has up to three roots near SR 1, two
    of them stable; the reference then lists them all and the core must return one of the stable
    ones, the one the flow reaches from rest (docs/models.md, "Steady state in every quadrant")."""
    wp = sign * PUMP_RAD_S
    wt = SPEED_RATIOS[i] * wp
    expected, candidates = ref.steady_state(wp, wt, ref.geometry_appendix_d())
    row = core_states[sign].iloc[i]
    scale = 1e-3 * PUMP_RAD_S**2 * 3e-3  # 1e-3 of the stall torque at this speed, N·m
    if len(candidates) <= 1:
        assert _agrees(row, expected, scale), (expected, row.to_dict())
    else:
        stable = [c for c in candidates if c["stable"]]
        assert any(_agrees(row, c, scale) for c in stable), (candidates, row.to_dict())
        # reached from rest: no other stable root of the same flow direction lies nearer zero
        same_side = [c for c in stable if np.sign(c["Q"]) == np.sign(row["flow_m3_s"])]
        assert abs(row["flow_m3_s"]) <= min(abs(c["Q"]) for c in same_side) * (1 + 1e-7)


def test_the_reference_is_passive_in_both_flow_directions():
    """The reference's own energy identity: absorbed power = ρ|Q|·loss ≥ 0 at random points of
    both flow directions."""
    worst, smallest = ref.check_absorbed_power(ref.geometry_appendix_d(), n=200)
    assert worst < 1e-12 and smallest > 0.0, (worst, smallest)


@pytest.mark.parametrize("speed_ratio", [1.01, 1.02, 1.2])
def test_a_run_held_in_coast_settles_on_the_steady_state(speed_ratio):
    """Just above SR 1 the flow starts forwards with the stator at rest, yet a run held there (pump
    and turbine speeds given) settles on the free-wheeling reverse-flow state: the closed form must
    return that state, not no-flow (it did until the fallback to the other direction)."""
    conv = load_converter("li-sunden-2016")
    t = np.linspace(0.0, 30.0, 301)
    drive = Speeds(t, np.full_like(t, PUMP_RAD_S), np.full_like(t, speed_ratio * PUMP_RAD_S))
    late = simulate(conv, drive, "hrovat-tobler").frame().iloc[-1]
    steady = tcsim.steady_state(conv, "hrovat-tobler", PUMP_RAD_S, speed_ratio * PUMP_RAD_S).iloc[0]
    assert steady["stator_mode"] == "free-wheeling" and steady["flow_m3_s"] < 0.0
    assert abs(late["pump_torque_nm"] - steady["pump_torque_nm"]) <= 1e-4 * abs(steady["pump_torque_nm"])
    assert abs(late["flow_m3_s"] - steady["flow_m3_s"]) <= 1e-4 * abs(steady["flow_m3_s"])
