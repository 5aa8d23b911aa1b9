"""Start-up times (issue 16 item 7): ``import tcsim``, ``import tcsim.cli`` and ``tcsim --help`` in
fresh interpreters, median of repeats, with a bare ``python -c pass`` as the floor measured in the
same run. Not a test: it prints, it asserts nothing.

    python3 bench/bench_startup.py [REPEATS]
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time

CASES = {
    "python -c pass (floor)": [sys.executable, "-c", "pass"],
    "import tcsim": [sys.executable, "-c", "import tcsim"],
    "import tcsim.cli": [sys.executable, "-c", "import tcsim.cli"],
    "tcsim --help": [sys.executable, "-m", "tcsim", "--help"],
    "import tcsim; tcsim.simulate (first use)": [sys.executable, "-c", "import tcsim; tcsim.simulate"],
}


def wall(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, capture_output=True, check=True)
    return time.perf_counter() - t0


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 7
    for name, cmd in CASES.items():
        wall(cmd)  # warm the file cache
        times = [wall(cmd) for _ in range(repeats)]
        print(f"{name:42s} median {statistics.median(times):.3f} s (min {min(times):.3f} s, {repeats} runs)")


if __name__ == "__main__":
    main()
