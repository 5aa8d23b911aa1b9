"""Design studies (docs/design.md, "Design studies"): one or two parameters of a design swept over a
full grid, each design's steady-state, take-off and launch figures as ``tcsim design`` computes them
(its summary, :mod:`tcsim.analysis.design_report`), batched.

Every design is derived by :func:`tcsim.models.design_file.derive_converters` (the core's geometry
of all designs in one threaded call, then each converter validated as a converter file is); the
Hrovat & Tobler characteristics of all designs at :data:`~tcsim.units.DEFAULT_PUMP_SPEED_RPM` (SR
0–1 in steps of 0.01 and the coupling point, as ``tcsim design``) go to the core's closed form in
one call; the isolated take-offs (:func:`tcsim.simulation.transient.simulate_batch`) and the vehicle
launches (:func:`~tcsim.analysis.design_report.launch_column_runs`) go in batched calls of
:data:`TAKEOFF_CHUNK` designs (GIL released, ``threads`` workers); their figures are
:func:`~tcsim.analysis.design_report.takeoff_figures` and
:func:`~tcsim.analysis.design_report.launch_figures`. A design whose derivation, steady state,
take-off or launch fails keeps its row, with NaN figures and the one-line reason in ``error``; the
others are unaffected.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..errors import InputError
from ..models.converter import Converter
from ..models.design import TorusDesign
from ..models.design_file import DesignFile, derive_converters, load_design_file
from ..models.drives import isolated_takeoff
from ..models.dynamic import dynamic_model
from ..models.steady import _derived, coupling_point, hrovat_tobler_steady_state, steady_torque_ratio
from ..simulation.transient import SolverError, TransientResult, simulate_batch
from ..units import DEFAULT_PUMP_SPEED_RPM, RAD_S_PER_RPM
from .design_report import (
    SUMMARY_COLUMNS,
    TAKEOFF_END_S,
    TAKEOFF_STEP_S,
    launch_column_runs,
    launch_figures,
    takeoff_figures,
)

#: The torus's axial width, m: not a field of ``[design]`` but swept through the elliptic profile's
#: squash ratio, ``1 − axial_width_m / (R_p − R_s)`` at each design's radii (docs/design.md).
AXIAL_WIDTH = "axial_width_m"
#: The parameters a study sweeps: the numeric fields of ``[design]`` (:class:`TorusDesign`) and
#: :data:`AXIAL_WIDTH`.
SWEEP_PARAMETERS: tuple[str, ...] = (
    *(
        f.name
        for f in fields(TorusDesign)
        if f.name.endswith(("_m", "_m2", "_deg", "_kg_m3", "_ratio")) and not f.name.endswith("_path_m")
    ),
    AXIAL_WIDTH,
)
#: Values per swept parameter: the fewest and the most; the most designs in one study.
SWEEP_COUNT_RANGE = (2, 1000)
MAX_DESIGNS = 20_000
#: The figures of each design (the summary columns of ``tcsim design``, without name and role).
FIGURE_COLUMNS: tuple[str, ...] = tuple(c for c in SUMMARY_COLUMNS if c not in ("converter", "role"))
#: Take-offs per batched core call: bounds the memory of the runs' outputs (about 0.26 MB per take-off).
TAKEOFF_CHUNK = 1000
#: The geometry columns added to each row: the equivalent fluid length L_f, m.
GEOMETRY_COLUMNS = ("fluid_length_m",)


def parse_sweep(text: str, source: str = "--sweep") -> tuple[str, np.ndarray]:
    """``NAME=MIN:MAX:N`` → the parameter name and ``N`` evenly spaced values from MIN to MAX.

    Raises :class:`InputError` naming ``source`` for an unknown NAME, a non-finite bound,
    ``MIN >= MAX``, or N not an integer in :data:`SWEEP_COUNT_RANGE`.
    """
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep or name not in SWEEP_PARAMETERS:
        expected = f"NAME=MIN:MAX:N with NAME one of {', '.join(SWEEP_PARAMETERS)}"
        raise InputError(source, "NAME", name if sep else text, expected)
    parts = spec.split(":")
    if len(parts) != 3:
        raise InputError(source, name, spec, "MIN:MAX:N (two bounds and a count)")
    try:
        lo, hi = float(parts[0]), float(parts[1])
    except ValueError:
        raise InputError(source, f"{name} bounds", f"{parts[0]}:{parts[1]}", "two numbers MIN:MAX") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise InputError(source, f"{name} bounds", f"{parts[0]}:{parts[1]}", "finite MIN < MAX")
    least, most = SWEEP_COUNT_RANGE
    count = int(parts[2]) if parts[2].strip().isdigit() else parts[2]
    if not isinstance(count, int) or not least <= count <= most:
        raise InputError(source, f"{name} count", count, f"an integer N from {least} to {most}")
    return name, np.linspace(lo, hi, count)


def check_sweep(
    sweep: Mapping[str, Sequence[float] | np.ndarray], source: str = "--sweep", chunked: bool = False
) -> None:
    """One or two known parameters, each with finite values, at most :data:`MAX_DESIGNS` designs
    unless ``chunked`` (a study kept as shards holds no row in memory: the counts of
    :data:`SWEEP_COUNT_RANGE` bound it); else :class:`InputError` naming ``source``."""
    if not 1 <= len(sweep) <= 2:
        raise InputError(source, "parameters", len(sweep), "one or two swept parameters")
    for name, values in sweep.items():
        if name not in SWEEP_PARAMETERS:
            raise InputError(source, "NAME", name, f"one of {', '.join(SWEEP_PARAMETERS)}")
        v = np.asarray(values, dtype=float)
        if v.ndim != 1 or v.size < 1 or not np.isfinite(v).all():
            raise InputError(source, name, f"{v.size} values", "a non-empty sequence of finite numbers")
    total = math.prod(len(v) for v in sweep.values())
    if total > MAX_DESIGNS and not chunked:
        expected = f"at most {MAX_DESIGNS} designs in one study (more with --chunk-size)"
        raise InputError(source, "designs", total, expected)


@dataclass(frozen=True)
class _Steady:
    """A design's steady-state figures, and its characteristic's SR and TR (for the take-off dip)."""

    figures: dict[str, float]
    speed_ratio: np.ndarray
    torque_ratio: np.ndarray


def _swept(design: TorusDesign, values: dict[str, float]) -> TorusDesign:
    """``design`` with the swept ``values``; an axial width becomes the squash ratio at the design's
    (possibly swept) radii (outside [0, 1) the core refuses the design, naming the squash ratio)."""
    fields_: dict[str, Any] = {k: v for k, v in values.items() if k != AXIAL_WIDTH}
    d = replace(design, **fields_)
    if AXIAL_WIDTH in values:
        d = replace(d, squash_ratio=1.0 - values[AXIAL_WIDTH] / (d.pump_exit_radius_m - d.stator_exit_radius_m))
    return d


def _steady_figures(convs: Sequence[Converter]) -> list[_Steady | str]:
    """Per converter its steady-state figures and the characteristic's SR and TR (for the take-off
    dip), all converters' closed-form steady states in one core call; a converter without a steady
    state somewhere on its characteristic gets the reason."""
    wp = DEFAULT_PUMP_SPEED_RPM * RAD_S_PER_RPM
    grids, rows = [], []
    for conv in convs:
        cp = coupling_point(conv)
        sr = np.linspace(0.0, 1.0, 101)
        grids.append((np.unique(np.append(sr, cp)) if cp is not None else sr, cp))
        rows.append(np.repeat(conv.core_geometry(), len(grids[-1][0]), axis=0))
    if not convs:
        return []
    sr_all = np.concatenate([g for g, _ in grids])
    out = hrovat_tobler_steady_state(np.concatenate(rows), np.full(sr_all.shape, wp), sr_all * wp, strict=False)
    df = _derived(
        pd.DataFrame(
            {
                "speed_ratio": sr_all,
                "torque_ratio": steady_torque_ratio(out),
                "pump_speed_rad_s": np.full(sr_all.shape, wp),
                "pump_torque_nm": out["pump_torque_nm"],
            }
        )
    )
    cols = {c: df[c].to_numpy(dtype=float) for c in ("speed_ratio", "torque_ratio", "k_factor_rpm_per_sqrt_nm")}
    cols["efficiency"] = df["efficiency"].to_numpy(dtype=float)
    result: list[_Steady | str] = []
    start = 0
    for sr, cp in grids:
        part = {c: v[start : start + len(sr)] for c, v in cols.items()}
        start += len(sr)
        bad = ~np.isfinite(part["torque_ratio"])
        if bad.any():
            result.append(f"steady state: none at SR {float(part['speed_ratio'][bad][0]):g}")
            continue
        below = part["efficiency"][part["speed_ratio"] < (cp if cp is not None else np.inf)]
        figures = {
            "stall_torque_ratio": float(part["torque_ratio"][0]),
            "stall_k_factor_rpm_per_sqrt_nm": float(part["k_factor_rpm_per_sqrt_nm"][0]),
            "peak_converter_efficiency": float(below.max()) if below.size else math.nan,
            "coupling_point_speed_ratio": float("nan") if cp is None else float(cp),
        }
        result.append(_Steady(figures, part["speed_ratio"], part["torque_ratio"]))
    return result


def _takeoffs(convs: Sequence[Converter], threads: int) -> list[TransientResult | str]:
    """The isolated take-offs of ``convs`` in one batched core call; when one fails, each run again
    alone so that only the failing ones become their error message."""
    if not convs:
        return []
    times = np.round(np.arange(0.0, TAKEOFF_END_S + TAKEOFF_STEP_S / 2, TAKEOFF_STEP_S), 10).tolist()
    models = [dynamic_model(c, "hrovat-tobler") for c in convs]
    try:
        return list(simulate_batch(models, [isolated_takeoff()], times, threads=threads))
    except (InputError, SolverError):
        out: list[TransientResult | str] = []
        for m in models:
            try:
                out.append(simulate_batch([m], [isolated_takeoff()], times, threads=1)[0])
            except (InputError, SolverError) as e:
                out.append(f"take-off: {e}")
        return out


def _launches(convs: Sequence[Converter], threads: int) -> list[Mapping[str, np.ndarray] | str]:
    """The launches of ``convs`` (their :data:`LAUNCH_COLUMNS`) in one core call, each run or the
    one-line reason it failed."""
    if not convs:
        return []
    return [r if isinstance(r, dict) else f"launch: {r}" for r in launch_column_runs(convs, threads=threads)]


def pareto_front(stall_tr: np.ndarray, dip: np.ndarray) -> np.ndarray:
    """True for the designs no other design beats: none with a stall TR at least as high and a
    take-off dip at least as small, and better in one (NaN rows are never on the front)."""
    tr, d = np.asarray(stall_tr, dtype=float), np.asarray(dip, dtype=float)
    ok = np.isfinite(tr) & np.isfinite(d)
    front = ok.copy()
    for i in np.flatnonzero(ok):
        beats = ok & (tr >= tr[i]) & (d <= d[i]) & ((tr > tr[i]) | (d < d[i]))
        front[i] = not beats.any()
    return front


def design_study(
    design: DesignFile | str | Path, sweep: Mapping[str, Sequence[float] | np.ndarray], threads: int = 2
) -> pd.DataFrame:
    """The figures of every design of the full grid of ``sweep`` around the base ``design``.

    Parameters
    ----------
    design : DesignFile, str or Path
        The base design: a read design file, a bundled design's name or a design ``.toml``.
    sweep : mapping
        One or two of :data:`SWEEP_PARAMETERS` → their values (units of the ``[design]`` field: m,
        m², degrees, kg/m³, or the squash ratio; ``axial_width_m`` in m). Sweeping ``squash_ratio``
        or ``axial_width_m`` of a circular design sweeps the elliptic profile (squash 0, width
        ``R_p − R_s``, is the circle).
    threads : int
        Core workers for the take-offs (0: all cores).

    Returns
    -------
    pandas.DataFrame
        One row per design, the first parameter varying slowest: the swept values, the shape
        effects (m²) and ``fluid_length_m`` (m), :data:`FIGURE_COLUMNS`, ``pareto_front`` (bool:
        stall TR against take-off dip) and ``error`` (empty, or why the design has no figures).
    """
    file = design if isinstance(design, DesignFile) else load_design_file(design)
    check_sweep(sweep)
    names = list(sweep)
    file = study_base(file, names)
    grid = list(itertools.product(*(np.asarray(sweep[n], dtype=float).tolist() for n in names)))
    df = design_rows(file, names, grid, threads)
    front = pareto_front(df["stall_torque_ratio"].to_numpy(), df["takeoff_effective_tr_dip"].to_numpy())
    df.insert(len(df.columns) - 1, "pareto_front", front)
    return df


def study_base(file: DesignFile, names: Sequence[str]) -> DesignFile:
    """The base design of a study of ``names``: a circular design swept in its squash ratio or axial
    width becomes the elliptic one of squash 0 (the circle); a polyline's width is refused."""
    if AXIAL_WIDTH in names and file.design.profile == "polyline":
        raise InputError(
            "--sweep", "NAME", AXIAL_WIDTH, "a circular or elliptic design (a polyline's paths set its width)"
        )
    if {"squash_ratio", AXIAL_WIDTH} & set(names) and file.design.profile == "circular":  # squash 0: the circle
        file = replace(file, design=replace(file.design, profile="elliptic", squash_ratio=0.0))
    return file


def _blamed_on_sweep(e: InputError, names: Sequence[str]) -> InputError:
    """A design's refusal for a swept value, shown as the sweep's (``--sweep: squash_ratio = 1.5``)
    rather than the design file's, which does not hold the value (a trial finding); an axial width
    is refused through the squash ratio it gives. Any other refusal as it is."""
    key = e.field.rpartition(".")[2]
    if key in names:
        return InputError("--sweep", key, e.value, e.expected)
    if key == "squash_ratio" and AXIAL_WIDTH in names:
        return InputError("--sweep", f"{AXIAL_WIDTH} (as squash_ratio)", e.value, e.expected)
    return e


def design_rows(
    file: DesignFile, names: Sequence[str], grid: Sequence[tuple[float, ...]], threads: int = 2
) -> pd.DataFrame:
    """The rows of :func:`design_study` of the designs ``grid`` (values of ``names`` each, around
    :func:`study_base` ``file``) without ``pareto_front`` (which compares all designs): each row
    depends on its design alone, so the rows of a part of the grid are those of the whole."""
    rows: list[dict[str, Any]] = []
    convs: list[Converter] = []
    files = [replace(file, design=_swept(file.design, dict(zip(names, combo)))) for combo in grid]
    for combo, derived in zip(grid, derive_converters(files)):
        row: dict[str, Any] = dict(zip(names, combo)) | {"error": ""}
        if isinstance(derived, InputError):
            row["error"] = str(_blamed_on_sweep(derived, names))
        else:
            convs.append(derived.converter)
            row["fluid_length_m"] = derived.geometry.fluid_length_m
        rows.append(row)
    converted = [r for r in rows if not r["error"]]
    steadies = _steady_figures(convs)
    chunks = range(0, len(convs), TAKEOFF_CHUNK)
    runs = itertools.chain.from_iterable(_takeoffs(convs[i : i + TAKEOFF_CHUNK], threads) for i in chunks)
    launches = itertools.chain.from_iterable(_launches(convs[i : i + TAKEOFF_CHUNK], threads) for i in chunks)
    for row, conv, steady, run, launch in zip(converted, convs, steadies, runs, launches):
        g = conv.geometry
        assert g is not None  # derived converters have [geometry]
        row |= {f"{e}_shape_effect_m2": getattr(g, f"{e}_shape_effect_m2") for e in ("pump", "turbine", "stator")}
        failed = next((x for x in (steady, run, launch) if isinstance(x, str)), None)
        if failed is not None:
            row["error"] = failed
            continue
        assert isinstance(steady, _Steady) and isinstance(run, TransientResult) and not isinstance(launch, str)
        sr, tr = steady.speed_ratio, steady.torque_ratio
        row |= steady.figures | takeoff_figures(run.columns, sr, tr) | launch_figures(launch, sr, tr)
    df = pd.DataFrame(rows).reindex(columns=list(row_columns(names)))
    df["error"] = df["error"].fillna("")
    return df


def row_columns(names: Sequence[str]) -> tuple[str, ...]:
    """The columns of :func:`design_rows` (:func:`design_study` adds ``pareto_front`` before ``error``)."""
    columns = [*names, "pump_shape_effect_m2", "turbine_shape_effect_m2", "stator_shape_effect_m2"]
    columns += [*GEOMETRY_COLUMNS, *(c for c in FIGURE_COLUMNS if not c.endswith("_shape_effect_m2")), "error"]
    return tuple(columns)


__all__ = [
    "FIGURE_COLUMNS",
    "MAX_DESIGNS",
    "SWEEP_COUNT_RANGE",
    "SWEEP_PARAMETERS",
    "check_sweep",
    "design_rows",
    "design_study",
    "pareto_front",
    "parse_sweep",
]
