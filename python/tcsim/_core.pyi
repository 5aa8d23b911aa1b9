"""Typed stub of the PyO3 extension ``tcsim._core`` (``crates/tcsim-py/src/lib.rs``).

Arrays are float64 NumPy arrays; speeds in rad/s, torques in N·m, flows in m³/s. Every function
raises :class:`CoreInputError` for input the core refuses (``ValueError`` for wrong shapes).
"""

from collections.abc import Sequence
from typing import Any, TypeAlias

import numpy as np
import numpy.typing as npt

_Array: TypeAlias = npt.NDArray[np.float64]
_ArrayLike: TypeAlias = npt.ArrayLike
#: One run of a batch, a tuple tagged by its first item: ("ok", {column: array}, [event tuple]),
#: ("input", message, field, value, expected) or ("solver", message).
_RunEntry: TypeAlias = tuple[Any, ...]

class CoreInputError(ValueError):
    """Bad input to the tcsim core: args are (message, field, value, expected)."""

def capacity_conventions() -> list[str]: ...
def capacity_to_cf(convention_key: str, values: _ArrayLike) -> _Array: ...
def cf_to_capacity(convention_key: str, cf: _ArrayLike) -> _Array: ...
def ht_parameter_names() -> list[str]: ...
def ht_check_geometry(geometry: _ArrayLike) -> None: ...
def ht_steady_states(
    geometry: _ArrayLike, pump_speed_rad_s: _ArrayLike, turbine_speed_rad_s: _ArrayLike, strict: bool = True
) -> dict[str, Any]: ...
def ht_coupling_point(geometry: _ArrayLike) -> float | None: ...
def ht_ratio_gradients(
    geometry: _ArrayLike, pump_speed_rad_s: float, speed_ratio: _ArrayLike, free: list[str]
) -> tuple[_Array, _Array, _Array, _Array]: ...
def table_check(speed_ratio: _ArrayLike, torque_ratio: _ArrayLike, capacity_factor_nm_s2: _ArrayLike) -> None: ...
def table_steady_states(
    speed_ratio: _ArrayLike,
    torque_ratio: _ArrayLike,
    capacity_factor_nm_s2: _ArrayLike,
    pump_speed_rad_s: _ArrayLike,
    turbine_speed_rad_s: _ArrayLike,
) -> dict[str, Any]: ...
def smoothed_rate(time_s: _ArrayLike, values: _ArrayLike, window_s: float) -> _Array: ...
def transient_columns() -> list[str]: ...
def transient_runs(
    models: list[dict[str, Any]],
    drives: list[dict[str, Any]],
    init: dict[str, float] | None = None,
    options: dict[str, Any] | None = None,
    threads: int = 0,
) -> list[_RunEntry]: ...
def launch_columns() -> list[str]: ...
def launch_runs(
    models: list[dict[str, Any]],
    vehicle: dict[str, Any],
    scenario: dict[str, Any],
    options: dict[str, Any] | None = None,
    threads: int = 0,
) -> list[_RunEntry]: ...

# physics owned by the core (one owner per fact)
def default_flow_time_constant_s(geometry: _ArrayLike, fluid_length_m: float) -> float: ...
def reference_pump_speed_rpm() -> float: ...
def reference_pump_speed_rad_s() -> float: ...
def mass_matrix_bound(
    geometry: _ArrayLike,
    fluid_length_m: float,
    inertia_kg_m2: Sequence[float],
    shape_effect_m2: Sequence[float],
) -> dict[str, Any]: ...
def steady_mode_names() -> dict[int, str]: ...
def steady_torque_ratio(
    stator_mode: npt.NDArray[np.int8], pump_torque_nm: _ArrayLike, turbine_torque_nm: _ArrayLike
) -> _Array: ...
def vehicle_engine_drag_nm(speed_rad_s: float, drag_torque_nm: float, drag_nm_s_per_rad: float) -> float: ...
