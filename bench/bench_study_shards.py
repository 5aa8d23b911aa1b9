"""Streamed study of isolated take-offs to Parquet shards: peak memory and rows/s (issue 16, item 5).

What is measured: ``N`` isolated 10 s take-offs (:func:`tcsim.models.drives.isolated_takeoff`, drive
c) of the bundled ``li-sunden-2016`` converter, Hrovat & Tobler model, 101 samples each, each run
with its own parameters (pump and turbine shape effects 0–0.025 m², friction loss 0.1–0.3, drawn
by Weyl sequences of the case index, so that a case is a pure function of its index), computed in
chunks of ``--chunk-size`` take-offs by :func:`tcsim.simulation.transient.simulate_batch` (all
cores) and written by :func:`tcsim.io.shards.run_to_shards` as one Parquet shard per chunk with
the columns ``case``, ``time_s``, ``pump_speed_rad_s``, ``turbine_speed_rad_s``,
``turbine_torque_nm``, ``flow_m3_s`` (101 rows per take-off). Peak memory is the process's
``ru_maxrss``; compare it across N to see that it does not grow with the number of chunks.

    python3 bench/bench_study_shards.py --runs 100000 --chunk-size 1000 --out /tmp/takeoffs
"""

from __future__ import annotations

import argparse
import functools
import resource
import shutil
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from tcsim.io.shards import run_to_shards
from tcsim.models.drives import isolated_takeoff
from tcsim.models.dynamic import dynamic_model
from tcsim.simulation.transient import simulate_batch

TIMES = np.linspace(0.0, 10.0, 101)
KEPT = ("time_s", "pump_speed_rad_s", "turbine_speed_rad_s", "turbine_torque_nm", "flow_m3_s")
#: Irrational multipliers of the Weyl sequences of the three parameters.
WEYL = (0.6180339887498949, 0.41421356237309515, 0.7320508075688772)


@dataclass(frozen=True)
class TakeoffStudy:
    """``runs`` isolated take-offs, case ``i`` with the parameters of :func:`parameters`."""

    runs: int
    kind: str = "bench-isolated-takeoffs"
    columns: tuple[str, ...] = ("case", *KEPT)

    @property
    def n_cases(self) -> int:
        return self.runs

    def definition(self) -> dict[str, Any]:
        return {"runs": self.runs, "times_s": TIMES.tolist(), "weyl": list(WEYL)}

    def rows(self, start: int, stop: int) -> pd.DataFrame:
        base = _base_model()
        i = np.arange(start, stop)
        sp, st, friction = parameters(i)
        models = []
        for a, b, f in zip(sp, st, friction):
            m = base.with_shape_effects(float(a), float(b))
            geometry = list(m.spec["geometry"])
            geometry[14] = float(f)  # friction_loss
            models.append(type(m)(m.name, {**m.spec, "geometry": geometry}, m.source))
        results = simulate_batch(models, [isolated_takeoff()], times_s=TIMES)
        cols = {"case": np.repeat(i, len(TIMES))}
        for name in KEPT:
            cols[name] = np.concatenate([r.columns[name] for r in results])
        return pd.DataFrame(cols)


def parameters(i: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pump and turbine shape effects, m², and friction loss of the cases ``i``."""
    u = [np.modf(i * w)[0] for w in WEYL]
    return 0.025 * u[0], 0.025 * u[1], 0.1 + 0.2 * u[2]


@functools.cache
def _base_model():
    return dynamic_model("li-sunden-2016", "hrovat-tobler")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=100_000)
    parser.add_argument("--chunk-size", type=int, default=1000)
    parser.add_argument("--out", default="/tmp/tcsim-bench-takeoffs")
    parser.add_argument("--keep", action="store_true", help="keep the shards (removed by default)")
    args = parser.parse_args()
    shutil.rmtree(args.out, ignore_errors=True)
    t0 = time.perf_counter()
    run = run_to_shards(TakeoffStudy(args.runs), args.out, args.chunk_size)
    wall = time.perf_counter() - t0
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    size_mb = sum(p.stat().st_size for p in __import__("pathlib").Path(args.out).rglob("*.parquet")) / 2**20
    print(
        f"{args.runs} take-offs in {run.n_chunks} chunks of {args.chunk_size}: {run.rows} rows in {wall:.1f} s "
        f"({args.runs / wall:.0f} take-offs/s, {run.rows / wall:.3g} rows/s), shards {size_mb:.0f} MB, "
        f"peak RSS {peak_mb:.0f} MB"
    )
    if not args.keep:
        shutil.rmtree(args.out, ignore_errors=True)


if __name__ == "__main__":
    main()
