"""Benchmark: scaling of a take-off batch with threads, and memory per run (issue 16, items 4 and 9).

Not part of the test suite. Run:
``python bench/bench_scaling.py [RUNS] [SAMPLES] [THREADS...] [--path columns|batch|both]
[--columns all|peer] [--repeat N]`` (default 10 000 runs, 101 samples, threads 1 and 2, both paths,
all columns, 3 repeats).

Each configuration runs in a fresh interpreter (``--child``), so that its peak resident set size
(``resource.getrusage(RUSAGE_SELF).ru_maxrss``) is its own: RUNS isolated Hrovat & Tobler take-offs
(the ``bench_transient.py`` batch: the bundled ``li-sunden-2016`` converter with shape effects and
friction loss drawn per run, drive c, 10 s, SAMPLES samples) in one call with THREADS workers, of

* ``columns``: :func:`simulate_columns` (the columnar path: one array per column for all runs, no
  Python object per run), or
* ``batch``: :func:`simulate_batch` (a list of ``TransientResult``, one per run, whose columns are
  views of the columnar arrays),

with all 33 columns (``--columns all``) or the 9 columns of the CVODE peer (``--columns peer``,
``bench/cvode_peer.py`` ``TCSIM_COLUMNS``). Printed per configuration (medians over the repeats;
the configurations take turns within each repeat, so that a change of the machine's load falls on
all): the wall time of the call and, inside it, of the core call (``_core.transient_batch``: parsing,
the parallel runs with the GIL released, the arrays), the Python rest, the CPU time of the process
during the call, the peak RSS and the RSS growth per run (peak minus the RSS before the call, over
RUNS). Then the speed-up of each thread count over the first (ratio of medians). The load average
is printed before each repeat and with each result (``os.getloadavg``): on a shared machine the
speed-up is a lower bound.
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
from cvode_peer import TCSIM_COLUMNS  # noqa: E402
from tcsim.models.drives import isolated_takeoff  # noqa: E402
from tcsim.models.dynamic import dynamic_model  # noqa: E402


def _rss_now_kb() -> int:
    """Current resident set size, KiB (Linux /proc)."""
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) for line in fh if line.startswith("VmRSS:"))


def child(runs: int, samples: int, threads: int, path: str, columns: str) -> dict:
    """One configuration in this process; the measurements as a dict."""
    core, core_time = transient._core.transient_batch, []

    def timed(*args):
        t0 = time.perf_counter()
        out = core(*args)
        core_time.append(time.perf_counter() - t0)
        return out

    transient._core.transient_batch = timed
    models = batch_models(dynamic_model("li-sunden-2016", "hrovat-tobler"), runs)
    drive, times = isolated_takeoff(), np.linspace(0.0, 10.0, samples)
    chosen = list(TCSIM_COLUMNS) if columns == "peer" else None
    call = transient.simulate_columns if path == "columns" else transient.simulate_batch
    call(models[:20], [drive], times_s=times, threads=threads, columns=chosen)  # warm-up
    core_time.clear()
    rss0 = _rss_now_kb()
    ru0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    results = call(models, [drive], times_s=times, threads=threads, columns=chosen)
    wall = time.perf_counter() - t0
    ru1 = resource.getrusage(resource.RUSAGE_SELF)
    if path == "columns":
        assert (results.status == transient.RUN_OK).all() and results.columns["time_s"].shape == (runs, samples)
    else:
        assert len(results) == runs and all(len(r["time_s"]) == samples for r in results)
    return {
        "runs": runs,
        "samples": samples,
        "threads": threads,
        "path": path,
        "columns": columns,
        "wall_s": wall,
        "core_s": core_time[0],
        "cpu_s": (ru1.ru_utime + ru1.ru_stime) - (ru0.ru_utime + ru0.ru_stime),
        "peak_rss_kb": ru1.ru_maxrss,
        "rss_before_kb": rss0,
        "load": os.getloadavg(),
    }


def _median(rows: list[dict], key: str) -> float:
    return float(np.median([r[key] for r in rows]))


def _options(argv: list[str]) -> tuple[list[str], dict[str, str]]:
    """Positional arguments and ``--name value`` options."""
    args, opts = [], {}
    it = iter(argv)
    for a in it:
        if a.startswith("--"):
            opts[a[2:]] = next(it)
        else:
            args.append(a)
    return args, opts


def main(argv: list[str]) -> None:
    args, opts = _options(argv)
    runs = int(args[0]) if args else 10_000
    samples = int(args[1]) if len(args) > 1 else 101
    thread_counts = [int(a) for a in args[2:]] or [1, 2]
    paths = ["columns", "batch"] if opts.get("path", "both") == "both" else [opts["path"]]
    columns, repeat = opts.get("columns", "all"), int(opts.get("repeat", "3"))
    print(f"{runs} take-offs, {samples} samples each, {columns} columns, {os.cpu_count()} CPUs")
    configs = [(p, n) for p in paths for n in thread_counts]
    rows: dict[tuple[str, int], list[dict]] = {c: [] for c in configs}
    for k in range(repeat):
        print(f"repeat {k + 1}/{repeat}: load before {os.getloadavg()}")
        for path, threads in configs:
            done = subprocess.run(
                [sys.executable, __file__, "--child", str(runs), str(samples), str(threads), path, columns],
                capture_output=True,
                text=True,
                timeout=3600,
            )
            if done.returncode != 0:
                raise SystemExit(f"child failed: {done.stderr.strip()}")
            rows[(path, threads)].append(json.loads(done.stdout.splitlines()[-1]))
    for (path, threads), rs in rows.items():
        wall, core = _median(rs, "wall_s"), _median(rs, "core_s")
        growth = (_median(rs, "peak_rss_kb") - _median(rs, "rss_before_kb")) / runs
        walls = ", ".join(f"{r['wall_s']:.2f}" for r in rs)
        loads = ", ".join(f"{r['load'][0]:.1f}" for r in rs)
        print(
            f"{path}, threads {threads}: {wall:.2f} s ({wall / runs * 1e6:.0f} µs/run; runs {walls} s), core call "
            f"{core:.2f} s, Python rest {wall - core:.2f} s, CPU {_median(rs, 'cpu_s'):.2f} s; peak RSS "
            f"{_median(rs, 'peak_rss_kb') / 1024:.0f} MiB ({growth:.1f} KiB per run over the "
            f"{_median(rs, 'rss_before_kb') / 1024:.0f} MiB before the call); load after {loads}"
        )
    for path in paths:
        base = rows[(path, thread_counts[0])]
        for threads in thread_counts[1:]:
            r = rows[(path, threads)]
            print(
                f"{path}: speed-up {thread_counts[0]} → {threads} threads: whole call "
                f"{_median(base, 'wall_s') / _median(r, 'wall_s'):.2f}×, core call "
                f"{_median(base, 'core_s') / _median(r, 'core_s'):.2f}×"
            )


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        a = sys.argv[2:]
        print(json.dumps(child(int(a[0]), int(a[1]), int(a[2]), a[3], a[4])))
    else:
        main(sys.argv[1:])
