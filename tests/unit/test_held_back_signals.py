"""``tcsim.io.outputs._blocked``: SIGINT and SIGTERM held back while the block runs, also when the
kernel gives the signal to a thread other than the main one (as on a loaded machine, where the
core's workers and BLAS threads exist), and acted on as their handler would when the block ends."""

from __future__ import annotations

import os
import select
import signal
import threading
from collections.abc import Iterator

import pyarrow as pa
import pytest

from tcsim.io import shards
from tcsim.io.outputs import _blocked


@pytest.fixture
def land() -> Iterator:
    """``land(sig)``: the signal handled by another thread's C handler (Python then runs the handler
    in the main thread at its next bytecode); returns once that C handler has run (``wait``)."""
    stop = threading.Event()
    bystander = threading.Thread(target=stop.wait, daemon=True)
    bystander.start()
    r, w = os.pipe()
    os.set_blocking(w, False)
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    # Ctrl-C as a terminal has it: a runner started in the background (CI under `nohup ... &`, a
    # shell without job control) inherits SIGINT ignored, and an ignored signal stays ignored
    signal.signal(signal.SIGINT, signal.default_int_handler)

    def send(sig: signal.Signals, wait: bool = True) -> None:
        old = signal.set_wakeup_fd(w)
        try:
            assert bystander.ident is not None
            signal.pthread_kill(bystander.ident, sig)
            if wait:
                select.select([r], [], [])
                os.read(r, 1)
        finally:
            signal.set_wakeup_fd(old)

    try:
        yield send
    finally:
        stop.set()
        bystander.join()
        os.close(r)
        os.close(w)
        for s, h in handlers.items():
            signal.signal(s, h)


def _raise(signum, frame):
    raise KeyboardInterrupt(signal.Signals(signum).name)


def test_a_signal_landing_in_the_block_is_raised_when_it_ends(land):
    signal.signal(signal.SIGTERM, _raise)
    steps = []
    with pytest.raises(KeyboardInterrupt, match="SIGTERM"), _blocked():
        land(signal.SIGTERM)
        steps.append("the rest of the block")  # bytecodes after the landing: the handler ran before
    assert steps == ["the rest of the block"]
    assert signal.getsignal(signal.SIGTERM) is _raise  # the handler is put back


def test_nested_blocks_raise_once_at_the_outer_end(land):
    steps = []
    with pytest.raises(KeyboardInterrupt), _blocked():
        with _blocked():
            land(signal.SIGINT)
            steps.append("inner")
        steps.append("outer")
    assert steps == ["inner", "outer"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_held_signal_that_was_ignored_stays_ignored(land):
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    with _blocked():
        land(signal.SIGTERM, wait=False)  # an ignored signal runs no C handler where nothing holds it
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_IGN


def test_a_shard_interrupted_as_its_file_is_made_leaves_no_partial_file(land, tmp_path, monkeypatch):
    """``tcsim.io.shards._store``: a signal held back while the temporary shard is made raises when that
    block ends; the clean-up must already cover the file (its ``try`` opened before the file exists)."""
    (tmp_path / shards.SHARDS).mkdir()
    made = []
    real = shards.tempfile.mkstemp

    def mkstemp_then_signal(*args, **kwargs):
        fd, name = real(*args, **kwargs)
        made.append(name)
        land(signal.SIGINT)  # inside the held-back block that made the file
        return fd, name

    monkeypatch.setattr(shards.tempfile, "mkstemp", mkstemp_then_signal)
    manifest = {"columns": None, "chunks": {}}
    with pytest.raises(KeyboardInterrupt):
        shards._store(tmp_path, manifest, 0, pa.table({"x": [1.0, 2.0]}))
    assert made and os.listdir(tmp_path / shards.SHARDS) == []
    assert manifest["chunks"] == {}
