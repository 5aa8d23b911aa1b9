"""Wall time of a 1024-design study of two parameters (32 × 32: squash ratio × pump exit radius of the
bundled ``li-sunden-2016-design``, elliptic profile), steady-state and take-off figures for each
design (docs/design.md, "Design studies"). Not a test: it prints the time, it asserts nothing on it.

    python3 bench/bench_design_study.py [THREADS]
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace

import numpy as np

from tcsim.analysis.design_study import design_study
from tcsim.models.design_file import load_design_file


def main() -> None:
    """Run the study once after a small warm-up and print its wall time."""
    threads = int(sys.argv[1]) if len(sys.argv) > 1 else 2
    base = load_design_file("li-sunden-2016-design")
    file = replace(base, design=replace(base.design, profile="elliptic", squash_ratio=0.0))
    sweep = {"squash_ratio": np.linspace(0.0, 0.4, 32), "pump_exit_radius_m": np.linspace(0.11, 0.14, 32)}
    design_study(file, {"squash_ratio": [0.0, 0.2]}, threads)  # warm-up
    t0 = time.perf_counter()
    study = design_study(file, sweep, threads)
    wall = time.perf_counter() - t0
    failed = int((study["error"] != "").sum())
    print(f"{len(study)} designs ({failed} without figures), {threads} threads: {wall:.2f} s wall")


if __name__ == "__main__":
    main()
