"""Benchmark: scaling of a take-off batch with threads, and memory per run (issue 16, item 9).

Not part of the test suite. Run: ``python bench/bench_scaling.py [RUNS] [SAMPLES] [THREADS...]``
(default 10 000 runs, 101 samples, threads 1 and 2).

Each configuration runs in a fresh interpreter (``--child``), so that its peak resident set size
(``resource.getrusage(RUSAGE_SELF).ru_maxrss``) is its own: RUNS isolated Hrovat & Tobler take-offs
(the ``bench_transient.py`` batch: the bundled ``li-sunden-2016`` converter with shape effects and
friction loss drawn per run, drive c, 10 s, SAMPLES samples, all 27 columns) in one
:func:`simulate_batch` call with THREADS workers. Printed per configuration: the wall time of the
call and, inside it, of the core call (``_core.transient_runs``, GIL released) and of the Python
side (unpacking the results); the CPU time of the process during the call; the peak RSS and the
RSS growth per run (peak minus the RSS before the call, divided by RUNS: the results and the
core's buffers). Then the speed-up of each thread count over 1 thread. The machine's load average
is printed with the numbers (``os.getloadavg``): on a shared machine the speed-up is a lower bound.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import tcsim.simulation.transient as transient  # noqa: E402
from bench_transient import batch_models  # noqa: E402
from tcsim.models.drives import isolated_takeoff  # noqa: E402
from tcsim.models.dynamic import dynamic_model  # noqa: E402


def _rss_now_kb() -> int:
    """Current resident set size, KiB (Linux /proc)."""
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) for line in fh if line.startswith("VmRSS:"))


def child(runs: int, samples: int, threads: int) -> dict:
    """One configuration in this process; the measurements as a dict."""
    core, core_time = transient._core.transient_runs, []

    def timed(*args):
        t0 = time.perf_counter()
        out = core(*args)
        core_time.append(time.perf_counter() - t0)
        return out

    transient._core.transient_runs = timed
    models = batch_models(dynamic_model("li-sunden-2016", "hrovat-tobler"), runs)
    drive, times = isolated_takeoff(), np.linspace(0.0, 10.0, samples)
    transient.simulate_batch(models[:20], [drive], times_s=times, threads=threads)  # warm-up
    core_time.clear()
    rss0 = _rss_now_kb()
    ru0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    results = transient.simulate_batch(models, [drive], times_s=times, threads=threads)
    wall = time.perf_counter() - t0
    ru1 = resource.getrusage(resource.RUSAGE_SELF)
    assert len(results) == runs and all(len(r["time_s"]) == samples for r in results)
    return {
        "runs": runs,
        "samples": samples,
        "threads": threads,
        "wall_s": wall,
        "core_s": core_time[0],
        "cpu_s": (ru1.ru_utime + ru1.ru_stime) - (ru0.ru_utime + ru0.ru_stime),
        "peak_rss_kb": ru1.ru_maxrss,
        "rss_before_kb": rss0,
        "load": os.getloadavg(),
    }


def main(argv: list[str]) -> None:
    runs = int(argv[0]) if argv else 10_000
    samples = int(argv[1]) if len(argv) > 1 else 101
    thread_counts = [int(a) for a in argv[2:]] or [1, 2]
    print(f"{runs} take-offs, {samples} samples each, {os.cpu_count()} CPUs; load before {os.getloadavg()}")
    rows = []
    for threads in thread_counts:
        done = subprocess.run(
            [sys.executable, __file__, "--child", str(runs), str(samples), str(threads)],
            capture_output=True,
            text=True,
            timeout=3600,
        )
        if done.returncode != 0:
            raise SystemExit(f"child failed: {done.stderr.strip()}")
        r = json.loads(done.stdout.splitlines()[-1])
        rows.append(r)
        growth = (r["peak_rss_kb"] - r["rss_before_kb"]) / runs
        print(
            f"threads {threads}: {r['wall_s']:.2f} s ({r['wall_s'] / runs * 1e6:.0f} µs/run), core call "
            f"{r['core_s']:.2f} s, Python side {r['wall_s'] - r['core_s']:.2f} s, CPU {r['cpu_s']:.2f} s; "
            f"peak RSS {r['peak_rss_kb'] / 1024:.0f} MiB ({growth:.1f} KiB per run over the "
            f"{r['rss_before_kb'] / 1024:.0f} MiB before the call); load after {tuple(round(x, 2) for x in r['load'])}"
        )
    base = rows[0]
    for r in rows[1:]:
        print(
            f"speed-up {base['threads']} → {r['threads']} threads: whole call {base['wall_s'] / r['wall_s']:.2f}×, "
            f"core call {base['core_s'] / r['core_s']:.2f}×"
        )


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        print(json.dumps(child(int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]))))
    else:
        main(sys.argv[1:])
