"""tcsim installed from its wheel exports FMUs with no source tree and no cargo (issue 13).

The wheel is the one the CI built (``.ci/run``: ``pip wheel`` once, installed for the whole suite,
its path in ``$TCSIM_WHEEL``), else the newest ``dist/tcsim-*.whl``; without either the
test is skipped (building a wheel here would compile the workspace again). A wheel older than the
sources fails the test with the command that rebuilds it.

The wheel is installed (``pip --python``, no dependencies, no index) into a fresh virtual environment
in a temporary folder; the dependencies (numpy, ...) come from this interpreter's site-packages
through a ``.pth`` file placed after the fresh site-packages, so ``tcsim`` itself can only come from
the wheel (checked). ``tcsim export-fmu`` runs there from a folder outside the source tree with a
PATH that holds no cargo and without ``$TCSIM_FMU_LIBRARY``. Its FMU must carry the packaged library
and its sources, validate in FMPy, and simulate in both interfaces within the 0.5 % tube of the
replay run. The export's duration is printed (``-s`` shows it), never asserted.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
import venv
import zipfile
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy.validation import validate_fmu  # noqa: E402

from tcsim.io import fmu as tfmu  # noqa: E402
from tcsim.transient import PumpTorqueTurbineSpeed, simulate  # noqa: E402

pytestmark = [pytest.mark.fmu, pytest.mark.subprocess]

REPO = Path(__file__).resolve().parents[2]
#: The wheel to install (set by .ci/run); without it, the newest of dist/.
WHEEL_ENV = "TCSIM_WHEEL"
BUILD_WHEEL = "python3 -m pip wheel --no-deps -w dist ."
CONVERTER, MODEL = "li-sunden-2016", "hrovat-tobler"
TUBE = 0.005  # 0.5 % of the reference's range


def _newest_source_mtime() -> float:
    """The newest modification time of what the wheel is built from."""
    paths = [REPO / "pyproject.toml", REPO / "Cargo.toml", REPO / "Cargo.lock"]
    paths += list((REPO / "crates").glob("*/Cargo.toml")) + list((REPO / "crates").glob("*/src/**/*.rs"))
    paths += list((REPO / "python" / "tcsim").rglob("*.py")) + list((REPO / "tools" / "build_backend").glob("*.py"))
    return max(p.stat().st_mtime for p in paths if p.is_file())


@pytest.fixture(scope="module")
def wheel() -> Path:
    env = os.environ.get(WHEEL_ENV)
    if env:
        path = Path(env)
        if not path.is_file():
            pytest.fail(f"{WHEEL_ENV}={env}: no such file")
    else:
        found = sorted((REPO / "dist").glob("tcsim-*.whl"), key=lambda p: p.stat().st_mtime)
        if not found:
            pytest.skip(f"no wheel of tcsim: build one with '{BUILD_WHEEL}' (.ci/run does, and sets {WHEEL_ENV})")
        path = found[-1]
    if path.stat().st_mtime < _newest_source_mtime():
        pytest.fail(f"{path} is older than the sources: rebuild it with '{BUILD_WHEEL}'")
    return path


def _without_cargo(path: str) -> str:
    """``path`` (a PATH) without the directories that hold a ``cargo`` (``~/.cargo/bin``, ...)."""
    return os.pathsep.join(d for d in path.split(os.pathsep) if d and shutil.which("cargo", path=d) is None)


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> dict[str, object]:
    """A fresh virtual environment with the wheel installed: its folder, python, environment."""
    home = tmp_path_factory.mktemp("fresh") / "venv"
    venv.EnvBuilder(with_pip=False).create(home)
    python = home / "bin" / "python"
    site_dir = subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    # the wheel first: with the dependencies' .pth in place, pip would see this process's tcsim (a
    # non-editable install from the same wheel in CI) as "already satisfied" and install nothing
    pip = [sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "--no-index", str(wheel)]
    p = subprocess.run(pip, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    assert (home / "bin" / "tcsim").is_file(), p.stdout
    dependencies = [p for p in sys.path if p.endswith(("site-packages", "dist-packages")) and Path(p).is_dir()]
    (Path(site_dir) / "zz_test_dependencies.pth").write_text("\n".join(dependencies) + "\n")
    env = {k: v for k, v in os.environ.items() if k not in (tfmu.LIBRARY_ENV, "PYTHONPATH", "VIRTUAL_ENV")}
    env["PATH"] = os.pathsep.join([str(home / "bin"), _without_cargo(os.environ.get("PATH", ""))])
    return {"home": home, "python": python, "env": env}


PROBE = """\
import json, shutil, tcsim
from tcsim.io import fmu
root = fmu.source_root()
print(json.dumps({"tcsim": tcsim.__file__, "root": root and str(root), "cargo": shutil.which("cargo"),
                  "libraries": [str(p) for p in fmu.find_libraries(build=False)]}))
"""


def test_installed_copy_has_its_library_and_no_source_tree(installed, tmp_path):
    """The fresh environment imports tcsim from the wheel, sees no source tree and no cargo, and
    finds the library the wheel carries."""
    home = Path(installed["home"])
    p = subprocess.run(
        [installed["python"], "-c", PROBE], capture_output=True, text=True, env=installed["env"], cwd=tmp_path
    )
    assert p.returncode == 0, p.stderr
    probe = json.loads(p.stdout)
    assert Path(probe["tcsim"]).is_relative_to(home), probe
    assert probe["root"] is None and probe["cargo"] is None, probe
    [lib] = probe["libraries"]
    assert Path(lib).is_relative_to(home) and Path(lib).parent.name == "_fmu", probe


def _library_links_no_python(lib: Path) -> None:
    """The FMU library needs no libpython and no Py* symbol (``ldd``/``nm`` where present)."""
    if shutil.which("ldd"):
        assert "libpython" not in subprocess.run(["ldd", lib], capture_output=True, text=True).stdout
    if shutil.which("nm"):
        undefined = subprocess.run(["nm", "-D", "--undefined-only", lib], capture_output=True, text=True).stdout
        assert not [ln for ln in undefined.splitlines() if ln.split()[-1].startswith(("Py", "_Py"))]


def test_export_from_the_installed_wheel_without_cargo(installed, tmp_path):
    """``tcsim export-fmu`` of the installed copy: exit 0 with no warning, the FMU carries the
    packaged library and its Rust sources, validates, and simulates in Co-Simulation and Model
    Exchange within the 0.5 % tube of the replay run."""
    out = tmp_path / "out" / "ht.fmu"
    command = [Path(installed["home"]) / "bin" / "tcsim", "export-fmu", CONVERTER, "--model", MODEL, "-o", out]
    start = time.perf_counter()
    p = subprocess.run(command, capture_output=True, text=True, env=installed["env"], cwd=tmp_path, timeout=600)
    print(f"\nexport-fmu from the installed wheel, no cargo: {time.perf_counter() - start:.2f} s")
    assert p.returncode == 0 and "warning" not in p.stderr.lower(), (p.stdout, p.stderr)
    with zipfile.ZipFile(out) as zf:
        names = set(zf.namelist())
        binary = zf.read("binaries/linux64/tcsim_converter.so")
    site_lib = next(Path(installed["home"]).rglob("tcsim/_fmu/libtcsim_fmu.so"))
    assert binary == site_lib.read_bytes()
    _library_links_no_python(site_lib)
    for name in (
        "sources/README.md",
        "sources/Cargo.toml",
        "sources/Cargo.lock",
        "sources/crates/tcsim-fmu/src/lib.rs",
    ):
        assert name in names, sorted(names)
    assert "sources/crates/tcsim-core/Cargo.toml" in names and not any("tcsim-py" in n for n in names)
    assert validate_fmu(str(out)) == []
    _simulates_like_replay(out)


def _simulates_like_replay(path: Path) -> None:
    """FMPy in both interfaces, a pump-torque ramp at rising turbine speed, against the engine run
    with the same inputs: within TUBE of the range, ±1 output interval (1 ms)."""
    t = np.round(np.arange(0.0, 2.0 + 1e-9, 1e-3), 6)
    tp, wt = np.interp(t, [0.0, 0.1, 0.3, 2.0], [40.0, 40.0, 250.0, 250.0]), 32.0 * t
    ref = simulate(
        CONVERTER,
        PumpTorqueTurbineSpeed(
            [0.0, 0.1, 0.3, 2.0], [40.0, 40.0, 250.0, 250.0], [0.0, 3.2, 9.6, 64.0], derivative_window_s=0.0
        ),
        model=MODEL,
        times_s=t,
    )
    names = ("pump_torque_nm", "turbine_speed_rad_s", "turbine_accel_rad_s2")
    inp = np.array(list(zip(t, tp, wt, np.full_like(t, 32.0))), dtype=[("time", float)] + [(n, float) for n in names])
    for fmi_type in ("CoSimulation", "ModelExchange"):
        res = fmpy.simulate_fmu(str(path), fmi_type=fmi_type, input=inp, output_interval=1e-3, stop_time=2.0)
        assert res["time"][-1] == pytest.approx(2.0)
        later = res["time"] > 1.5e-3  # at t = 0 a co-simulation cannot know the turbine's rate
        for col in ("pump_speed_rad_s", "turbine_torque_nm"):
            span = float(np.ptp(ref[col]))
            for ti, yi in zip(res["time"][later], res[col][later]):
                near = ref[col][np.abs(ref["time_s"] - ti) <= 1e-3 + 1e-9]
                assert near.min() - TUBE * span <= yi <= near.max() + TUBE * span, (fmi_type, col, ti, yi)
