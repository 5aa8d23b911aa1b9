"""Driver of the C + SUNDIALS CVODE peer of the isolated take-off (``bench/cvode_peer/takeoff.c``).

Not part of the package or the test suite. :func:`build` compiles the peer with
``bench/cvode_peer/build.sh`` (gcc and Debian's ``libsundials-dev``, CVODE 6.x) when the binary is
missing or older than its source; :func:`run` runs it in a subprocess on the parameters of
``scipy_reference.load_parameters()`` and a scenario of ``scipy_reference.takeoff_scenario()``, and
returns the peer's own timing (median and fastest of ``repeats`` runs after a warm-up, measured with
its monotonic clock, so process start-up is excluded), its solver statistics, events and samples.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent / "cvode_peer"
BINARY = HERE / "takeoff"
SAMPLE_COLUMNS = (
    "time_s",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
    "stator_speed_rad_s",
    "flow_m3_s",
    "pump_torque_nm",
    "turbine_torque_nm",
    "stator_torque_nm",
    "loss_power_w",
)
#: The same quantities' columns in tcsim (:data:`tcsim.transient.COLUMNS`): what tcsim is asked for
#: when it is timed against the peer with the same outputs (``simulate(..., columns=TCSIM_COLUMNS)``).
TCSIM_COLUMNS = tuple({"loss_power_w": "fluid_loss_power_w"}.get(c, c) for c in SAMPLE_COLUMNS)


class PeerUnavailable(RuntimeError):
    """The peer cannot be built here (no gcc or no SUNDIALS headers and libraries)."""


def available() -> bool:
    """Whether the peer can be built here: gcc and the CVODE headers."""
    return shutil.which("gcc") is not None and Path("/usr/include/cvode/cvode.h").exists()


def build(binary: Path = BINARY) -> Path:
    """The peer's binary at ``binary``, compiled first if missing or older than its source."""
    source = HERE / "takeoff.c"
    if binary.exists() and binary.stat().st_mtime >= source.stat().st_mtime:
        return binary
    if not available():
        raise PeerUnavailable("needs gcc and libsundials-dev (apt-get install -y libsundials-dev)")
    done = subprocess.run(["sh", str(HERE / "build.sh"), str(binary)], capture_output=True, text=True)
    if done.returncode != 0:
        raise PeerUnavailable(f"build failed: {done.stderr.strip()}")
    return binary


def parameter_text(params: dict, scenario: dict) -> str:
    """The peer's stdin: one ``name value`` line per parameter, the pump torque table, the end time."""
    lines = [f"{k} {float(v)!r}" for k, v in params.items()]
    lines += [
        f"IL {float(scenario['load_inertia_kg_m2'])!r}",
        f"T0 {float(scenario['load_torque_nm'])!r}",
        f"cd {float(scenario['load_drag_nm_s2'])!r}",
        f"t_end {float(scenario['t_span'][1])!r}",
    ]
    for name, key in (("table_t", "pump_torque_times_s"), ("table_T", "pump_torque_nm")):
        values = [float(v) for v in scenario[key]]
        lines.append(f"{name} {len(values)} " + " ".join(repr(v) for v in values))
    if scenario["t_span"][0] != 0.0 or scenario["turbine_speed0_rad_s"] != 0.0:
        raise ValueError("the peer starts at t = 0 from a turbine at rest")
    return "\n".join(lines) + "\n"


def run(params: dict, scenario: dict, repeats: int, samples: int, binary: Path = BINARY) -> dict:
    """Run the peer: ``median_s``, ``fastest_s`` per run, ``stats`` (steps, rhs, jac, lu, roots: CVODE's
    counters summed over the run's segments), ``events`` [(time_s, kind)] and the sample columns
    (:data:`SAMPLE_COLUMNS`, equally spaced over the scenario's span) as arrays."""
    done = subprocess.run(
        [str(build(binary)), str(repeats), str(samples)],
        input=parameter_text(params, scenario),
        capture_output=True,
        text=True,
        timeout=600,
    )
    if done.returncode != 0:
        raise RuntimeError(f"CVODE peer exit status {done.returncode}: {done.stderr.strip()}")
    out: dict = {"events": []}
    rows = []
    for line in done.stdout.splitlines():
        tag, *fields = line.split()
        if tag == "timing":
            out["median_s"], out["fastest_s"] = float(fields[0]), float(fields[1])
        elif tag == "stats":
            out["stats"] = dict(zip(("steps", "rhs", "jac", "lu", "roots"), map(int, fields)))
        elif tag == "event":
            out["events"].append((float(fields[0]), fields[1]))
        elif tag == "sample":
            rows.append([float(v) for v in fields])
    table = np.array(rows)
    out.update({name: table[:, i] for i, name in enumerate(SAMPLE_COLUMNS)})
    return out
