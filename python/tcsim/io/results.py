"""Result files of the commands (CSV, TOML, JSON, Markdown), written into a staging directory of
:func:`tcsim.io.outputs.output_dir`. Figures are written by :mod:`tcsim.plots`, reports' text by
:mod:`tcsim.reports`."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import tomli_w

from ..analysis.fitting import FitResult
from ..analysis.launch import Launch
from ..analysis.replay import Replay
from ..models.characteristic import Characteristic
from ..models.converter import Converter, parse_converter


def write_frames(files: dict[str, pd.DataFrame], out_dir: Path) -> list[Path]:
    """Each frame as ``out_dir/<name>`` (CSV, no index), in order; the paths written."""
    paths = []
    for filename, df in files.items():
        paths.append(Path(out_dir) / filename)
        df.to_csv(paths[-1], index=False)
    return paths


def write_launch_files(result: Launch, out_dir: Path) -> list[Path]:
    """The CSV files of a launch: ``<model>.csv``, ``summary.csv``, ``timeseries.csv``, ``events.csv``,
    ``scenario.csv`` and, with the sweep, ``shape_sweep.csv`` and ``shape_sweep_summary.csv``."""
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
    return write_frames(files, out_dir)


def write_replay_files(replay: Replay, out_dir: Path) -> list[Path]:
    """The CSV files of a replay: ``<model>.csv``, ``events.csv``, ``measurement.csv`` and, when the
    measurement has reference outputs, ``metrics.csv``."""
    files = {f"{name}.csv": result.frame() for name, result in replay.results.items()}
    files.update({"events.csv": replay.events, "measurement.csv": replay.measured_frame()})
    if len(replay.metrics):
        files["metrics.csv"] = replay.metrics
    return write_frames(files, out_dir)


def write_fit_files(
    stage: Path, start: Converter, fitted: Converter, result: FitResult, table: Characteristic, report_md: str
) -> None:
    """``fitted.toml`` (validated as every other command will read it back), ``fit_report.json`` and
    ``fit_report.md`` (``report_md``)."""
    doc = fitted.to_toml_dict()
    parse_converter(doc, "fitted.toml")  # what every other command will read back
    header = (
        f"# Written by tcsim fit: [geometry] of {start.name} fitted to {table.source}\n"
        f"# over SR 0-{result.speed_ratio_max:g}. See fit_report.md.\n\n"
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
