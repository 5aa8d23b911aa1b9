"""Transient simulation of an isolated converter (documented path ``tcsim.transient``, kept as a facade).

The code lives in :mod:`tcsim.models.dynamic` (models), :mod:`tcsim.models.drives` (drives) and
:mod:`tcsim.simulation.transient` (runs); see ``docs/transient.md``.
"""

from __future__ import annotations

from .models.drives import DERIVATIVE_WINDOW_S, Drive, PumpTorqueLoad, PumpTorqueTurbineSpeed, Speeds, isolated_takeoff
from .models.dynamic import (
    FLOW_TIME_CONSTANT_PUMP_SPEED_RAD_S,
    DynamicModel,
    default_flow_time_constant_s,
    dynamic_model,
    resolve_model,
)
from .simulation.transient import (
    COLUMNS,
    EVENT_KINDS,
    RUN_INPUT_ERROR,
    RUN_OK,
    RUN_OVERFLOW,
    RUN_SOLVER_ERROR,
    BatchColumns,
    Event,
    SolverError,
    TransientResult,
    simulate,
    simulate_batch,
    simulate_columns,
)

__all__ = [
    "COLUMNS",
    "EVENT_KINDS",
    "RUN_INPUT_ERROR",
    "RUN_OK",
    "RUN_OVERFLOW",
    "RUN_SOLVER_ERROR",
    "BatchColumns",
    "DERIVATIVE_WINDOW_S",
    "FLOW_TIME_CONSTANT_PUMP_SPEED_RAD_S",
    "Drive",
    "DynamicModel",
    "Event",
    "PumpTorqueLoad",
    "PumpTorqueTurbineSpeed",
    "SolverError",
    "Speeds",
    "TransientResult",
    "default_flow_time_constant_s",
    "dynamic_model",
    "isolated_takeoff",
    "resolve_model",
    "simulate",
    "simulate_batch",
    "simulate_columns",
]
