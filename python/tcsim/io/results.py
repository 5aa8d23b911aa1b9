"""Result files of the commands (tables as CSV, Parquet or ``.mat`` by :mod:`tcsim.io.tables`; TOML,
JSON, Markdown), written into a staging directory of :func:`tcsim.io.outputs.output_dir`. Figures are
written by :mod:`tcsim.plots`, reports' text by :mod:`tcsim.reports`."""

from __future__ import annotations

import json
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import tomli_w

from ..analysis.launch import Launch
from ..analysis.replay import Replay
from ..errors import TcsimWarning
from ..models.characteristic import Characteristic
from ..models.converter import Converter, parse_converter
from ..simulation.transient import INFINITE_ALLOWED, NAN_NOT_EXPECTED
from .tables import CSV, TableFormat, column_in_unit, write_table

if TYPE_CHECKING:  # the fit's type only: importing the fitting module imports scipy.optimize
    from ..analysis.fitting import FitResult


def _partly_nan(df: pd.DataFrame, name: str) -> np.ndarray:
    """NaN cells of a physical quantity in a run that has the quantity at other samples (a column
    that is NaN for a whole run, per ``model`` when the frame has one, is a coordinate the model
    lacks)."""
    nan = df[name].isna().to_numpy()
    runs = df.groupby("model", sort=False)[name] if "model" in df.columns else [(None, df[name])]
    partly = np.zeros(len(df), dtype=bool)
    for _, col in runs:
        if not col.isna().all():
            partly[df.index.get_indexer(col.index)] = col.isna().to_numpy()
    return nan & partly


def non_finite_columns(df: pd.DataFrame) -> dict[str, int]:
    """Columns of ``df`` that hold a value a result file must not hold silently, with their count:
    ±inf anywhere but in :data:`INFINITE_ALLOWED`; NaN in a physical quantity
    (:data:`NAN_NOT_EXPECTED`) of a run that has it at other samples. Rows that a boolean ``valid``
    column flags as invalid are explained by their ``reason`` (the backward operating points) and
    not counted."""
    out = {}
    df = df.reset_index(drop=True)
    explained = np.zeros(len(df), dtype=bool)
    if "valid" in df.columns and "reason" in df.columns and pd.api.types.is_bool_dtype(df["valid"]):
        explained = ~df["valid"].to_numpy()
    for name in df.columns:
        col = df[name]
        if name == "model" or not pd.api.types.is_numeric_dtype(col) or pd.api.types.is_bool_dtype(col):
            continue
        bad = np.zeros(len(df), dtype=bool)
        if str(name).endswith(NAN_NOT_EXPECTED) and name not in INFINITE_ALLOWED:
            bad |= _partly_nan(df, name)
        if name not in INFINITE_ALLOWED:
            bad |= np.isinf(col.to_numpy(dtype=float))
        bad &= ~explained
        if bad.any():
            out[str(name)] = int(bad.sum())
    return out


def write_frames(
    files: dict[str, pd.DataFrame], out_dir: Path, table_format: TableFormat = CSV, warn: bool = True
) -> list[Path]:
    """Each frame as ``out_dir/<name>`` in order, by :func:`tcsim.io.tables.write_table` (``name``
    ends in ``.csv``; the suffix is ``table_format``'s); the paths written. With ``warn``, a frame
    with values a result must not hold silently (:func:`non_finite_columns`) is written as it is,
    with a :class:`~tcsim.errors.TcsimWarning` naming the file, the columns and the count."""
    paths = []
    for name, df in files.items():
        filename = table_format.file_name(name)
        bad = non_finite_columns(df) if warn else {}
        if bad:
            listed = ", ".join(f"{column_in_unit(k, table_format.speed_unit)} ({n})" for k, n in bad.items())
            warnings.warn(
                f"{filename}: non-finite values (inf, or NaN in a physical quantity) in {listed}: the run overflowed "
                "or its inputs were outside the model's range; check them before using the file",
                TcsimWarning,
                stacklevel=2,
            )
        paths.append(write_table(df, Path(out_dir), name, table_format))
    return paths


def write_launch_files(result: Launch, out_dir: Path, table_format: TableFormat = CSV) -> list[Path]:
    """The tables of a launch (``table_format``, default CSV): ``<model>.csv``, ``summary.csv``,
    ``timeseries.csv``, ``events.csv``, ``scenario.csv`` and, with the sweep, ``shape_sweep.csv``
    and ``shape_sweep_summary.csv``."""
    files: dict[str, pd.DataFrame] = {f"{name}.csv": f for name, f in result.frames.items()}
    files.update(
        {
            "summary.csv": result.summary,
            "timeseries.csv": result.timeseries(),
            "events.csv": result.events,
            "scenario.csv": result.scenario.frame(),
        }
    )
    if result.sweep is not None and result.sweep_summary is not None:
        files["shape_sweep.csv"] = result.sweep
        files["shape_sweep_summary.csv"] = result.sweep_summary
    return write_frames(files, out_dir, table_format)


def write_replay_files(replay: Replay, out_dir: Path, table_format: TableFormat = CSV) -> list[Path]:
    """The tables of a replay (``table_format``, default CSV): ``<model>.csv``, ``events.csv``,
    ``measurement.csv`` and, when the measurement has reference outputs, ``metrics.csv``."""
    files = {f"{name}.csv": result.frame() for name, result in replay.results.items()}
    files.update({"events.csv": replay.events, "measurement.csv": replay.measured_frame()})
    if len(replay.metrics):
        files["metrics.csv"] = replay.metrics
    return write_frames(files, out_dir, table_format)


def write_fit_files(
    stage: Path,
    start: Converter,
    fitted: Converter,
    result: FitResult,
    table: Characteristic,
    report_md: str,
    provenance: Sequence[str] = (),
) -> None:
    """``fitted.toml`` (validated as every other command will read it back; its header comment says
    where the values come from, ``provenance``), ``fit_report.json`` and ``fit_report.md`` (``report_md``)."""
    doc = fitted.to_toml_dict()
    parse_converter(doc, "fitted.toml")  # what every other command will read back
    header = (
        f"# Written by tcsim fit: [geometry] of {start.name} fitted to {table.source}\n"
        f"# over SR 0-{result.speed_ratio_max:g}. See fit_report.md.\n"
        + "".join(f"# - {line}\n" for line in provenance)
        + "\n"
    )
    (stage / "fitted.toml").write_text(header + tomli_w.dumps(doc), encoding="utf-8")
    (stage / "fit_report.json").write_text(
        json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n", encoding="utf-8"
    )
    (stage / "fit_report.md").write_text(report_md, encoding="utf-8")


def write_text_files(files: dict[str, str], out_dir: Path) -> list[Path]:
    """Each text as ``out_dir/<name>`` (UTF-8); the paths written."""
    paths = []
    for filename, text in files.items():
        paths.append(Path(out_dir) / filename)
        paths[-1].write_text(text, encoding="utf-8")
    return paths
