"""The PEP 517 build backend of tcsim: maturin's, plus the FMU library inside the wheel.

``pip install .``, ``pip wheel .`` and ``python -m build`` call :func:`build_wheel`. It lets maturin
build the wheel of the Python package and its extension ``tcsim._core`` (``crates/tcsim-py``), then
runs ``cargo build --release -p tcsim-fmu`` in the same target directory (the third-party crates
are compiled already; ``tcsim-core`` and ``tcsim-fmu`` are compiled in the FMU library's feature set,
which a later ``cargo build --release --workspace`` reuses for ``tcsim-core``) and adds to the wheel,
as package data of ``tcsim``:

* ``tcsim/_fmu/<library>``: the FMU library as cargo names it (``libtcsim_fmu.so`` on Linux,
  ``libtcsim_fmu.dylib`` on macOS, ``tcsim_fmu.dll`` on Windows), a ``cdylib`` that links no Python;
* ``tcsim/_fmu/sources/``: the Rust sources it was built from (``tcsim.io.fmu_sources``), which
  ``tcsim export-fmu`` puts into every FMU's ``sources/``.

So an installed tcsim exports FMUs without a source tree and without cargo. The wheel's ``RECORD``
gets a line (SHA-256, size) for each added file.

:func:`build_editable` (``pip install -e .``) builds the library too, but leaves it in
``target/release``: an editable install takes it from there, with the stale-library check of
:func:`tcsim.io.fmu.find_libraries`. ``maturin develop`` and ``maturin build`` do not go through
this backend: they build the extension only.

Every other hook is maturin's.
"""

from __future__ import annotations

import base64
import csv
import hashlib
import importlib.util
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import zipfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import maturin
from maturin import (  # noqa: F401  (the hooks this backend does not change)
    build_sdist,
    get_requires_for_build_editable,
    get_requires_for_build_sdist,
    get_requires_for_build_wheel,
    prepare_metadata_for_build_editable,
    prepare_metadata_for_build_wheel,
)

#: The source tree: this file is ``tools/build_backend/tcsim_backend.py`` in it.
ROOT = Path(__file__).resolve().parents[2]
#: The cargo package of the FMU library and the name of its library target.
FMU_PACKAGE, FMU_TARGET = "tcsim-fmu", "tcsim_fmu"
#: Suffixes of a shared library (the cdylib among cargo's artifacts; not ``.dll.lib`` or ``.pdb``).
LIBRARY_SUFFIXES = (".so", ".dylib", ".dll")


#: What a first build takes, said while it runs (measured: ``pip wheel .`` from an empty target
#: directory on the project's 2-core machine: 100 s, bench/README.md "Cold build").
FIRST_BUILD_NOTE = "first build ≈ 2 min on 2 cores"
#: A line of cargo's that says a crate is being compiled (``   Compiling nalgebra v0.33.2``).
_COMPILING = re.compile(r"^\s*Compiling (\S+) v\S+")


def compiled_crate(line: str) -> str | None:
    """The crate a line of cargo's output starts compiling, or None."""
    m = _COMPILING.match(line)
    return m.group(1) if m else None


def progress_text(crates: int, elapsed_s: float, crate: str = "") -> str:
    """The one-line progress shown on the terminal while cargo compiles (the crate last: a narrow
    terminal cuts it first)."""
    minutes, seconds = divmod(int(elapsed_s), 60)
    return f"tcsim build: {crates} crates, {minutes}:{seconds:02d} ({FIRST_BUILD_NOTE}): {crate}".rstrip(": ")


def _terminal():
    """The user's terminal for progress lines, or None: when ``pip`` shows the build's output
    itself (``-v``: stderr is a terminal), or there is no terminal (CI, a pipe)."""
    if os.isatty(2):
        return None
    try:
        return open("/dev/tty", "w", encoding="utf-8")  # noqa: SIM115  (closed by build_progress)
    except OSError:
        return None


def _relay(read_fd: int, stderr_fd: int, tty) -> None:
    """Copy every line from ``read_fd`` to ``stderr_fd`` unchanged; count cargo's ``Compiling``
    lines on ``tty``'s progress line."""
    start, crates = time.monotonic(), 0
    with os.fdopen(read_fd, "rb") as pipe:
        for raw in pipe:
            os.write(stderr_fd, raw)
            crate = compiled_crate(raw.decode("utf-8", "replace"))
            if crate is not None and tty is not None:
                crates += 1
                text = progress_text(crates, time.monotonic() - start, crate)
                tty.write("\r\x1b[K" + text[: max(20, shutil.get_terminal_size().columns - 1)])
                tty.flush()


@contextmanager
def build_progress() -> Iterator[None]:
    """While the body runs, a progress line on the user's terminal: pip hides a build backend's
    output unless ``-v``, and a first build compiles for minutes. Standard error (file descriptor
    2, which cargo inherits) goes through a pipe whose lines are copied to the real standard error
    unchanged, so ``pip -v`` and a failed build's log show everything as before. Without a terminal
    nothing changes but the copy."""
    tty = _terminal()
    if tty is None:
        yield
        return
    saved = os.dup(2)
    read_fd, write_fd = os.pipe()
    os.dup2(write_fd, 2)
    os.close(write_fd)
    relay = threading.Thread(target=_relay, args=(read_fd, saved, tty), daemon=True)
    relay.start()
    try:
        yield
    finally:
        sys.stderr.flush()
        os.dup2(saved, 2)  # closes the pipe's last write end: the relay reads to the end and stops
        relay.join(timeout=10)
        os.close(saved)
        tty.write("\r\x1b[K")
        tty.close()


def _fmu_sources():
    """``python/tcsim/io/fmu_sources.py``, loaded by its path (the ``tcsim`` package cannot be
    imported before its extension is built)."""
    path = ROOT / "python" / "tcsim" / "io" / "fmu_sources.py"
    spec = importlib.util.spec_from_file_location("_tcsim_fmu_sources", path)
    assert spec is not None and spec.loader is not None, path
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def build_fmu_library() -> Path:
    """``cargo build --release -p tcsim-fmu`` in the source tree; the library it made (the path
    cargo reports for the ``cdylib``, in whatever target directory cargo uses)."""
    cargo = shutil.which("cargo")
    if cargo is None:
        raise RuntimeError("cargo is not on PATH: building tcsim needs Rust 1.89 or newer (https://rustup.rs)")
    command = [cargo, "build", "--release", "-p", FMU_PACKAGE, "--message-format=json-render-diagnostics"]
    print(f"tcsim: building the FMU library: cargo build --release -p {FMU_PACKAGE}", file=sys.stderr, flush=True)
    start = time.monotonic()
    p = subprocess.run(command, cwd=ROOT, stdout=subprocess.PIPE, text=True, check=False)
    print(f"tcsim: cargo build of {FMU_PACKAGE}: {time.monotonic() - start:.1f} s", file=sys.stderr, flush=True)
    if p.returncode != 0:
        raise RuntimeError(
            f"'cargo build --release -p {FMU_PACKAGE}' failed (exit {p.returncode}); cargo's messages are above"
        )
    for line in p.stdout.splitlines():
        message = json.loads(line) if line.startswith("{") else {}
        target = message.get("target", {})
        if message.get("reason") == "compiler-artifact" and target.get("name") == FMU_TARGET:
            if "cdylib" in target.get("kind", []):
                for name in message.get("filenames", []):
                    if name.endswith(LIBRARY_SUFFIXES):
                        return Path(name)
    raise RuntimeError(f"cargo built {FMU_PACKAGE} but reported no cdylib of {FMU_TARGET}")


def _record_hash(data: bytes) -> str:
    return "sha256=" + base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()


def add_to_wheel(wheel: Path, files: Mapping[str, Path]) -> None:
    """Add ``files`` (path in the wheel -> file) to ``wheel`` and to its ``RECORD``, in place (the
    new wheel is written beside it and renamed over it)."""
    with zipfile.ZipFile(wheel) as zin:
        record_name = next(n for n in zin.namelist() if n.endswith(".dist-info/RECORD"))
        record_info = zin.getinfo(record_name)
        entries = [(info, zin.read(info)) for info in zin.infolist() if info.filename != record_name]
        rows = [row for row in csv.reader(io.StringIO(zin.read(record_name).decode())) if row and row[0] != record_name]
    tmp = wheel.with_name(wheel.name + ".part")
    with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as zout:
        for info, data in entries:
            zout.writestr(info, data)
        for arcname, path in sorted(files.items()):
            data = path.read_bytes()
            info = zipfile.ZipInfo(arcname, date_time=record_info.date_time)
            info.external_attr = (0o755 if path.suffix in LIBRARY_SUFFIXES else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            zout.writestr(info, data)
            rows.append([arcname, _record_hash(data), str(len(data))])
        rows.append([record_name, "", ""])
        text = io.StringIO()
        csv.writer(text, lineterminator="\n").writerows(rows)
        zout.writestr(record_info, text.getvalue())
    os.replace(tmp, wheel)


def build_wheel(
    wheel_directory: str, config_settings: Mapping[str, Any] | None = None, metadata_directory: str | None = None
) -> str:
    """maturin's wheel, with the FMU library and its sources in ``tcsim/_fmu/``."""
    with build_progress():
        name = maturin.build_wheel(wheel_directory, config_settings, metadata_directory)
        library = build_fmu_library()
    sources = _fmu_sources()
    package_dir = f"tcsim/{sources.PACKAGED_DIR}"
    with tempfile.TemporaryDirectory(prefix="tcsim-wheel-") as tmp:
        stage = Path(tmp) / sources.SOURCES_DIR
        sources.copy_rust_sources(ROOT, stage)
        files = {f"{package_dir}/{library.name}": library}
        files |= {f"{package_dir}/{p.relative_to(stage.parent).as_posix()}": p for p in stage.rglob("*") if p.is_file()}
        add_to_wheel(Path(wheel_directory) / name, files)
    print(f"tcsim: added {package_dir}/{library.name} and its sources to {name}", file=sys.stderr, flush=True)
    return name


def build_editable(
    wheel_directory: str, config_settings: Mapping[str, Any] | None = None, metadata_directory: str | None = None
) -> str:
    """maturin's editable wheel; the FMU library is built and stays in the target directory."""
    with build_progress():
        name = maturin.build_editable(wheel_directory, config_settings, metadata_directory)
        build_fmu_library()
    return name
