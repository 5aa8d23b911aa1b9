"""Fit Hrovat & Tobler parameters to a characteristic table (``tcsim fit``).

Li & Sundén (2016) §3.2.1 matched the steady state of the Hrovat & Tobler (1985) model to the
manufacturer's table by tuning the parameters that cannot be measured (loss coefficients) and the
mean-streamline blade angles, with the pump at a fixed speed and SR swept from 0 to the coupling
point. §4.3.2 reports that the match needed some angles outside their measured ranges. This
module does that matching as a bounded least-squares problem:

* residuals: relative errors of TR and CF at the table's points with SR in [0, SR_max]; SR_max
  defaults to the table's coupling point (first SR with TR = 1), as the thesis cut its figures
  3.3 and 3.4 there;
* parameters: a user-chosen subset of the fifteen steady-state parameters (user units, angles in
  degrees), each within bounds; the optimiser works in the scaled space ``u = (x − lo)/(hi − lo)``;
* Jacobian: exact, from the core's forward-mode derivatives (``_core.ht_ratio_gradients``);
* points without a steady state give a large finite residual, larger than any cost the start
  reaches, so a trust-region step into such a region is always rejected.

The steady state is homogeneous in pump speed (TR and CF do not depend on it), so the fit runs at
2000 rpm. Layers: :func:`fit_hrovat_tobler` is the pure fit (geometry and table in, a
:class:`FitResult` out); :func:`fit_command` loads files, calls it and writes the outputs.
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd
from scipy.optimize import least_squares

from .. import _core
from ..errors import InputError, TcsimWarning
from ..models.characteristic import Characteristic
from ..models.converter import STEADY_KEYS, STEADY_SCALE, Converter, GeometrySection, InertiaSection, load_converter
from ..models.steady import characterise_hrovat_tobler, ratio_frame
from ..units import DEFAULT_PUMP_SPEED_RAD_S, RAD_S_PER_RPM
from .fit_derived import (
    DERIVATION,
    DERIVED_KEYS,
    RADII_ORDER,
    check_usable,
    derive_geometry,
    derive_inertia,
    parameter_warnings,
    provenance,
    radii_ordered,
)

PUMP_SPEED_RAD_S = DEFAULT_PUMP_SPEED_RAD_S
CORE_NAMES = tuple(_core.ht_parameter_names())
ANGLES = tuple(k for k in STEADY_KEYS if k.endswith("_deg"))
LOSSES = ("pump_shock_loss", "turbine_shock_loss", "stator_shock_loss", "friction_loss")
RADII = ("pump_exit_radius_m", "turbine_exit_radius_m", "stator_exit_radius_m")

#: Default free set: what cannot be measured (losses) and the mean-streamline angles (§3.2.1).
DEFAULT_FREE = LOSSES + ANGLES
#: Table D.1 ranges of the angles (Li & Sundén 2016, Appendix D).
ANGLE_BOUNDS_DEG = (-60.0, 60.0)
SHOCK_BOUNDS = (0.05, 5.0)
FRICTION_BOUNDS = (0.01, 2.0)
DENSITY_BOUNDS = (700.0, 1000.0)
SIZE_FACTOR = 4.0  # radii and flow area: start / 4 to start × 4
COUPLING_TR = 1.0 + 1e-9
N_STARTS = 8
SEED = 20160874  # thesis number 2016:74
START_SPREAD = 0.15  # standard deviation of the extra starts in the scaled space

_BOUND_HELP = "NAME=LO:HI with LO < HI, e.g. pump_exit_angle_deg=-60:60"


# --------------------------------------------------------------------------------------------
# parameters and bounds


def parse_free(text: str | None) -> tuple[str, ...]:
    """The ``--free`` option: comma-separated geometry keys, or the default set."""
    if text is None:
        return DEFAULT_FREE
    return tuple(n.strip() for n in text.split(",") if n.strip()) or ("",)


def check_free(free: Sequence[str]) -> tuple[str, ...]:
    """Known, distinct user-facing names; raises InputError on the argument ``free`` (a sequence of
    names: one name alone is refused, not read as its letters)."""
    if isinstance(free, str):
        raise InputError.argument("free", free, f"a list of names, e.g. [{free!r}]")
    names = tuple(free)
    if not names:
        raise InputError.argument("free", "", "at least one parameter")
    for n in names:
        if n not in STEADY_KEYS:
            raise InputError.argument("free", n, f"one of {', '.join(STEADY_KEYS)}")
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise InputError.argument("free", dup, "each parameter once")
    return names


def parse_bounds(items: Sequence[str]) -> dict[str, tuple[float, float]]:
    """The ``--bound NAME=LO:HI`` options (repeatable) as a dict; raises InputError on ``--bound``."""
    out: dict[str, tuple[float, float]] = {}
    for item in items:
        name, eq, rng = item.partition("=")
        lo_text, colon, hi_text = rng.partition(":")
        try:
            lo, hi = float(lo_text), float(hi_text)
        except ValueError:
            lo = hi = math.nan
        if not (eq and colon and name.strip()) or not (math.isfinite(lo) and math.isfinite(hi)):
            raise InputError("command line", "--bound", item, _BOUND_HELP)
        name = name.strip()
        if name in out:
            raise InputError("command line", "--bound", item, f"one bound per parameter ({name} given twice)")
        out[name] = (lo, hi)
    return out


def _admissible(name: str) -> tuple[float, float, bool]:
    """The range the model accepts (Li & Sundén 2016, Table 2.2): (lo, hi, lo inclusive)."""
    if name in ANGLES:
        return -90.0, 90.0, False
    if name in LOSSES:
        return 0.0, math.inf, True
    return 0.0, math.inf, False


def default_bounds(name: str, start: float) -> tuple[float, float]:
    """Default bounds of a free parameter, widened to contain the start value."""
    if name in ANGLES:
        lo, hi = ANGLE_BOUNDS_DEG
    elif name == "friction_loss":
        lo, hi = FRICTION_BOUNDS
    elif name in LOSSES:
        lo, hi = SHOCK_BOUNDS
    elif name == "fluid_density_kg_m3":
        lo, hi = DENSITY_BOUNDS
    else:
        lo, hi = start / SIZE_FACTOR, start * SIZE_FACTOR
    return min(lo, start), max(hi, start)


def resolve_bounds(
    free: Sequence[str], bounds: Mapping[str, tuple[float, float]] | None, start: Mapping[str, float]
) -> dict[str, tuple[float, float]]:
    """Bounds of every free parameter: the user's where given, the defaults otherwise."""
    bounds = dict(bounds or {})
    for name, (lo, hi) in bounds.items():
        text = f"{name}={lo:g}:{hi:g}"
        if name not in STEADY_KEYS:
            raise InputError.argument("bounds", text, f"a bound on one of {', '.join(STEADY_KEYS)}")
        if name not in free:
            raise InputError.argument(
                "bounds", text, f"a bound on a free parameter ({', '.join(free)}); make {name} free too"
            )
        if not lo < hi:
            raise InputError.argument("bounds", text, "LO < HI")
        a_lo, a_hi, inclusive = _admissible(name)
        if lo < a_lo or (lo == a_lo and not inclusive) or hi >= a_hi:
            low = f"{'≥' if inclusive else '>'} {a_lo:g}"
            raise InputError.argument(
                "bounds",
                text,
                f"bounds the model accepts: LO {low}" + (f", HI < {a_hi:g}" if math.isfinite(a_hi) else ""),
            )
        if not lo <= start[name] <= hi:
            raise InputError.argument("bounds", text, f"bounds that contain the start value {name} = {start[name]:g}")
    return {n: bounds.get(n) or default_bounds(n, start[n]) for n in free}


# --------------------------------------------------------------------------------------------
# the fitted range of the table


def table_coupling_point(table: Characteristic) -> float | None:
    """The table's coupling point: its first point with 0 ≤ SR < 1 and TR ≤ 1 (+1e-9); None when
    no point below SR 1 has reached TR = 1."""
    sr, tr, _ = table.arrays()
    coupled = np.flatnonzero((sr >= 0) & (sr < 1) & (tr <= COUPLING_TR))
    return float(sr[coupled[0]]) if coupled.size else None


def default_speed_ratio_max(table: Characteristic) -> float:
    """The table's coupling point (:func:`table_coupling_point`), else its last point below SR 1.

    At SR = 1 the model's steady state has no flow and no torque, so a table point there cannot
    be matched; a table that reaches TR = 1 only at SR = 1 is fitted up to its last point below.
    """
    coupling = table_coupling_point(table)
    if coupling is not None:
        return coupling
    sr, _, _ = table.arrays()
    drive = (sr >= 0) & (sr < 1)
    if not drive.any():
        raise InputError(
            table.source or "Characteristic",
            "speed_ratio",
            f"{sr[0]:g} to {sr[-1]:g}",
            "table points with SR from 0 to below 1",
        )
    return float(sr[drive][-1])


def fit_points(
    table: Characteristic, speed_ratio_max: float | None
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """SR_max and the table points with SR in [0, SR_max]."""
    if speed_ratio_max is None:
        speed_ratio_max = default_speed_ratio_max(table)
    elif not (math.isfinite(speed_ratio_max) and 0 < speed_ratio_max <= 1):
        raise InputError.argument("speed_ratio_max", speed_ratio_max, "a speed ratio above 0, at most 1")
    sr, tr, cf = table.arrays()
    keep = (sr >= 0) & (sr <= speed_ratio_max + 1e-12)
    if keep.sum() < 2:
        points = f"at least 2 points of {table.source or 'the table'}"
        raise InputError.argument("speed_ratio_max", speed_ratio_max, f"a range from SR 0 holding {points}")
    return float(speed_ratio_max), sr[keep], tr[keep], cf[keep]


# --------------------------------------------------------------------------------------------
# the least-squares problem


class _Problem:
    """Residuals and exact Jacobian in the scaled space ``u = (x − lo)/(hi − lo)``."""

    def __init__(self, geometry: GeometrySection, free, bounds, sr, tr, cf):
        self.free = tuple(free)
        self.sr, self.tr, self.cf = (np.ascontiguousarray(a, dtype=float) for a in (sr, tr, cf))
        self.base = geometry.core_row()
        self.index = np.array([STEADY_KEYS.index(n) for n in self.free])
        self.radii = [STEADY_KEYS.index(n) for n in RADII]  # pump, turbine, stator
        self.core_free = [CORE_NAMES[i] for i in self.index]
        self.lo = np.array([bounds[n][0] for n in self.free])
        self.span = np.array([bounds[n][1] - bounds[n][0] for n in self.free])
        self.scale = STEADY_SCALE[self.index] * self.span  # d core value / d u
        self.penalty = 1e3
        self._cache: tuple[bytes, tuple] | None = None
        self.nfev = 0

    def to_x(self, u: npt.ArrayLike) -> np.ndarray:
        return self.lo + np.asarray(u) * self.span

    def to_u(self, x: npt.ArrayLike) -> np.ndarray:
        return (np.asarray(x) - self.lo) / self.span

    def evaluate(self, u: np.ndarray):
        """TR, CF and their derivatives with respect to u (NaN where no steady state exists)."""
        key = np.asarray(u, dtype=float).tobytes()
        if self._cache is None or self._cache[0] != key:
            row = self.base.copy()
            row[self.index] = self.to_x(u) * STEADY_SCALE[self.index]
            self.nfev += 1
            nan, dnan = np.full(self.sr.shape, np.nan), np.full((len(self.sr), len(self.free)), np.nan)
            out = (nan, nan, dnan, dnan)  # infeasible: radii without a torus (fit_derived), no steady state
            if radii_ordered(*row[self.radii]):
                try:
                    tr, cf, dtr, dcf = _core.ht_ratio_gradients(row[None, :], PUMP_SPEED_RAD_S, self.sr, self.core_free)
                    out = (tr, cf, dtr * self.scale, dcf * self.scale)
                except _core.CoreInputError:  # e.g. no losses at all: no steady state anywhere
                    pass
            self._cache = (key, out)
        return self._cache[1]

    def raw_residuals(self, u) -> np.ndarray:
        tr, cf, _, _ = self.evaluate(u)
        return np.concatenate([tr / self.tr - 1.0, cf / self.cf - 1.0])

    def residuals(self, u) -> np.ndarray:
        return np.nan_to_num(self.raw_residuals(u), nan=self.penalty)

    def jacobian(self, u) -> np.ndarray:
        _, _, dtr, dcf = self.evaluate(u)
        jac = np.vstack([dtr / self.tr[:, None], dcf / self.cf[:, None]])
        return np.nan_to_num(jac, nan=0.0, posinf=0.0, neginf=0.0)

    def feasible(self, u) -> bool:
        return bool(np.isfinite(self.raw_residuals(u)).all())

    def solve(self, u0: np.ndarray):
        """One bounded trust-region-reflective run from ``u0`` (feasible)."""
        cost0 = 0.5 * float(np.sum(self.residuals(u0) ** 2))
        # any infeasible point then costs more than the start, so steps into one are rejected
        self.penalty = 10.0 * (math.sqrt(2.0 * cost0) + 1.0)
        return least_squares(
            self.residuals,
            u0,
            jac=self.jacobian,
            bounds=(0.0, 1.0),
            method="trf",
            ftol=1e-10,
            xtol=1e-10,
            gtol=1e-10,
            max_nfev=100 * (len(self.free) + 1),
        )


def _starts(problem: _Problem, u0: np.ndarray, n_starts: int) -> list[np.ndarray]:
    """The start point and ``n_starts − 1`` fixed-seed perturbations of it that have a steady state."""
    rng = np.random.default_rng(SEED)
    starts = [u0]
    for _ in range(20 * n_starts):
        if len(starts) >= n_starts:
            break
        u = np.clip(u0 + START_SPREAD * rng.standard_normal(u0.shape), 0.0, 1.0)
        if problem.feasible(u):
            starts.append(u)
    return starts


def _best_fit(problem: _Problem, u0: np.ndarray, n_starts: int):
    """Multi-start: the run with the lowest cost; every run is deterministic."""
    best = None
    starts = _starts(problem, u0, n_starts)
    for u in starts:
        res = problem.solve(u)
        if problem.feasible(res.x) and (best is None or res.cost < best.cost):
            best = res
    return best, len(starts)


# --------------------------------------------------------------------------------------------
# statistics at the solution


def _correlation(jac: np.ndarray, cost: float) -> dict[str, Any]:
    """Covariance ~ s²·(JᵀJ)⁻¹ (pseudo-inverse when singular), correlations, identifiability.

    The pseudo-inverse comes from the SVD of J, dropping singular values below the rank
    tolerance. A parameter with a component in the null space of J is not identifiable from TR
    and CF: its standard error is reported as NaN. The residuals are model-form error rather
    than noise, so the standard errors only indicate how well the table pins each parameter.
    """
    m, k = jac.shape
    _, sv, vt = np.linalg.svd(jac, full_matrices=True)
    tol = (sv.max(initial=0.0) if sv.size else 0.0) * max(m, k) * np.finfo(float).eps
    rank = int(np.sum(sv > tol))
    cond = float(sv[0] / sv[rank - 1]) if rank else math.inf
    v = vt[:rank].T
    cov = (v / sv[:rank] ** 2) @ v.T
    null = vt[rank:].T
    identifiable = np.linalg.norm(null, axis=1) < 1e-6 if null.size else np.ones(k, dtype=bool)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = np.where(np.outer(sd, sd) > 0, cov / np.outer(sd, sd), np.nan)
    s2 = 2.0 * cost / (m - k) if m > k else math.nan
    std = np.where(identifiable, sd * math.sqrt(s2), np.nan) if m > k else np.full(k, np.nan)
    return {
        "rank": rank,
        "condition_number": cond,
        "correlation": np.clip(corr, -1.0, 1.0),
        "std_scaled": std,
        "identifiable": identifiable,
    }


# --------------------------------------------------------------------------------------------
# the result


@dataclass(frozen=True)
class FitResult:
    """A fit of Hrovat & Tobler parameters to a table (user units: angles in degrees).

    ``geometry`` is the fitted geometry with its fluid length and shape effects derived from the
    fitted radii and angles (:func:`.fit_derived.derive_geometry`); ``warnings`` has one line per
    free parameter at a bound or outside its measured range (:func:`.fit_derived.parameter_warnings`).
    """

    geometry: GeometrySection
    start: GeometrySection
    free: tuple[str, ...]
    bounds: dict[str, tuple[float, float]]
    active: dict[str, str]
    speed_ratio_max: float
    speed_ratio: np.ndarray
    torque_ratio_table: np.ndarray
    capacity_factor_table: np.ndarray
    torque_ratio_model: np.ndarray
    capacity_factor_model: np.ndarray
    correlation: np.ndarray
    std_error: np.ndarray
    jacobian_rank: int
    condition_number: float
    identifiable: np.ndarray
    nfev: int
    njev: int
    starts: int
    elapsed_s: float
    message: str
    table_source: str = ""
    notes: tuple[str, ...] = field(default_factory=tuple)
    #: One line per free parameter at a bound or outside its measured range (:mod:`.fit_derived`).
    warnings: tuple[str, ...] = field(default_factory=tuple)

    @property
    def values(self) -> dict[str, float]:
        return {n: getattr(self.geometry, n) for n in self.free}

    @property
    def start_values(self) -> dict[str, float]:
        return {n: getattr(self.start, n) for n in self.free}

    @property
    def tr_error(self) -> np.ndarray:
        return self.torque_ratio_model / self.torque_ratio_table - 1.0

    @property
    def cf_error(self) -> np.ndarray:
        return self.capacity_factor_model / self.capacity_factor_table - 1.0

    @property
    def rms_tr(self) -> float:
        return float(np.sqrt(np.mean(self.tr_error**2)))

    @property
    def rms_cf(self) -> float:
        return float(np.sqrt(np.mean(self.cf_error**2)))

    @property
    def max_tr(self) -> float:
        return float(np.max(np.abs(self.tr_error)))

    @property
    def max_cf(self) -> float:
        return float(np.max(np.abs(self.cf_error)))

    @property
    def singular(self) -> bool:
        return self.jacobian_rank < len(self.free)

    def to_dict(self) -> dict[str, Any]:
        """The numbers of ``fit_report.json`` (relative errors as fractions, not %)."""

        def num(x):
            return None if not np.isfinite(x) else float(x)

        return {
            "table": self.table_source,
            "speed_ratio_max": self.speed_ratio_max,
            "pump_speed_rpm": PUMP_SPEED_RAD_S / RAD_S_PER_RPM,
            "parameters": {
                n: {
                    "start": self.start_values[n],
                    "fitted": self.values[n],
                    "lower": self.bounds[n][0],
                    "upper": self.bounds[n][1],
                    "active": self.active.get(n),
                    "std_error": num(self.std_error[i]),
                    "identifiable": bool(self.identifiable[i]),
                }
                for i, n in enumerate(self.free)
            },
            "errors": {
                "rms_torque_ratio": self.rms_tr,
                "rms_capacity_factor": self.rms_cf,
                "max_torque_ratio": self.max_tr,
                "max_capacity_factor": self.max_cf,
            },
            "points": {
                "speed_ratio": self.speed_ratio.tolist(),
                "torque_ratio_table": self.torque_ratio_table.tolist(),
                "torque_ratio_model": self.torque_ratio_model.tolist(),
                "capacity_factor_table": self.capacity_factor_table.tolist(),
                "capacity_factor_model": self.capacity_factor_model.tolist(),
            },
            "correlation": {
                "parameters": list(self.free),
                "matrix": [[num(v) for v in row] for row in self.correlation],
                "jacobian_rank": self.jacobian_rank,
                "singular": self.singular,
                "condition_number": num(self.condition_number),
            },
            "optimiser": {
                "method": "scipy.optimize.least_squares, trf, analytic Jacobian",
                "nfev": self.nfev,
                "njev": self.njev,
                "starts": self.starts,
                "seed": SEED,
                "message": self.message,
                "elapsed_s": self.elapsed_s,
            },
            "derived": {k: getattr(self.geometry, k) for k in DERIVED_KEYS},
            "derivation": DERIVATION,
            "warnings": list(self.warnings),
            "notes": list(self.notes),
        }

    def one_line(self) -> str:
        """One paragraph for the console."""
        active = ", ".join(f"{n} at {side} bound" for n, side in self.active.items()) or "none"
        return (
            f"fitted {len(self.free)} parameters to {len(self.speed_ratio)} points of {self.table_source} "
            f"(SR 0–{self.speed_ratio_max:g}): RMS error TR {100 * self.rms_tr:.3g} %, CF {100 * self.rms_cf:.3g} % "
            f"(max {100 * self.max_tr:.3g} %, {100 * self.max_cf:.3g} %); active bounds: {active}; "
            f"{self.nfev} evaluations, {self.starts} starts, {self.elapsed_s:.2f} s"
        )


# --------------------------------------------------------------------------------------------
# the fit


def fit_hrovat_tobler(
    geometry: GeometrySection,
    table: Characteristic,
    free: Sequence[str] = DEFAULT_FREE,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    speed_ratio_max: float | None = None,
    n_starts: int = N_STARTS,
) -> FitResult:
    """Fit the ``free`` Hrovat & Tobler parameters of ``geometry`` to ``table``.

    Bounded least squares (scipy ``least_squares``, trust-region reflective, exact Jacobian) of
    the relative errors of TR and CF at the table points with SR in [0, ``speed_ratio_max``]
    (default: the table's coupling point), in the manner of Li & Sundén (2016) §3.2.1; the model
    is the closed-form steady state of Hrovat & Tobler (1985), Li & Sundén eqs 2.12–2.25.
    ``bounds`` maps user-facing names (angles in degrees) to (lo, hi); free parameters without
    one get :func:`default_bounds`. The start and ``n_starts − 1`` fixed-seed perturbations of
    it are run and the best kept. Raises :class:`InputError` for bad names, bounds or ranges.
    """
    t0 = time.perf_counter()
    if isinstance(n_starts, bool) or not isinstance(n_starts, int | np.integer) or n_starts < 1:
        raise InputError.argument("n_starts", n_starts, "an integer of at least 1 (the start itself)")
    if not isinstance(geometry, GeometrySection):
        expected = "a GeometrySection (the [geometry] of a converter: tcsim.load_converter(name).geometry)"
        raise InputError.argument("geometry", type(geometry).__name__, expected)
    if not isinstance(table, Characteristic):
        expected = "a Characteristic (a table: tcsim.fitting.target_table(name or file))"
        raise InputError.argument("table", type(table).__name__, expected)
    free = check_free(free)
    radii = [getattr(geometry, n) for n in RADII]
    if not radii_ordered(*radii):
        raise InputError(
            "start converter",
            "[geometry] radii",
            ", ".join(f"{n} {r:g}" for n, r in zip(RADII, radii)),
            f"{RADII_ORDER} (the fit derives the fluid length and shape effects from a circular torus through them)",
        )
    start = {n: float(getattr(geometry, n)) for n in free}
    resolved = resolve_bounds(free, bounds, start)
    srmax, sr, tr, cf = fit_points(table, speed_ratio_max)
    problem = _Problem(geometry, free, resolved, sr, tr, cf)
    u0 = np.clip(problem.to_u([start[n] for n in free]), 0.0, 1.0)
    if not problem.feasible(u0):
        bad = sr[~np.isfinite(problem.raw_residuals(u0)[: len(sr)])]
        raise InputError(
            "start converter",
            "[geometry]",
            f"no steady state at SR {bad[0]:g}",
            "a start point with a steady state at every fitted speed ratio",
        )
    best, n_run = _best_fit(problem, u0, int(n_starts))
    return _result(problem, best, geometry, resolved, srmax, table, n_run, time.perf_counter() - t0)


def _active(problem: _Problem, u: np.ndarray, mask: np.ndarray) -> dict[str, str]:
    out = {}
    for i, n in enumerate(problem.free):
        if mask[i] < 0 or u[i] <= 1e-6:
            out[n] = "lower"
        elif mask[i] > 0 or u[i] >= 1 - 1e-6:
            out[n] = "upper"
    return out


#: A fitted model whose TR or CF misses a table point by more than this (relative) is warned of.
MISSED_RELATIVE_ERROR = 0.2


def warn_if_missed(source: str, sr, tr_table, cf_table, tr_model, cf_model) -> None:
    """Warn on the terminal when the fitted model misses a table point by more than
    :data:`MISSED_RELATIVE_ERROR` in TR or CF: a fit that ends 100 % off a table (a capacity in the
    wrong unit) reported success with exit 0, its error only in the report."""
    with np.errstate(divide="ignore", invalid="ignore"):
        errors = {"TR": np.abs(tr_model / tr_table - 1), "CF": np.abs(cf_model / cf_table - 1)}
    name, e = max(errors.items(), key=lambda kv: float(np.nanmax(kv[1], initial=0.0)))
    if not np.nanmax(e, initial=0.0) > MISSED_RELATIVE_ERROR and np.isfinite(e).all():
        return
    i = int(np.nanargmax(np.where(np.isfinite(e), e, np.inf)))
    warnings.warn(
        f"{source}: the fitted model misses the table: {name} {100 * e[i]:.3g} % off at SR {sr[i]:g} "
        f"(more than {100 * MISSED_RELATIVE_ERROR:g} %); the model cannot follow this table with the free "
        "parameters in their bounds: check the table's capacity convention and units, or free more "
        "parameters or widen their bounds",
        TcsimWarning,
        stacklevel=3,
    )


def _result(problem: _Problem, res, geometry, bounds, srmax, table, n_run, elapsed) -> FitResult:
    x = problem.to_x(res.x)
    label = table.source or "the table"  # a Characteristic made in Python has no file
    values = geometry.model_dump()
    values.update({n: float(v) for n, v in zip(problem.free, x)})
    fitted = GeometrySection(**values)
    tr, cf, _, _ = problem.evaluate(res.x)
    stats = _correlation(problem.jacobian(res.x), float(res.cost))
    active = _active(problem, res.x, res.active_mask)
    warned = parameter_warnings(label, {n: getattr(fitted, n) for n in problem.free}, bounds, active)
    notes = []
    if stats["rank"] < len(problem.free):
        notes.append(
            f"JᵀJ is singular (rank {stats['rank']} of {len(problem.free)}): the table determines only "
            f"{stats['rank']} combinations of the free parameters, and the fit is one of many equivalent "
            "points; correlations from the pseudo-inverse, standard errors only for identifiable parameters"
        )
    if 2 * len(tr) < len(problem.free):
        # on the terminal too: a fit of 10 parameters to 2 points reported success with exit 0 (the
        # default free set's own rank deficiency, 7 of 10 on a full table, is the report's to explain)
        warnings.warn(
            f"{label}: the fit is not unique: {len(tr)} points give {2 * len(tr)} values (TR and "
            f"CF) for {len(problem.free)} free parameters (rank {stats['rank']}); free fewer parameters or "
            "fit a table with more points",
            TcsimWarning,
            stacklevel=2,
        )
    warn_if_missed(label, problem.sr, problem.tr, problem.cf, np.asarray(tr), np.asarray(cf))
    size = ("fluid_density_kg_m3" in problem.free, "flow_area_m2" in problem.free, bool(set(problem.free) & set(RADII)))
    if sum(size) > 1:
        notes.append(
            "CF scales with ρ·A·R³ (R a common scale of the three radii) and TR not at all, so density, "
            "flow area and a common radius scale are interchangeable: free only one of density, flow area "
            "and the set of radii for a unique size"
        )
    return FitResult(
        geometry=derive_geometry(fitted),
        start=geometry,
        free=problem.free,
        bounds=bounds,
        active=active,
        speed_ratio_max=srmax,
        speed_ratio=problem.sr,
        torque_ratio_table=problem.tr,
        capacity_factor_table=problem.cf,
        torque_ratio_model=np.asarray(tr),
        capacity_factor_model=np.asarray(cf),
        correlation=stats["correlation"],
        std_error=stats["std_scaled"] * problem.span,
        jacobian_rank=stats["rank"],
        condition_number=stats["condition_number"],
        identifiable=stats["identifiable"],
        nfev=problem.nfev,
        njev=int(res.njev or 0),
        starts=n_run,
        elapsed_s=elapsed,
        message=str(res.message),
        table_source=table.source,
        notes=tuple(notes),
        warnings=tuple(warned),
    )


def target_label(target: str) -> str:
    path = Path(target)
    return path.stem if path.suffix else target


def target_table(target: str) -> Characteristic:
    """The characteristic table of ``target`` (bundled name, .toml, .csv, .vtcc)."""
    conv = load_converter(target)
    if conv.characteristic is None:
        raise InputError(
            conv.path,
            "[characteristic]",
            "missing",
            "a characteristic table to fit (.csv, .vtcc, or a converter .toml with [characteristic])",
        )
    if conv.characteristic.by_torque:
        raise InputError(
            conv.path,
            "[characteristic]",
            f"{len(conv.characteristic.by_torque)} tables",
            "one characteristic table to fit (this converter's capacity depends on the input torque: "
            "fit one table at a time)",
        )
    return conv.characteristic


def fitted_converter(start: Converter, result: FitResult, table: Characteristic, label: str) -> Converter:
    """The start converter with the fitted [geometry] and the target table as its [characteristic].

    The fitted converter describes the converter of the target table: its table and quasi-dynamic
    models use that table, its Hrovat & Tobler model the fitted geometry. The fluid length and shape
    effects are derived from the fitted radii and angles (:data:`.fit_derived.DERIVATION`), the fluid
    part of [inertia] too when a size parameter is free (:func:`.fit_derived.derive_inertia`);
    [sources] says which values were fitted, derived or taken from the start converter.
    """
    assert start.geometry is not None  # the fit needs one
    inertia, inertia_derived = derive_inertia(start.inertia, start.geometry, result.geometry)
    sources = dict(start.sources)
    for n in result.free:
        sources[f"geometry.{n}"] = (
            f"fitted by tcsim fit to {label} over SR 0–{result.speed_ratio_max:g} "
            f"(start value {result.start_values[n]:g}; see fit_report.md)"
        )
    for n in DERIVED_KEYS:
        sources[f"geometry.{n}"] = f"derived by tcsim fit: {DERIVATION}"
    kept = "derived by tcsim fit: the start's metal part plus the fitted torus's fluid ρA∫R²dl; start: "
    for key in InertiaSection.model_fields if inertia is not None else ():
        was = start.sources.get(f"inertia.{key}", "start converter")
        sources[f"inertia.{key}"] = (kept + was) if inertia_derived else f"{was} (taken from the start by tcsim fit)"
    if start.quasi_dynamic is not None:
        for key in start.quasi_dynamic.model_dump(exclude_none=True):
            was = start.sources.get(f"quasi_dynamic.{key}", "start converter")
            sources[f"quasi_dynamic.{key}"] = f"{was} (taken from the start by tcsim fit: not geometry)"
    for col in ("speed_ratio", "torque_ratio", "capacity_factor_nm_s2"):
        sources[f"characteristic.{col}"] = f"fitting target {table.source}"
    return dataclasses.replace(
        start,
        name=f"{start.name}-fit-{label}",
        characteristic=table,
        inertia=inertia,
        geometry=result.geometry,
        description=(
            f"{start.name} with [geometry] fitted to {label}: RMS error TR {100 * result.rms_tr:.3g} %, "
            f"CF {100 * result.rms_cf:.3g} % over SR 0–{result.speed_ratio_max:g}"
        ),
        source=f"{start.source}; [geometry] fitted by tcsim fit to {table.source}",
        sources=sources,
    )


@dataclass(frozen=True)
class FitOutcome:
    """What ``tcsim fit`` writes: the checked fitted converter, where its values come from, and every
    warning (one line each: the parameters' of :attr:`FitResult.warnings`, then the checks')."""

    converter: Converter
    provenance: tuple[str, ...]
    warnings: tuple[str, ...]


def fit_outcome(start: Converter, result: FitResult, table: Characteristic, label: str) -> FitOutcome:
    """The fitted converter of ``result``, checked by :func:`.fit_derived.check_usable` (an
    :class:`InputError` on the target table if a command would refuse it), with its provenance."""
    conv = fitted_converter(start, result, table, label)
    checks = check_usable(conv, table.source, table_coupling_point(table))
    derived = start.inertia is not None and conv.inertia != start.inertia
    lines = provenance(start, result.free, derived, label, start.quasi_dynamic is not None)
    return FitOutcome(conv, tuple(lines), (*result.warnings, *checks))


def model_curve(conv: Converter) -> pd.DataFrame:
    """The model over SR 0–1 (with the coupling point); NaN where a point has no steady state."""
    try:
        return characterise_hrovat_tobler(conv)
    except InputError:  # a point of the sweep without a steady state: plot the others
        sr = np.linspace(0.0, 1.0, 101)
        tr, cf, _, _ = _core.ht_ratio_gradients(conv.core_geometry(), PUMP_SPEED_RAD_S, sr, [])
        return ratio_frame(sr, tr, cf)
