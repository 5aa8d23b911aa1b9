"""Interrupting a ``tcsim`` command at a moment of its run (the interrupt tests of the CLI).

The moments are found by the run's phases, not by sleeping: "start" is when ``tcsim.cli.main`` has
installed its SIGTERM handler (Linux's /proc/PID/status), "writing" when the staging folder of the
output exists and its manifest does not yet. That second moment is checked with the process stopped
(SIGSTOP), and the signal is sent before it continues: on a loaded machine the run could otherwise
finish its writing between the poll that saw the staging folder and the signal (and then rightly
report its output as written completely). A run caught too late is let finish and started again."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import pytest

from tcsim.io.outputs import MANIFEST

HANG_GUARD_S = 600  # a hang guard only; nothing is asserted about durations
POLL_S = 0.005
ATTEMPTS = 5  # runs started for the "writing" moment before the test gives up


def _handles_sigterm(pid: int) -> bool:
    """Whether the process has a handler for SIGTERM (``SigCgt`` in /proc/PID/status)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    caught = next(line for line in status.splitlines() if line.startswith("SigCgt:")).split()[1]
    return bool(int(caught, 16) >> (signal.SIGTERM - 1) & 1)


def _stages(cwd: Path, out: str) -> list[Path]:
    return [p for p in cwd.iterdir() if p.name.startswith(f".{out}.") and p.name.endswith(".partial")]


def _still_writing(cwd: Path, out: str) -> bool:
    """A staging folder without its manifest (written last, just before the commit) and no output."""
    stages = _stages(cwd, out)
    return bool(stages) and not (cwd / out).exists() and not any((s / MANIFEST).exists() for s in stages)


PHASES = {"start": lambda p, cwd, out: _handles_sigterm(p.pid), "writing": lambda p, cwd, out: bool(_stages(cwd, out))}


#: A moment of a run: a name of :data:`PHASES`, or a test of the running process, its working
#: directory and its output directory's name (e.g. "two shards are listed").
Phase = str | Callable[[subprocess.Popen, Path, str], bool]


def interrupt(
    args: Sequence[str], sig: signal.Signals, phase: Phase, cwd: Path, out: str = "o"
) -> subprocess.CompletedProcess:
    """Run ``tcsim *args`` in ``cwd`` (its output directory ``out``), send ``sig`` when ``phase`` is
    reached, return what it did."""
    if phase == "start" and not Path("/proc/self/status").exists():
        pytest.skip("needs /proc to see the start of main()")
    for _ in range(ATTEMPTS):
        r = _interrupt_once(args, sig, phase, cwd, out)
        if r is not None:
            return r
        shutil.rmtree(cwd / out)  # the run finished its writing before it could be stopped: again
    pytest.fail(f"tcsim {args[0]}: {ATTEMPTS} runs wrote their output before they were caught writing it")


def _interrupt_once(
    args: Sequence[str], sig: signal.Signals, phase: Phase, cwd: Path, out: str
) -> subprocess.CompletedProcess | None:
    """One run of :func:`interrupt`; None if the run had passed the phase when it was stopped."""
    env = dict(os.environ, COLUMNS="200")
    cmd = [sys.executable, "-m", "tcsim", *args]
    p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    caught = True
    try:
        reached = PHASES[phase] if isinstance(phase, str) else phase
        while not reached(p, cwd, out):
            if p.poll() is not None:
                stdout, err = p.communicate()
                pytest.fail(f"tcsim {args[0]} ended (exit {p.returncode}) before its phase {phase!r}: {err}")
            time.sleep(POLL_S)
        if phase == "writing":
            p.send_signal(signal.SIGSTOP)  # stopped, the run cannot pass the moment while it is checked
            caught = _still_writing(cwd, out)
        if caught:
            p.send_signal(sig)  # pending until the run continues
        p.send_signal(signal.SIGCONT)
        stdout, err = p.communicate(timeout=HANG_GUARD_S)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    if not caught:
        assert p.returncode == 0, (p.returncode, err)
        return None
    return subprocess.CompletedProcess(p.args, p.returncode, stdout, err)


class ClientStopped(Exception):
    """Raised from a sharded study's ``on_chunk`` hook: the client stops mid-study as if killed."""


def stop_after(n: int, written: list[int]) -> Callable[[int], None]:
    """An ``on_chunk`` hook that records each chunk written in ``written`` and stops the client
    (:class:`ClientStopped`) after the ``n``-th."""

    def hook(index: int) -> None:
        written.append(index)
        if len(written) == n:
            raise ClientStopped

    return hook
