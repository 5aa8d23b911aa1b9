"""Where the instructions of one isolated take-off go: tcsim (Rust core) and the C + CVODE peer.

Not part of the test suite. Run: ``python bench/profile_takeoff.py [SAMPLES]`` (default 1001); needs
valgrind and cargo (and, for the peer, gcc and libsundials-dev). Issue 16, item 2: measurement only.

Each program runs under ``valgrind --tool=callgrind`` twice, with a small and a larger number of
take-offs; the difference divided by the difference in runs is the cost of one take-off, free of
start-up and of the machine's load (instructions, not seconds). Inclusive instruction counts and
call counts per function come from ``callgrind_annotate``. Programs:

* tcsim: ``crates/tcsim-core/examples/takeoff_profile.rs`` (the bundled converter, drive c, 10 s,
  SAMPLES samples, default options; ``simulate`` then the 27 ``columns``).
* peer: ``bench/cvode_peer/takeoff`` (same take-off; 9 output columns).

Then, in wall time (medians of ``WALL_REPEATS`` in this process, so the machine's load enters): one
``tcsim.transient.simulate`` through the Python API, and inside it the core call
(``_core.transient_batch``: the run, its columns and their hand-over to NumPy); the rest
is Python (checking inputs, building the result).

The split printed for tcsim: *integration* is ``run_segment`` less the sampling inside it; of it,
*our callbacks* are the right-hand side (``Segment::reduced_rhs``; the trait methods are inlined),
the model's Jacobian (``force_jacobian``) and the root functions, and *solver* is the rest (the
NDF/BDF integrator of ``engine/bdf``: step bookkeeping, Newton, LU, error control, root finding);
*sampling* is the integrator's interpolation (``Bdf::interpolate``, at the sample times and in the
root finding) plus ``Segment::sample`` (a sample's state, rates and torques); *columns* is
``outputs::columns`` (27 columns from the samples).
"""

from __future__ import annotations

import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, os.path.dirname(__file__))
import numpy as np  # noqa: E402

import cvode_peer  # noqa: E402
import scipy_reference as ref  # noqa: E402
import tcsim.simulation.transient as transient  # noqa: E402
from tcsim.models.drives import isolated_takeoff  # noqa: E402
from tcsim.models.dynamic import dynamic_model  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "target/release/examples/takeoff_profile"
RUNS = (2, 12)
WALL_REPEATS = 300
LINE = re.compile(r"\s*([\d,]+) \(\s*[\d.]+%\)\s+([*<>]\s+)?(\S.*?) \[")
CALLS = re.compile(r"\(([\d,]+)x\)")


def callgrind(cmd: list[str], stdin: str | None = None) -> tuple[dict[str, int], dict[str, int], str]:
    """Inclusive instructions and calls per function of ``cmd`` run under callgrind; its stdout."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cg.out")
        done = subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *cmd],
            input=stdin,
            capture_output=True,
            text=True,
            check=True,
            timeout=1800,
        )
        tree = subprocess.run(
            ["callgrind_annotate", "--inclusive=yes", "--tree=caller", "--threshold=100", out],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    cost: dict[str, int] = {}
    calls: dict[str, int] = {}
    for block in tree.split("\n\n"):
        pending, callers = 0, []
        for line in block.splitlines():
            m = LINE.match(line)
            if not m:
                continue
            name = CALLS.sub("", m.group(3).split(":", 1)[-1]).strip()
            if m.group(2) and m.group(2).startswith("<"):
                c = CALLS.search(line)
                n = int(c.group(1).replace(",", "")) if c else 0
                pending += n
                callers.append((name, n, int(m.group(1).replace(",", ""))))
            elif m.group(2) and m.group(2).startswith("*"):
                cost[name] = cost.get(name, 0) + int(m.group(1).replace(",", ""))
                calls[name] = calls.get(name, 0) + pending
                # calls and inclusive cost by caller too, as "callee <- caller"
                for caller, n, c in callers:
                    calls[f"{name} <- {caller}"] = calls.get(f"{name} <- {caller}", 0) + n
                    cost[f"{name} <- {caller}"] = cost.get(f"{name} <- {caller}", 0) + c
                pending, callers = 0, []
    return cost, calls, done.stdout


def per_run(cmds: list[list[str]], stdin: str | None = None) -> tuple[dict[str, float], dict[str, float], str]:
    """Instructions and calls per take-off: the difference of two callgrind runs over RUNS."""
    (c0, n0, _), (c1, n1, out) = (callgrind(c, stdin) for c in cmds)
    k = RUNS[1] - RUNS[0]
    cost = {f: (c1[f] - c0.get(f, 0)) / k for f in c1}
    calls = {f: (n1[f] - n0.get(f, 0)) / k for f in n1}
    return cost, calls, out


def find(table: dict[str, float], *parts: str) -> float:
    """Sum over the functions whose name contains all of ``parts`` (the "callee <- caller" entries of
    the calls only when a part has " <- ")."""
    by_caller = any(" <- " in p for p in parts)
    return sum(v for f, v in table.items() if all(p in f for p in parts) and (by_caller or " <- " not in f))


def exact(table: dict[str, float], name: str) -> float:
    """The entry of the function called exactly ``name`` (C symbols), 0 if absent."""
    return sum(v for f, v in table.items() if f.removeprefix("???:") == name)


def tcsim_profile(samples: int) -> None:
    subprocess.run(["cargo", "build", "--release", "--example", "takeoff_profile"], cwd=ROOT, check=True)
    cost, calls, out = per_run([[str(EXAMPLE), str(r), str(samples)] for r in RUNS])
    total = find(cost, "takeoff_profile::main")
    # the integrator's right-hand sides (the samples call reduced_rhs too, through kinematics)
    rhs = find(cost, "Segment::reduced_rhs <- ", "engine::bdf::Bdf<S>::step") + find(
        cost, "Segment::reduced_rhs <- ", "SmoothSegment>::rhs"
    )
    jac = find(cost, "SmoothSegment>::jacobian_times <- ", "engine::bdf::Bdf<S>::refactor")
    roots = find(cost, "converter_segment::Segment::root_values")
    interp = find(cost, "engine::bdf::Bdf<S>::interpolate")
    sample = find(cost, "converter_segment::Segment::sample")
    segment = find(cost, "engine::segment::run_segment")
    columns = find(cost, "engine::outputs::columns")
    integration = segment - interp - sample
    ours = rhs + jac + roots
    pct = lambda x: f"{x / 1e3:8.0f} k instructions ({100 * x / total:4.1f} %)"  # noqa: E731
    print(f"tcsim, {samples} samples: {out.strip().splitlines()[-1]}")
    print(f"  per take-off            {pct(total)}")
    print(f"  integration             {pct(integration)}")
    parts = f"RHS {rhs / 1e3:.0f} k, Jacobian {jac / 1e3:.0f} k, roots {roots / 1e3:.0f} k"
    print(f"    our callbacks         {pct(ours)} ({parts})")
    print(f"    solver                {pct(integration - ours)}")
    print(f"  sampling                {pct(interp + sample)} (interpolation {interp / 1e3:.0f} k)")
    print(f"  columns                 {pct(columns)}")
    print(f"  rest (initial state...) {pct(total - segment - columns)}")
    print(
        "  calls per take-off: RHS {:.0f}, Jacobian-vector products {:.0f}, LU factorisations {:.0f}, "
        "linear solves {:.0f}, root-function evaluations {:.0f}, samples {:.0f}".format(
            # the integrator's RHS calls (the samples and root functions call reduced_rhs too)
            find(calls, "Segment::reduced_rhs <- ", "engine::bdf::Bdf<S>::step")
            + find(calls, "Segment::reduced_rhs <- ", "SmoothSegment>::rhs"),
            find(calls, "SmoothSegment>::jacobian_times <- ", "engine::bdf::Bdf<S>::refactor"),
            find(calls, "engine::bdf::lu::Lu::factor"),
            find(calls, "engine::bdf::lu::Lu::solve"),
            find(calls, "converter_segment::Segment::root_values"),
            find(calls, "converter_segment::Segment::sample"),
        )
    )
    steps = int(re.search(r"(\d+) steps", out).group(1))
    per_step = f"integration {integration / steps:.0f} instructions, solver {(integration - ours) / steps:.0f}"
    print(f"  per step ({steps} steps): {per_step}")


def peer_profile(samples: int) -> None:
    try:
        binary = str(cvode_peer.build())
    except cvode_peer.PeerUnavailable as e:
        print(f"CVODE peer skipped: {e}")
        return
    stdin = cvode_peer.parameter_text(ref.load_parameters(), ref.takeoff_scenario())
    runs = [r * 5 for r in RUNS]  # the peer's loop runs a warm-up too; more runs, same difference
    cost, _, out = per_run([[binary, str(r), str(samples)] for r in runs], stdin)
    scale = (RUNS[1] - RUNS[0]) / (runs[1] - runs[0])
    cost = {f: v * scale for f, v in cost.items()}
    total = exact(cost, "main")
    dky = exact(cost, "CVodeGetDky")
    cvode = exact(cost, "CVode") - dky
    pct = lambda x: f"{x / 1e3:8.0f} k instructions ({100 * x / total:4.1f} %)"  # noqa: E731
    stats = next(line for line in out.splitlines() if line.startswith("stats")).split()[1:]
    print(f"C + CVODE peer, {samples} samples: steps {stats[0]}, RHS {stats[1]}, Jacobians {stats[2]}, LU {stats[3]}")
    print(f"  per take-off            {pct(total)}")
    parts = f"RHS {exact(cost, 'rhs') / 1e3:.0f} k, roots {exact(cost, 'roots') / 1e3:.0f} k"
    print(f"  CVode (integration)     {pct(cvode)} ({parts})")
    print(f"  CVodeGetDky (sampling)  {pct(dky)}")
    print(f"  sample outputs          {pct(exact(cost, 'sample'))}")
    print(f"  rest (initial state...) {pct(total - exact(cost, 'CVode') - exact(cost, 'sample'))}")


def python_split(samples: int) -> None:
    """Median wall time of ``simulate`` through the Python API and of the core call inside it."""
    core, core_times = transient._core.transient_batch, []

    def timed(*args):
        t0 = time.perf_counter()
        out = core(*args)
        core_times.append(time.perf_counter() - t0)
        return out

    model, drive, times = (
        dynamic_model("li-sunden-2016", "hrovat-tobler"),
        isolated_takeoff(),
        np.linspace(0, 10, samples),
    )
    transient._core.transient_batch = timed
    try:
        transient.simulate(model, drive, times_s=times)
        core_times.clear()
        totals = []
        for _ in range(WALL_REPEATS):
            t0 = time.perf_counter()
            transient.simulate(model, drive, times_s=times)
            totals.append(time.perf_counter() - t0)
    finally:
        transient._core.transient_batch = core
    total, inside = statistics.median(totals), statistics.median(core_times)
    print(
        f"Python API, {samples} samples (wall, median of {WALL_REPEATS}, load {os.getloadavg()[0]:.1f}): simulate "
        f"{total * 1e6:.0f} µs, of which the core call {inside * 1e6:.0f} µs and Python "
        f"{(total - inside) * 1e6:.0f} µs ({100 * (total - inside) / total:.0f} %)"
    )


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1001
    tcsim_profile(n)
    peer_profile(n)
    python_split(n)
