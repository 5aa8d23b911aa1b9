"""Where ``export-fmu`` takes the FMU library and its sources from (``tcsim.io.fmu``), and how the
build backend adds them to the wheel (``tools/build_backend/tcsim_backend.py``).

The order is ``$TCSIM_FMU_LIBRARY``, the library installed with the package (``tcsim/_fmu/``), then
the source tree's ``target/``; the sources follow the package first as well. The installed
directory is replaced here by a temporary one (``packaged_dir``), so no wheel is needed.
"""

from __future__ import annotations

import base64
import csv
import hashlib
import importlib.util
import io
import os
import zipfile
from pathlib import Path

import pytest

from tcsim.io import fmu as tfmu
from tcsim.io import fmu_sources

REPO = Path(__file__).resolve().parents[2]
LIBRARY = tfmu._local_library_file()


@pytest.fixture
def installed(tmp_path, monkeypatch) -> Path:
    """A stand-in for ``tcsim/_fmu/`` of an installed wheel: a library file and its sources."""
    d = tmp_path / "site" / "tcsim" / "_fmu"
    (d / "sources").mkdir(parents=True)
    (d / LIBRARY).write_bytes(b"\x7fELF packaged")
    (d / "sources" / "Cargo.lock").write_text("# the packaged lock\n")
    monkeypatch.setattr(tfmu, "packaged_dir", lambda: d)
    monkeypatch.delenv(tfmu.LIBRARY_ENV, raising=False)
    return d


def test_installed_library_comes_before_the_source_tree(installed, tmp_path, monkeypatch):
    tree = tmp_path / "tree"
    (tree / "crates" / "tcsim-fmu").mkdir(parents=True)
    (tree / "Cargo.toml").write_text("[workspace]\n")
    (tree / "crates" / "tcsim-fmu" / "Cargo.toml").write_text("[package]\n")
    (tree / "target" / "release").mkdir(parents=True)
    (tree / "target" / "release" / LIBRARY).write_bytes(b"built in the tree")
    monkeypatch.setattr(tfmu, "source_root", lambda: tree)
    assert tfmu.find_libraries(build=False) == [installed / LIBRARY]
    (installed / LIBRARY).unlink()  # a source checkout: the tree's build
    assert tfmu.find_libraries(build=False) == [tree / "target" / "release" / LIBRARY]


def test_environment_variable_comes_before_the_installed_library(installed, tmp_path, monkeypatch):
    own = tmp_path / "own" / LIBRARY
    own.parent.mkdir()
    own.write_bytes(b"mine")
    monkeypatch.setenv(tfmu.LIBRARY_ENV, str(own))
    assert tfmu.find_libraries(build=False) == [own]


def test_no_library_anywhere_names_every_way_out(installed, monkeypatch):
    (installed / LIBRARY).unlink()
    monkeypatch.setattr(tfmu, "source_root", lambda: None)
    with pytest.raises(tfmu.FmuLibraryError) as e:
        tfmu.find_libraries()
    assert all(s in str(e.value) for s in (tfmu.LIBRARY_ENV, "pip install", "cargo build --release -p tcsim-fmu"))


def test_sources_come_from_the_package_when_it_carries_them(installed, tmp_path):
    dest = tmp_path / "fmu" / "sources"
    tfmu._write_sources(REPO, dest)
    assert (dest / "Cargo.lock").read_text() == "# the packaged lock\n"
    assert "cargo build --release -p tcsim-fmu" in (dest / "README.md").read_text()


def test_sources_of_the_tree_hold_the_two_crates_only(tmp_path):
    dest = tmp_path / "sources"
    fmu_sources.copy_rust_sources(REPO, dest)
    assert sorted(p.name for p in (dest / "crates").iterdir()) == ["tcsim-core", "tcsim-fmu"]
    assert 'members = ["crates/tcsim-core", "crates/tcsim-fmu"]' in (dest / "Cargo.toml").read_text()
    assert (dest / "crates" / "tcsim-fmu" / "src" / "lib.rs").is_file() and (dest / "Cargo.lock").is_file()


def _backend():
    pytest.importorskip("maturin")
    path = REPO / "tools" / "build_backend" / "tcsim_backend.py"
    spec = importlib.util.spec_from_file_location("_tcsim_backend_under_test", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_files_added_to_a_wheel_are_in_its_record(tmp_path):
    """Each added file has its SHA-256 and size in RECORD; RECORD stays last and without a hash."""
    wheel = tmp_path / "demo-1.0-py3-none-any.whl"
    with zipfile.ZipFile(wheel, "w") as zf:
        zf.writestr("demo/__init__.py", "")
        zf.writestr("demo-1.0.dist-info/RECORD", "demo/__init__.py,sha256=x,0\ndemo-1.0.dist-info/RECORD,,\n")
    lib = tmp_path / "libdemo.so"
    lib.write_bytes(b"\x7fELF" + bytes(range(256)))
    _backend().add_to_wheel(wheel, {"demo/_fmu/libdemo.so": lib})
    with zipfile.ZipFile(wheel) as zf:
        rows = list(csv.reader(io.StringIO(zf.read("demo-1.0.dist-info/RECORD").decode())))
        data = zf.read("demo/_fmu/libdemo.so")
        mode = zf.getinfo("demo/_fmu/libdemo.so").external_attr >> 16
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    assert data == lib.read_bytes() and mode == 0o755
    assert ["demo/_fmu/libdemo.so", f"sha256={digest}", str(len(data))] in rows
    assert rows[-1] == ["demo-1.0.dist-info/RECORD", "", ""] and rows[0][0] == "demo/__init__.py"
    assert not list(tmp_path.glob("*.part"))


def test_build_progress_counts_cargo_crates_and_copies_stderr_unchanged(tmp_path):
    """The build backend's progress line (issue 16 item 8): every line cargo writes reaches the real
    standard error unchanged (pip -v and a failed build's log lose nothing), and each ``Compiling``
    line advances the count on the terminal."""
    backend = _backend()
    assert backend.compiled_crate("   Compiling nalgebra v0.33.2") == "nalgebra"
    assert backend.compiled_crate("   Compiling tcsim-core v0.1.0 (/src/crates/tcsim-core)") == "tcsim-core"
    assert backend.compiled_crate("    Finished `release` profile [optimized] target(s) in 3.2s") is None
    assert backend.compiled_crate("warning: Compiling is a word") is None
    lines = [
        b"   Compiling libc v0.2.170\n",
        b"warning: unused \xff byte\n",
        b"   Compiling tcsim-core v0.1.0 (/src)\n",
        b"    Finished release\n",
    ]
    read_fd, write_fd = os.pipe()
    os.write(write_fd, b"".join(lines))
    os.close(write_fd)
    copy = tmp_path / "stderr"
    tty = io.StringIO()
    with open(copy, "wb") as out:
        backend._relay(read_fd, out.fileno(), tty)
    assert copy.read_bytes() == b"".join(lines)
    shown = tty.getvalue().split("\r\x1b[K")[1:]
    assert len(shown) == 2 and all(s.startswith("tcsim build: ") and len(s) <= 79 for s in shown), shown
    assert shown[0].startswith("tcsim build: 1 crates, 0:00") and shown[0].endswith(": libc")
    assert shown[1].startswith("tcsim build: 2 crates") and backend.FIRST_BUILD_NOTE in shown[1]


def test_build_progress_changes_nothing_without_a_terminal(monkeypatch):
    """Without a terminal (CI, a pipe) the backend leaves standard error as it is."""
    backend = _backend()
    monkeypatch.setattr(backend, "_terminal", lambda: None)
    before = os.fstat(2)
    with backend.build_progress():
        during = os.fstat(2)
    assert (during.st_ino, during.st_dev) == (before.st_ino, before.st_dev)
