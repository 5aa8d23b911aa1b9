"""Benchmark: batched closed-form Hrovat & Tobler steady state through the Python API.

Not part of the test suite. Run: ``python bench/bench_steady_state.py``.

Measures points per second of :func:`tcsim.hrovat_tobler_steady_state` (one geometry row,
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

N = 1_000_000
N_REF = 2_000


def reference_locked(g: dict, wp: float, wt: float) -> tuple[float, float, float]:
    """Q, pump torque and delivered turbine torque with a locked stator, by root finding on eq 2.15."""
    rho, A = g["fluid_density_kg_m3"], g["flow_area_m2"]
    rp, rt, rs = g["pump_exit_radius_m"], g["turbine_exit_radius_m"], g["stator_exit_radius_m"]
    tp, tt, ts = (math.tan(math.radians(g[k])) for k in ("pump_exit_angle_deg", "turbine_exit_angle_deg", "stator_exit_angle_deg"))
    tpp, ttt, tss = (math.tan(math.radians(g[k])) for k in ("pump_inlet_angle_deg", "turbine_inlet_angle_deg", "stator_inlet_angle_deg"))
    cp, ct, cs, f = g["pump_shock_loss"], g["turbine_shock_loss"], g["stator_shock_loss"], g["friction_loss"]

    def rhs(Q):
        q = Q / A
        head = rho * (rp**2 * wp**2 + rt**2 * wt**2 - rp**2 * wt * wp) + rho * q * (wp * (rp * tp - rs * ts) + wt * (rt * tt - rp * tp))
        shock = cp * (-rs * wp + q * (ts - tpp)) ** 2 + ct * (rp * (wp - wt) + q * (tp - ttt)) ** 2 + cs * (rt * wt + q * (tt - tss)) ** 2
        friction = f * q * q * (3 + tp**2 + tt**2 + ts**2)
        return head - rho / 2 * (shock + friction)

    Q = brentq(rhs, 1e-12, 10.0, xtol=1e-15, rtol=1e-15, maxiter=200)
    q = Q / A
    pump = rho * (wp * rp**2 + rp * tp * q - rs * ts * q) * Q
    turbine = -rho * (wt * rt**2 + rt * tt * q - wp * rp**2 - rp * tp * q) * Q
    return Q, pump, turbine


def main() -> None:
    conv = tcsim.load_converter("li-sunden-2016")
    geometry = conv.core_geometry()
    rng = np.random.default_rng(0)
    wp = rng.uniform(100.0, 400.0, N)
    sr = rng.uniform(0.0, 1.0, N)
    wt = sr * wp

    tcsim.hrovat_tobler_steady_state(geometry, wp[:1000], wt[:1000])  # warm-up
    times = []
    for _ in range(7):
        t0 = time.perf_counter()
        out = tcsim.hrovat_tobler_steady_state(geometry, wp, wt)
        times.append(time.perf_counter() - t0)
    t_tcsim = statistics.median(times) / N

    # reference on locked-stator points below the coupling point
    cp = tcsim.coupling_point(conv)
    idx = np.flatnonzero(sr < cp)[:N_REF]
    g = conv.geometry.model_dump()
    t0 = time.perf_counter()
    ref = np.array([reference_locked(g, wp[i], wt[i]) for i in idx])
    t_ref = (time.perf_counter() - t0) / len(idx)

    err = max(np.max(np.abs(ref[:, 0] / out["flow_m3_s"][idx] - 1)),
              np.max(np.abs(ref[:, 1] / out["pump_torque_nm"][idx] - 1)),
              np.max(np.abs(ref[:, 2] / out["turbine_torque_nm"][idx] - 1)))
    assert err < 1e-8, f"reference and tcsim disagree: {err:.3g}"

    rate = 1.0 / t_tcsim
    print(f"{'implementation':<34}{'points/s':>14}{'µs/point':>12}")
    print(f"{'tcsim (batched closed form, core)':<34}{rate:>14.3e}{1e6 * t_tcsim:>12.4f}")
    print(f"{'SciPy brentq per point (locked)':<34}{1 / t_ref:>14.3e}{1e6 * t_ref:>12.4f}")
    print(f"speed-up tcsim / SciPy: {t_ref / t_tcsim:,.0f}x   (agreement on {len(idx)} locked points: max rel diff {err:.2e})")
    print(f"requirement >= 1e6 points/s: {'met' if rate >= 1e6 else 'NOT met'}")


if __name__ == "__main__":
    main()
