"""Benchmark: batched closed-form Hrovat & Tobler steady state through the Python API.

Not part of the test suite. Run: ``python bench/bench_steady_state.py`` (tcsim installed, or
``PYTHONPATH=python``).

Measures :func:`tcsim.steady.hrovat_tobler_steady_state` (one geometry row, 10⁵ and 10⁶ operating
points) on one thread and on every core, and compares it, in the same process, on the same inputs,
with two peers (issue 16):

* the vectorised NumPy closed form of the same equations in every quadrant, with the same clutch
  and flow-direction rules and the same outputs (``bench/numpy_steady_state.py``, ``steady_state``);
* the locked-stator quadratic alone (``locked_drive``: the issue's "20-line closed form", which does
  less work than either: no clutch, no other quadrant; valid below the coupling point only);
* a SciPy ``brentq`` per point (locked stator), as a SciPy user would write it.

Timings are medians of ``REPEATS`` calls after a warm-up, the implementations taking turns within
each repeat so that a change of the machine's load falls on all of them. The outputs are checked to
agree before any ratio is printed. The load average is printed with the figures.
"""

from __future__ import annotations

import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

import tcsim
from tcsim.models.steady import coupling_point, hrovat_tobler_steady_state

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy_steady_state as peer  # noqa: E402

SIZES = (100_000, 1_000_000)  # points of a batch
N_REF = 2_000
REPEATS = 7
COLUMNS = ("flow_m3_s", "stator_speed_rad_s", "pump_torque_nm", "turbine_torque_nm", "stator_torque_nm")


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


def interleaved_medians(fns: dict, repeats: int, cpu: dict | None = None) -> dict[str, float]:
    """Median wall time (s) of each of ``fns`` over ``repeats`` rounds, one call of each per round,
    after one warm-up call of each; ``cpu``, if given, gets the median CPU time of the process (s)."""
    for fn in fns.values():
        fn()
    times: dict[str, list[float]] = {k: [] for k in fns}
    cpu_times: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            t0, c0 = time.perf_counter(), time.process_time()
            fn()
            times[k].append(time.perf_counter() - t0)
            cpu_times[k].append(time.process_time() - c0)
    if cpu is not None:
        cpu.update({k: statistics.median(v) for k, v in cpu_times.items()})
    return {k: statistics.median(v) for k, v in times.items()}


def max_difference(a: dict, b: dict, geometry: np.ndarray, wp: np.ndarray, wt: np.ndarray, where=None) -> float:
    """Largest difference between two results relative to each point's scale (flow A·R_p·ω, speed
    ω, torque ρ·A·R_p³·ω², ω = max(|ω_p|, |ω_t|)) or the value, whichever is larger."""
    area, rho, rp = geometry[0, 0], geometry[0, 1], geometry[0, 2]
    w = np.maximum(np.abs(wp), np.abs(wt))
    scale = {"flow_m3_s": area * rp * w, "stator_speed_rad_s": w}
    sel = np.ones(wp.shape, bool) if where is None else where
    worst = 0.0
    for c in COLUMNS:
        s = scale.get(c, rho * area * rp**3 * w**2)
        x, y = a[c][sel], b[c][sel]
        with np.errstate(invalid="ignore"):
            d = np.where(x == y, 0.0, np.abs(x - y) / np.maximum(np.abs(y), s[sel]))
        worst = max(worst, float(np.nanmax(d)))
    return worst


def compare_peers(geometry: np.ndarray, wp: np.ndarray, wt: np.ndarray, label: str) -> None:
    """Check the core against both NumPy peers on ``wp``, ``wt``, then time them all and print."""
    core = hrovat_tobler_steady_state(geometry, wp, wt, strict=False, threads=1)
    full = peer.steady_state(geometry, wp, wt)
    assert np.array_equal(core["stator_mode"], full["stator_mode"]), "modes differ"
    err_full = max_difference(core, full, geometry, wp, wt)
    # the locked peer's domain: drive (ω_p > 0, 0 ≤ ω_t ≤ ω_p) where the core's stator is locked
    locked = (core["stator_mode"] == 0) & (wp > 0) & (wt >= 0) & (wt <= wp)
    err_locked = max_difference(core, peer.locked_drive(geometry, wp, wt), geometry, wp, wt, locked)
    assert err_full < 1e-12 and err_locked < 1e-12, (err_full, err_locked)
    cores = os.cpu_count() or 1
    fns = {
        "core, 1 thread": lambda: hrovat_tobler_steady_state(geometry, wp, wt, strict=False, threads=1),
        f"core, {cores} threads": lambda: hrovat_tobler_steady_state(geometry, wp, wt, strict=False, threads=0),
        "NumPy closed form, every quadrant": lambda: peer.steady_state(geometry, wp, wt),
        "NumPy locked stator alone": lambda: peer.locked_drive(geometry, wp, wt),
    }
    cpu: dict[str, float] = {}
    t = interleaved_medians(fns, REPEATS, cpu)
    n = len(wp)
    one, many = t["core, 1 thread"], t[f"core, {cores} threads"]
    print(f"\n{label}: {n:,} points, median of {REPEATS} (load average {os.getloadavg()[0]:.2f} before)")
    print(f"{'implementation':<36}{'ms':>9}{'ns/point':>10}{'CPU ns/point':>14}")
    for k, v in t.items():
        print(f"{k:<36}{1e3 * v:>9.2f}{1e9 * v / n:>10.1f}{1e9 * cpu[k] / n:>14.1f}")
    # CPU time of the process: the work done, whatever share of a core the machine's load left it
    c_one = cpu["core, 1 thread"]
    print(
        f"CPU-time ratio NumPy every quadrant / core: {cpu['NumPy closed form, every quadrant'] / c_one:.2f}x, "
        f"NumPy locked alone / core: {cpu['NumPy locked stator alone'] / c_one:.2f}x (core on 1 thread)"
    )
    print(
        f"ratio NumPy every quadrant / core: {t['NumPy closed form, every quadrant'] / one:.2f}x (1 thread), "
        f"{t['NumPy closed form, every quadrant'] / many:.2f}x ({cores} threads)"
    )
    print(
        f"ratio NumPy locked alone / core:   {t['NumPy locked stator alone'] / one:.2f}x (1 thread), "
        f"{t['NumPy locked stator alone'] / many:.2f}x ({cores} threads)"
    )
    print(f"core {cores} threads / 1 thread speed-up: {one / many:.2f}x")
    print(f"agreement: {err_full:.1e} (every quadrant), {err_locked:.1e} (locked points)")


def main() -> None:
    conv = tcsim.load_converter("li-sunden-2016")
    geometry = conv.core_geometry()
    rng = np.random.default_rng(0)
    for n in SIZES:
        wp = rng.uniform(100.0, 400.0, n)
        sr = rng.uniform(0.0, 1.0, n)
        compare_peers(geometry, wp, sr * wp, "drive (pump 100-400 rad/s, SR 0-1)")
    n = SIZES[-1]
    wp = rng.choice([-1.0, 1.0], n) * rng.uniform(100.0, 400.0, n)
    compare_peers(geometry, wp, rng.uniform(-3.0, 5.0, n) * wp, "every quadrant (|pump| 100-400 rad/s, SR -3 to 5)")
    scipy_reference(conv, geometry, rng)


def scipy_reference(conv, geometry: np.ndarray, rng: np.random.Generator) -> None:
    """The SciPy brentq peer on locked points of a drive batch of 10⁶ points."""
    N = SIZES[-1]
    wp = rng.uniform(100.0, 400.0, N)
    sr = rng.uniform(0.0, 1.0, N)
    wt = sr * wp
    t_tcsim = interleaved_medians({"core": lambda: hrovat_tobler_steady_state(geometry, wp, wt, threads=1)}, 3)["core"]
    t_tcsim /= N
    out = hrovat_tobler_steady_state(geometry, wp, wt)
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
    print(f"\n{'implementation':<34}{'points/s':>14}{'µs/point':>12}")
    print(f"{'tcsim (batched, core, 1 thread)':<34}{rate:>14.3e}{1e6 * t_tcsim:>12.4f}")
    print(f"{'SciPy brentq per point (locked)':<34}{1 / t_ref:>14.3e}{1e6 * t_ref:>12.4f}")
    print(
        f"speed-up tcsim / SciPy: {t_ref / t_tcsim:,.0f}x  ({N:,} tcsim points, median of 3; "
        f"SciPy on {len(idx)} locked points, extrapolated per point)"
    )
    print("agreement (max relative difference): " + ", ".join(f"{c} {d:.1e}" for c, d in diffs.items()))
    print(f"requirement >= 1e6 points/s: {'met' if rate >= 1e6 else 'NOT met'}")


if __name__ == "__main__":
    main()
