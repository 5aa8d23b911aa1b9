"""Benchmark: the 10 s isolated Hrovat & Tobler take-off, tcsim against SciPy ``solve_ivp``.

Not part of the test suite. Run: ``python bench/bench_transient.py`` (tcsim installed, or
``PYTHONPATH=python``).

* **tcsim**: :func:`tcsim.transient.simulate` on the bundled ``li-sunden-2016`` converter under
  :func:`tcsim.transient.isolated_takeoff` (drive c; the stator releases at the coupling point),
  1001 output samples, default tolerances (rtol 1e-6). Wall time through the Python API, median of
  ``REPEATS`` after a warm-up.
* **SciPy**: ``bench/scipy_reference.py``, the same equations, modes and events written with
  ``solve_ivp`` (LSODA and Radau, rtol 1e-6, analytic Jacobian), same scenario and samples.
* **Agreement** is checked before any ratio is printed: event times and the state at 10 s.
* **Batch**: 10 000 take-offs with different parameter sets (pump and turbine shape effects drawn
  within the admissible range, friction loss 0.1–0.3) in one :func:`simulate_batch` call on all
  cores, 101 samples per run.

Targets (issue 3): ≥ 50× faster than the faster SciPy method, ≤ 1 ms per run (median), 10 000
runs in under 10 s on 2 cores.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import scipy_reference as ref  # noqa: E402
from tcsim.models.drives import isolated_takeoff  # noqa: E402
from tcsim.models.dynamic import dynamic_model  # noqa: E402
from tcsim.simulation.transient import simulate, simulate_batch  # noqa: E402
from timing import median_and_fastest  # noqa: E402

REPEATS = 50
SCIPY_REPEATS = 5
BATCH = 10_000
TIMES = np.linspace(0.0, 10.0, 1001)
#: The batch keeps 101 samples per run (every 0.1 s): 10 000 runs × 27 columns × 1001 samples would
#: be 2.2 GB of results, which measures memory traffic rather than the solver.
BATCH_TIMES = np.linspace(0.0, 10.0, 101)


def median_time(fn, repeats: int) -> float:
    return median_and_fastest(fn, repeats)[0]


def check_agreement(ours, theirs, label: str) -> None:
    ev_ours = [e.time_s for e in ours.events]
    ev_theirs = [t for t, _kind in theirs["events"]]
    assert len(ev_ours) == len(ev_theirs), (label, ev_ours, ev_theirs)
    assert max((abs(a - b) for a, b in zip(ev_ours, ev_theirs)), default=0.0) < 1e-4, (label, ev_ours, ev_theirs)
    for name in ("pump_speed_rad_s", "turbine_speed_rad_s", "flow_m3_s"):
        a, b = ours[name][-1], theirs[name][-1]
        assert abs(a - b) <= 1e-4 * abs(b), (label, name, a, b)


def batch_models(base, n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    models = []
    for sp, st, f in zip(rng.uniform(0.0, 0.025, n), rng.uniform(0.0, 0.025, n), rng.uniform(0.1, 0.3, n)):
        m = base.with_shape_effects(sp, st)
        geometry = list(m.spec["geometry"])
        geometry[14] = f  # friction_loss
        models.append(type(m)(m.name, {**m.spec, "geometry": geometry}, m.source))
    return models


def main() -> None:
    model = dynamic_model("li-sunden-2016", "hrovat-tobler")
    drive = isolated_takeoff()
    params, scenario = ref.load_parameters(), ref.takeoff_scenario()

    ours = simulate(model, drive, times_s=TIMES)
    t_ours = median_time(lambda: simulate(model, drive, times_s=TIMES), REPEATS)
    print(
        f"tcsim (diffsol BDF), Python API: {t_ours * 1e3:.3f} ms per run (median of {REPEATS}); "
        f"events {[(round(e.time_s, 5), e.kind) for e in ours.events]}"
    )

    best = None
    for method in ("LSODA", "Radau"):
        theirs = ref.simulate(params, scenario, method=method, rtol=1e-6, t_eval=TIMES)
        check_agreement(ours, theirs, method)
        t = median_time(
            lambda method=method: ref.simulate(params, scenario, method=method, rtol=1e-6, t_eval=TIMES), SCIPY_REPEATS
        )
        print(
            f"SciPy solve_ivp {method:5s}: {t * 1e3:8.2f} ms per run (median of {SCIPY_REPEATS}), "
            f"{t / t_ours:6.1f}× tcsim's time; agrees (events < 1e-4 s, final state < 1e-4)"
        )
        best = t if best is None else min(best, t)

    models = batch_models(model, BATCH)
    t0 = time.perf_counter()
    results = simulate_batch(models, [drive], times_s=BATCH_TIMES)
    t_batch = time.perf_counter() - t0
    released = sum(any(e.kind == "stator-release" for e in r.events) for r in results)
    print(
        f"batch: {BATCH} take-offs in {t_batch:.2f} s on {os.cpu_count()} cores "
        f"({t_batch / BATCH * 1e6:.0f} µs per run); "
        f"{released} released the stator"
    )

    speedup = best / t_ours
    print(
        f"\nspeed-up over the faster SciPy method: {speedup:.0f}× (target ≥ 50×); "
        f"per run {t_ours * 1e3:.3f} ms (target ≤ 1 ms); "
        f"batch {t_batch:.2f} s (target < 10 s)"
    )
    ok = speedup >= 50 and t_ours <= 1e-3 and t_batch < 10
    print("targets met" if ok else "TARGETS NOT MET")


if __name__ == "__main__":
    main()
