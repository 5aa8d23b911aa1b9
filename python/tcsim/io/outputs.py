"""Where the commands write: one rule for output directories, one for single output files.

Output directories (``--out DIR``)
----------------------------------
* A run writes every file into a staging folder beside ``DIR`` (``.DIR.XXXXXXXX.partial``) and
  renames the complete folder into place at the end: ``DIR`` appears whole or not at all.
* Every run writes a manifest, :data:`MANIFEST` (``tcsim-manifest.json``): the tcsim version, the
  command line and each file's name, size (bytes) and SHA-256.
* ``DIR`` may be missing (it is created, with its parents), an empty directory, or a previous tcsim
  output: a directory holding exactly the files its manifest lists, each with the listed size and
  SHA-256. Such a directory is replaced whole (old renamed aside, new renamed in, old removed);
  nothing of the old run is kept. The command line warns when it replaced another command's output.
* Anything else is refused (:class:`~tcsim.errors.InputError`, exit 2): a path that is a file, a
  directory holding other files (also a previous output with a file added or changed), and a
  ``DIR`` that contains an input file of the same run.
* The rule is checked before the compute (:func:`check_output_dir`) and again at the commit, which
  holds an exclusive ``flock`` on the parent directory (no lock file), so that two runs into the same
  ``DIR`` give two complete results one after the other, or a result and an error, never a mixture.
  SIGINT and SIGTERM are held back during the commit (:func:`_blocked`); a signal that arrived before
  it cancels it.

Output files (``export-fmu -o FILE.fmu``)
-----------------------------------------
Written to ``.FILE.fmu.XXXXXXXX.partial`` beside it and renamed into place; an existing ``FILE.fmu``
is replaced only if it is a regular file that is not an input of the run; a directory or any other
kind of file of that name is refused.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import shutil
import signal
import sys
import tempfile
import threading
import warnings
from collections.abc import Callable, Iterable, Iterator, Sequence
from importlib import metadata
from pathlib import Path
from typing import Any

from ..errors import InputError, TcsimWarning, raise_if_interrupted

#: The manifest every output directory holds.
MANIFEST = "tcsim-manifest.json"
#: What a refused ``--out`` is expected to be.
EXPECTED_DIR = "a new or empty directory, or the output of an earlier tcsim run"
_SIGNALS = {signal.SIGINT, signal.SIGTERM}

#: The command line recorded in manifests: set by the command-line entry point while it runs; the
#: Python program's ``sys.argv`` otherwise.
command_line: list[str] = []
#: Output directories and files this process has put in place (for the interrupt message).
committed: list[Path] = []


def _refuse(out: Path, expected: str) -> InputError:
    return InputError.argument("out", str(out), expected)


def _listing(names: Sequence[str]) -> str:
    """``'a', 'b' and 1 more``."""
    shown = ", ".join(n if n.endswith(")") else repr(n) for n in sorted(names)[:2])
    return shown + (f" and {len(names) - 2} more" if len(names) > 2 else "")


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}{'' if n == 1 else 's'}"


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _files(root: Path) -> dict[str, Path]:
    """Every entry below ``root`` that is not a directory, by its ``/``-separated relative name."""
    return {p.relative_to(root).as_posix(): p for p in root.rglob("*") if p.is_symlink() or not p.is_dir()}


def _foreign_files(out: Path) -> list[str]:
    """What keeps the directory ``out`` from being replaced: the files that are not exactly as the
    manifest lists them (all of them without a readable manifest), as ``name (why)``."""
    files = _files(out)
    try:
        listed = {f["name"]: f for f in json.loads((out / MANIFEST).read_text(encoding="utf-8"))["files"]}
    except (OSError, ValueError, KeyError, TypeError):
        return sorted(files)
    bad = [f"{n!r} (not in the manifest)" for n in files if n != MANIFEST and n not in listed]
    bad += [f"{n!r} (missing)" for n in listed if n not in files]
    for name, entry in listed.items():
        path = files.get(name)
        if path is None:
            continue
        if path.is_symlink() or path.stat().st_size != entry.get("size") or _sha256(path) != entry.get("sha256"):
            bad.append(f"{name!r} (changed)")
    return sorted(bad)


def _contained_inputs(out: Path, inputs: Iterable[str | Path]) -> list[str]:
    """The input files of the run that are ``out`` or lie inside it (an argument that names no file,
    such as a bundled converter's name, is none)."""
    target = out.resolve()
    inside = []
    for inp in inputs:
        path = Path(inp)
        if path.is_file():
            resolved = path.resolve()
            if resolved == target or resolved.is_relative_to(target):
                inside.append(str(inp))
    return inside


def _check_creatable(out: Path) -> None:
    """Refuse an ``out`` that could not be made (before a run, not after it): its nearest existing
    ancestor is not a directory, or no directory can be created in it (probed with an empty
    directory, removed at once)."""
    ancestor = next(p for p in (out.parent, *out.parent.parents) if p.exists() or p == p.parent)
    if not ancestor.is_dir():
        raise _refuse(out, f"a directory that can be created ({str(ancestor)!r} is not a directory)")
    where = Path(os.path.abspath(out)).resolve().parent if out.is_symlink() else ancestor
    with _blocked():
        try:
            os.rmdir(tempfile.mkdtemp(prefix=".tcsim-probe.", dir=where))
        except OSError as e:
            raise _refuse(out, f"a writable directory ({e.strerror})") from None


def check_output_dir(out: str | Path, inputs: Iterable[str | Path] = ()) -> None:
    """Refuse an ``out`` the rule of this module does not allow, or one that cannot be created
    (:class:`InputError`)."""
    out = Path(out)
    contained = _contained_inputs(out, inputs)
    if any(out.resolve() == Path(c).resolve() for c in contained):
        raise _refuse(out, "a directory, not an input file of this run")
    if contained:
        raise _refuse(out, f"a directory that holds no input of this run (it holds {_listing(contained)})")
    _check_creatable(out)
    if not out.exists() and not out.is_symlink():
        return
    if not out.is_dir():
        raise _refuse(out, f"{EXPECTED_DIR} (a file of that name exists)")
    if not any(out.iterdir()):
        return
    foreign = _foreign_files(out)
    if foreign:
        if (out / MANIFEST).is_file():
            what = f"an earlier tcsim output with {_count(len(foreign), 'file')} changed since"
        else:
            what = f"{_count(len(foreign), 'file')} tcsim did not write"
        raise _refuse(out, f"{EXPECTED_DIR} (it holds {what}: {_listing(foreign)}; choose another --out)")


def _manifest(stage: Path) -> str:
    try:
        version = metadata.version("tcsim")
    except metadata.PackageNotFoundError:
        version = "0+unknown"
    files = [
        {"name": name, "size": path.stat().st_size, "sha256": _sha256(path)}
        for name, path in sorted(_files(stage).items())
    ]
    command = command_line or sys.argv
    return json.dumps({"tcsim": version, "command": command, "files": files}, indent=1) + "\n"


@contextlib.contextmanager
def _locked_and_uninterrupted(directory: Path) -> Iterator[None]:
    """An exclusive ``flock`` on ``directory`` with SIGINT and SIGTERM held back (:func:`_blocked`); a
    signal that arrived before is let through first (it raises on entry, also when its exception
    was lost earlier: :func:`~tcsim.errors.raise_if_interrupted`), so that the commit does not start."""
    fd = os.open(directory, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        with _blocked():
            raise_if_interrupted()
            yield
    finally:
        os.close(fd)  # also releases the lock


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _commit_dir(stage: Path, out: Path, shown: Path, inputs: Sequence[str | Path]) -> None:
    """Move the complete ``stage`` to ``out`` under the lock of :func:`_locked_and_uninterrupted`."""
    os.chmod(stage, 0o777 & ~_umask())
    with _locked_and_uninterrupted(out.parent):
        check_output_dir(shown, inputs)
        aside = None
        if out.is_dir() and any(out.iterdir()):
            aside = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=out.parent))
            os.rename(out, aside)  # renames over the empty directory mkdtemp made
        try:
            os.rename(stage, out)  # replaces an empty directory
        except OSError:
            if aside is not None:
                os.rename(aside, out)
            raise
        committed.append(shown)
        if aside is not None:
            shutil.rmtree(aside, ignore_errors=True)


def _make_parents(parent: Path, out: Path) -> list[Path]:
    """Create ``parent`` and its missing ancestors; the ones created, innermost first."""
    created = [p for p in (parent, *parent.parents) if not p.exists()]
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise _refuse(out, f"a directory that can be created ({e.strerror})") from None
    return created


@contextlib.contextmanager
def output_dir(out: str | Path, inputs: Sequence[str | Path] = ()) -> Iterator[Path]:
    """Yield a staging directory; when the block ends without an exception, add the manifest and put
    the directory in place as ``out`` by the rule of this module (``inputs``: the run's input files).
    On an exception (also an interrupt) nothing is left: no staging folder, no ``out``, no parent
    directory this call created."""
    shown = Path(out)
    check_output_dir(shown, inputs)
    earlier = _another_command(shown)
    target = Path(os.path.abspath(shown))
    target = target.resolve() if target.is_symlink() else target
    created: list[Path] = []
    stage: Path | None = None
    done = False
    try:
        with _blocked():  # what is created is recorded before a signal can interrupt
            created = _make_parents(target.parent, shown)
            try:
                stage = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".partial", dir=target.parent))
            except OSError as e:
                raise _refuse(shown, f"a writable directory ({e.strerror})") from None
        yield stage
        (stage / MANIFEST).write_text(_manifest(stage), encoding="utf-8")
        _commit_dir(stage, target, shown, inputs)
        done = True
    finally:
        if not done:
            _held_back(lambda: _discard(stage, created))
    if earlier is not None:  # once it is done (a warning raised as an error loses nothing)
        warnings.warn(f"{shown}/: replaced the output of an earlier `{earlier}`", TcsimWarning, stacklevel=3)


def _another_command(out: Path) -> str | None:
    """The command line of the earlier output in ``out`` when this command line is another command
    (a launch into a drive's folder): by the rule it is replaced whole, which a user reusing a name
    may not expect, so :func:`output_dir` says so once it is done. None for the same command run
    again, outside the command line, and without an earlier output."""
    try:
        earlier = json.loads((out / MANIFEST).read_text(encoding="utf-8"))["command"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not (command_line[:1] == ["tcsim"] and isinstance(earlier, list) and earlier[:1] == ["tcsim"]):
        return None
    if len(earlier) > 1 and len(command_line) > 1 and earlier[1] != command_line[1]:
        return " ".join(str(w) for w in earlier)
    return None


def _discard(staged: Path | None, created: Sequence[Path]) -> None:
    """Remove the staging folder or file ``staged`` and the ``created`` parent directories left empty."""
    if staged is not None and staged.is_dir() and not staged.is_symlink():
        shutil.rmtree(staged, ignore_errors=True)
    elif staged is not None:
        staged.unlink(missing_ok=True)
    _remove_empty(created)


def _remove_empty(directories: Sequence[Path]) -> None:
    for directory in directories:
        with contextlib.suppress(OSError):
            directory.rmdir()


@contextlib.contextmanager
def _blocked() -> Iterator[None]:
    """SIGINT and SIGTERM held back while the block runs, and raised (by the handler they had) when it ends.

    Blocking them in this thread (``pthread_sigmask``) is not enough: the process has other threads
    (the core's workers, BLAS), the kernel hands the signal to one of them, and Python runs its
    handler in the main thread at the next bytecode, inside the block. So the block also replaces the
    Python handlers by one that only records the signal; a signal that arrived before the block
    raises on entry (``signal.signal`` runs pending handlers first), before anything in it has run.
    Outside the main thread (where Python runs no handler) only the mask applies."""
    if threading.current_thread() is not threading.main_thread():
        old = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
        try:
            yield
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
        return
    held: list[int] = []
    previous: dict[int, Any] = {}
    try:
        for sig in sorted(s for s in _SIGNALS if signal.getsignal(s) is not None):  # None: not set by Python
            previous[sig] = signal.signal(sig, lambda signum, frame: held.append(signum))
        old = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
        try:
            yield
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)  # a pending signal is recorded here
    finally:
        late = _restore(previous)
        if held:
            _deliver(held[0], previous[held[0]])
        if late is not None:
            raise late


def _restore(previous: dict[int, Any]) -> KeyboardInterrupt | None:
    """Put the ``previous`` handlers back, all of them also when a signal lands meanwhile (the handler
    already put back raises it: it is returned, to be raised after)."""
    late: KeyboardInterrupt | None = None
    for sig, handler in previous.items():
        while signal.getsignal(sig) != handler:
            try:
                signal.signal(sig, handler)
            except KeyboardInterrupt as e:  # raised before the handler is set: set it again
                late = late or e
    return late


def _deliver(sig: int, handler: Any) -> None:
    """Act on a signal held back by :func:`_blocked` as its ``handler`` would have."""
    if callable(handler):
        handler(sig, None)
    elif handler == signal.SIG_DFL:
        signal.raise_signal(sig)


def _held_back(action: Callable[[], object]) -> None:
    """Run ``action`` (which may be run again) in :func:`_blocked`, also when a signal lands while the
    block is being entered (a second Ctrl-C during the clean-up after the first): that one raises after
    ``action`` has run."""
    interrupt: KeyboardInterrupt | None = None
    done = False
    while not done:
        try:
            with _blocked():
                action()
                done = True
        except KeyboardInterrupt as e:
            interrupt = interrupt or e
    if interrupt is not None:
        raise interrupt


def check_output_file(out: str | Path, inputs: Iterable[str | Path] = ()) -> None:
    """Refuse an output file ``out`` that is an input of the run, or that exists and is not a
    regular file (:class:`InputError`)."""
    out = Path(out)
    if _contained_inputs(out, inputs):
        raise _refuse(out, "a file that is not an input of this run")
    if out.is_dir():
        raise _refuse(out, f"a {out.suffix + ' ' if out.suffix else ''}file (a directory of that name exists)")
    if out.exists() and not out.is_file():
        raise _refuse(out, "a regular file (a special file of that name exists)")


@contextlib.contextmanager
def output_file(out: str | Path, inputs: Sequence[str | Path] = ()) -> Iterator[Path]:
    """Yield a temporary file beside ``out``; when the block ends without an exception, rename it to
    ``out`` (atomically, SIGINT and SIGTERM blocked), after checking :func:`check_output_file` again."""
    shown = Path(out)
    check_output_file(shown, inputs)
    target = Path(os.path.abspath(shown))
    created: list[Path] = []
    tmp: Path | None = None
    done = False
    try:
        with _blocked():  # what is created is recorded before a signal can interrupt
            created = _make_parents(target.parent, shown)
            try:
                fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".partial", dir=target.parent)
                os.close(fd)
            except OSError as e:
                raise _refuse(shown, f"a writable location ({e.strerror})") from None
            tmp = Path(name)
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        with _locked_and_uninterrupted(target.parent):
            check_output_file(shown, inputs)
            os.replace(tmp, target)
            committed.append(shown)
            done = True
    finally:
        if not done:
            _held_back(lambda: _discard(tmp, created))
