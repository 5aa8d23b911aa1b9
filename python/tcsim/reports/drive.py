"""What ``tcsim drive`` prints: the summary as rows of metrics with one column per model (it fits
80 columns with the three models' names whole; ``summary.csv`` has every column at full precision),
and where the files are."""

from __future__ import annotations

from pathlib import Path

from rich import box
from rich.console import Group
from rich.table import Table

from ..analysis.drive import Drive
from .format import fmt_number, rich_text

#: Rows of the drive table: (label with unit, summary.csv column, format).
DRIVE_ROWS: tuple[tuple[str, str, str], ...] = (
    ("RMS speed error [km/h]", "rms_speed_error_km_h", ".2f"),
    ("max speed error [km/h]", "max_speed_error_km_h", ".2f"),
    ("engine work [kJ]", "engine_work_kj", ".0f"),
    ("converter loss [kJ]", "converter_loss_kj", ".1f"),
    ("lock-up clutch slip loss [kJ]", "lockup_loss_kj", ".1f"),
    ("clutch closing (events) [kJ]", "event_loss_kj", ".1f"),
    ("heat to the fluid [kJ]", "heat_to_fluid_kj", ".1f"),
    ("brakes [kJ]", "brake_energy_kj", ".0f"),
    ("engine braking [kJ]", "engine_braking_kj", ".1f"),
    ("time locked up [-]", "lockup_time_fraction", ".0%"),
    ("energy residual [-]", "energy_residual", ".1e"),
)


def _drive_table(result: Drive) -> Table:
    s = result.summary
    title = (
        f"drive of {result.vehicle.name} ({result.vehicle.converter.name}) over {result.cycle.name}: "
        f"{s.duration_s.iloc[0]:.0f} s, {s.distance_km.iloc[0]:.2f} km"
    )
    table = Table(title=rich_text(title), box=box.SIMPLE_HEAD, pad_edge=False)
    table.add_column("metric", no_wrap=True)
    names = [str(m) for m in s["model"]]
    for name in names:
        table.add_column(rich_text(name), justify="right", no_wrap=True, min_width=len(name))
    for label, column, spec in DRIVE_ROWS:
        table.add_row(rich_text(label), *(fmt_number(v, spec) for v in s[column]))
    return table


def drive_report(result: Drive, out: Path, ext: str = "csv", plots: bool = True) -> Group:
    """A rich table of the drive's summary (docs/drive.md) and where the files are (tables with the
    suffix ``ext``; the figures if ``plots``)."""
    tables = ["summary", *result.runs, "events", "cycle"]
    files = [*(f"{name}.{ext}" for name in tables), *(("speed.png", "losses.png") if plots else ())]
    return Group(_drive_table(result), rich_text(f"written to {out}/: {', '.join(files)}"))
