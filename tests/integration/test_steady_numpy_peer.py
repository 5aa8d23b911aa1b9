"""The core's batched Hrovat & Tobler steady state against the NumPy closed form (issue 16).

``bench/numpy_steady_state.py`` is the bench's peer: the same equations written as a vectorised NumPy
closed form from the thesis and docs/models.md (the momentum form ``Σ ω_x (h_x − h_src(x))`` of the
head, its own root formula, the clutch and flow-direction rules with boolean masks), not from the
core's code. The two must give the same mode at every point and the same values to round-off (1e-12
of the point's own scale) in every quadrant: drive, the coupling point and the free-wheeling stator,
the no-flow band, coast with reverse flow (locked and free-wheeling stator), the pump reversed or at
rest, held flow (shock coefficients above 1) and flow that could start either way (below 1), and the
points without a steady state (non-finite speeds). Expectations are computed at test time from the
bundled converters' parameters, so that regenerated converter data does not change the test.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from tcsim import _core
from tcsim.models.converter import load_converter
from tcsim.models.steady import hrovat_tobler_steady_state

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import numpy_steady_state as peer  # noqa: E402

RTOL = 1e-12
NAMES = _core.ht_parameter_names()


def _speeds(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Pump speeds of both signs and at rest, SR −3 to 5, and the edges: SR 0 and 1, both at rest,
    the pump at rest with the turbine turning, non-finite speeds."""
    rng = np.random.default_rng(seed)
    wp = rng.choice([-400.0, -120.0, 0.0, 60.0, 209.44, 400.0], n) * rng.uniform(0.5, 1.0, n)
    wt = rng.uniform(-3.0, 5.0, n) * np.where(wp == 0.0, 200.0, wp)
    edges_wp = [0.0, 0.0, 200.0, 200.0, -200.0, 200.0, -200.0, np.nan, 200.0, np.inf]
    edges_wt = [0.0, 150.0, 0.0, 200.0, -200.0, -200.0, 200.0, 100.0, np.nan, 0.0]
    return np.concatenate([edges_wp, wp]), np.concatenate([edges_wt, wt])


def _scales(geometry: np.ndarray, wp: np.ndarray, wt: np.ndarray) -> dict[str, np.ndarray]:
    """Each column's scale at each point: flow A·R_p·ω, speed ω, torque ρ·A·R_p³·ω² with
    ω = max(|ω_p|, |ω_t|)."""
    g = np.atleast_2d(geometry)
    area, rho, rp = (g[:, NAMES.index(k)] for k in ("flow_area_m2", "fluid_density_kg_m3", "pump_exit_radius_m"))
    w = np.maximum(np.abs(wp), np.abs(wt))
    torque = rho * area * rp**3 * w**2
    return {
        "flow_m3_s": area * rp * w,
        "stator_speed_rad_s": w,
        "pump_torque_nm": torque,
        "turbine_torque_nm": torque,
        "stator_torque_nm": torque,
    }


def _compare(geometry: np.ndarray, wp: np.ndarray, wt: np.ndarray) -> dict[str, np.ndarray]:
    """Assert that the core and the peer agree at every point; return the core's result."""
    core = hrovat_tobler_steady_state(geometry, wp, wt, strict=False)
    ref = peer.steady_state(geometry, wp, wt)
    mismatch = np.flatnonzero(core["stator_mode"] != ref["stator_mode"])
    assert mismatch.size == 0, [(wp[i], wt[i], core["stator_mode"][i], ref["stator_mode"][i]) for i in mismatch[:5]]
    scales = _scales(geometry, wp, wt)
    for column, scale in scales.items():
        a, b = core[column], ref[column]
        assert np.array_equal(np.isnan(a), np.isnan(b)), column
        with np.errstate(invalid="ignore"):
            err = np.where(np.isnan(b) | (a == b), 0.0, np.abs(a - b) / np.maximum(np.abs(b), scale))
        worst = int(np.argmax(err))
        assert err[worst] <= RTOL, (column, err[worst], wp[worst], wt[worst], a[worst], b[worst])
    return core


@pytest.mark.parametrize("name", ["li-sunden-2016", "li-sunden-2016-fitted"])
def test_the_core_batch_is_the_numpy_closed_form_in_every_quadrant(name):
    geometry = load_converter(name).core_geometry()
    wp, wt = _speeds(40_000, seed=16)
    core = _compare(geometry, wp, wt)
    flow, mode = core["flow_m3_s"], core["stator_mode"]
    # every branch was met: each stator mode and no steady state, both flow directions, and the
    # reverse flow with the stator locked and free-wheeling
    assert {0, 1, 2, -1} <= set(np.unique(mode).tolist())
    for m in (0, 1):
        assert np.any((mode == m) & (flow > 0.0)), m
    assert np.any((mode == 0) & (flow < 0.0)) or name == "li-sunden-2016"  # Appendix D's coast releases
    assert np.any((mode == 1) & (flow < 0.0))


def test_the_core_batch_is_the_numpy_closed_form_with_one_row_per_point():
    """Parameter rows per point, in runs (the design studies' layout) and shuffled: shock coefficients
    above 1 (a band of held flow, no flow with the stator at rest) and below 1 (either direction
    could start, the stronger wins), radii and angles varied."""
    base = load_converter("li-sunden-2016").core_geometry()[0]
    rng = np.random.default_rng(160)
    n_rows = 400
    rows = np.repeat(base[None, :], n_rows, axis=0)
    for k in ("pump_shock_loss", "turbine_shock_loss", "stator_shock_loss"):
        rows[:, NAMES.index(k)] = rng.uniform(0.3, 2.5, n_rows)
    for k in ("pump_exit_radius_m", "friction_loss"):
        rows[:, NAMES.index(k)] *= rng.uniform(0.9, 1.1, n_rows)
    rows[:, NAMES.index("stator_exit_angle_rad")] += rng.uniform(-0.1, 0.1, n_rows)
    for row in rows:
        _core.ht_check_geometry(np.ascontiguousarray(row))
    wp, wt = _speeds(50 * n_rows - 10, seed=161)
    for geometry in (np.repeat(rows, 50, axis=0), rows[rng.integers(0, n_rows, wp.size)]):
        core = _compare(np.ascontiguousarray(geometry), wp, wt)
        held = (core["stator_mode"] == 2) & (core["stator_speed_rad_s"] == 0.0) & (wp != wt)
        assert held.any()  # flow held at rest by shock coefficients above 1


def test_the_locked_drive_closed_form_is_the_cores_below_the_coupling_point():
    """The bench's second peer (the locked-stator quadratic alone, as in the issue) is the core's
    state wherever the core's stator is locked in drive."""
    conv = load_converter("li-sunden-2016")
    geometry = conv.core_geometry()
    rng = np.random.default_rng(3)
    wp = rng.uniform(100.0, 400.0, 20_000)
    wt = rng.uniform(0.0, 1.0, wp.size) * wp
    core = hrovat_tobler_steady_state(geometry, wp, wt)
    ref = peer.locked_drive(geometry, wp, wt)
    locked = core["stator_mode"] == 0
    assert locked.mean() > 0.8
    for column, scale in _scales(geometry, wp, wt).items():
        err = np.abs(core[column] - ref[column])[locked] / np.maximum(np.abs(ref[column]), scale)[locked]
        assert err.max() <= RTOL, column
