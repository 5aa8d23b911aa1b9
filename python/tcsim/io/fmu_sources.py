"""What an FMU needs besides its model: the FMU library and its Rust sources, as the source tree holds
them and as an installed tcsim carries them.

This module imports nothing of tcsim (standard library only): the build backend
(``tools/build_backend/tcsim_backend.py``) loads it by its path while it builds the wheel, before
``tcsim._core`` exists, and :mod:`tcsim.io.fmu` uses it at export. It owns two facts:

* :data:`PACKAGED_DIR`: the directory of the installed package (``tcsim/_fmu/``) that holds the FMU
  library the wheel was built with (under the name cargo gives it, e.g. ``libtcsim_fmu.so``) and,
  in ``sources/``, the Rust sources it was built from;
* :func:`copy_rust_sources`: which files of the source tree make the FMU's ``sources/``.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

#: The installed package's FMU directory, relative to the ``tcsim`` package directory.
PACKAGED_DIR = "_fmu"
#: The Rust sources' directory inside :data:`PACKAGED_DIR` (and inside the FMU).
SOURCES_DIR = "sources"
#: The crates an FMU's sources hold: the FMU library and the core it is built on.
SOURCE_CRATES = ("tcsim-core", "tcsim-fmu")
_CRATE_FILES = ("Cargo.toml", "build.rs", "README.md", "LICENSE")
_CRATE_DIRS = ("src", "include")


def is_source_tree(root: Path) -> bool:
    """True when ``root`` is a tcsim source tree (its ``Cargo.toml`` and ``crates/tcsim-fmu``)."""
    return (root / "Cargo.toml").is_file() and (root / "crates" / "tcsim-fmu" / "Cargo.toml").is_file()


def copy_rust_sources(root: Path, dest: Path) -> None:
    """Copy what rebuilds the FMU library from the source tree ``root`` into ``dest``: the
    workspace ``Cargo.toml`` (its members cut to :data:`SOURCE_CRATES`), ``Cargo.lock``, ``LICENSE``
    and, of each crate of :data:`SOURCE_CRATES`, its manifest and sources."""
    dest.mkdir(parents=True, exist_ok=True)
    members = ", ".join(f'"crates/{crate}"' for crate in SOURCE_CRATES)
    ws = (root / "Cargo.toml").read_text()
    ws = re.sub(r"(?ms)^members\s*=\s*\[.*?\]", f"members = [{members}]", ws, count=1)
    (dest / "Cargo.toml").write_text(ws)
    for name in ("Cargo.lock", "LICENSE"):
        if (root / name).is_file():
            shutil.copy2(root / name, dest / name)
    for crate in SOURCE_CRATES:
        src, out = root / "crates" / crate, dest / "crates" / crate
        out.mkdir(parents=True)
        for name in _CRATE_FILES:
            if (src / name).is_file():
                shutil.copy2(src / name, out / name)
        for d in _CRATE_DIRS:
            if (src / d).is_dir():
                shutil.copytree(src / d, out / d, ignore=shutil.ignore_patterns("target", "*.orig", "*.rej", ".*"))
