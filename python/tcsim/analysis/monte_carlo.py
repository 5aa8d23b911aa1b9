"""Monte Carlo studies of the vehicle launch (``tcsim monte-carlo FILE``, docs/study.md "Monte Carlo
studies"): ``runs`` cases per grid point, each a launch of every model of the study with converter
and vehicle parameters drawn from the study file's distributions or swept over its grids
(:mod:`tcsim.models.study_file`).

**Reproducible whatever the chunking.** Case ``i`` draws its random parameters, in the order the
file lists them, from its own generator ``numpy.random.Generator(PCG64(SeedSequence([seed, r])))``,
``r`` its run (``i`` without a grid, ``i % runs`` with one: every grid point sees the same draws),
and takes the grid values of grid point ``i // runs`` (the grid parameters a full factorial, the
first of the file varying slowest; a grid takes nothing from the generator, so a file without a
grid draws as before grids existed): its values depend on the seed and ``i`` alone, so the rows of
a study are bit for bit the same computed in one piece, in chunks of any size, or on any dask worker
(:class:`MonteCarloStudy` is a :class:`~tcsim.analysis.chunked.ChunkedStudy`).

**A case.** The converter (when a ``converter.*`` parameter is drawn) and the vehicle (when a
``vehicle.*`` one is) are rebuilt with the drawn values and validated as files are; every model
runs the launch (:func:`tcsim.simulation.launch.launch_columns`, the cases sharing a vehicle
batched :data:`CASES_PER_CALL` to a core call); the launch summary (:func:`tcsim.analysis.launch.launch_summary`,
the dip and recovery against the ``table`` run of the same case) gives the outputs. A case the
converter or vehicle checks refuse (a combination of drawn values), or a model's run that fails,
keeps its rows with NaN outputs and the one-line reason in ``error``.

**Rows** (:meth:`MonteCarloStudy.columns`): ``case`` (int), ``model``, each parameter, drawn or swept
(named by its key, ``vehicle.body.mass_kg``), each output (float; ``shift_count`` too, for NaN), ``error``
(empty when the run finished); one row per case and model, cases in order, models in the study's order.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from scipy.special import ndtr, ndtri

from ..errors import InputError
from ..models.converter import Converter
from ..models.dynamic import DynamicModel, dynamic_model
from ..models.study_file import (
    Grid,
    Lognormal,
    Normal,
    Parameter,
    StudyFile,
    TruncatedNormal,
    Uniform,
    build_converter,
    build_vehicle,
    converter_data,
    count_grid_points,
    vehicle_data,
    warn_about_unused_parameters,
)
from ..models.vehicle import Vehicle
from ..simulation.launch import launch_columns
from ..simulation.scenarios import Scenario, flip_flop, part_pedal
from .launch import REFERENCE_MODEL, SUMMARY_COLUMNS, launch_summary

#: The outputs a study may keep: the launch summary's columns (docs/launch_summary.md).
OUTPUTS: tuple[str, ...] = tuple(c for c in SUMMARY_COLUMNS if c != "model")
#: The outputs measured against the :data:`~tcsim.analysis.launch.REFERENCE_MODEL` run of the same case.
REFERENCE_OUTPUTS: tuple[str, ...] = (
    "effective_torque_ratio_dip_first_0_5_s",
    "effective_torque_ratio_dip_time_s",
    "mean_effective_torque_ratio_deficit_first_0_5_s",
    "effective_torque_ratio_recovery_time_s",
)
#: The columns of a launch run the summary reads.
RUN_COLUMNS: tuple[str, ...] = (
    "time_s",
    "vehicle_speed_m_s",
    "vehicle_accel_m_s2",
    "effective_torque_ratio",
    "gear",
    "shifting",
)
#: Cases sharing a vehicle per core call (bounds the memory of the runs' columns: about 0.45 MB per run).
CASES_PER_CALL = 16
#: The built-in scenarios by the study file's name.
SCENARIOS: dict[str, Callable[[], Scenario]] = {"flip-flop": flip_flop, "part-pedal": part_pedal}


def case_generator(seed: int, index: int) -> np.random.Generator:
    """The random generator of case ``index``: a function of the seed and the index alone."""
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, index])))


def _truncated_normal(d: TruncatedNormal, u: float) -> float:
    """The truncated normal's quantile at ``u`` (0 ≤ u < 1), computed in the tail nearer the mean."""
    a, b = (d.low - d.mean) / d.std, (d.high - d.mean) / d.std
    sign = 1.0
    if a > 0:  # both in the upper tail: draw the mirror image, where ndtr keeps its precision
        a, b, sign = -b, -a, -1.0
    pa, pb = float(ndtr(a)), float(ndtr(b))
    z = float(np.clip(ndtri(pa + u * (pb - pa)), a, b))
    return float(np.clip(d.mean + sign * z * d.std, d.low, d.high))


def draw(distribution: Normal | Uniform | Lognormal | TruncatedNormal, rng: np.random.Generator) -> float:
    """One value of ``distribution`` from ``rng``."""
    if isinstance(distribution, Normal):
        return float(rng.normal(distribution.mean, distribution.std))
    if isinstance(distribution, Uniform):
        return float(rng.uniform(distribution.low, distribution.high))
    if isinstance(distribution, Lognormal):
        mu, sigma = distribution.log_parameters()
        return float(rng.lognormal(mu, sigma))
    return _truncated_normal(distribution, float(rng.random()))


def grid_values(parameters: Sequence[Parameter], point: int) -> dict[int, float]:
    """The values of grid point ``point`` by the index of each grid parameter in ``parameters``: the
    full factorial of the grids, the first grid parameter varying slowest."""
    out: dict[int, float] = {}
    for j in reversed(range(len(parameters))):
        grid = parameters[j].distribution
        if isinstance(grid, Grid):
            point, k = divmod(point, len(grid))
            out[j] = grid.value(k)
    return out


def grid_points(parameters: Sequence[Parameter]) -> int:
    """The number of grid points of ``parameters`` (1 without a grid)."""
    return count_grid_points(p.distribution for p in parameters)


def draw_cases(parameters: Sequence[Parameter], seed: int, start: int, stop: int, runs: int = 1) -> np.ndarray:
    """The values of the cases ``start`` to ``stop`` (exclusive), ``runs`` cases per grid point:
    shape (cases, parameters); a grid parameter's values those of point ``i // runs``, the others
    drawn in order from :func:`case_generator` ``(seed, r)``, ``r`` the case's run: ``i % runs``
    with a grid (every grid point sees the same draws, common random numbers, so that the sweep's
    differences are the swept parameter's and not the sampling's), ``i`` without one."""
    out = np.empty((max(stop - start, 0), len(parameters)))
    random = [j for j, p in enumerate(parameters) if not isinstance(p.distribution, Grid)]
    swept = len(random) < len(parameters)
    for row, i in enumerate(range(start, stop)):
        rng = case_generator(seed, i % runs if swept else i)
        for j in random:
            out[row, j] = draw(parameters[j].distribution, rng)  # type: ignore[arg-type]
        for j, v in grid_values(parameters, i // runs).items():
            out[row, j] = v
    return out


@dataclass(frozen=True)
class _Case:
    """A case ready to run: its vehicle and models, or why it cannot run."""

    index: int
    vehicle: Vehicle | None
    models: list[DynamicModel]
    error: str = ""


@dataclass(frozen=True)
class MonteCarloStudy:
    """A Monte Carlo launch study as plain, picklable data (:class:`~tcsim.analysis.chunked.ChunkedStudy`):
    the converter's and vehicle's TOML data and files, the scenario's name, the models, the runs per
    grid point (:attr:`n_cases` in all), the seed, the outputs and the parameters (drawn or swept).
    ``threads``: core workers of each call (0: all cores); it does not change the rows."""

    converter_path: str
    converter_toml: dict[str, Any]
    vehicle_path: str
    vehicle_toml: dict[str, Any]
    scenario: str
    models: tuple[str, ...]
    runs: int
    seed: int
    outputs: tuple[str, ...]
    parameters: tuple[Parameter, ...]
    threads: int = 0
    kind: str = "monte-carlo"

    @property
    def n_cases(self) -> int:
        """Grid points × runs."""
        return grid_points(self.parameters) * self.runs

    @property
    def columns(self) -> tuple[str, ...]:
        return ("case", "model", *(p.key for p in self.parameters), *self.outputs, "error")

    def definition(self) -> dict[str, Any]:
        """Everything the rows depend on (the study file's name and description do not). With a
        grid, also how the runs draw (``draws``: every grid point the same), so that shards of a
        grid study drawn otherwise are never resumed; a file without a grid is defined as before."""
        record: dict[str, Any] = {
            "converter": {"file": self.converter_path, "toml": self.converter_toml},
            "vehicle": {"file": self.vehicle_path, "toml": self.vehicle_toml},
            "scenario": self.scenario,
            "models": list(self.models),
            "runs": self.runs,
            "seed": self.seed,
            "outputs": list(self.outputs),
            "distributions": [
                {"parameter": p.key, **p.distribution.model_dump(exclude_none=p.is_grid)} for p in self.parameters
            ],
        }
        if any(p.is_grid for p in self.parameters):
            record["draws"] = "common random numbers: run r of every grid point draws from (seed, r)"
        return record

    def __getstate__(self) -> dict[str, Any]:
        """Plain data only (what a dask worker receives): the converter, models and vehicle built from
        it (core objects) are built again where the study runs."""
        return {k: v for k, v in self.__dict__.items() if k != "_base"}

    @functools.cached_property
    def _base(self) -> tuple[Converter, list[DynamicModel], Vehicle]:
        conv = build_converter(self.converter_toml, self.converter_path)
        models = [dynamic_model(conv, m) for m in self.models]
        return conv, models, build_vehicle(self.vehicle_toml, self.vehicle_path, conv)

    def _case(self, index: int, values: np.ndarray) -> _Case:
        conv, models, vehicle = self._base
        drawn: dict[str, dict[tuple[str, str], float]] = {"converter": {}, "vehicle": {}}
        for p, v in zip(self.parameters, values.tolist()):
            drawn[p.target][(p.section, p.name)] = v
        try:
            if drawn["converter"]:
                conv = build_converter(converter_data(self.converter_toml, drawn["converter"]), self.converter_path)
                models = [dynamic_model(conv, m) for m in self.models]
            if drawn["vehicle"]:
                vehicle = build_vehicle(vehicle_data(self.vehicle_toml, drawn["vehicle"]), self.vehicle_path, conv)
        except InputError as e:
            return _Case(index, None, [], str(e))
        return _Case(index, vehicle, models)

    def rows(self, start: int, stop: int) -> pd.DataFrame:
        """The rows of the cases ``start`` to ``stop`` (exclusive): see the module's docstring."""
        values = draw_cases(self.parameters, self.seed, start, stop, self.runs)
        cases = [self._case(start + k, values[k]) for k in range(len(values))]
        runs = _run_cases(cases, SCENARIOS[self.scenario](), self.threads)
        release = SCENARIOS[self.scenario]().brake_release_time_s
        rows: list[dict[str, Any]] = []
        for case, drawn, results in zip(cases, values, runs):
            rows += self._case_rows(case, drawn, results, release)
        df = pd.DataFrame(rows, columns=list(self.columns))
        return df.astype({"case": "int64", **dict.fromkeys(self.columns[2:-1], "float64")})

    def _case_rows(
        self, case: _Case, drawn: np.ndarray, results: list[dict[str, np.ndarray] | Exception], release_s: float
    ) -> list[dict[str, Any]]:
        params = {p.key: v for p, v in zip(self.parameters, drawn.tolist())}
        frames = {m: pd.DataFrame(r) for m, r in zip(self.models, results) if isinstance(r, dict)}
        summary = launch_summary(frames, release_s).set_index("model") if frames else None
        out = []
        for k, model in enumerate(self.models):
            error = case.error or (str(results[k]) if isinstance(results[k], Exception) else "")
            row = {"case": case.index, "model": model, **params, "error": error}
            for name in self.outputs:
                row[name] = math.nan if error or summary is None else float(summary.at[model, name])  # type: ignore[arg-type]
            out.append(row)
        return out


def _run_cases(
    cases: Sequence[_Case], scenario: Scenario, threads: int
) -> list[list[dict[str, np.ndarray] | Exception]]:
    """Each case's runs (per model its :data:`RUN_COLUMNS`, or its error), the consecutive cases
    that share a vehicle in core calls of up to :data:`CASES_PER_CALL` cases."""
    out: list[list[dict[str, np.ndarray] | Exception]] = [[] for _ in cases]
    group: list[int] = []

    def flush() -> None:
        if not group:
            return
        first = cases[group[0]]
        assert first.vehicle is not None
        models = [m for k in group for m in cases[k].models]
        try:
            results = launch_columns(first.vehicle, scenario, models, RUN_COLUMNS, None, threads)
        except InputError:  # a bad input of the whole call: each case alone, so that only it fails
            results = []
            for k in group:
                vehicle = cases[k].vehicle
                assert vehicle is not None
                try:
                    results += launch_columns(vehicle, scenario, cases[k].models, RUN_COLUMNS, None, threads)
                except InputError as e:
                    results += [e] * len(cases[k].models)
        for j, k in enumerate(group):
            n = len(cases[k].models)
            out[k] = results[j * n : (j + 1) * n]
        group.clear()

    for k, case in enumerate(cases):
        if case.vehicle is None:
            continue
        same = group and cases[group[0]].vehicle.core is case.vehicle.core  # type: ignore[union-attr]
        if group and (not same or len(group) == CASES_PER_CALL):
            flush()
        group.append(k)
    flush()
    return out


def monte_carlo_study(file: StudyFile, threads: int = 0) -> MonteCarloStudy:
    """The study of a checked study file (:func:`tcsim.models.study_file.load_study_file`); its
    outputs checked (:data:`OUTPUTS`; the dip and recovery need the ``table`` model), and every
    model built from the converter, before anything runs."""
    for name in file.doc.outputs:
        if name not in OUTPUTS:
            raise InputError(file.path, "outputs", name, f"a launch summary column: one of {', '.join(OUTPUTS)}")
        if name in REFERENCE_OUTPUTS and REFERENCE_MODEL not in file.models:
            expected = f"the {REFERENCE_MODEL!r} model among the models (the dip is measured against its run)"
            raise InputError(file.path, "outputs", name, expected)
    study = MonteCarloStudy(
        converter_path=file.converter.path,
        converter_toml=file.converter.to_toml_dict(),
        vehicle_path=file.vehicle.path,
        vehicle_toml=file.vehicle.to_toml_dict(),
        scenario=file.doc.scenario,
        models=file.models,
        runs=file.doc.n_runs,
        seed=file.doc.seed,
        outputs=tuple(dict.fromkeys(file.doc.outputs)),
        parameters=file.parameters,
        threads=threads,
    )
    _ = study._base  # every model of the converter built (an InputError now, not in a worker)
    warn_about_unused_parameters(file)
    return study


def run_monte_carlo(
    study: MonteCarloStudy, block: int = CASES_PER_CALL, progress: Callable[[int, int], None] | None = None
) -> pd.DataFrame:
    """Every row of ``study`` in this process, ``block`` cases at a time (``progress(done, total)``
    after each block): the same rows as ``study.rows(0, study.n_cases)``."""
    parts = []
    for start in range(0, study.n_cases, block):
        parts.append(study.rows(start, min(start + block, study.n_cases)))
        if progress is not None:
            progress(min(start + block, study.n_cases), study.n_cases)
    return pd.concat(parts, ignore_index=True) if parts else study.rows(0, 0)


__all__ = [
    "OUTPUTS",
    "REFERENCE_OUTPUTS",
    "MonteCarloStudy",
    "case_generator",
    "draw",
    "draw_cases",
    "grid_points",
    "grid_values",
    "monte_carlo_study",
    "run_monte_carlo",
]
