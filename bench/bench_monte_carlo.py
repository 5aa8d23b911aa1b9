"""Monte Carlo launch study (``tcsim monte-carlo``, issue 16 item 6): runs per second per core and
peak memory of a streamed study.

What is measured: the study file ``tcsim init monte-carlo`` writes (bundled ``midsize-awd-8at`` and
its converter; vehicle mass, engine inertia, turbine inertia and the quasi-dynamic pump shape effect
drawn; the three models; the flip-flop launch to 100 km/h) with ``--runs`` cases, computed by
:func:`tcsim.io.shards.run_to_shards` in chunks of ``--chunk-size`` cases with ``--threads`` core
workers per call. A run is one model's launch (3 per case). Peak memory is the process's
``ru_maxrss``.

    python3 bench/bench_monte_carlo.py --runs 200 --threads 1          # runs per second per core
    python3 bench/bench_monte_carlo.py --runs 10000 --chunk-size 500   # peak memory, streamed
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import resource
import shutil
import tempfile
import time
from pathlib import Path

from tcsim.analysis.monte_carlo import monte_carlo_study
from tcsim.io.shards import run_to_shards
from tcsim.io.templates import make_template
from tcsim.models.study_file import load_study_file


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=200)
    parser.add_argument("--chunk-size", type=int, default=100)
    parser.add_argument("--threads", type=int, default=0, help="core workers per call (0: all cores)")
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="bench-mc-"))
    try:
        text = make_template("monte-carlo", "mc.toml").text.replace("runs = 100\n", f"runs = {args.runs}\n")
        (work / "mc.toml").write_text(text, encoding="utf-8")
        study = dataclasses.replace(monte_carlo_study(load_study_file(work / "mc.toml")), threads=args.threads)
        t0, c0 = time.perf_counter(), time.process_time()
        run = run_to_shards(study, work / "out", args.chunk_size)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        runs = run.rows
        cores = args.threads or os.cpu_count() or 1
        print(
            f"{args.runs} cases, {runs} runs ({len(study.models)} models) in {run.n_chunks} chunks: {wall:.1f} s wall"
        )
        print(f"{runs / wall:.1f} runs/s, {runs / wall / cores:.1f} runs/s per core ({cores} threads), CPU {cpu:.1f} s")
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(f"{runs / cpu:.1f} runs per CPU-second; peak memory {peak:.0f} MB")
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
