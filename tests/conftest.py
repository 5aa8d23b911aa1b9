"""Shared fixtures: paths, the command line in-process and as a subprocess, the FMU library, and
the markers that say what a test is (from its folder: ``unit``, ``integration``, ``cli``,
``golden``; ``fmu`` for tests that load the FMU library, ``subprocess`` for tests that start one)."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest
from hypothesis import HealthCheck, settings

from tcsim.cli import main
from tcsim.errors import TcsimWarning
from tcsim.io import fmu as fmu_io

REPO = Path(__file__).resolve().parents[1]

# Property-based tests (hypothesis): "ci", the default, is a fixed, reproducible budget;
# HYPOTHESIS_PROFILE=long runs many random examples by hand (tests/cli/bad_inputs/README.md).
settings.register_profile(
    "ci",
    max_examples=50,
    deadline=None,
    derandomize=True,
    database=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
settings.register_profile(
    "long",
    max_examples=2000,
    deadline=None,
    database=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
CONVERTER_DATA = REPO / "tests" / "data" / "converters"  # published tables (tests/data/README.md)

# Li & Sundén (2016) Table C.1 with CF in N·m/(rad/s)², from the published table in tests/data
TABLE_C1 = CONVERTER_DATA / "li_sunden_2016_table_c1.csv"
_C1 = pd.read_csv(TABLE_C1, comment="#")
C1_SR: list[float] = _C1["speed_ratio"].tolist()
C1_TR: list[float] = _C1["torque_ratio"].tolist()
C1_CF: list[float] = _C1["capacity_factor_nm_s2"].tolist()


@dataclass
class Run:
    code: int
    stdout: str
    stderr: str


def run_cli(*args: str, cwd: Path | None = None) -> Run:
    """Run ``python -m tcsim`` in a subprocess, as a user would (for the few smoke tests)."""
    env = dict(os.environ, COLUMNS="200")
    p = subprocess.run(
        [sys.executable, "-m", "tcsim", *map(str, args)], capture_output=True, text=True, cwd=cwd, env=env, timeout=600
    )
    return Run(p.returncode, p.stdout, p.stderr)


def run_cli_in_process(*args: str, cwd: Path | None = None) -> Run:
    """Run ``tcsim.cli.main`` in this process, with its own stdout, stderr, warning filters and
    working directory, and a 200-column terminal; an exception that escapes ``main`` fails the test."""
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    with contextlib.ExitStack() as stack:
        stack.enter_context(contextlib.redirect_stdout(out))
        stack.enter_context(contextlib.redirect_stderr(err))
        stack.enter_context(warnings.catch_warnings())
        stack.enter_context(pytest.MonkeyPatch.context()).setenv("COLUMNS", "200")
        warnings.simplefilter("default")
        if cwd is not None:
            os.chdir(cwd)
            stack.callback(os.chdir, here)
        code = main([str(a) for a in args])
    return Run(code, out.getvalue(), err.getvalue())


@pytest.fixture
def cli():
    """The command line, in-process (``run_cli`` is the subprocess form for smoke tests)."""
    return run_cli_in_process


@pytest.fixture
def c1_csv(tmp_path) -> Path:
    p = tmp_path / "c1.csv"
    rows = "\n".join(f"{s},{t},{c!r}" for s, t, c in zip(C1_SR, C1_TR, C1_CF))
    p.write_text("# Li & Sundén (2016) Table C.1\nspeed_ratio,torque_ratio,capacity_factor_nm_s2\n" + rows + "\n")
    return p


@pytest.fixture(scope="session")
def fmu_library() -> Path:
    """The FMU library that the build made (``cargo build --release --workspace``, part of the
    README's test command) or ``$TCSIM_FMU_LIBRARY``; no test builds it. A missing library, or one
    older than the Rust sources, fails the test with what to run."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", TcsimWarning)  # a stale library
        try:
            return fmu_io.find_libraries(build=False)[0]
        except (fmu_io.FmuLibraryError, TcsimWarning) as e:
            pytest.fail(f"{e} (the README's test command builds it)")


FOLDER_MARKERS = {"unit", "integration", "cli", "golden"}


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark each test by its folder, and ``fmu`` where it uses the FMU library."""
    for item in items:
        folder = item.path.relative_to(REPO / "tests").parts[0]
        if folder in FOLDER_MARKERS:
            item.add_marker(folder)
        if "fmu_library" in getattr(item, "fixturenames", ()):
            item.add_marker("fmu")


@pytest.fixture(scope="module")
def cluster():
    """A dask ``LocalCluster`` of two worker processes with one thread each (skipped without the
    ``dask`` extra): the cluster of the sharded studies' tests."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=50
    ) as c:
        yield c
