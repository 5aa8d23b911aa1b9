"""Wall-time measurement shared by the benchmarks."""

from __future__ import annotations

import statistics
import time


def median_and_fastest(fn, repeats: int) -> tuple[float, float]:
    """Median and fastest wall time of ``repeats`` calls of ``fn`` after one warm-up call, s."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times)
