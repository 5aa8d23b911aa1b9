"""The files of ``tcsim design`` (docs/design.md, "tcsim design"), written into a staging folder
of :func:`tcsim.io.outputs.output_dir`: ``converter.toml``, ``characteristic.csv`` (the design's),
``reference_characteristic.csv``, ``takeoff.csv`` and ``launch.csv`` (both converters, a
``converter`` column) and ``summary.csv`` (or ``.parquet``, ``.mat``: :mod:`tcsim.io.tables`)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import tomli_w

from ..analysis.design_report import DesignReport
from .results import write_frames
from .tables import CSV, TableFormat

#: The header of the written ``converter.toml``.
CONVERTER_HEADER = (
    "# Derived by `tcsim design` from the design file {name}: every value's formula is in [sources]\n"
    "# (docs/design.md). A converter file like any other: it runs the hrovat-tobler model.\n\n"
)


def _stacked(runs: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """The runs one below the other, the converter's name in a first column ``converter``."""
    frame = pd.concat([df.assign(converter=name) for name, df in runs.items()], ignore_index=True)
    return frame[["converter", *(c for c in frame.columns if c != "converter")]]


def write_design_files(
    report: DesignReport, design_path: str, out_dir: Path, table_format: TableFormat = CSV
) -> list[Path]:
    """The converter file and the tables of ``report`` (``table_format``, default CSV) into
    ``out_dir``; the paths written."""
    out_dir = Path(out_dir)
    toml = out_dir / "converter.toml"
    header = CONVERTER_HEADER.format(name=Path(design_path).name)
    toml.write_text(header + tomli_w.dumps(report.derived.document), encoding="utf-8")
    (design, steady), (_, ref_steady) = report.characteristics.items()
    frames = {
        "characteristic.csv": steady,
        "reference_characteristic.csv": ref_steady,
        "takeoff.csv": _stacked(report.takeoffs),
        "launch.csv": _stacked(report.launches),
        "summary.csv": report.summary,
    }
    return [toml, *write_frames(frames, out_dir, table_format)]
