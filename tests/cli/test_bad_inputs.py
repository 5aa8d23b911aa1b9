"""The bad-input catalogue (``tests/cli/bad_inputs/*.toml``, format in its README): every case gives
its exit code and exactly one stderr line ``error: <file>: <field> = <value>: expected ...`` naming
the file and the case's fragments; no traceback, nothing written, no input changed."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

CATALOGUE = Path(__file__).resolve().parent / "bad_inputs"
REPO = CATALOGUE.parents[2]
#: Folders whose files a case may name as ``base`` (by file name, which must be unique).
BASE_ROOTS = (REPO / "python" / "tcsim" / "data", REPO / "tests" / "data", REPO / "tests" / "golden" / "data")
#: Hang guard of a case run as a subprocess, s (never asserted on: a timeout fails the case).
SUBPROCESS_TIMEOUT_S = 60.0
CASE_KEYS = {
    *("id", "command", "exit", "file", "message", "files", "subprocess", "pending", "timeout", "tags"),
    *("writes", "warning"),
}
FILE_KEYS = {"text", "hex", "base", "replace", "prepend", "append", "make", "args", "dir"}
COMMANDS = (
    "converters",
    "characterise",
    "fit",
    "study",
    "replay",
    "fit-shapes",
    "launch",
    "export-fmu",
    "operating-point",
    "monte-carlo",
    "design",
)


def _load() -> list[dict[str, Any]]:
    cases = []
    for toml in sorted(CATALOGUE.glob("*.toml")):
        for case in tomllib.loads(toml.read_text(encoding="utf-8")).get("case", []):
            cases.append({**case, "_topic": toml.stem})
    return cases


CASES = _load()


def _bases() -> dict[str, Path]:
    found: dict[str, list[Path]] = {}
    for root in BASE_ROOTS:
        for p in sorted(root.rglob("*")):
            if p.is_file():
                found.setdefault(p.name, []).append(p)
    return {name: paths[0] for name, paths in found.items() if len(paths) == 1}


BASES = _bases()


def _make(name: str) -> Callable[..., None]:
    sys.path.insert(0, str(CATALOGUE))
    try:
        import make  # noqa: PLC0415  the catalogue's writers, beside its data
    finally:
        sys.path.remove(str(CATALOGUE))
    return getattr(make, name)


def create(root: Path, name: str, spec: dict[str, Any]) -> None:
    """Write one input file of a case (see the README for the keys)."""
    assert set(spec) <= FILE_KEYS, f"{name}: unknown keys {set(spec) - FILE_KEYS}"
    path = root / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if spec.get("dir"):
        path.mkdir()
        return
    if "make" in spec:
        _make(spec["make"])(path, **spec.get("args", {}))
        return
    if "hex" in spec:
        path.write_bytes(bytes.fromhex(spec["hex"]))
        return
    if "base" in spec:
        assert spec["base"] in BASES, f"{spec['base']} is not a unique file under {[str(r) for r in BASE_ROOTS]}"
        text = BASES[spec["base"]].read_text(encoding="utf-8")
    else:
        text = spec["text"]
    for old, new in spec.get("replace", []):
        assert old in text, f"{name}: {old!r} not in the base file"
        text = text.replace(old, new, 1)
    path.write_bytes((spec.get("prepend", "") + text + spec.get("append", "")).encode("utf-8"))


def snapshot(root: Path) -> dict[str, str]:
    """Every file and folder under ``root`` (hidden ones too): relative path -> SHA-256 or "dir"."""
    out = {}
    for p in sorted(root.rglob("*")):
        rel = str(p.relative_to(root))
        out[rel] = "dir" if p.is_dir() else hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def run_subprocess(args: list[str], cwd: Path, timeout: float) -> tuple[int, str, str]:
    env = dict(os.environ, COLUMNS="200")
    try:
        p = subprocess.run(
            [sys.executable, "-m", "tcsim", *args], capture_output=True, text=True, cwd=cwd, env=env, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"no answer within the {timeout:g} s hang guard")
    return p.returncode, p.stdout, p.stderr


def check_message(case: dict[str, Any], stderr: str) -> None:
    """One ``error:`` line naming the file (``command line`` for options and usage errors), the
    fragments and what was expected."""
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    if "warning" in case:  # a warning the case names (about what caused the error) may come first
        warned = [ln for ln in lines if ln.startswith("warning: ")]
        assert any(all(f in ln for f in case["warning"]) for ln in warned), (case["warning"], warned)
        lines = [ln for ln in lines if ln not in warned]
    assert len(lines) == 1, f"expected one stderr line, got {len(lines)}: {lines}"
    msg = lines[0]
    assert msg.startswith("error: "), msg
    assert "expected" in msg, msg
    assert case["file"] in msg, f"file {case['file']!r} not named in {msg!r}"
    for fragment in case.get("message", []):
        assert fragment in msg, f"{fragment!r} not in {msg!r}"


def _param(case: dict[str, Any]):
    marks = [pytest.mark.subprocess] if case.get("subprocess") else []
    if "pending" in case:
        marks.append(pytest.mark.xfail(strict=True, reason=f"pending: {case['pending']}"))
    return pytest.param(case, id=case["id"], marks=marks)


@pytest.mark.parametrize("case", [_param(c) for c in CASES])
def test_bad_input(cli, tmp_path, case):
    assert set(case) - {"_topic"} <= CASE_KEYS, f"unknown keys {set(case) - CASE_KEYS - {'_topic'}}"
    for name, spec in case.get("files", {}).items():
        create(tmp_path, name, spec)
    before = snapshot(tmp_path)
    if case.get("subprocess"):
        code, out, err = run_subprocess(case["command"], tmp_path, case.get("timeout", SUBPROCESS_TIMEOUT_S))
    else:
        r = cli(*case["command"], cwd=tmp_path)
        code, out, err = r.code, r.stdout, r.stderr
    assert "Traceback" not in out + err, err
    assert code == case["exit"], (code, out, err)
    after = snapshot(tmp_path)
    if code == 0:  # a legal input that must work (``writes``: what it writes)
        assert not [ln for ln in err.splitlines() if ln.startswith(("error", "tcsim failed"))], err
        if "warning" in case:  # a legal but implausible input: one warning names it
            warned = [ln for ln in err.splitlines() if ln.startswith("warning: ")]
            assert any(all(f in ln for f in case["warning"]) for ln in warned), (case["warning"], warned)
        for written in case["writes"]:
            assert written in after, f"{written} not written"
        new = [p for p in after if p not in before]
        assert all(any(p == w or p.startswith(w + "/") for w in case["writes"]) for p in new), new
        after = {p: h for p, h in after.items() if p in before}
    else:
        check_message(case, err)
    assert after == before, "the run wrote, removed or changed a file"


# --------------------------------------------------------------------------------------------
# the catalogue itself


def features(case: dict[str, Any]) -> set[str]:
    """What a case exercises: its command, ``command --option`` for each option it gives,
    ``command .ext`` for each input file it names (``.mat-v7.3`` for a v7.3 file), and its tags."""
    command, *args = case["command"]
    out = {command, *(f"{command} {a}" for a in args if a.startswith("--")), *case.get("tags", [])}
    files = case.get("files", {})
    for a in args:
        spec = files.get(a)
        if spec is not None and not spec.get("dir"):
            v73 = spec.get("args", {}).get("v73") or spec.get("args", {}).get("fmt") == "v73.mat"
            out.add(f"{command} {Path(a).suffix.lower()}{'-v7.3' if v73 else ''}")
    return out


#: Every command, every input format and every option the issue names.
REQUIRED_FEATURES = {
    *COMMANDS,
    "characterise .toml",  # converter TOML
    "characterise .csv",  # table CSV
    "characterise .vtcc",  # VECTO
    "launch .toml",  # vehicle TOML
    *(f"launch {ext}" for ext in (".csv", ".parquet", ".mat", ".mf4")),  # scenario files
    *(f"replay {ext}" for ext in (".csv", ".parquet", ".mat", ".mat-v7.3", ".mf4")),  # measurements
    "replay --channel",
    "replay --initial",
    "replay --window",
    "replay --metrics-window",
    "characterise --pump-speed-rpm",
    "characterise --model",
    "replay --model",
    "fit --target",
    "fit-shapes .csv",
    "study .toml",
    "export-fmu --model",
    "export-fmu --out",
    "launch --scenario",
}


def test_catalogue_is_large_unique_and_covers_every_command_and_format():
    assert len(CASES) >= 60, len(CASES)
    ids = [c["id"] for c in CASES]
    assert len(ids) == len(set(ids)), sorted({i for i in ids if ids.count(i) > 1})
    covered = set().union(*(features(c) for c in CASES))
    assert REQUIRED_FEATURES <= covered, sorted(REQUIRED_FEATURES - covered)
    for c in CASES:
        assert c["command"][0] in COMMANDS, c["id"]
        assert c.get("file") or c["exit"] == 0, f"{c['id']}: no file to name"
        assert (c["exit"] == 0) == ("writes" in c), f"{c['id']}: exit 0 exactly when it names what it writes"
        assert c.get("pending") is None or c["_topic"] == "pending", f"{c['id']}: pending cases go in pending.toml"
    pending = [c for c in CASES if c["_topic"] == "pending"]
    assert all(c.get("pending") for c in pending)
