"""Benchmark: the cold build of ``pip install .`` (issue 16, items 8 and 9).

Not part of the test suite. Run: ``python bench/bench_cold_build.py [REV]`` (default ``HEAD``).

The revision is cloned (``git clone``, then ``git checkout REV``) into a temporary directory, so its
``target/`` is empty and nothing of this checkout's build is reused, and ``python -m pip wheel .
--no-deps`` builds it there: the PEP 517 backend (maturin, then the FMU library) compiles every
crate from source. The crates' sources come from cargo's registry cache (``~/.cargo/registry``),
as on a machine that has fetched them once; a first fetch adds the download time.

Printed: the wall time, the CPU time of the build and its child processes (user + system, from
``resource.getrusage(RUSAGE_CHILDREN)``: what the build costs whatever the machine's load), the
number of crates cargo compiled (``Compiling`` lines, pip ``-v``), and the load average before and
after. On a shared machine the wall time is an upper bound; the CPU time divided by the cores is a
lower bound of the wall time on an idle machine.
"""

from __future__ import annotations

import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def cold_build(rev: str = "HEAD") -> dict[str, float]:
    """Clone ``rev`` into a temporary directory and build its wheel from an empty target directory."""
    with tempfile.TemporaryDirectory(prefix="tcsim-cold-") as tmp:
        src = Path(tmp) / "src"
        subprocess.run(["git", "clone", "-q", str(REPO), str(src)], check=True)
        subprocess.run(["git", "-C", str(src), "checkout", "-q", rev], check=True)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        load = os.getloadavg()[0]
        start = time.monotonic()
        run = subprocess.run(
            [sys.executable, "-m", "pip", "wheel", "-v", ".", "--no-deps", "-w", str(Path(tmp) / "wheel")],
            cwd=src,
            capture_output=True,
            text=True,
            check=False,
        )
        wall = time.monotonic() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if run.returncode != 0:
            raise SystemExit(f"the build failed (exit {run.returncode}):\n{run.stderr[-3000:]}")
        crates = len(re.findall(r"^\s*Compiling \S+ v", run.stdout + run.stderr, flags=re.M))
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        return {"wall_s": wall, "cpu_s": cpu, "crates": crates, "load_before": load, "load_after": os.getloadavg()[0]}


def main(argv: list[str]) -> None:
    rev = argv[1] if len(argv) > 1 else "HEAD"
    r = cold_build(rev)
    print(
        f"cold build of {rev}: wall {r['wall_s']:.0f} s, CPU {r['cpu_s']:.0f} s (user + system), "
        f"{r['crates']:.0f} crates compiled; {os.cpu_count()} CPUs, load average {r['load_before']:.1f} before, "
        f"{r['load_after']:.1f} after"
    )


if __name__ == "__main__":
    main(sys.argv)
