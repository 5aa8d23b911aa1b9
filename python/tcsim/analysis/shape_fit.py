"""Fit shape effects to a transient measurement, and the shape-effect sweep (Li & Sundén 2016 §4.1).

The shape effects S_p and S_t are the only design parameters that carry the fluid dynamics into
the torque equations of the dynamic models (eqs 2.12 and 2.13). The thesis raised them by hand to
match the drop in effective torque ratio during a take-off (§4.1, figures 4.1–4.4); this module

* takes the measured effective torques of eqs 3.3 and 3.4 (:func:`tcsim.analysis.effective.measured_effective_torques`),
* fits (S_p, S_t) by bounded least squares of the simulated against the measured effective
  turbine torque or effective TR (:func:`fit_shape_effects`),
* runs the thesis's sweep over S_p = S_t (:func:`shape_effect_sweep`), plotted like figures
  4.1/4.2 by :func:`tcsim.plots.shape_sweep.plot_shape_effect_sweep`.

Sign convention (eqs 2.12–2.18, docs/physics.md §4): the effective turbine output torque is
``T_transfer,t − ρS_t·Q̇`` and the effective pump input torque ``T_transfer,p + ρS_p·Q̇``, so a
positive S deepens the drop in effective TR while the flow builds up (the thesis's chapter 4).

The Hrovat & Tobler model accepts only shape effects that keep its mass matrix positive definite,
``ρL_f/A > Σ ρ²S_x²/I_x`` (docs/physics.md §4); the quasi-dynamic model has no such bound. See
``docs/shape_fit.md``.
"""

from __future__ import annotations

import contextlib
import math
import time
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd
from scipy.optimize import least_squares

from ..errors import InputError
from ..models.converter import Converter
from ..models.drives import PumpTorqueTurbineSpeed, Speeds
from ..models.dynamic import DynamicModel, NearCouplingWarning, dynamic_model, resolve_model
from ..models.measurement import Measurement
from ..models.shape_effects import THESIS_VALUES_M2, MassMatrixBound, inadmissible_note, mass_matrix_bound
from ..simulation.transient import SolverError, TransientResult, simulate_batch
from .effective import measured_effective_torques

MODELS = ("quasi-dynamic", "hrovat-tobler")
TARGETS = ("effective_turbine_torque_nm", "effective_torque_ratio")
DRIVES = ("pump-torque", "speeds")
#: How the simulated target is made (:func:`fit_shape_effects`): the run's own column (the model's
#: rates), or from the run's speeds by the measured target's filter.
RATES = ("model", "filtered")
#: The columns :func:`measured_effective_torques` takes besides ``time_s``.
EFFECTIVE_CHANNELS = ("pump_torque_nm", "turbine_torque_nm", "pump_speed_rad_s", "turbine_speed_rad_s")
#: Default bounds of the quasi-dynamic shape effects, m² (the thesis went up to 0.4).
QUASI_DYNAMIC_BOUNDS_M2 = (-0.5, 0.5)
#: Default H&T bounds as a fraction of the mass-matrix bound; also the joint condition's margin.
BOUND_FRACTION = 0.98
#: Relative tolerance of the fit's runs: the solver's noise must stay below the finite differences.
FIT_RTOL = 1e-8
#: Finite-difference step of the Jacobian, as a fraction of each parameter's bound span.
FD_STEP = 1e-3
#: Output grid of a sweep whose drive has only a few time stamps, s.
SWEEP_STEP_S = 1e-3


# ---------------------------------------------------------------------------------------------
# shared helpers


def _model(converter: Converter | str | DynamicModel, model: str | DynamicModel) -> DynamicModel:
    """The dynamic model to fit or sweep; only the two models with shape effects."""
    return resolve_model(converter, model, MODELS, " (the table model has no shape effects)")


def _runs(models: Sequence[DynamicModel], drive, times_s, rtol: float | None) -> list[TransientResult | str]:
    """All runs in one batched core call; if one fails, each alone, a failure as its message."""
    if not models:
        return []
    try:
        return list(simulate_batch(models, [drive], times_s, rtol=rtol))
    except (SolverError, InputError):
        if len(models) == 1:
            return [_single(models[0], drive, times_s, rtol)]
        return [_single(m, drive, times_s, rtol) for m in models]


def _single(model: DynamicModel, drive, times_s, rtol) -> TransientResult | str:
    try:
        return simulate_batch([model], [drive], times_s, rtol=rtol, threads=1)[0]
    except (SolverError, InputError) as e:
        return str(e)


# ---------------------------------------------------------------------------------------------
# the fit


@dataclass
class ShapeFitResult:
    """A fit of the shape effects to a transient measurement (Li & Sundén 2016 §4.1)."""

    model: str  # 'quasi-dynamic' or 'hrovat-tobler'
    target: str  # 'effective_turbine_torque_nm' or 'effective_torque_ratio'
    pump_shape_effect_m2: float
    turbine_shape_effect_m2: float
    rmse: float  # of the target at the optimum (N·m or -)
    rmse_at_zero: float  # with S_p = S_t = 0
    evaluations: int  # model runs, Jacobian columns included
    bound_m2: tuple[float, float] | None  # H&T: admissible |S_p|, |S_t| (each with the other at 0)
    pump_bounds_m2: tuple[float, float] = (math.nan, math.nan)
    turbine_bounds_m2: tuple[float, float] = (math.nan, math.nan)
    equal: bool = False
    points: int = 0
    time_window_s: tuple[float, float] = (math.nan, math.nan)
    active: dict[str, str] = field(default_factory=dict)
    message: str = ""
    elapsed_s: float = 0.0

    @property
    def unit(self) -> str:
        return "N·m" if self.target.endswith("_nm") else "-"

    def to_dict(self) -> dict[str, Any]:
        """The numbers of ``shape_fit.json``."""
        return {
            "model": self.model,
            "target": self.target,
            "equal": self.equal,
            "pump_shape_effect_m2": self.pump_shape_effect_m2,
            "turbine_shape_effect_m2": self.turbine_shape_effect_m2,
            "rmse": self.rmse,
            "rmse_at_zero": self.rmse_at_zero,
            "unit": self.unit,
            "bound_m2": list(self.bound_m2) if self.bound_m2 is not None else None,
            "pump_bounds_m2": list(self.pump_bounds_m2),
            "turbine_bounds_m2": list(self.turbine_bounds_m2),
            "active_bounds": dict(self.active),
            "points": self.points,
            "time_window_s": list(self.time_window_s),
            "optimiser": {
                "method": "scipy.optimize.least_squares, trf, batched forward differences",
                "evaluations": self.evaluations,
                "message": self.message,
                "elapsed_s": self.elapsed_s,
            },
        }

    def bound_warnings(self, source: str) -> list[str]:
        """One line per shape effect that ended at a bound of the fit, naming ``source`` (the
        measurement), as ``tcsim fit`` warns of its parameters (a fresh-eyes trial found S_t at
        its lower bound −0.5 m² said only in ``shape_fit.md``)."""
        bounds = {
            "shape_effect_m2": self.pump_bounds_m2,
            "pump_shape_effect_m2": self.pump_bounds_m2,
            "turbine_shape_effect_m2": self.turbine_bounds_m2,
        }
        value = {
            "shape_effect_m2": self.pump_shape_effect_m2,
            "pump_shape_effect_m2": self.pump_shape_effect_m2,
            "turbine_shape_effect_m2": self.turbine_shape_effect_m2,
        }
        return [
            f"{source}: fitted {name} = {value[name]:.5g} m² ends at its {side} bound (bounds "
            f"{bounds[name][0]:.4g} to {bounds[name][1]:.4g} m²): the best fit may lie beyond it"
            for name, side in self.active.items()
        ]

    def one_line(self) -> str:
        return (
            f"{self.model}: S_p = {self.pump_shape_effect_m2:.5g} m², S_t = {self.turbine_shape_effect_m2:.5g} m²; "
            f"RMSE of {self.target} {self.rmse:.4g} {self.unit} (S = 0: {self.rmse_at_zero:.4g}); "
            f"{self.evaluations} runs, {self.elapsed_s:.2f} s"
        )


class _Problem:
    """Residuals (simulated − measured target) over x = (S_p, S_t), or x = (S,) with S_p = S_t.
    Runs are cached by x; points that break the mass-matrix bound (H&T, with the margin
    :data:`BOUND_FRACTION`) or fail in the solver get a large constant residual and never reach
    the core."""

    def __init__(self, model: DynamicModel, drive, times, measured, target, equal, bound, lo, hi, rtol, filtered=None):
        self.model, self.drive, self.times, self.measured = model, drive, times, measured
        self.target, self.equal, self.bound, self.rtol = target, equal, bound, rtol
        # (all measured time stamps, the fit points among them) when the target is re-derived from
        # the run's speeds as the measured one was (rates="filtered"); None: the run's own column
        self.filtered = filtered
        self.run_times = times if filtered is None else filtered[0]
        self.lo, self.hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        self.cache: dict[bytes, np.ndarray | None] = {}
        self.runs = 0
        self.penalty = 1e6

    def shapes(self, x) -> tuple[float, float]:
        x = np.atleast_1d(np.asarray(x, dtype=float))
        return (float(x[0]), float(x[0])) if self.equal else (float(x[0]), float(x[1]))

    def feasible(self, x) -> bool:
        return self.bound is None or self.bound.within(*self.shapes(x), BOUND_FRACTION)

    def evaluate(self, xs: Sequence[np.ndarray]) -> list[np.ndarray | None]:
        """Raw residuals at each x (None: inadmissible or failed); the new ones in one batch."""
        keys = [np.asarray(x, dtype=float).tobytes() for x in xs]
        new: dict[bytes, np.ndarray] = {}
        for k, x in zip(keys, xs):
            if k not in self.cache and k not in new:
                if self.feasible(x):
                    new[k] = x
                else:
                    self.cache[k] = None
        models = [self.model.with_shape_effects(*self.shapes(x)) for x in new.values()]
        self.runs += len(models)
        for k, run in zip(new, _runs(models, self.drive, self.run_times, self.rtol)):
            self.cache[k] = None if isinstance(run, str) else self.simulated(run) - self.measured
        return [self.cache[k] for k in keys]

    def simulated(self, run: TransientResult) -> np.ndarray:
        """The run's target at the fit points: its own column, or (``filtered``) the effective
        torques of its speeds and torques by :func:`measured_effective_torques`, the function and
        filter that made the measured target, at every measured time stamp."""
        if self.filtered is None:
            return run[self.target]
        inertia = self.model.spec["inertia_kg_m2"]
        channels = {c: run[c] for c in ("time_s", *EFFECTIVE_CHANNELS)}
        return measured_effective_torques(channels, inertia[1], inertia[0])[self.target][self.filtered[1]]

    def fun(self, x) -> np.ndarray:
        r = self.evaluate([x])[0]
        return np.full(len(self.times), self.penalty) if r is None or not np.isfinite(r).all() else r

    def jac(self, x) -> np.ndarray:
        """Forward differences (backward at an upper bound or at the admissible edge), all
        columns in one batched core call."""
        x = np.asarray(x, dtype=float)
        steps = FD_STEP * (self.hi - self.lo)
        plus = [x + steps[i] * np.eye(len(x))[i] for i in range(len(x))]
        minus = [x - steps[i] * np.eye(len(x))[i] for i in range(len(x))]
        forward = [bool(p[i] <= self.hi[i] and self.feasible(p)) for i, p in enumerate(plus)]
        points = [p if f else m for p, m, f in zip(plus, minus, forward)]
        f0, *cols = self.evaluate([x, *points])
        jac = np.zeros((len(self.times), len(x)))
        for i, (col, fwd) in enumerate(zip(cols, forward)):
            if f0 is not None and col is not None:
                jac[:, i] = (col - f0) / (steps[i] if fwd else -steps[i])
        return np.nan_to_num(jac, nan=0.0, posinf=0.0, neginf=0.0)


def _check_bounds(name: str, given, default: tuple[float, float], bound: float | None) -> tuple[float, float]:
    if given is None:
        return default
    lo, hi = (float(v) for v in given)
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise InputError("command line", name, f"{lo:g}:{hi:g}", "finite bounds LO < HI, m²")
    if bound is not None and max(abs(lo), abs(hi)) >= bound:
        raise InputError(
            "command line",
            name,
            f"{lo:g}:{hi:g}",
            f"bounds within the admissible ±{bound:.4g} m² of the Hrovat & Tobler model "
            "(mass matrix positive definite, docs/physics.md §4)",
        )
    return lo, hi


def _fit_bounds(bound: MassMatrixBound | None, pump_bounds, turbine_bounds, equal: bool):
    """Box bounds of (S_p, S_t): the user's, else ±0.98·the admissible bound (H&T) or ±0.5 m²."""
    if bound is None:
        single = None
        dp = dt = QUASI_DYNAMIC_BOUNDS_M2
    else:
        single = (bound.equal(), bound.equal()) if equal else bound.single()
        dp, dt = ((-BOUND_FRACTION * b, BOUND_FRACTION * b) for b in single)
    return (
        single,
        _check_bounds("pump_bounds", pump_bounds, dp, single and single[0]),
        _check_bounds("turbine_bounds", turbine_bounds, dt, single and single[1]),
    )


def _fit_points(measured_time_s, measured_target, time_window) -> np.ndarray:
    """The fit points among the measured samples: finite, within ``time_window`` (a boolean mask)."""
    t, y = np.asarray(measured_time_s, dtype=float), np.asarray(measured_target, dtype=float)
    if t.shape != y.shape:
        raise InputError("measurement", "target", f"{len(y)} values", f"as many as the time stamps ({len(t)})")
    keep = np.isfinite(t) & np.isfinite(y)
    if time_window is not None:
        keep &= (t >= time_window[0]) & (t <= time_window[1])
    if keep.sum() < 3:
        raise InputError("measurement", "time_window", time_window, "at least 3 finite target samples to fit")
    return keep


def _filtered(rates: str, measured_time_s, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """``rates`` of :func:`fit_shape_effects`: None for "model", else (every measured time stamp,
    the fit points among them) for "filtered"."""
    if rates not in RATES:
        raise InputError.argument("rates", rates, f"one of {', '.join(RATES)}")
    if rates == "model":
        return None
    t = np.asarray(measured_time_s, dtype=float)
    if not np.isfinite(t).all():
        raise InputError("measurement", "time_s", "a non-finite time stamp", 'finite time stamps (rates="filtered")')
    return t, keep


def _rmse(r: np.ndarray | None) -> float:
    return math.nan if r is None else float(np.sqrt(np.mean(r**2)))


def _active(x, lo, hi, names) -> dict[str, str]:
    span = np.asarray(hi) - np.asarray(lo)
    out = {}
    for n, xi, low, high, width in zip(names, x, lo, hi, span):
        if xi - low <= 1e-6 * width:
            out[n] = "lower"
        elif high - xi <= 1e-6 * width:
            out[n] = "upper"
    return out


def fit_shape_effects(
    converter: Converter | str | DynamicModel,
    model: str | DynamicModel,
    drive,
    measured_time_s,
    measured_target,
    target: str = "effective_turbine_torque_nm",
    pump_bounds: tuple[float, float] | None = None,
    turbine_bounds: tuple[float, float] | None = None,
    equal: bool = False,
    time_window: tuple[float, float] | None = None,
    rtol: float = FIT_RTOL,
    rates: str = "model",
) -> ShapeFitResult:
    """Fit the shape effects (S_p, S_t) of ``model`` so that its ``target`` under ``drive``
    matches the measured one (Li & Sundén 2016 §4.1, done as an optimisation).

    Least squares (scipy ``least_squares``, trust-region reflective, within bounds) of the
    simulated minus the measured target at the measured time stamps (within ``time_window``),
    from S = 0. ``equal``: one S with S_p = S_t, as in the thesis's figures. Default bounds:
    ±0.98·the admissible bound of each S with the other at 0 (Hrovat & Tobler; for ``equal`` the
    bound of S_p = S_t), ±0.5 m² (quasi-dynamic). Points inside the box that break the joint
    condition ``ρ²S_p²/I_p + ρ²S_t²/I_t ≤ 0.98²(ρL_f/A − ρ²S_s²/I_s)`` get a large residual and
    are never simulated. The finite-difference Jacobian's columns run in one batched core call.

    ``rates``: ``"model"`` compares the run's own ``target`` column (its rates are the model's
    states' exact derivatives; for a target simulated by the model itself); ``"filtered"`` makes the
    simulated target as :func:`measured_effective_torques` made the measured one, from the run's
    speeds and torques at every measured time stamp with the same derivative filter, so that the
    filter's smoothing of a measured speed is on both sides (``tcsim fit-shapes`` uses it: with the
    model's rates, the effective TR's pump term was biased by the filter, 2e-3 and 6e-3 m² on S_p
    and S_t of a (0.15, 0.10) m² truth, at any ``rtol``).
    """
    t0 = time.perf_counter()
    if target not in TARGETS:
        raise InputError("command line", "--target", target, f"one of {', '.join(TARGETS)}")
    base = _model(converter, model)
    bound = mass_matrix_bound(base)
    single, bp, bt = _fit_bounds(bound, pump_bounds, turbine_bounds, equal)
    keep = _fit_points(measured_time_s, measured_target, time_window)
    times, measured = np.asarray(measured_time_s, dtype=float)[keep], np.asarray(measured_target, dtype=float)[keep]
    filtered = _filtered(rates, measured_time_s, keep)
    lo, hi = (np.array([bp[0]]), np.array([bp[1]])) if equal else (np.array([bp[0], bt[0]]), np.array([bp[1], bt[1]]))
    problem = _Problem(base, drive, times, measured, target, equal, bound, lo, hi, rtol, filtered)
    with _fitted_model_warnings_only() as fitted:
        res, zero = _solve(problem, lo, hi)
        sp, st = problem.shapes(res.x)
        fitted.append(base.with_shape_effects(sp, st))
    names = ("shape_effect_m2",) if equal else ("pump_shape_effect_m2", "turbine_shape_effect_m2")
    return ShapeFitResult(
        model=base.name,
        target=target,
        pump_shape_effect_m2=sp,
        turbine_shape_effect_m2=st,
        rmse=_rmse(problem.evaluate([res.x])[0]),
        rmse_at_zero=_rmse(zero),
        evaluations=problem.runs,
        bound_m2=single,
        pump_bounds_m2=bp,
        turbine_bounds_m2=bp if equal else bt,
        equal=equal,
        points=len(times),
        time_window_s=(float(times[0]), float(times[-1])),
        active=_active(res.x, lo, hi, names),
        message=str(res.message),
        elapsed_s=time.perf_counter() - t0,
    )


@contextlib.contextmanager
def _fitted_model_warnings_only() -> Iterator[list[DynamicModel]]:
    """Warnings of the runs inside, each message once, with the near-coupling warning of the model
    the caller appends (the fitted one) instead of one per trial point (``fit-shapes --model
    quasi-dynamic`` printed it 23 times, for 23 trial shape effects)."""
    fitted: list[DynamicModel] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield fitted
    seen: set[str] = set()
    for w in caught:
        if not issubclass(w.category, NearCouplingWarning) and str(w.message) not in seen:
            seen.add(str(w.message))
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    for model in fitted:
        model.warn_if_fragile_near_coupling()


def _solve(problem: _Problem, lo: np.ndarray, hi: np.ndarray):
    """The least-squares fit of ``problem`` from S = 0 (clipped into the bounds), and the residuals
    at S = 0."""
    x0 = np.clip(np.zeros(len(lo)), lo, hi)
    r0 = problem.evaluate([x0])[0]
    if r0 is None or not np.isfinite(r0).all():
        raise InputError(
            "command line",
            "bounds",
            f"start {problem.shapes(x0)}",
            "a start point (S clipped into the bounds) that the model can run",
        )
    problem.penalty = 10.0 * (float(np.linalg.norm(r0)) + 1.0)
    res = least_squares(
        problem.fun,
        x0,
        jac=problem.jac,
        bounds=(lo, hi),
        method="trf",
        x_scale=hi - lo,
        ftol=1e-12,
        xtol=1e-10,
        gtol=1e-12,
        max_nfev=60 * (len(x0) + 1),
    )
    return res, problem.evaluate([np.zeros(len(lo))])[0]


# ---------------------------------------------------------------------------------------------
# the sweep (thesis figures 4.1–4.4)


def _pairs(values_m2, pairs) -> list[tuple[float, float]]:
    out = [(float(v), float(v)) for v in values_m2] + [(float(p), float(t)) for p, t in (pairs or ())]
    return list(dict.fromkeys(out))


def _label(pump_m2: float, turbine_m2: float) -> str:
    return f"Sp=St={pump_m2:g}" if pump_m2 == turbine_m2 else f"Sp={pump_m2:g}, St={turbine_m2:g}"


def _sweep_times(drive, times_s) -> np.ndarray:
    """The output times: given, else the drive's stamps when dense, else a 1 ms grid over them."""
    if times_s is not None:
        return np.asarray(times_s, dtype=float)
    stamps = np.asarray(drive.time_s, dtype=float)
    if len(stamps) >= 200:
        return stamps
    n = int(round((stamps[-1] - stamps[0]) / SWEEP_STEP_S))
    return np.linspace(stamps[0], stamps[-1], min(max(n, 1), 20_000) + 1)


SWEEP_COLUMNS = (
    "time_s",
    "speed_ratio",
    "effective_torque_ratio",
    "effective_turbine_torque_nm",
    "effective_pump_torque_nm",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
)


def _sweep_rows(pair, run: TransientResult | str | None, note: str) -> pd.DataFrame:
    head = {"pump_shape_effect_m2": pair[0], "turbine_shape_effect_m2": pair[1], "label": _label(*pair)}
    if not isinstance(run, TransientResult):
        return pd.DataFrame(
            [{**head, "admissible": False, "note": note or str(run), **{c: math.nan for c in SWEEP_COLUMNS}}]
        )
    cols = {c: run[c] for c in SWEEP_COLUMNS}
    return pd.DataFrame({**head, "admissible": True, "note": "", **cols})


def shape_effect_sweep(
    converter: Converter | str | DynamicModel,
    model: str | DynamicModel,
    drive,
    values_m2: Sequence[float] = THESIS_VALUES_M2,
    pairs: Sequence[tuple[float, float]] | None = None,
    times_s: npt.ArrayLike | None = None,
    rtol: float | None = None,
) -> pd.DataFrame:
    """Effective TR for S_p = S_t = v (each v in ``values_m2``) and for the explicit ``pairs``
    (e.g. the thesis's (0.4, 0.3)), all in one batched core call (Li & Sundén 2016 §4.1,
    figures 4.1–4.4).

    A tidy frame: ``pump_shape_effect_m2``, ``turbine_shape_effect_m2``, ``label``,
    ``admissible``, ``note``, then :data:`SWEEP_COLUMNS`. A pair the Hrovat & Tobler model
    refuses (mass matrix not positive definite), or a run that fails, is one row with
    ``admissible`` False, NaN values and the reason in ``note``.
    """
    base = _model(converter, model)
    bound = mass_matrix_bound(base)
    times = _sweep_times(drive, times_s)
    todo = _pairs(values_m2, pairs)
    ok = [p for p in todo if bound is None or bound.admissible(*p)]
    runs = dict(zip(ok, _runs([base.with_shape_effects(*p) for p in ok], drive, times, rtol)))
    frames = [
        _sweep_rows(p, runs.get(p), "" if p in runs or bound is None else inadmissible_note(bound, *p)) for p in todo
    ]
    return pd.concat(frames, ignore_index=True)


def _at_zero(df: pd.DataFrame) -> pd.Series | None:
    """Effective TR of the S_p = S_t = 0 run by time, if the sweep has one."""
    z = df[(df.pump_shape_effect_m2 == 0) & (df.turbine_shape_effect_m2 == 0) & df.admissible]
    return z.set_index("time_s")["effective_torque_ratio"] if len(z) else None


def _argmin(values: np.ndarray) -> int | None:
    return int(np.nanargmin(values)) if np.isfinite(values).any() else None


def sweep_minima(df: pd.DataFrame, time_window: tuple[float, float] | None = None) -> pd.DataFrame:
    """Per pair, within ``time_window`` (default: the whole run): the minimum effective TR and its
    time; the deepest drop below the S = 0 run (``drop_below_zero``, positive when below) and its
    time; and the effective TR at the end of the run (thesis §4.1: the drop, and its recovery)."""
    zero = _at_zero(df)
    rows = []
    for (sp, st), g in df.groupby(["pump_shape_effect_m2", "turbine_shape_effect_m2"], sort=False):
        w = g if time_window is None else g[(g.time_s >= time_window[0]) & (g.time_s <= time_window[1])]
        tr, t = w["effective_torque_ratio"].to_numpy(dtype=float), w["time_s"].to_numpy(dtype=float)
        below = zero.reindex(t).to_numpy() - tr if zero is not None else np.full(len(tr), np.nan)
        i, j = _argmin(tr), _argmin(-below)
        rows.append(
            {
                "pump_shape_effect_m2": sp,
                "turbine_shape_effect_m2": st,
                "label": g["label"].iloc[0],
                "admissible": bool(g["admissible"].iloc[0]),
                "min_effective_torque_ratio": tr[i] if i is not None else math.nan,
                "time_of_min_s": t[i] if i is not None else math.nan,
                "drop_below_zero": below[j] if j is not None else math.nan,
                "time_of_drop_s": t[j] if j is not None else math.nan,
                "final_effective_torque_ratio": float(g["effective_torque_ratio"].iloc[-1]),
            }
        )
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------------------------
# for the command


def required_channels(target: str, drive: str) -> tuple[str, ...]:
    inputs = (
        ("pump_torque_nm", "turbine_speed_rad_s")
        if drive == "pump-torque"
        else ("pump_speed_rad_s", "turbine_speed_rad_s")
    )
    wanted = ("turbine_torque_nm",) + (
        ("pump_torque_nm", "pump_speed_rad_s") if target == "effective_torque_ratio" else ()
    )
    return tuple(dict.fromkeys(inputs + wanted))


def drive_of(m: Measurement, drive: str):
    if drive == "pump-torque":
        return PumpTorqueTurbineSpeed(m.time_s, m.channels["pump_torque_nm"], m.channels["turbine_speed_rad_s"])
    return Speeds(m.time_s, m.channels["pump_speed_rad_s"], m.channels["turbine_speed_rad_s"])


def check_choice(option: str, value: str, choices: Sequence[str]) -> None:
    if value not in choices:
        raise InputError("command line", option, value, f"one of {', '.join(choices)}")


def measured_frame(m: Measurement, effective: Mapping[str, np.ndarray]) -> pd.DataFrame:
    d = {k: v for k, v in effective.items() if k.startswith("effective_") or k == "time_s"}
    if "pump_speed_rad_s" in m.channels:
        with np.errstate(divide="ignore", invalid="ignore"):
            d["speed_ratio"] = m.channels["turbine_speed_rad_s"] / m.channels["pump_speed_rad_s"]
    return pd.DataFrame(d)


def steady_run(conv: Converter, drive, times) -> pd.DataFrame | None:
    """The steady-state (table) model under the same drive, if the converter has a table."""
    if conv.characteristic is None or conv.inertia is None:
        return None
    run = _runs([dynamic_model(conv, "table")], drive, times, None)[0]
    return run.frame() if isinstance(run, TransientResult) else None
