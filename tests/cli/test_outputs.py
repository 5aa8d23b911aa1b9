"""The output-directory rule (tcsim.io.outputs, docs/guarantees.md): created whole, replaces only an
empty directory or an unchanged earlier tcsim output, never a folder holding other files, never an
input of the same run; two runs into the same directory at once never mix."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import threading
import zipfile
from pathlib import Path

import pandas as pd
import pytest

import tcsim.models.steady as steady
from conftest import TABLE_C1
from tcsim.errors import InputError
from tcsim.io import fmu as fmu_io
from tcsim.io import outputs
from tcsim.io.outputs import MANIFEST, output_dir
from tcsim.units import RAD_S_PER_RPM


def snapshot(root: Path) -> dict[str, bytes]:
    """Every file below ``root`` with its bytes."""
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def assert_refused(r, *fragments: str) -> None:
    assert r.code == 2, (r.code, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: command line: --out = "), r.stderr
    for f in fragments:
        assert f in lines[0], (f, lines[0])


def assert_manifest_consistent(out: Path) -> dict:
    """``out`` holds exactly the files its manifest lists, with their sizes and SHA-256."""
    doc = json.loads((out / MANIFEST).read_text())
    listed = {f["name"]: f for f in doc["files"]}
    present = {k for k in snapshot(out) if k != MANIFEST}
    assert present == set(listed), present ^ set(listed)
    for name, entry in listed.items():
        data = (out / name).read_bytes()
        assert (len(data), hashlib.sha256(data).hexdigest()) == (entry["size"], entry["sha256"]), name
    return doc


def no_staging_left(parent: Path) -> None:
    left = [p.name for p in parent.iterdir() if p.name.endswith((".partial", ".old"))]
    assert left == [], left


# ---------------------------------------------------------------------------------------------
# never an input of the run


def test_characterise_into_the_folder_of_its_own_table_is_refused(cli, tmp_path):
    """Defect 4: `tcsim characterise characteristic.csv --out .` replaced the user's table (exit 0)."""
    shutil.copy(TABLE_C1, tmp_path / "characteristic.csv")
    before = snapshot(tmp_path)
    r = cli("characterise", "characteristic.csv", "--out", ".", cwd=tmp_path)
    assert_refused(r, "'.'", "no input of this run", "'characteristic.csv'")
    assert snapshot(tmp_path) == before


def test_an_output_folder_that_contains_an_input_deeper_down_is_refused(cli, tmp_path):
    (tmp_path / "data").mkdir()
    shutil.copy(TABLE_C1, tmp_path / "data" / "c1.csv")
    before = snapshot(tmp_path)
    r = cli("characterise", tmp_path / "data" / "c1.csv", "--out", tmp_path)
    assert_refused(r, "no input of this run", "c1.csv")
    assert snapshot(tmp_path) == before


def test_out_naming_the_input_file_is_refused(cli, tmp_path):
    shutil.copy(TABLE_C1, tmp_path / "c1.csv")
    before = snapshot(tmp_path)
    r = cli("characterise", "c1.csv", "--out", "c1.csv", cwd=tmp_path)
    assert_refused(r, "a directory, not an input file of this run")
    assert snapshot(tmp_path) == before


def test_fit_target_inside_out_is_refused(cli, tmp_path):
    """A table called table.csv next to the run's output (here `fit --target table.csv --out .`)."""
    shutil.copy(TABLE_C1, tmp_path / "table.csv")
    before = snapshot(tmp_path)
    r = cli("fit", "li-sunden-2016", "--target", "table.csv", "--out", ".", cwd=tmp_path)
    assert_refused(r, "'table.csv'")
    assert snapshot(tmp_path) == before


# ---------------------------------------------------------------------------------------------
# what may be replaced


def test_a_folder_holding_other_files_is_refused_before_the_compute(cli, tmp_path, monkeypatch):
    out = tmp_path / "o"
    out.mkdir()
    for name in ("notes.txt", "a.csv", "b.csv"):
        (out / name).write_text("mine\n")
    before = snapshot(tmp_path)

    def no_compute(*args, **kwargs):
        raise AssertionError("the compute ran although --out is refused")

    monkeypatch.setattr("tcsim.models.steady.characterise", no_compute)
    r = cli("characterise", "li-sunden-2016", "--out", out)
    assert_refused(r, "3 files tcsim did not write", "'a.csv', 'b.csv' and 1 more", "choose another --out")
    assert snapshot(tmp_path) == before


def test_out_that_is_a_file_is_refused(cli, tmp_path):
    (tmp_path / "o").write_text("mine\n")
    r = cli("characterise", "li-sunden-2016", "--out", tmp_path / "o")
    assert_refused(r, "a file of that name exists")
    assert (tmp_path / "o").read_text() == "mine\n"


def test_missing_parents_are_created_and_an_empty_folder_is_replaced(cli, tmp_path):
    r = cli("characterise", "li-sunden-2016", "--out", tmp_path / "a" / "b" / "o")
    assert r.code == 0, r.stderr
    doc = assert_manifest_consistent(tmp_path / "a" / "b" / "o")
    assert doc["command"][:2] == ["tcsim", "characterise"] and doc["tcsim"]
    (tmp_path / "empty").mkdir()
    assert cli("characterise", "li-sunden-2016", "--out", tmp_path / "empty").code == 0
    assert_manifest_consistent(tmp_path / "empty")
    no_staging_left(tmp_path)


def test_an_earlier_output_is_replaced_whole(cli, tmp_path):
    """Defect 4: files of an earlier run stayed beside the new ones."""
    out = tmp_path / "o"
    with output_dir(out) as stage:
        (stage / "old.csv").write_text("old\n")
        (stage / "shared.csv").write_text("old\n")
    assert_manifest_consistent(out)
    with output_dir(out) as stage:
        (stage / "shared.csv").write_text("new\n")
    assert snapshot(out).keys() == {"shared.csv", MANIFEST}
    assert (out / "shared.csv").read_text() == "new\n"
    assert_manifest_consistent(out)
    (out / "stale.csv").write_text("x\n")  # not the earlier output any more: refused
    assert_refused(cli("characterise", "li-sunden-2016", "--out", out), "'stale.csv' (not in the manifest)")
    (out / "stale.csv").unlink()
    assert cli("characterise", "li-sunden-2016", "--out", out).code == 0
    doc = assert_manifest_consistent(out)
    assert "shared.csv" not in snapshot(out) and doc["command"][:2] == ["tcsim", "characterise"]
    no_staging_left(tmp_path)


def test_replacing_the_output_of_another_command_warns_and_of_the_same_command_does_not(cli, tmp_path):
    # fresh-eyes trial: a launch into a drive's folder replaced it without a word
    out = tmp_path / "o"
    assert cli("characterise", "li-sunden-2016", "--out", out, "--no-plots").code == 0
    again = cli("characterise", "li-sunden-2016", "--out", out, "--no-plots")
    assert again.code == 0 and "the output of an earlier" not in again.stderr, again.stderr
    other = cli("design", "li-sunden-2016-design", "--out", out, "--no-plots")
    assert other.code == 0, other.stderr
    warned = [line for line in other.stderr.splitlines() if "the output of an earlier" in line]
    earlier = f"tcsim characterise li-sunden-2016 --out {out} --no-plots"
    assert warned == [f"warning: {out}/: replaced the output of an earlier `{earlier}`"]
    assert json.loads((out / MANIFEST).read_text())["command"][1] == "design"
    with output_dir(out) as stage:  # the Python API: no command line, no warning (pytest's argv)
        (stage / "a.csv").write_text("a\n")
    assert (out / "a.csv").is_file()


def test_an_earlier_output_with_a_changed_file_is_refused(cli, tmp_path):
    out = tmp_path / "o"
    assert cli("characterise", "li-sunden-2016", "--out", out).code == 0
    with open(out / "characteristic.csv", "a") as f:
        f.write("# my note\n")
    before = snapshot(tmp_path)
    r = cli("characterise", "li-sunden-2016", "--out", out)
    assert_refused(r, "an earlier tcsim output with 1 file changed since", "'characteristic.csv' (changed)")
    assert snapshot(tmp_path) == before
    # a file added and a file changed: both counted (the trial saw only the added one named)
    (out / "x.fmu").write_bytes(b"PK")
    r = cli("characterise", "li-sunden-2016", "--out", out)
    assert_refused(r, "2 files changed since", "'characteristic.csv' (changed)", "'x.fmu' (not in the manifest)")


def test_the_rule_is_checked_again_after_the_compute(cli, tmp_path, monkeypatch):
    """A file that appears in --out during the compute: refused before writing, nothing written."""
    out = tmp_path / "o"
    run = steady.characterise

    def compute_while_someone_writes(*args, **kwargs):
        out.mkdir()
        (out / "theirs.txt").write_text("theirs\n")
        return run(*args, **kwargs)

    monkeypatch.setattr(steady, "characterise", compute_while_someone_writes)
    r = cli("characterise", "li-sunden-2016", "--out", out)
    assert_refused(r, "'theirs.txt'")
    assert snapshot(tmp_path) == {"o/theirs.txt": b"theirs\n"}
    no_staging_left(tmp_path)


def test_the_rule_is_checked_again_at_the_commit(tmp_path):
    out = tmp_path / "o"
    with pytest.raises(InputError, match="'theirs.txt'"), output_dir(out) as stage:
        (stage / "ours.csv").write_text("1\n")
        out.mkdir()
        (out / "theirs.txt").write_text("theirs\n")
    assert snapshot(tmp_path) == {"o/theirs.txt": b"theirs\n"}


def test_a_failed_run_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError), output_dir(tmp_path / "new" / "o") as stage:
        (stage / "half.csv").write_text("1\n")
        raise RuntimeError("the run failed while writing")
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------------------------------------
# two runs at once


def _write_run(out: Path, tag: str, barrier: threading.Barrier, errors: list) -> None:
    try:
        with output_dir(out) as stage:
            for i in range(20):
                (stage / f"f{i}.txt").write_text(f"{tag} {i}\n")
            (stage / f"only_{tag}.txt").write_text(tag)
            barrier.wait(timeout=30)  # both runs are staged before either commits
    except Exception as e:  # a clear error is allowed; recorded and checked below
        errors.append(e)


def test_two_runs_into_the_same_folder_in_process_never_mix(tmp_path):
    out = tmp_path / "o"
    barrier, errors = threading.Barrier(2), []
    threads = [threading.Thread(target=_write_run, args=(out, tag, barrier, errors)) for tag in ("a", "b")]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert errors == []  # both complete, one after the other
    files = snapshot(out)
    tags = {name.removeprefix("only_").removesuffix(".txt") for name in files if name.startswith("only_")}
    assert len(tags) == 1, sorted(files)
    (tag,) = tags
    assert all(files[f"f{i}.txt"] == f"{tag} {i}\n".encode() for i in range(20))
    assert_manifest_consistent(out)
    no_staging_left(tmp_path)


@pytest.mark.subprocess
def test_two_processes_into_the_same_folder_never_mix(tmp_path):
    out = tmp_path / "o"
    env = dict(os.environ, COLUMNS="200")
    runs = [
        subprocess.Popen(
            [sys.executable, "-m", "tcsim", "characterise", "li-sunden-2016", "--pump-speed-rpm", rpm, "--out", out],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        for rpm in ("1000", "2000")
    ]
    results = [(p.wait(timeout=600), p.stderr.read() if p.stderr else "") for p in runs]
    for p in runs:
        for stream in (p.stdout, p.stderr):
            if stream:
                stream.close()
    codes = sorted(code for code, _ in results)
    assert codes in ([0, 0], [0, 2]), results
    for code, err in results:
        if code == 2:
            assert len(err.strip().splitlines()) == 1 and "--out" in err, err
    doc = assert_manifest_consistent(out)
    rpm = float(doc["command"][doc["command"].index("--pump-speed-rpm") + 1])
    pump = pd.read_csv(out / "characteristic.csv")["pump_speed_rad_s"]
    assert (pump == rpm * RAD_S_PER_RPM).all()  # the table is the run's whose manifest is there
    no_staging_left(tmp_path)


def test_manifest_module_state_is_per_run(cli, tmp_path):
    """The committed list that the interrupt message uses starts empty for every run."""
    assert cli("characterise", "li-sunden-2016", "--out", tmp_path / "o").code == 0
    assert outputs.committed == [tmp_path / "o"]
    assert cli("characterise", "li-sunden-2016", "--out", tmp_path / "o", "--model", "nope").code == 2
    assert outputs.committed == []


def test_a_bundled_name_is_not_an_input_file(cli, tmp_path):
    """`--out li-sunden-2016` twice: the converter argument names the bundled converter, not the
    earlier output directory of that name."""
    for _ in range(2):
        assert cli("characterise", "li-sunden-2016", "--out", "li-sunden-2016", cwd=tmp_path).code == 0
    assert_manifest_consistent(tmp_path / "li-sunden-2016")


# ---------------------------------------------------------------------------------------------
# export-fmu: one file


def test_export_fmu_replaces_only_an_fmu(cli, fmu_library, monkeypatch, tmp_path):
    monkeypatch.setenv(fmu_io.LIBRARY_ENV, str(fmu_library))
    mine = tmp_path / "mine.fmu"
    mine.write_text("not an FMU\n")
    r = cli("export-fmu", "li-sunden-2016", "--model", "table", "--out", mine)
    assert_refused(r, "the file is not an FMU")
    assert mine.read_text() == "not an FMU\n"
    (tmp_path / "dir.fmu").mkdir()
    assert_refused(cli("export-fmu", "li-sunden-2016", "--model", "table", "--out", tmp_path / "dir.fmu"), "directory")
    out = tmp_path / "c.fmu"
    for _ in range(2):  # written, then replaced
        assert cli("export-fmu", "li-sunden-2016", "--model", "table", "--out", out).code == 0
        with zipfile.ZipFile(out) as zf:
            assert "modelDescription.xml" in zf.namelist()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.fmu", "dir.fmu", "mine.fmu"]


@pytest.mark.subprocess
def test_a_reader_that_closes_stdout_ends_what_is_shown_not_the_run(tmp_path):
    # fresh-eyes trial: `tcsim … | true` exited 1 without a word (click's EPIPE exit) after writing
    # the whole output, against "a run that exits with anything but 0 has written nothing"
    out = tmp_path / "o"
    command = [sys.executable, "-m", "tcsim", "characterise", "li-sunden-2016", "--out", str(out)]
    p = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=tmp_path)
    assert p.stdout is not None
    p.stdout.close()  # the reader leaves before the first line
    _, err = p.communicate(timeout=600)  # a hang guard only
    assert p.returncode == 0, err.decode()
    assert b"Traceback" not in err and b"failed" not in err and b"Exception ignored" not in err, err.decode()
    assert_manifest_consistent(out)
