"""Transient simulation of an isolated converter: models, drives, one-line and batch runs.

The engine is the Rust core's (:mod:`tcsim._core`): diffsol's BDF solver on the models in
mass-matrix form, with root finding for the stator one-way clutch and for flow reversal.
See ``docs/transient.md`` for the equations, events and conventions.

API tiers (after FMPy):

* one line: :func:`simulate` (a converter, a model name and a drive → :class:`TransientResult`);
* reusable objects: :func:`dynamic_model` → :class:`DynamicModel` (with
  :meth:`DynamicModel.with_shape_effects` for sweeps), drives :class:`PumpTorqueTurbineSpeed`,
  :class:`Speeds`, :class:`PumpTorqueLoad`;
* batch: :func:`simulate_batch`, N models × one drive, one model × N drives, or N pairs, with the
  GIL released and one worker per core;
* raw: ``tcsim._core.transient_runs`` with the dicts of :meth:`DynamicModel.spec` and ``Drive.spec``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Union

import numpy as np
import pandas as pd

from . import _core
from .converter import MODELS, Converter, load_converter
from .errors import InputError, core_value

#: Default width of the smoothing window of measured-speed derivatives, s (see docs/transient.md).
DERIVATIVE_WINDOW_S = 0.04
#: Pump speed at which the default quasi-dynamic flow time constant is evaluated (stall), rad/s.
FLOW_TIME_CONSTANT_PUMP_SPEED_RAD_S = 2000.0 * math.pi / 30.0

COLUMNS: tuple[str, ...] = tuple(_core.transient_columns())


class SolverError(RuntimeError):
    """The solver failed (not the user's fault): the message gives the time and the state."""


# ---------------------------------------------------------------------------------------------
# Models


@dataclass(frozen=True)
class DynamicModel:
    """A converter model ready for the transient engine.

    ``spec`` is the dict the core takes; ``source`` names the converter file for messages.
    """

    name: str
    spec: dict[str, Any]
    source: str

    @property
    def shape_effect_m2(self) -> tuple[float, ...]:
        """The shape effects (pump, turbine[, stator]); empty for the table model."""
        return tuple(self.spec.get("shape_effect_m2", ()))

    def with_shape_effects(self, pump_m2: float, turbine_m2: float, stator_m2: float | None = None) -> DynamicModel:
        """The same model with other shape effects (eqs 2.16–2.18 sign convention)."""
        if self.name == "table":
            raise ValueError("the table model has no shape effects")
        shape = [pump_m2, turbine_m2]
        if self.name == "hrovat-tobler":
            shape.append(self.shape_effect_m2[2] if stator_m2 is None else stator_m2)
        return replace(self, spec={**self.spec, "shape_effect_m2": [float(s) for s in shape]})


def _require(conv: Converter, section: str, model: str) -> Any:
    value = getattr(conv, section)
    if value is None:
        raise InputError(conv.path, f"[{section}]", "missing", f"a [{section}] section for the transient {model} model")
    return value


def _table_spec(conv: Converter) -> dict[str, Any]:
    c = conv.characteristic
    return {
        "speed_ratio": c.speed_ratio.tolist(),
        "torque_ratio": c.torque_ratio.tolist(),
        "capacity_factor_nm_s2": c.capacity_factor_nm_s2.tolist(),
    }


def _inertia(conv: Converter, model: str) -> list[float]:
    i = _require(conv, "inertia", model)
    return [i.pump_kg_m2, i.turbine_kg_m2, i.stator_kg_m2]


def default_flow_time_constant_s(conv: Converter) -> float:
    """Default τ_Q of the quasi-dynamic model: the fluid's inertance over the slope of the net head
    with respect to the flow, ``τ_Q = (ρL_f/A) / |∂F_Q/∂Q|``, for the Hrovat & Tobler geometry at
    stall (locked stator) and 2000 rpm pump speed (physics notes §5). It scales as 1/ω_p."""
    g = _require(conv, "geometry", "quasi-dynamic (default flow time constant)")
    wp = FLOW_TIME_CONSTANT_PUMP_SPEED_RAD_S
    flow = float(_core.ht_steady_states(conv.core_geometry(), np.array([wp]), np.array([0.0]))["flow_m3_s"][0])
    rad = math.pi / 180.0
    tp, tt, ts = (math.tan(getattr(g, f"{e}_exit_angle_deg") * rad) for e in ("pump", "turbine", "stator"))
    tpp, ttt, tss = (math.tan(getattr(g, f"{e}_inlet_angle_deg") * rad) for e in ("pump", "turbine", "stator"))
    rp, rs = g.pump_exit_radius_m, g.stator_exit_radius_m
    q = flow / g.flow_area_m2
    # ∂/∂q of eq 2.15's right-hand side divided by ρ, at ω_t = ω_s = 0 (dhead/dq and shock/friction)
    slope = wp * (rp * tp - rs * ts) - (
        g.pump_shock_loss * (-rs * wp + q * (ts - tpp)) * (ts - tpp)
        + g.turbine_shock_loss * (rp * wp + q * (tp - ttt)) * (tp - ttt)
        + g.stator_shock_loss * q * (tt - tss) ** 2
        + g.friction_loss * (3 + tp * tp + tt * tt + ts * ts) * q
    )
    return g.fluid_length_m / abs(slope)


def dynamic_model(converter: Converter | str, model: str = "hrovat-tobler") -> DynamicModel:
    """The transient model ``model`` of a converter (a :class:`Converter`, bundled name or file).

    * ``table``: [characteristic] and [inertia];
    * ``hrovat-tobler``: [geometry] (with fluid length and shape effects) and [inertia];
    * ``quasi-dynamic``: [characteristic], [inertia] and [quasi_dynamic]; the fluid density and
      pump radius come from [quasi_dynamic] or else [geometry], and τ_Q from
      ``flow_time_constant_s`` or else :func:`default_flow_time_constant_s`.
    """
    conv = converter if isinstance(converter, Converter) else load_converter(converter)
    conv.require(model)
    spec: dict[str, Any] = {"kind": model, "inertia_kg_m2": _inertia(conv, model)}
    if model == "table":
        spec.update(_table_spec(conv))
    elif model == "hrovat-tobler":
        g = conv.geometry
        spec.update(
            geometry=conv.core_geometry()[0].tolist(),
            fluid_length_m=g.fluid_length_m,
            shape_effect_m2=[g.pump_shape_effect_m2, g.turbine_shape_effect_m2, g.stator_shape_effect_m2],
        )
    else:
        qd = _require(conv, "quasi_dynamic", model)
        spec.update(_table_spec(conv))
        spec["shape_effect_m2"] = [qd.pump_shape_effect_m2, qd.turbine_shape_effect_m2]
        for key in ("fluid_density_kg_m3", "pump_exit_radius_m"):
            value = getattr(qd, key, None)
            if value is None:
                value = getattr(_require(conv, "geometry", f"quasi-dynamic ({key} is not in [quasi_dynamic])"), key)
            spec[key] = value
        tau = qd.flow_time_constant_s
        spec["flow_time_constant_s"] = tau if tau is not None else default_flow_time_constant_s(conv)
    return DynamicModel(model, spec, conv.path)


def resolve_model(
    converter: Converter | str | DynamicModel | None,
    model: str | DynamicModel,
    allowed: Sequence[str] = MODELS,
    why: str = "",
) -> DynamicModel:
    """A :class:`DynamicModel` given directly (as ``model``, or as ``converter``), or the model named
    ``model`` of ``converter`` (a :class:`Converter`, bundled name or file). A model outside
    ``allowed`` is an InputError on ``--model`` (``why`` explains the restriction)."""
    expected = f"one of {', '.join(allowed)}{why}"
    if isinstance(model, DynamicModel):
        m = model
    elif isinstance(converter, DynamicModel):
        m = converter
    else:
        if model not in allowed:
            raise InputError("command line", "--model", model, expected)
        m = dynamic_model(converter, model)
    if m.name not in allowed:
        raise InputError("command line", "--model", m.name, expected)
    return m


# ---------------------------------------------------------------------------------------------
# Drives


def _arr(x) -> list[float] | float:
    if np.isscalar(x):
        return float(x)
    return np.asarray(x, dtype=float).tolist()


@dataclass(frozen=True)
class PumpTorqueTurbineSpeed:
    """Drive (a), the thesis/VSIM causality: pump torque and turbine speed given (time series);
    pump speed and turbine torque come out. The turbine speed's derivative is smoothed over
    ``derivative_window_s`` (local least-squares slope)."""

    time_s: np.ndarray
    pump_torque_nm: np.ndarray
    turbine_speed_rad_s: np.ndarray
    derivative_window_s: float = DERIVATIVE_WINDOW_S

    def spec(self) -> dict[str, Any]:
        return {
            "kind": "pump-torque-turbine-speed",
            "time_s": _arr(self.time_s),
            "pump_torque_nm": _arr(self.pump_torque_nm),
            "turbine_speed_rad_s": _arr(self.turbine_speed_rad_s),
            "derivative_window_s": self.derivative_window_s,
        }


@dataclass(frozen=True)
class Speeds:
    """Drive (b): pump and turbine speeds given; the torques come out."""

    time_s: np.ndarray
    pump_speed_rad_s: np.ndarray
    turbine_speed_rad_s: np.ndarray
    derivative_window_s: float = DERIVATIVE_WINDOW_S

    def spec(self) -> dict[str, Any]:
        return {
            "kind": "speeds",
            "time_s": _arr(self.time_s),
            "pump_speed_rad_s": _arr(self.pump_speed_rad_s),
            "turbine_speed_rad_s": _arr(self.turbine_speed_rad_s),
            "derivative_window_s": self.derivative_window_s,
        }


@dataclass(frozen=True)
class PumpTorqueLoad:
    """Drive (c): pump torque given; the turbine drives a load inertia against
    ``load_torque_nm + load_drag_nm_s2·ω_t|ω_t|``. Both speeds come out."""

    time_s: np.ndarray
    pump_torque_nm: np.ndarray
    load_inertia_kg_m2: float
    load_torque_nm: np.ndarray | float = 0.0
    load_drag_nm_s2: float = 0.0

    def spec(self) -> dict[str, Any]:
        return {
            "kind": "pump-torque-load",
            "time_s": _arr(self.time_s),
            "pump_torque_nm": _arr(self.pump_torque_nm),
            "load_torque_nm": _arr(self.load_torque_nm),
            "load_inertia_kg_m2": float(self.load_inertia_kg_m2),
            "load_drag_nm_s2": float(self.load_drag_nm_s2),
        }


Drive = Union[PumpTorqueTurbineSpeed, Speeds, PumpTorqueLoad]


def isolated_takeoff(tip_out: bool = False) -> PumpTorqueLoad:
    """The isolated take-off of the tests and benchmarks (drive c), 0–10 s: pump torque 40 N·m,
    ramped to 250 N·m over 0.1–0.3 s (with ``tip_out``, down to −30 N·m over 5.0–5.1 s); the
    turbine drives 1.2 kg·m² against 10 N·m and 0.002 N·m/(rad/s)²."""
    t = [0.0, 0.1, 0.3] + ([5.0, 5.1] if tip_out else []) + [10.0]
    tp = [40.0, 40.0, 250.0] + ([250.0, -30.0, -30.0] if tip_out else [250.0])
    return PumpTorqueLoad(np.array(t), np.array(tp), load_inertia_kg_m2=1.2, load_torque_nm=10.0, load_drag_nm_s2=0.002)


# ---------------------------------------------------------------------------------------------
# Runs


@dataclass(frozen=True)
class Event:
    time_s: float
    kind: str  # stator-release, stator-lock, flow-zero, flow-start
    stator_locked: bool
    flow_direction: float  # after the event: +1, −1, 0 (held at zero)


@dataclass
class TransientResult:
    """Columns of a run (SI, names per conventions.md; see :data:`COLUMNS`) and its events."""

    model: str
    columns: dict[str, np.ndarray]
    events: list[Event] = field(default_factory=list)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def frame(self) -> pd.DataFrame:
        """The columns as a DataFrame, without the all-NaN columns of coordinates the model lacks."""
        df = pd.DataFrame(self.columns)
        return df.loc[:, df.notna().any() | (df.columns == "time_s")]


def _options(rtol: float | None, **extra) -> dict[str, Any]:
    o = dict(extra)
    if rtol is not None:
        o["rtol"] = rtol
    return o


def _unpack(entry, model: DynamicModel, index: int | None) -> TransientResult:
    status = entry[0]
    where = "" if index is None else f" (run {index})"
    if status == "ok":
        _, cols, events = entry
        return TransientResult(model.name, dict(cols), [Event(*e) for e in events])
    if status == "input":
        _, _msg, fld, value, expected = entry
        raise InputError(model.source, fld + where, core_value(value), expected)
    raise SolverError(f"{model.name}{where}: {entry[1]}")


def _initial(initial: dict[str, float] | None) -> dict[str, float] | None:
    allowed = {"pump_speed_rad_s", "turbine_speed_rad_s", "stator_speed_rad_s", "flow_m3_s"}
    if initial:
        bad = set(initial) - allowed
        if bad:
            raise InputError(
                "initial state", sorted(bad)[0], initial[sorted(bad)[0]], f"one of {', '.join(sorted(allowed))}"
            )
    return initial


def simulate(
    converter: Converter | str | DynamicModel,
    drive: Drive,
    model: str = "hrovat-tobler",
    times_s: Sequence[float] | None = None,
    initial: dict[str, float] | None = None,
    rtol: float | None = None,
    **solver_options,
) -> TransientResult:
    """Run one model under one drive; samples at ``times_s`` (default: the drive's time stamps).

    The initial state is the steady state consistent with the first input sample (drive c: with
    the turbine at rest) unless ``initial`` gives ``pump_speed_rad_s``, ``turbine_speed_rad_s``,
    ``stator_speed_rad_s`` or ``flow_m3_s``.
    """
    m = converter if isinstance(converter, DynamicModel) else dynamic_model(converter, model)
    return simulate_batch([m], [drive], times_s, initial, rtol, threads=1, **solver_options)[0]


def simulate_batch(
    models: Sequence[DynamicModel],
    drives: Sequence[Drive],
    times_s: Sequence[float] | None = None,
    initial: dict[str, float] | None = None,
    rtol: float | None = None,
    threads: int = 0,
    **solver_options,
) -> list[TransientResult]:
    """Run ``models[i]`` under ``drives[i]``; a sequence of length one is broadcast. The runs go to
    the core in one call, which releases the GIL and uses ``threads`` workers (0: all cores).
    Raises :class:`InputError` or :class:`SolverError` for the first run that fails."""
    specs = []
    for d in drives:
        s = d.spec()
        if times_s is not None:
            s["output_time_s"] = np.asarray(times_s, dtype=float).tolist()
        specs.append(s)
    try:
        raw = _core.transient_runs(
            [m.spec for m in models], specs, _initial(initial), _options(rtol, **solver_options), threads
        )
    except _core.CoreInputError as e:
        _msg, fld, value, expected = e.args
        raise InputError(
            models[0].source if len(models) == 1 else "model or drive", fld, core_value(value), expected
        ) from None
    n = len(raw)
    return [_unpack(r, models[i if len(models) > 1 else 0], i if n > 1 else None) for i, r in enumerate(raw)]
