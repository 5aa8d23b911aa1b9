"""The vehicle file's physical ranges (``crates/tcsim-core/src/vehicle/parameters.rs``): each value
that once made ``tcsim launch`` fail in the solver (exit 1) is now refused when the file is read
(exit 2), with one line naming the file and the field as the file writes it, and nothing written.

The cases are the bundled vehicle with one field multiplied by a factor of 1e30, 1e6, 1e-6 or 1e-30
(arrays: every value), those of the probe that gave exit 1 before the ranges.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BUNDLED = REPO / "python" / "tcsim" / "data" / "vehicles" / "midsize-awd-8at.toml"

# (section, key, factor) -> the field the message names
FORMER_EXIT_1 = {
    ("engine", "full_load_torque_nm", 1e30): "[engine].full_load_torque_nm[0]",
    ("engine", "fast_time_constant_s", 1e-30): "[engine].fast_time_constant_s",
    ("engine", "boost_time_constant_s", 1e-30): "[engine].boost_time_constant_s",
    ("gearbox", "ratios", 1e30): "[gearbox].ratios[0]",
    ("gearbox", "ratios", 1e6): "[gearbox].ratios[0]",
    ("gearbox", "output_inertia_kg_m2", 1e-6): "[gearbox].output_inertia_kg_m2",
    ("gearbox", "output_inertia_kg_m2", 1e-30): "[gearbox].output_inertia_kg_m2",
    ("gearbox", "shift_clutch_capacity_nm", 1e30): "[gearbox].shift_clutch_capacity_nm",
    ("lockup", "capacity_nm", 1e30): "[lockup].capacity_nm",
    ("lockup", "capacity_nm", 1e6): "[lockup].capacity_nm",
    ("driveline", "final_drive_ratio", 1e30): "[driveline].final_drive_ratio",
    ("driveline", "final_drive_ratio", 1e6): "[driveline].final_drive_ratio",
    ("driveline", "front_shaft_stiffness_nm_per_rad", 1e30): "[driveline].front_shaft_stiffness_nm_per_rad",
    ("driveline", "rear_shaft_stiffness_nm_per_rad", 1e30): "[driveline].rear_shaft_stiffness_nm_per_rad",
    ("driveline", "front_shaft_damping_nm_s_per_rad", 1e30): "[driveline].front_shaft_damping_nm_s_per_rad",
    ("driveline", "rear_shaft_damping_nm_s_per_rad", 1e30): "[driveline].rear_shaft_damping_nm_s_per_rad",
    ("driveline", "rear_shaft_damping_nm_s_per_rad", 1e6): "[driveline].rear_shaft_damping_nm_s_per_rad",
    ("driveline", "front_axle_inertia_kg_m2", 1e-30): "[driveline].front_axle_inertia_kg_m2",
    ("driveline", "rear_axle_inertia_kg_m2", 1e-30): "[driveline].rear_axle_inertia_kg_m2",
    ("tyres", "rolling_radius_m", 1e30): "[tyres].rolling_radius_m",
    ("tyres", "rolling_radius_m", 1e6): "[tyres].rolling_radius_m",
    ("tyres", "slip_stiffness", 1e30): "[tyres].slip_stiffness",
    ("tyres", "slip_stiffness", 1e6): "[tyres].slip_stiffness",
    ("body", "mass_kg", 1e30): "[body].mass_kg",
    ("body", "drag_area_m2", 1e30): "[body].drag_area_m2",
    ("body", "mass_kg", 1e-30): "[body].mass_kg",
    ("body", "air_density_kg_m3", 1e30): "[body].air_density_kg_m3",
    ("engine", "idle_governor_gain_nm_s_per_rad", 1e6): "[engine].idle_governor_gain_nm_s_per_rad",
    ("engine", "idle_governor_gain_nm_s_per_rad", 1e30): "[engine].idle_governor_gain_nm_s_per_rad",
}


def scaled(section: str, key: str, factor: float) -> str:
    """The bundled vehicle's text with ``[section].key`` (every value of an array) times ``factor``."""
    value = tomllib.loads(BUNDLED.read_text(encoding="utf-8"))[section][key]
    new = f"[{', '.join(repr(v * factor) for v in value)}]" if isinstance(value, list) else repr(value * factor)
    lines, current = [], ""
    for line in BUNDLED.read_text(encoding="utf-8").splitlines():
        if m := re.match(r"^\[(\w+)\]", line):
            current = m.group(1)
        if current == section and re.match(rf"^{key}\s*=", line):
            line = f"{key} = {new}"
        lines.append(line)
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    ("section", "key", "factor", "field"),
    [pytest.param(s, k, f, name, id=f"{s}.{k}*{f:g}") for (s, k, f), name in FORMER_EXIT_1.items()],
)
def test_a_former_solver_failure_is_refused_naming_the_field(cli, tmp_path, section, key, factor, field):
    veh = tmp_path / "veh.toml"
    veh.write_text(scaled(section, key, factor), encoding="utf-8")
    r = cli("launch", "veh.toml", "--model", "table", "--out", "out", cwd=tmp_path)
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.code == 2, (r.code, r.stderr)
    assert len(lines) == 1 and lines[0].startswith("error: veh.toml: "), lines
    assert f" {field} = " in lines[0] and "expected a finite number" in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["veh.toml"], "the run wrote a file"
