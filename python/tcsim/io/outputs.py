"""All-or-nothing output directories.

Commands write every file into a temporary directory beside the target and move them into
place only when the whole job has succeeded, so a failed run leaves nothing half-written.
"""

from __future__ import annotations

import contextlib
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from ..errors import InputError


@contextlib.contextmanager
def output_dir(out: str | Path) -> Iterator[Path]:
    """Yield a staging directory; on success its files replace those of the same name in ``out``."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError("command line", "--out", str(out), "a directory (a file of that name exists)")
    parent = out.resolve().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial", dir=parent))
    except OSError as e:
        raise InputError("command line", "--out", str(out), f"a writable directory ({e.strerror})") from None
    try:
        yield stage
        out.mkdir(parents=True, exist_ok=True)
        for item in sorted(stage.rglob("*")):
            target = out / item.relative_to(stage)
            if item.is_dir():
                target.mkdir(exist_ok=True)
            else:
                item.replace(target)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
