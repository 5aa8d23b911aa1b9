"""Typed stub of the PyO3 extension ``tcsim._core`` (``crates/tcsim-py/src/lib.rs``).

Arrays are float64 NumPy arrays; speeds in rad/s, torques in N·m, flows in m³/s. Every function
raises :class:`CoreInputError` for input the core refuses (``ValueError`` for wrong shapes).
"""

from collections.abc import Sequence
from typing import Any, Literal, TypeAlias

import numpy as np
import numpy.typing as npt

_Array: TypeAlias = npt.NDArray[np.float64]
_ArrayLike: TypeAlias = npt.ArrayLike
#: The input a core error is about (``input_sources()``).
InputSourceKey: TypeAlias = Literal["converter", "drive", "initial", "scenario", "vehicle", "options"]

class CoreInputError(ValueError):
    """Bad input to the tcsim core: args are (message, field, value, expected, source), ``source``
    an :data:`InputSourceKey`."""

def input_sources() -> list[str]: ...

class RunError:
    """Why a run of a batch failed: ``kind`` "input" (with source, field, value, expected as in
    :class:`CoreInputError`) or "solver" (message only)."""

    kind: Literal["input", "solver"]
    message: str
    source: InputSourceKey | None
    field: str | None
    value: str | None
    expected: str | None
    def __init__(
        self,
        kind: str,
        message: str,
        source: str | None = None,
        field: str | None = None,
        value: str | None = None,
        expected: str | None = None,
    ) -> None: ...

class TransientEvent:
    """An event of an isolated run; ``flow_direction`` after it: +1, −1 or 0 (held at zero)."""

    time_s: float
    kind: str
    stator_locked: bool
    flow_direction: float
    def __init__(self, time_s: float, kind: str, stator_locked: bool, flow_direction: float) -> None: ...

class LaunchEvent:
    """An event of a launch run (gear shifts, lock-up, converter events) and the gear after it."""

    time_s: float
    kind: str
    gear: int
    def __init__(self, time_s: float, kind: str, gear: int) -> None: ...

class TransientRun:
    """One run of :func:`transient_runs`: columns and events if ``ok``, else ``error``."""

    ok: bool
    columns: dict[str, _Array]
    events: list[TransientEvent]
    error: RunError | None
    def __init__(
        self,
        columns: dict[str, _Array] | None = None,
        events: Sequence[TransientEvent] = (),
        error: RunError | None = None,
    ) -> None: ...

class LaunchRun:
    """One run of :func:`launch_runs`: columns and events if ``ok``, else ``error``."""

    ok: bool
    columns: dict[str, _Array]
    events: list[LaunchEvent]
    error: RunError | None
    def __init__(
        self,
        columns: dict[str, _Array] | None = None,
        events: Sequence[LaunchEvent] = (),
        error: RunError | None = None,
    ) -> None: ...

def capacity_conventions() -> list[str]: ...
def capacity_to_cf(convention_key: str, values: _ArrayLike) -> _Array: ...
def cf_to_capacity(convention_key: str, cf: _ArrayLike) -> _Array: ...
def ht_parameter_names() -> list[str]: ...
def ht_check_geometry(geometry: _ArrayLike) -> None: ...
def ht_steady_states(
    geometry: _ArrayLike,
    pump_speed_rad_s: _ArrayLike,
    turbine_speed_rad_s: _ArrayLike,
    strict: bool = True,
    threads: int = 0,
) -> dict[str, Any]: ...
def ht_coupling_point(geometry: _ArrayLike) -> float | None: ...
def ht_ratio_gradients(
    geometry: _ArrayLike, pump_speed_rad_s: float, speed_ratio: _ArrayLike, free: list[str]
) -> tuple[_Array, _Array, _Array, _Array]: ...
def table_check(
    speed_ratio: _ArrayLike,
    torque_ratio: _ArrayLike,
    capacity_factor_nm_s2: _ArrayLike,
    overrun: str | None = None,
    interpolation: str | None = None,
    input_torque_nm: list[float] | None = None,
    table_rows: list[float] | None = None,
) -> None: ...
def table_steady_states(
    speed_ratio: _ArrayLike,
    torque_ratio: _ArrayLike,
    capacity_factor_nm_s2: _ArrayLike,
    pump_speed_rad_s: _ArrayLike,
    turbine_speed_rad_s: _ArrayLike,
    overrun: str | None = None,
    interpolation: str | None = None,
    lenient: bool = False,
    input_torque_nm: list[float] | None = None,
    table_rows: list[float] | None = None,
) -> dict[str, Any]: ...
def table_steady_states_at_pump_torque(
    speed_ratio: _ArrayLike,
    torque_ratio: _ArrayLike,
    capacity_factor_nm_s2: _ArrayLike,
    pump_torque_nm: float,
    at_speed_ratio: _ArrayLike,
    overrun: str | None = None,
    interpolation: str | None = None,
    input_torque_nm: list[float] | None = None,
    table_rows: list[float] | None = None,
) -> dict[str, Any]: ...
def ht_pump_speeds_at_pump_torque(geometry: _ArrayLike, pump_torque_nm: float, speed_ratio: _ArrayLike) -> _Array: ...
def table_operating_points(
    speed_ratio: _ArrayLike,
    torque_ratio: _ArrayLike,
    capacity_factor_nm_s2: _ArrayLike,
    turbine_speed_rad_s: _ArrayLike,
    turbine_torque_nm: _ArrayLike | None = None,
    pump_speed_limit_rad_s: float | None = None,
    overrun: str | None = None,
    interpolation: str | None = None,
    threads: int = 0,
    turbine_power_w: _ArrayLike | None = None,
) -> dict[str, Any]: ...
def ht_operating_points(
    geometry: _ArrayLike,
    turbine_speed_rad_s: _ArrayLike,
    turbine_torque_nm: _ArrayLike | None = None,
    pump_speed_limit_rad_s: float | None = None,
    threads: int = 0,
    turbine_power_w: _ArrayLike | None = None,
) -> dict[str, Any]: ...
def operating_point_reasons() -> dict[int, tuple[str, bool]]: ...
def smoothed_rate(time_s: _ArrayLike, values: _ArrayLike, window_s: float) -> _Array: ...
def transient_columns() -> list[str]: ...
def transient_runs(
    models: list[dict[str, Any]],
    drives: list[dict[str, Any]],
    init: dict[str, float] | None = None,
    options: dict[str, Any] | None = None,
    threads: int = 0,
) -> list[TransientRun]: ...
def transient_batch(
    models: list[dict[str, Any]],
    drives: list[dict[str, Any]],
    init: dict[str, float] | None = None,
    options: dict[str, Any] | None = None,
    threads: int = 0,
    columns: list[str] | None = None,
) -> dict[str, Any]: ...
def transient_event_kinds() -> list[str]: ...
def output_value_rules() -> tuple[list[str], list[str]]: ...
def launch_columns() -> list[str]: ...

class Vehicle:
    """A vehicle file read and validated once by the core (``read_vehicle``)."""

    @property
    def file(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def description(self) -> str | None: ...
    @property
    def converter(self) -> str: ...
    @property
    def sources(self) -> dict[str, str]: ...
    def to_dict(self) -> dict[str, Any]: ...

def read_vehicle(text: str, file: str) -> Vehicle: ...
def vehicle_sections() -> list[str]: ...
def vehicle_schema() -> list[dict[str, Any]]: ...
def launch_runs(
    models: list[dict[str, Any]],
    vehicle: Vehicle,
    scenario: dict[str, Any],
    options: dict[str, Any] | None = None,
    threads: int = 0,
) -> list[LaunchRun]: ...
def drive_columns() -> list[str]: ...
def drive_runs(
    models: list[dict[str, Any]],
    vehicle: Vehicle,
    cycle: dict[str, Any],
    options: dict[str, Any] | None = None,
    threads: int = 0,
) -> list[LaunchRun]: ...

# physics owned by the core (one owner per fact)
def default_flow_time_constant_s(geometry: _ArrayLike, fluid_length_m: float) -> float: ...
def qd_coupling_time_constant_bound_s(spec: dict[str, Any]) -> float: ...
def check_model(spec: dict[str, Any]) -> None: ...
def unit_constants() -> dict[str, float]: ...
def lockup_limits() -> tuple[float, str]: ...
def plausibility_ranges() -> list[tuple[str, str, float, float, str]]: ...
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

# The FMU's variable table (crates/tcsim-fmu/src/variables.rs, bound in crates/tcsim-py/src/fmu.rs)

#: ``modelIdentifier`` of the FMU.
FMU_MODEL_IDENTIFIER: str
FMU_LOG_CATEGORIES: list[tuple[str, str]]
#: Value reference of the first tunable parameter.
FMU_FIRST_PARAMETER_VR: int

def fmu_variables(spec: dict[str, Any], causality: str) -> list[dict[str, Any]]:
    """The FMU's variables of a model specification (its ``kind`` is the model) under a causality,
    in ``<ModelVariables>`` order: ``vr``, ``name``, ``causality``, ``variability``, ``initial``,
    ``unit``, ``display_unit``, ``description``, ``start``, ``start_text``, ``derivative_of``,
    ``dependencies``, ``key``, ``index``."""

def fmu_signals() -> list[dict[str, Any]]:
    """The signals by value reference: ``vr``, ``name``, ``unit``, ``description``, ``models``, ``state``."""

def fmu_causalities() -> list[tuple[str, list[str]]]:
    """The ``--causality`` choices with the names of their two inputs."""

def fmu_common_inputs() -> list[str]:
    """The inputs every causality has besides its two (``lockup_capacity_nm``)."""

def fmu_event_indicators(model: str) -> int:
    """``numberOfEventIndicators`` of the FMU of a model kind."""

def fmu_units() -> list[tuple[str, list[tuple[str, int]], list[tuple[str, str]]]]:
    """``<UnitDefinitions>``: name, SI base-unit exponents, display units with their factors as text."""

#: FMI 3.0: value reference of ``time``, the independent variable.
FMU_TIME_VR: int
#: FMI 3.0: the key of ``resources/model.json`` holding the ``instantiationToken``.
FMU_INSTANTIATION_TOKEN_KEY: str

def fmu_event_indicator_variables(model: str) -> list[dict[str, Any]]:
    """FMI 3.0: the event indicators of a model kind as variables (as :func:`fmu_variables`)."""

def time_resolution_s(t: float) -> float: ...
def check_time_stamps(name: str, time_s: np.ndarray) -> None: ...
def ignored_initial(
    model: dict[str, Any], drive: dict[str, Any], initial: dict[str, float]
) -> list[tuple[str, str]]: ...

# issue 15: the geometry of converter designs (tcsim_core::converter::design)
def design_geometries(
    designs: list[dict[str, Any]], points: int = ..., strict: bool = ..., threads: int = ...
) -> dict[str, Any]:
    """The geometry of each design: float64 arrays named by :func:`design_columns` and ``error``,
    per design None or its bad input's message (with ``strict``, CoreInputError instead)."""

def design_columns() -> list[str]:
    """The result columns of :func:`design_geometries`, in order."""

def design_profiles() -> list[str]:
    """``circular``, ``elliptic``, ``polyline``."""

def design_integration() -> tuple[int, int, int, float]:
    """(default, least, most) integration nodes per element, and the polyline tolerance in m."""
