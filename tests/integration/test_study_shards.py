"""The Appendix D study in chunks written as Parquet shards (``tcsim study --chunk-size``,
:mod:`tcsim.io.shards`): identical to the unchunked study, resumable without recomputing or losing a
finished chunk, refusing another study's directory, interrupted cleanly, and on a dask cluster whose
worker and client die mid-study."""

from __future__ import annotations

import fcntl
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from interrupts import ClientStopped
from tcsim.analysis.chunked import appendix_d_study
from tcsim.analysis.study import COLUMNS, default_definition, run_study
from tcsim.errors import InputError
from tcsim.io.shards import MANIFEST, SHARDS, read_shards, run_to_shards, shard_name
from tcsim.models.converter import load_converter
from tcsim.units import RAD_S_PER_RPM

HANG_GUARD_S = 600  # a hang guard only; nothing is asserted about durations
POLL_S = 0.005
#: 15 parameters × 21 or 22 values: 324 cases of li-sunden-2016, 19 points each.
VALUES = 20


@pytest.fixture(scope="module")
def conv():
    return load_converter("li-sunden-2016")


@pytest.fixture(scope="module")
def definition():
    return default_definition().replace(values_per_parameter=VALUES)


@pytest.fixture(scope="module")
def unchunked(conv, definition):
    return run_study(conv, definition)


@pytest.fixture(scope="module")
def study(conv, definition):
    return appendix_d_study(conv, definition)


def snapshot(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def listed(out: Path) -> dict[str, dict]:
    return json.loads((out / MANIFEST).read_text())["chunks"]


# --------------------------------------------------------------------------------------------
# chunked = unchunked


@pytest.mark.parametrize("chunk_size", [1, 7, 50, 100_000])
def test_shards_in_order_are_the_unchunked_study_bit_for_bit(tmp_path, study, unchunked, chunk_size):
    run = run_to_shards(study, tmp_path / "s", chunk_size)
    n_chunks = -(-study.n_cases // chunk_size)
    assert run.computed == list(range(n_chunks)) and run.kept == []
    assert run.rows == len(unchunked) == study.n_cases * 19
    df = read_shards(tmp_path / "s")
    assert list(df.columns) == COLUMNS
    pd.testing.assert_frame_equal(df, unchunked, check_exact=True)
    shards = sorted(p.name for p in (tmp_path / "s" / SHARDS).iterdir())
    assert shards == [shard_name(i) for i in range(n_chunks)]


def test_speed_unit_applies_to_the_shards(tmp_path, study, unchunked):
    run_to_shards(study, tmp_path / "s", 40, speed_unit="rpm")
    df = read_shards(tmp_path / "s")
    assert "stator_speed_rpm" in df.columns and "stator_speed_rad_s" not in df.columns
    expected = unchunked["stator_speed_rad_s"] / RAD_S_PER_RPM
    pd.testing.assert_series_equal(df["stator_speed_rpm"], expected, check_names=False, check_exact=True)


# --------------------------------------------------------------------------------------------
# resuming


def test_rerun_of_a_complete_study_computes_nothing_and_changes_nothing(tmp_path, study):
    out = tmp_path / "s"
    run_to_shards(study, out, 30)
    before = snapshot(out)
    run = run_to_shards(study, out, 30)
    assert run.computed == [] and run.kept == list(range(run.n_chunks))
    assert snapshot(out) == before


def test_resume_computes_only_the_missing_changed_and_unlisted_chunks(tmp_path, study, unchunked):
    out = tmp_path / "s"
    first = run_to_shards(study, out, 30)
    shards = out / SHARDS
    (shards / shard_name(2)).unlink()  # missing
    with open(shards / shard_name(5), "r+b") as f:  # corrupt, same size
        f.seek(100)
        byte = f.read(1)
        f.seek(100)
        f.write(bytes([byte[0] ^ 0xFF]))
    manifest = json.loads((out / MANIFEST).read_text())
    del manifest["chunks"]["7"]  # written, but not listed (as after a crash between the two)
    (out / MANIFEST).write_text(json.dumps(manifest))
    (shards / ".part-00009.parquet.abc.partial").write_bytes(b"half")  # a killed run's temporary file
    redone = {f"{SHARDS}/{shard_name(i)}" for i in (2, 5, 7)}
    untouched = {n: b for n, b in snapshot(out).items() if n.endswith(".parquet") and n not in redone}
    assert len(untouched) == first.n_chunks - 3
    seen: list[int] = []
    run = run_to_shards(study, out, 30, on_chunk=seen.append)
    assert sorted(run.computed) == sorted(seen) == [2, 5, 7]
    assert run.kept == [i for i in range(first.n_chunks) if i not in (2, 5, 7)]
    assert not list(shards.glob("*.partial"))
    after = snapshot(out)
    assert all(after[n] == b for n, b in untouched.items())  # a finished chunk is never rewritten
    pd.testing.assert_frame_equal(read_shards(out), unchunked, check_exact=True)


def test_read_shards_refuses_an_incomplete_study(tmp_path, study):
    out = tmp_path / "s"
    run_to_shards(study, out, 30)
    (out / SHARDS / shard_name(3)).unlink()
    with pytest.raises(Exception, match="1 of 11 chunks missing or changed, e.g. chunk 3"):
        read_shards(out)


# --------------------------------------------------------------------------------------------
# refusals: exit 2, one line, the directory unchanged


def _refused(cli, out: Path, *args: str) -> str:
    before = snapshot(out)
    r = cli("study", "li-sunden-2016", "--out", out, *args)
    assert r.code == 2, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and r.stderr.startswith("error: command line: ")
    assert snapshot(out) == before
    return r.stderr


@pytest.fixture
def study_dir(cli, tmp_path):
    out = tmp_path / "s"
    r = cli("study", "li-sunden-2016", "--out", out, "--chunk-size", "10", "--values-per-parameter", "3")
    assert r.code == 0, r.stderr
    assert "51 cases, 969 points in 6 chunks of 10 cases (6 computed, 0 kept from an earlier run)" in r.stdout
    return out


def test_another_definition_in_the_directory_is_refused(cli, study_dir):
    err = _refused(cli, study_dir, "--chunk-size", "10", "--values-per-parameter", "4")
    assert "--out" in err and "it holds another study" in err
    assert "values_per_parameter = 3 there, 4 here" in err  # which setting differs, not only hashes
    err = _refused(cli, study_dir, "--chunk-size", "10", "--values-per-parameter", "3", "--speed-unit", "rpm")
    assert "it holds another study" in err and "speed_unit = 'rad/s' there, 'rpm' here" in err


def test_another_chunk_size_is_refused(cli, study_dir):
    err = _refused(cli, study_dir, "--chunk-size", "11", "--values-per-parameter", "3")
    assert "--chunk-size = 11: expected 10, the chunk size of the study in" in err


def test_a_directory_with_other_files_is_refused(cli, study_dir):
    (study_dir / "notes.txt").write_text("mine")
    err = _refused(cli, study_dir, "--chunk-size", "10", "--values-per-parameter", "3")
    assert "'notes.txt'" in err


def test_the_shards_and_the_manifest_have_the_mode_of_any_output(study_dir):
    """Trial finding: they were private (0600, from mkstemp), unlike every other output (the umask)."""
    mask = os.umask(0o022)
    os.umask(mask)
    files = [study_dir / MANIFEST, *(study_dir / SHARDS).iterdir()]
    assert len(files) == 7
    for f in files:
        assert f.stat().st_mode & 0o777 == 0o666 & ~mask, (f, oct(f.stat().st_mode))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("{not json", "a manifest.json that is not valid JSON"),
        ('{"format": "something else"}', "a manifest.json that is not a tcsim study's"),
    ],
)
def test_a_broken_manifest_is_named_as_such(cli, study_dir, text, expected):
    """Trial finding: a corrupt manifest was reported as "no manifest; choose another --out", which
    tells the user to give up the finished shards."""
    (study_dir / MANIFEST).write_text(text)
    err = _refused(cli, study_dir, "--chunk-size", "10", "--values-per-parameter", "3")
    assert expected in err, err
    with pytest.raises(InputError, match=expected.replace("'", ".")):
        read_shards(study_dir)


def test_a_study_another_run_is_writing_is_refused(cli, study_dir):
    fd = os.open(study_dir, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        err = _refused(cli, study_dir, "--chunk-size", "10", "--values-per-parameter", "3")
        assert "no other tcsim run is writing to" in err
    finally:
        os.close(fd)


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--chunk-size", "0"], "--chunk-size = 0: expected an integer from 1 to 1000000"),
        (["--chunk-size", "1", "--values-per-parameter", "1000"], "--chunk-size = 1: expected at least 2"),
        (["--scheduler", "local"], "--scheduler = 'local': expected to be given with --chunk-size"),
        (["--chunk-size", "5", "--workers", "2"], "--workers = 2: expected 1 to 1024 workers, with --scheduler local"),
        (["--values-per-parameter", "1001"], "expected an integer from 1 to 1000 without --chunk-size"),
    ],
)
def test_bad_options_are_exit_2_and_write_nothing(cli, tmp_path, args, expected):
    r = cli("study", "li-sunden-2016", "--out", tmp_path / "s", *args)
    assert r.code == 2 and expected in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "s").exists()


# --------------------------------------------------------------------------------------------
# interrupted


@pytest.mark.subprocess
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_an_interrupted_study_keeps_its_finished_shards_and_resumes(tmp_path, sig, conv):
    args = ["study", "li-sunden-2016", "--out", "o", "--chunk-size", "10", "--values-per-parameter", "300"]
    env = dict(os.environ, COLUMNS="200")
    p = subprocess.Popen(
        [sys.executable, "-m", "tcsim", *args], cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    out = tmp_path / "o"
    try:
        while not ((out / MANIFEST).is_file() and len(listed(out)) >= 3):
            assert p.poll() is None, p.communicate()
            time.sleep(POLL_S)
        p.send_signal(sig)
        stdout, stderr = p.communicate(timeout=HANG_GUARD_S)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert p.returncode == 128 + sig, stderr
    lines = stderr.decode().strip().splitlines()
    assert lines == [f"interrupted ({sig.name}): the finished chunks in o are kept; run it again to resume"]
    done = listed(out)
    n_chunks = json.loads((out / MANIFEST).read_text())["n_chunks"]
    assert 3 <= len(done) < n_chunks
    assert sorted(p.name for p in (out / SHARDS).iterdir()) == sorted(shard_name(int(i)) for i in done)
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, SHARDS]  # no temporary file anywhere
    seen: list[int] = []
    definition = default_definition().replace(values_per_parameter=300)
    run_to_shards(appendix_d_study(conv, definition), out, 10, on_chunk=seen.append)
    assert sorted(seen) == [i for i in range(n_chunks) if str(i) not in done]
    pd.testing.assert_frame_equal(read_shards(out), run_study(conv, definition), check_exact=True)


# --------------------------------------------------------------------------------------------
# on a dask cluster (the optional extra tcsim[dask])


@pytest.mark.subprocess
def test_dask_chunks_are_the_unchunked_study_bit_for_bit(tmp_path, cluster, study, unchunked):
    run = run_to_shards(study, tmp_path / "s", 13, scheduler=cluster.scheduler_address)
    assert sorted(run.computed) == list(range(run.n_chunks))
    pd.testing.assert_frame_equal(read_shards(tmp_path / "s"), unchunked, check_exact=True)


@pytest.mark.subprocess
def test_a_study_whose_worker_and_then_client_die_resumes_to_the_uninterrupted_result(
    tmp_path, cluster, study, unchunked
):
    """Acceptance (issue 16): kill one of the two workers mid-study (SIGKILL of its process), then
    stop the client; the rerun computes only the chunks not yet written and gives the same rows."""
    distributed = pytest.importorskip("distributed")
    with distributed.Client(cluster.scheduler_address, set_as_default=False) as client:
        pids = client.run(os.getpid)
    victim = sorted(pids.values())[0]
    out = tmp_path / "s"
    written: list[int] = []

    def hook(index: int) -> None:
        written.append(index)
        if len(written) == 3:  # chunks are still in flight (two per worker are submitted at a time)
            os.kill(victim, signal.SIGKILL)
        if len(written) == 12:
            raise ClientStopped

    with pytest.raises(ClientStopped):
        run_to_shards(study, out, 10, scheduler=cluster.scheduler_address, on_chunk=hook)
    done = sorted(int(i) for i in listed(out))
    assert done == sorted(written) and len(done) == 12
    assert not list((out / SHARDS).glob("*.partial"))
    run = run_to_shards(study, out, 10, scheduler=cluster.scheduler_address)
    assert run.kept == done  # never recomputed
    assert sorted(run.computed) == [i for i in range(run.n_chunks) if i not in done]
    pd.testing.assert_frame_equal(read_shards(out), unchunked, check_exact=True)
    with distributed.Client(cluster.scheduler_address, set_as_default=False) as client:
        assert victim not in client.run(os.getpid).values()  # the worker was killed (the nanny started another)


@pytest.mark.subprocess
def test_the_command_line_on_a_local_cluster(cli, tmp_path, conv):
    pytest.importorskip("distributed")
    args = ["--chunk-size", "10", "--values-per-parameter", "3", "--scheduler", "local", "--workers", "2"]
    r = cli("study", "li-sunden-2016", "--out", tmp_path / "s", *args)
    assert r.code == 0, r.stderr
    assert "51 cases, 969 points in 6 chunks of 10 cases (6 computed, 0 kept" in r.stdout
    expected = run_study(conv, default_definition().replace(values_per_parameter=3))
    pd.testing.assert_frame_equal(read_shards(tmp_path / "s"), expected, check_exact=True)
