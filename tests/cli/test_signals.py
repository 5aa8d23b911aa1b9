"""Interrupts (docs/guarantees.md): SIGINT exits 130 and SIGTERM 143, with one stderr line, and leave
no output directory, no staging folder and no other file. The moments are found by the run's phases,
not by sleeping: "just after start" is when ``tcsim.cli.main`` has installed its SIGTERM handler
(Linux's /proc/PID/status), "while writing" when the staging folder exists. The batch calls of the
core are cancelled by a signal: the call raises instead of running to its end."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

HANG_GUARD_S = 600  # a hang guard only; nothing is asserted about durations
POLL_S = 0.005

COMMANDS = {
    "launch": ["launch", "--sweep-shape-effects", "--out", "o"],
    "characterise": ["characterise", "li-sunden-2016", "--out", "o"],
    "study": ["study", "li-sunden-2016", "--out", "o"],
    "drive": ["drive", "--cycle", "udds", "--model", "hrovat-tobler", "--out", "o"],  # no overrun warning
    "design": ["design", "li-sunden-2016-design", "--out", "o"],
    "design-study": ["design-study", "li-sunden-2016-design", "--sweep", "squash_ratio=0:0.3:20", "--out", "o"],
}


def _handles_sigterm(pid: int) -> bool:
    """Whether the process has a handler for SIGTERM (``SigCgt`` in /proc/PID/status)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    caught = next(line for line in status.splitlines() if line.startswith("SigCgt:")).split()[1]
    return bool(int(caught, 16) >> (signal.SIGTERM - 1) & 1)


def _staging(cwd: Path) -> bool:
    return any(p.name.startswith(".o.") and p.name.endswith(".partial") for p in cwd.iterdir())


PHASES = {"start": lambda p, cwd: _handles_sigterm(p.pid), "writing": lambda p, cwd: _staging(cwd)}


def interrupt(command: str, sig: signal.Signals, phase: str, cwd: Path) -> subprocess.CompletedProcess:
    """Run the command in ``cwd``, send ``sig`` when ``phase`` is reached, return what it did."""
    if phase == "start" and not Path("/proc/self/status").exists():
        pytest.skip("needs /proc to see the start of main()")
    env = dict(os.environ, COLUMNS="200")
    p = subprocess.Popen(
        [sys.executable, "-m", "tcsim", *COMMANDS[command]],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        reached = PHASES[phase]
        while not reached(p, cwd):
            if p.poll() is not None:
                out, err = p.communicate()
                pytest.fail(f"{command} ended (exit {p.returncode}) before its phase {phase!r}: {err}")
            time.sleep(POLL_S)
        p.send_signal(sig)
        out, err = p.communicate(timeout=HANG_GUARD_S)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    return subprocess.CompletedProcess(p.args, p.returncode, out, err)


CASES = [
    ("launch", signal.SIGINT, "start"),
    ("launch", signal.SIGTERM, "start"),
    ("launch", signal.SIGINT, "writing"),
    ("launch", signal.SIGTERM, "writing"),
    ("characterise", signal.SIGINT, "writing"),
    ("study", signal.SIGTERM, "writing"),
    ("drive", signal.SIGINT, "start"),
    ("drive", signal.SIGTERM, "writing"),
    ("design", signal.SIGTERM, "start"),
    ("design", signal.SIGINT, "writing"),
    ("design-study", signal.SIGTERM, "start"),
    ("design-study", signal.SIGINT, "writing"),
]


@pytest.mark.subprocess
@pytest.mark.parametrize(("command", "sig", "phase"), CASES, ids=[f"{c}-{s.name}-{p}" for c, s, p in CASES])
def test_an_interrupted_run_exits_128_plus_the_signal_and_leaves_nothing(tmp_path, command, sig, phase):
    """Defect 1: Ctrl-C exited 0 without a word; SIGTERM while writing left a staging folder."""
    r = interrupt(command, sig, phase, tmp_path)
    assert r.returncode == 128 + sig, (r.returncode, r.stderr)
    assert r.stderr.strip().splitlines() == [f"interrupted ({sig.name}): nothing written"], r.stderr
    assert "Traceback" not in r.stdout + r.stderr
    assert sorted(os.listdir(tmp_path)) == []  # no o, no staging folder, nothing else


# ---------------------------------------------------------------------------------------------
# the core's batch calls are cancelled

#: A batch of launch runs far longer than any hang guard (some hours of work), started in a
#: subprocess that reports its thread count first; the signal is sent once the batch's threads exist.
BATCH_SCRIPT = """
import signal
import sys
from pathlib import Path
from tcsim import _core
from contextlib import nullcontext
from tcsim.cli.app import _signals_raise
from tcsim.models.dynamic import dynamic_model
from tcsim.models.vehicle import load_vehicle
from tcsim.simulation.scenarios import flip_flop

# Python installs its Ctrl-C handler only where SIGINT is not ignored; a shell without job control
# starts background jobs (CI under `nohup ... &`) with SIGINT ignored. Install it as a terminal would.
signal.signal(signal.SIGINT, signal.default_int_handler)
veh = load_vehicle(None)
spec = dynamic_model(veh.converter, "quasi-dynamic").spec
threads = next(l for l in Path("/proc/self/status").read_text().splitlines() if l.startswith("Threads:"))
print(threads.split()[1], flush=True)
with _signals_raise() if sys.argv[1] == "SIGTERM" else nullcontext():  # Python's own Ctrl-C otherwise
    try:
        options = {"output_step_s": 0.5, "max_output_bytes": 1e13}  # hours of runs, never all in memory
        _core.launch_runs([spec] * 200_000, veh.core, flip_flop().core_spec(), options, 0)
    except KeyboardInterrupt as e:
        print("raised by the call:", type(e).__name__, flush=True)
        sys.exit(3)
print("the batch ran to its end", flush=True)
"""


def _threads(pid: int) -> int:
    status = Path(f"/proc/{pid}/status").read_text()
    return int(next(line for line in status.splitlines() if line.startswith("Threads:")).split()[1])


@pytest.mark.subprocess
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=lambda s: s.name)
def test_a_signal_cancels_a_running_batch_call(sig):
    """Ctrl-C (Python's own handler) and SIGTERM (under ``main``'s handlers) during `_core.launch_runs`
    raise from the call; before, the batch ran to its end first (here: hours, caught by the hang guard)."""
    if not Path("/proc/self/status").exists():
        pytest.skip("needs /proc to see the batch's threads")
    cmd = [sys.executable, "-c", BATCH_SCRIPT, sig.name]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout is not None
        baseline = int(p.stdout.readline())
        while _threads(p.pid) <= baseline:  # the batch has started when its threads exist
            assert p.poll() is None, p.communicate()
            time.sleep(POLL_S)
        p.send_signal(sig)
        out, err = p.communicate(timeout=120)  # hang guard
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    expected = "Interrupted" if sig == signal.SIGTERM else "KeyboardInterrupt"
    assert (p.returncode, out.strip()) == (3, f"raised by the call: {expected}"), err
