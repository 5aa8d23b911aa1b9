"""Study directories: a chunked study (:mod:`tcsim.analysis.chunked`) written as Parquet shards as
its chunks finish, with a manifest, and resumed from them.

Layout of ``DIR``
-----------------
* ``DIR/shards/part-00000.parquet``, ... : one shard per chunk (its rows in the study's order; the
  number is the chunk's index, zero-padded to five digits, more digits past 99 999). Each shard is
  written to a temporary file beside it and renamed into place, so a shard is whole or absent.
* ``DIR/manifest.json``: :data:`FORMAT`, the tcsim version, the study's definition and its SHA-256
  (``definition_sha256``, over the definition, the chunk size's meaning aside: the kind of study,
  everything its rows depend on, the speed unit and the tcsim version), ``chunk_size`` (cases per
  chunk), ``n_cases``, ``n_chunks``, ``columns`` (name and Arrow type of each) and ``chunks``: for
  each finished chunk its ``file``, ``rows``, ``size`` (bytes) and ``sha256``. It is rewritten
  (temporary file and rename) as each shard is renamed into place, SIGINT and SIGTERM held back
  from the shard's rename to the manifest's, so that the shards in place are the listed ones.

Rules
-----
* ``DIR`` may be missing (created with its parents), empty, or a study directory of the same
  definition and chunk size. Anything else is refused (:class:`InputError`, exit 2, nothing
  changed): a file, a directory holding files that are not a study's, a study of another
  definition, another chunk size, a directory that holds an input of the run, or one another run
  is writing to (an exclusive ``flock`` on ``DIR`` for the whole run).
* Resuming: every chunk listed in the manifest whose shard has the listed size and SHA-256 is kept
  and not computed again; the others (missing, changed, or written but not yet listed) are computed
  and written. Temporary files of an interrupted run are removed.
* An interrupted run (SIGINT, SIGTERM, a failure) keeps every shard it finished; running the same
  command again completes the study. The shards of a complete study are read back in order by
  :func:`read_shards`.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import re
import tempfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from ..analysis.chunked import ChunkedStudy, check_chunk_size, check_scheduler, chunk_count, iter_chunks
from ..errors import InputError, raise_if_interrupted
from .outputs import MANIFEST as OUTPUT_MANIFEST
from .outputs import _blocked, _contained_inputs, _sha256, _umask
from .tables import SPEED_UNITS, to_speed_unit

#: The mode of a shard and of the manifest before the umask: that of any output file.
FILE_MODE = 0o666

#: The manifest of a study directory, and the folder of its shards.
MANIFEST = "manifest.json"
SHARDS = "shards"
#: The manifest's format, its first key.
FORMAT = "tcsim-study-shards 1"
#: The most chunks a study may have (the manifest is rewritten after each).
MAX_CHUNKS = 10_000
#: What a refused ``--out`` of a sharded study is expected to be.
EXPECTED = "a new or empty directory, or the study directory of this same study"
_SHARD = re.compile(r"part-\d{5,}\.parquet")
#: Study directories this process left incomplete (for the interrupt line of the command line).
resumable: list[str] = []


def shard_name(index: int) -> str:
    """``part-00012.parquet`` for chunk 12."""
    return f"part-{index:05d}.parquet"


def _version() -> str:
    try:
        return metadata.version("tcsim")
    except metadata.PackageNotFoundError:
        return "0+unknown"


def definition_record(study: ChunkedStudy, speed_unit: str = SPEED_UNITS[0]) -> dict[str, Any]:
    """What a study's rows depend on (hashed into ``definition_sha256``)."""
    return {"kind": study.kind, **study.definition(), "speed_unit": speed_unit, "tcsim": _version()}


def definition_sha256(record: dict[str, Any]) -> str:
    text = json.dumps(record, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass
class ShardRun:
    """What :func:`run_to_shards` did: the chunks it computed and the ones it kept from before."""

    out: Path
    n_cases: int
    chunk_size: int
    n_chunks: int
    rows: int = 0
    computed: list[int] = field(default_factory=list)
    kept: list[int] = field(default_factory=list)


def _refuse(out: Path, expected: str) -> InputError:
    return InputError("command line", "--out", str(out), expected)


def _manifest_or_problem(out: Path) -> tuple[dict[str, Any] | None, str]:
    """The study manifest in ``out``, or None and what is wrong with it: missing, unreadable (a
    permission), not JSON or not a tcsim study's (a trial found all of them reported as missing,
    with the advice to choose another directory: the finished shards would be given up)."""
    path = out / MANIFEST
    if not path.exists():
        return None, f"no {MANIFEST}"
    try:
        m = json.loads(path.read_text(encoding="utf-8"))
    except OSError as e:
        return None, f"a {MANIFEST} that cannot be read ({e.strerror})"
    except ValueError as e:
        return None, f"a {MANIFEST} that is not valid JSON ({e}): repair it, or remove the directory"
    if not (isinstance(m, dict) and m.get("format") == FORMAT):
        return None, f"a {MANIFEST} that is not a tcsim study's"
    return m, ""


def _is_ours(name: str) -> bool:
    """A file a study directory may hold: its manifest, a shard, a temporary file of either."""
    if name == MANIFEST or (name.startswith(f".{MANIFEST}.") and name.endswith(".partial")):
        return True
    folder, _, base = name.partition("/")
    return folder == SHARDS and "/" not in base and (_SHARD.fullmatch(base) is not None or base.endswith(".partial"))


def _foreign(out: Path, foreign: Sequence[str]) -> str:
    """What the files ``foreign`` of ``out`` are: another tcsim command's output when its output
    manifest (:data:`tcsim.io.outputs.MANIFEST`) says so (a plain, unsharded study's), else files
    tcsim did not write."""
    many = len(foreign) != 1
    try:
        command = [str(w) for w in json.loads((out / OUTPUT_MANIFEST).read_text(encoding="utf-8"))["command"]]
    except (OSError, ValueError, TypeError, KeyError):
        return f"{len(foreign)} file{'s' if many else ''} tcsim did not write as a sharded study, e.g. {foreign[0]!r}"
    name = command[1] if len(command) > 1 else "tcsim"
    return (
        f"the output of an unsharded 'tcsim {name}' run: {len(foreign)} file{'s' if many else ''}, e.g. {foreign[0]!r}"
    )


def _check_dir(
    out: Path, record: dict[str, Any], chunk_size: int, inputs: Sequence[str | Path]
) -> dict[str, Any] | None:
    """The manifest of the study directory ``out`` (None if it is new or empty), or refuse it; the
    study's definition ``record`` (:func:`definition_record`)."""
    digest = definition_sha256(record)
    if _contained_inputs(out, inputs):
        raise _refuse(out, f"{EXPECTED}, holding no input of this run")
    if not out.exists() and not out.is_symlink():
        return None
    if not out.is_dir():
        raise _refuse(out, f"{EXPECTED} (a file of that name exists)")
    names = [p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_symlink() or not p.is_dir()]
    if not names and not any(p for p in out.iterdir() if p.name != SHARDS):
        return None
    manifest, problem = _manifest_or_problem(out)
    foreign = sorted(n for n in names if not _is_ours(n))
    if foreign:
        raise _refuse(out, f"{EXPECTED} (it holds {_foreign(out, foreign)}; choose another --out)")
    if manifest is None:
        advice = "" if "repair" in problem or "cannot be read" in problem else "; choose another --out"
        raise _refuse(out, f"{EXPECTED} (it holds {problem}{advice})")
    if manifest.get("definition_sha256") != digest:
        old = str(manifest.get("definition_sha256"))[:12]
        what = f"another study: definition {old}…, not {digest[:12]}…"
        as_kept = json.loads(json.dumps(record, allow_nan=True))  # tuples as the manifest's lists
        where = _first_difference(manifest.get("definition"), as_kept)
        if where:
            what += f"; {where}"
        raise _refuse(out, f"{EXPECTED} (it holds {what}; choose another --out)")
    if manifest.get("chunk_size") != chunk_size:
        expected = f"{manifest.get('chunk_size')}, the chunk size of the study in {str(out)!r} (or another --out)"
        raise InputError("command line", "--chunk-size", chunk_size, expected)
    return manifest


def _first_difference(there: Any, here: Any, path: str = "") -> str:
    """Where the definition kept in a study directory first differs from this run's, as
    ``speed_unit = 'rad/s' there, 'rpm' here`` ("" if the kept one is missing or the same): a trial
    found the refusal naming only two hashes, with nothing to say which setting differed."""
    if isinstance(there, dict) and isinstance(here, dict):
        for key in sorted(set(there) | set(here), key=str):
            if there.get(key) != here.get(key):
                return _first_difference(there.get(key), here.get(key), f"{path}.{key}" if path else str(key))
        return ""
    if isinstance(there, list) and isinstance(here, list) and len(there) == len(here):
        for i, (a, b) in enumerate(zip(there, here)):
            if a != b:
                return _first_difference(a, b, f"{path}[{i}]")
        return ""
    if there is None or there == here:
        return ""

    def short(v: Any) -> str:
        text = repr(v)
        return text if len(text) <= 40 else text[:37] + "…"

    return f"{path} = {short(there)} there, {short(here)} here"


def _kept_chunks(out: Path, manifest: dict[str, Any] | None, n_chunks: int) -> dict[str, dict[str, Any]]:
    """The chunks of ``manifest`` whose shard is in place with its listed size and SHA-256."""
    kept: dict[str, dict[str, Any]] = {}
    for key, entry in (manifest or {}).get("chunks", {}).items():
        if not (isinstance(entry, dict) and key.isdigit() and int(key) < n_chunks):
            continue
        path = out / str(entry.get("file", ""))
        if entry.get("file") != f"{SHARDS}/{shard_name(int(key))}" or not path.is_file() or path.is_symlink():
            continue
        if path.stat().st_size == entry.get("size") and _sha256(path) == entry.get("sha256"):
            kept[key] = entry
    return kept


def _write_manifest(out: Path, manifest: dict[str, Any]) -> None:
    """``manifest`` as ``out/manifest.json``, by a temporary file and a rename."""
    fd, name = tempfile.mkstemp(prefix=f".{MANIFEST}.", suffix=".partial", dir=out)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(json.dumps(manifest, allow_nan=True) + "\n")  # compact, by the C encoder
        os.chmod(name, FILE_MODE & ~_umask())  # as any output (mkstemp makes it private)
        os.replace(name, out / MANIFEST)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(name)


@contextlib.contextmanager
def _exclusive(out: Path) -> Iterator[None]:
    """An exclusive ``flock`` on the directory ``out`` for the block, or refuse it if another run holds it."""
    fd = os.open(out, os.O_RDONLY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise _refuse(out, f"{EXPECTED} that no other tcsim run is writing to") from None
        yield
    finally:
        os.close(fd)


def _clean(out: Path, kept: dict[str, dict[str, Any]]) -> None:
    """Remove temporary files and the shards the manifest does not keep (they are computed again)."""
    keep = {entry["file"] for entry in kept.values()}
    for p in [*out.glob(f".{MANIFEST}.*.partial"), *(out / SHARDS).iterdir()]:
        if p.relative_to(out).as_posix() not in keep:
            p.unlink()


def _table(rows: pd.DataFrame, speed_unit: str) -> pa.Table:
    return pa.Table.from_pandas(to_speed_unit(rows, speed_unit), preserve_index=False)


def _columns(table: pa.Table) -> list[dict[str, str]]:
    return [{"name": f.name, "type": str(f.type)} for f in table.schema]


def _prepare(
    out: Path, record: dict[str, Any], chunk_size: int, n_cases: int, inputs: Sequence[str | Path]
) -> dict[str, Any]:
    """Under the lock: check ``out`` again (another run may have changed it), keep its finished
    chunks, remove the rest, and write the manifest; the manifest."""
    digest = definition_sha256(record)
    old = _check_dir(out, record, chunk_size, inputs)
    n_chunks = chunk_count(n_cases, chunk_size)
    kept = _kept_chunks(out, old, n_chunks)
    _clean(out, kept)
    manifest = {
        "format": FORMAT,
        "tcsim": _version(),
        "definition_sha256": digest,
        "definition": record,
        "chunk_size": chunk_size,
        "n_cases": n_cases,
        "n_chunks": n_chunks,
        "columns": (old or {}).get("columns") if kept else None,
        "chunks": kept,
    }
    with _blocked():
        _write_manifest(out, manifest)
    return manifest


def run_to_shards(
    study: ChunkedStudy,
    out: str | Path,
    chunk_size: int,
    speed_unit: str = SPEED_UNITS[0],
    scheduler: str | None = None,
    workers: int | None = None,
    inputs: Sequence[str | Path] = (),
    progress: Callable[[int, int], None] | None = None,
    on_chunk: Callable[[int], None] | None = None,
) -> ShardRun:
    """Compute the chunks of ``study`` that ``out`` does not hold yet and write each as its shard
    (see the module's docstring); ``progress(done, total)`` after each chunk (also once at the
    start), ``on_chunk(index)`` after each chunk written. Returns what was computed and kept.
    ``scheduler`` and ``workers``: :func:`tcsim.analysis.chunked.iter_chunks`."""
    out = Path(out)
    chunk_size = check_chunk_size(chunk_size)
    check_scheduler(scheduler, workers)
    n_cases = study.n_cases
    n_chunks = chunk_count(n_cases, chunk_size)
    if n_chunks > MAX_CHUNKS:
        least = -(-n_cases // MAX_CHUNKS)
        raise InputError("command line", "--chunk-size", chunk_size, f"at least {least} ({MAX_CHUNKS} chunks at most)")
    record = definition_record(study, speed_unit)
    _check_dir(out, record, chunk_size, inputs)  # before anything is created
    try:
        (out / SHARDS).mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise _refuse(out, f"a directory that can be created ({e.strerror})") from None
    with _exclusive(out):
        manifest = _prepare(out, record, chunk_size, n_cases, inputs)
        run = ShardRun(out, n_cases, chunk_size, n_chunks, kept=sorted(int(k) for k in manifest["chunks"]))
        todo = [i for i in range(n_chunks) if str(i) not in manifest["chunks"]]
        resumable.append(str(out))
        chunks = iter_chunks(study, chunk_size, todo, scheduler, workers)
        try:
            if progress is not None:
                progress(len(run.kept), n_chunks)
            for index, rows in chunks:
                _store(out, manifest, index, _table(rows, speed_unit))
                run.computed.append(index)
                if progress is not None:
                    progress(len(run.kept) + len(run.computed), n_chunks)
                if on_chunk is not None:
                    on_chunk(index)
        finally:
            chunks.close()
        resumable.remove(str(out))
    run.rows = sum(int(e["rows"]) for e in manifest["chunks"].values())
    return run


def _store(out: Path, manifest: dict[str, Any], index: int, table: pa.Table) -> None:
    """Write chunk ``index``'s shard to a temporary file, then rename it into place and list it in
    the manifest with SIGINT and SIGTERM held back, so that a shard in place is a listed one."""
    columns = _columns(table)
    if manifest["columns"] is None:
        manifest["columns"] = columns
    elif manifest["columns"] != columns:
        raise RuntimeError(f"chunk {index} has the columns {columns}, not the study's {manifest['columns']}")
    rel = f"{SHARDS}/{shard_name(index)}"
    name: str | None = None
    try:  # entered before the file exists: a signal held back while it is made raises inside
        with _blocked():
            fd, name = tempfile.mkstemp(prefix=f".{shard_name(index)}.", suffix=".partial", dir=out / SHARDS)
            os.close(fd)
        pq.write_table(table, name)
        os.chmod(name, FILE_MODE & ~_umask())  # as any output (mkstemp makes it private)
        entry = {"file": rel, "rows": table.num_rows, "size": os.path.getsize(name), "sha256": _sha256(Path(name))}
        with _blocked():
            os.replace(name, out / rel)
            manifest["chunks"][str(index)] = entry
            _write_manifest(out, manifest)
        raise_if_interrupted()  # a signal whose exception was lost stops the study after this chunk
    finally:
        if name is not None:
            with _blocked(), contextlib.suppress(FileNotFoundError):
                os.unlink(name)


def read_shards(out: str | Path, columns: Sequence[str] | None = None) -> pd.DataFrame:
    """The rows of the complete study in ``out``, in the study's order (``columns``: only those).
    Raises :class:`InputError` if ``out`` is not a study directory, is incomplete, or a shard is
    not as its manifest lists it."""
    out = Path(out)
    manifest, problem = _manifest_or_problem(out)
    if manifest is None:
        raise _refuse(out, f"a study directory with its {MANIFEST} (it holds {problem})")
    n = int(manifest["n_chunks"])
    kept = _kept_chunks(out, manifest, n)
    missing = [i for i in range(n) if str(i) not in kept]
    if missing:
        what = f"{len(missing)} of {n} chunks missing or changed, e.g. chunk {missing[0]}"
        raise _refuse(out, f"a complete study ({what}; run the study again to complete it)")
    tables = [pq.read_table(out / kept[str(i)]["file"], columns=list(columns) if columns else None) for i in range(n)]
    return pa.concat_tables(tables).to_pandas() if tables else pd.DataFrame(columns=list(columns or []))
