"""Benchmark: batched closed-form Hrovat & Tobler steady state through the Python API.

Not part of the test suite. Run: ``python bench/bench_steady_state.py`` (tcsim installed, or
``PYTHONPATH=python``).

Measures points per second of :func:`tcsim.steady.hrovat_tobler_steady_state` (one geometry row,
10⁶ operating points, locked and free-wheeling stator) and compares, in the same process, with a
plain SciPy reference: eq 2.15 of Li & Sundén (2016) with zero left-hand sides, solved per point
for Q with :func:`scipy.optimize.brentq` (locked stator), as a SciPy user would write it. The two
are checked to agree before the ratio is printed, so that the comparison is of the same equations.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np
from scipy.optimize import brentq

import tcsim
from tcsim.models.steady import coupling_point, hrovat_tobler_steady_state

N = 1_000_000  # points of the batched tcsim run
N_REF = 2_000
REPEATS = 7


def reference_locked(g: dict, wp: float, wt: float) -> tuple[float, float, float, float]:
    """Q, pump, delivered turbine and stator torques with a locked stator (Li & Sundén 2016).

    Eq 2.15 with zero left-hand side and ω_s = 0, losses of eqs 2.19–2.25 for Q > 0, solved for Q
    with brentq (default tolerances) between 0 and 10 m³/s; torques from eqs 2.12–2.14.
    """
    rho, A = g["fluid_density_kg_m3"], g["flow_area_m2"]
    rp, rt, rs = g["pump_exit_radius_m"], g["turbine_exit_radius_m"], g["stator_exit_radius_m"]
    tp, tt, ts = (
        math.tan(math.radians(g[k])) for k in ("pump_exit_angle_deg", "turbine_exit_angle_deg", "stator_exit_angle_deg")
    )
    tpp, ttt, tss = (
        math.tan(math.radians(g[k]))
        for k in ("pump_inlet_angle_deg", "turbine_inlet_angle_deg", "stator_inlet_angle_deg")
    )
    cp, ct, cs, f = g["pump_shock_loss"], g["turbine_shock_loss"], g["stator_shock_loss"], g["friction_loss"]

    def rhs(Q):
        q = Q / A
        head = rho * (rp**2 * wp**2 + rt**2 * wt**2 - rp**2 * wt * wp) + rho * q * (
            wp * (rp * tp - rs * ts) + wt * (rt * tt - rp * tp)
        )
        shock = (
            cp * (-rs * wp + q * (ts - tpp)) ** 2
            + ct * (rp * (wp - wt) + q * (tp - ttt)) ** 2
            + cs * (rt * wt + q * (tt - tss)) ** 2
        )
        friction = f * q * q * (3 + tp**2 + tt**2 + ts**2)
        return head - rho / 2 * (shock + friction)

    Q = brentq(rhs, 0.0, 10.0)
    q = Q / A
    pump = rho * (wp * rp**2 + rp * tp * q - rs * ts * q) * Q
    turbine = -rho * (wt * rt**2 + rt * tt * q - wp * rp**2 - rp * tp * q) * Q
    stator = rho * (rs * ts * q - wt * rt**2 - rt * tt * q) * Q
    return Q, pump, turbine, stator


def main() -> None:
    conv = tcsim.load_converter("li-sunden-2016")
    geometry = conv.core_geometry()
    rng = np.random.default_rng(0)
    wp = rng.uniform(100.0, 400.0, N)
    sr = rng.uniform(0.0, 1.0, N)
    wt = sr * wp

    hrovat_tobler_steady_state(geometry, wp[:1000], wt[:1000])  # warm-up
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        out = hrovat_tobler_steady_state(geometry, wp, wt)
        times.append(time.perf_counter() - t0)
    t_tcsim = statistics.median(times) / N

    # reference on locked-stator points below the coupling point
    cp = coupling_point(conv)
    idx = np.flatnonzero(sr < cp)[:N_REF]
    g = conv.geometry.model_dump()
    t0 = time.perf_counter()
    ref = np.array([reference_locked(g, wp[i], wt[i]) for i in idx])
    t_ref = (time.perf_counter() - t0) / len(idx)

    assert (out["stator_mode"][idx] == 0).all(), "reference points must have a locked stator"
    # relative differences; the stator holding torque passes through zero at the coupling point,
    # so its difference is taken relative to the pump torque
    scale = {"stator_torque_nm": np.abs(out["pump_torque_nm"][idx])}
    diffs = {
        c: float(np.max(np.abs(ref[:, k] - out[c][idx]) / scale.get(c, np.abs(out[c][idx]))))
        for k, c in enumerate(("flow_m3_s", "pump_torque_nm", "turbine_torque_nm", "stator_torque_nm"))
    }
    err = max(diffs.values())
    assert err < 1e-8, f"reference and tcsim disagree: {diffs}"

    rate = 1.0 / t_tcsim
    print(f"{'implementation':<34}{'points/s':>14}{'µs/point':>12}")
    print(f"{'tcsim (batched closed form, core)':<34}{rate:>14.3e}{1e6 * t_tcsim:>12.4f}")
    print(f"{'SciPy brentq per point (locked)':<34}{1 / t_ref:>14.3e}{1e6 * t_ref:>12.4f}")
    print(
        f"speed-up tcsim / SciPy: {t_ref / t_tcsim:,.0f}x  ({N:,} tcsim points, median of {REPEATS}; "
        f"SciPy on {len(idx)} locked points, extrapolated per point)"
    )
    print("agreement (max relative difference): " + ", ".join(f"{c} {d:.1e}" for c, d in diffs.items()))
    print(f"requirement >= 1e6 points/s: {'met' if rate >= 1e6 else 'NOT met'}")


if __name__ == "__main__":
    main()
