"""Benchmark: backward operating points of the table model through the Python API.

Not part of the test suite. Run: ``python bench/bench_operating_point.py`` (tcsim installed, or
``PYTHONPATH=python``).

Measures points per second of :func:`tcsim.operating_point` (table model, bundled ``li-sunden-2016``,
10⁶ drive points, DataFrame included) and of the raw core call, and compares, in the same process,
with a plain NumPy implementation of the same closed form (VECTO's: on every segment of the table
the delivered torque is a quadratic in the pump speed; all segments solved for all points, the
lowest pump speed inside its segment kept). The two are checked to agree before the ratio is
printed.
"""

from __future__ import annotations

import numpy as np

import tcsim
from tcsim import _core
from timing import median_and_fastest

N = 1_000_000
REPEATS = 7


def numpy_backward(sr: np.ndarray, tr: np.ndarray, cf: np.ndarray, wt: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Pump speeds, rad/s, of the drive points (ω_t > 0, SR inside the table) by the closed form, as a
    NumPy user would write it: with u = ω_p/ω_t, TR = α + β·SR and CF = γ + δ·SR on a segment,
    T/ω_t² = (αu + β)(γu + δ); the roots of every segment, the lowest one inside its segment."""
    tau = t / wt**2
    best = np.full(wt.shape, np.inf)
    for k in range(1, len(sr)):
        a, b = sr[k - 1], sr[k]
        beta = (tr[k] - tr[k - 1]) / (b - a)
        delta = (cf[k] - cf[k - 1]) / (b - a)
        alpha, gamma = tr[k - 1] - beta * a, cf[k - 1] - delta * a
        q2, q1, q0 = alpha * gamma, alpha * delta + beta * gamma, beta * delta - tau
        disc = q1 * q1 - 4.0 * q2 * q0
        sq = np.sqrt(np.maximum(disc, 0.0))
        lo, hi = 1.0 / b, (1.0 / a if a > 0 else np.inf)
        for root in ((-q1 + sq) / (2.0 * q2), (-q1 - sq) / (2.0 * q2)):
            ok = (disc >= 0) & (root >= lo * (1 - 1e-12)) & (root <= hi * (1 + 1e-12)) & (root < best)
            best = np.where(ok, root, best)
    return best * wt


def main() -> None:
    conv = tcsim.load_converter("li-sunden-2016")
    sr_t, tr_t, cf_t = conv.characteristic.arrays()
    rng = np.random.default_rng(0)
    wp = rng.uniform(100.0, 400.0, N)
    sr = rng.uniform(0.01, 0.95, N)
    wt = sr * wp
    t = tcsim.steady_state(conv, "table", wp, wt)["turbine_torque_nm"].to_numpy()  # the forward model

    api = {}

    def run_api():
        api["df"] = tcsim.operating_point(conv, wt, t)

    def run_core():
        api["core"] = _core.table_operating_points(sr_t, tr_t, cf_t, wt, t)

    def run_numpy():
        api["numpy"] = numpy_backward(sr_t, tr_t, cf_t, wt, t)

    results = {}
    for name, fn in (("api", run_api), ("core", run_core), ("numpy", run_numpy)):
        results[name] = median_and_fastest(fn, REPEATS)
    df = api["df"]
    assert df["valid"].all()
    err_np = float(np.max(np.abs(api["numpy"] - df["pump_speed_rad_s"]) / wp))
    err_fwd = float(np.max(np.abs(df["pump_speed_rad_s"] - wp) / wp))
    assert err_np < 1e-9 and err_fwd < 1e-9, (err_np, err_fwd)

    print(f"{'implementation':<44}{'points/s':>14}{'µs/point':>12}")
    labels = {
        "api": "tcsim.operating_point (DataFrame, 2 threads)",
        "core": "_core.table_operating_points (arrays)",
        "numpy": "NumPy closed form, all segments",
    }
    for name, (median, fastest) in results.items():
        print(f"{labels[name]:<44}{N / median:>14.3e}{1e6 * median / N:>12.4f}   (fastest {N / fastest:.3e}/s)")
    ratio = results["numpy"][0] / results["api"][0]
    print(f"speed-up tcsim API / NumPy: {ratio:.2f}x ({N:,} points, median of {REPEATS})")
    print(f"agreement: pump speed vs NumPy {err_np:.1e}, vs the forward grid {err_fwd:.1e} (max relative)")
    print(f"requirement >= 1e6 points/s through the API: {'met' if N / results['api'][0] >= 1e6 else 'NOT met'}")


if __name__ == "__main__":
    main()
