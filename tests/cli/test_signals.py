"""Interrupts (docs/guarantees.md): SIGINT exits 130 and SIGTERM 143, with one stderr line, and leave
no output directory, no staging folder and no other file. The moments are found by the run's phases,
not by sleeping: "just after start" is when ``tcsim.cli.main`` has installed its SIGTERM handler
(Linux's /proc/PID/status), "while writing" when the staging folder exists. The batch calls of the
core are cancelled by Ctrl-C (checked in-process: the call raises instead of returning)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from tcsim import _core
from tcsim.models.dynamic import dynamic_model
from tcsim.models.vehicle import load_vehicle
from tcsim.simulation.scenarios import flip_flop

#: Launch runs of the in-process batch: some 20 s of work on two cores, cancelled after 0.2 s.
N_RUNS = 400
HANG_GUARD_S = 600  # a hang guard only; nothing is asserted about durations
POLL_S = 0.005

COMMANDS = {
    "launch": ["launch", "--sweep-shape-effects", "--out", "o"],
    "characterise": ["characterise", "li-sunden-2016", "--out", "o"],
    "study": ["study", "li-sunden-2016", "--out", "o"],
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
# the core's batch calls are cancelled, in-process


def _sigint_soon(delay_s: float) -> threading.Timer:
    timer = threading.Timer(delay_s, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_ctrl_c_cancels_a_launch_batch():
    """A Ctrl-C during `_core.launch_runs` raises KeyboardInterrupt from the call itself: the
    batch (far longer than the delay) does not run to its end first, as it did before."""
    veh = load_vehicle(None)
    spec = dynamic_model(veh.converter, "quasi-dynamic").spec
    runs = None
    timer = _sigint_soon(0.2)
    try:
        with pytest.raises(KeyboardInterrupt):
            runs = _core.launch_runs([spec] * N_RUNS, veh.core, flip_flop().core_spec(), None, 0)
    finally:
        timer.cancel()
    assert runs is None


def test_sigterm_handler_of_main_cancels_a_batch():
    """The exception of a Python SIGTERM handler (as ``tcsim.cli.main`` installs) ends the batch too."""
    from tcsim.cli.app import Interrupted, _sigterm_raises

    veh = load_vehicle(None)
    spec = dynamic_model(veh.converter, "quasi-dynamic").spec
    runs, before = None, signal.getsignal(signal.SIGTERM)
    with _sigterm_raises():
        timer = threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGTERM))
        timer.start()
        try:
            with pytest.raises(Interrupted) as e:
                runs = _core.launch_runs([spec] * N_RUNS, veh.core, flip_flop().core_spec(), None, 0)
        finally:
            timer.cancel()
    assert runs is None and e.value.signum == signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) == before  # the previous handler is back
