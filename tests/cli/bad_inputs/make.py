"""Writers of the catalogue's binary and generated input files (``make = "NAME"`` in a case's
``[case.files]``; ``args`` are passed as keyword arguments). Each writes ``path`` and nothing else."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import scipy.io
from asammdf import MDF, Signal

REPO = Path(__file__).resolve().parents[3]
TAKEOFF = REPO / "tests" / "golden" / "data" / "takeoff_measurement.csv"
_MAT_V73_HEADER = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."


def _arrays(columns: dict[str, list]) -> dict[str, np.ndarray]:
    return {name: np.asarray(values, dtype=float) for name, values in columns.items()}


def write_mat_v73(path: Path, columns: dict[str, np.ndarray]) -> None:
    """An HDF5 file laid out like MATLAB v7.3: a 512-byte header, one (N, 1) double dataset per variable."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, values in columns.items():
            data = np.asarray(values)
            f.create_dataset(name, data=data.reshape(-1, 1)).attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as f:
        f.write(_MAT_V73_HEADER.ljust(116) + bytes(8) + b"\x00\x02IM")


def write_mdf(path: Path, columns: dict[str, np.ndarray], units: dict[str, str], time_s: np.ndarray) -> None:
    """An MDF4 file: one group, every channel on ``time_s``."""
    mdf = MDF(version="4.10")
    mdf.append([Signal(values, time_s, name=name, unit=units.get(name, "")) for name, values in columns.items()])
    mdf.save(path, overwrite=True)
    mdf.close()


def write_columns(path: Path, columns: dict[str, np.ndarray], units: dict[str, str], v73: bool) -> None:
    """``columns`` (with ``time_s``; MDF4 takes it as the time base) in the format of the suffix."""
    suffix = path.suffix.lower()
    if suffix == ".csv":
        pd.DataFrame(columns).to_csv(path, index=False, float_format="%.17g")
    elif suffix == ".parquet":
        pd.DataFrame(columns).to_parquet(path)
    elif suffix == ".mat" and v73:
        write_mat_v73(path, columns)
    elif suffix == ".mat":
        scipy.io.savemat(path, columns)
    elif suffix in (".mf4", ".mdf"):
        time_s = np.asarray(columns["time_s"], dtype=float)
        write_mdf(path, {k: v for k, v in columns.items() if k != "time_s"}, units, time_s)
    else:
        raise ValueError(f"no writer for {path.suffix}")


def columns(path: Path, columns: dict[str, list], units: dict[str, str] | None = None, v73: bool = False) -> None:
    """Columns given in the case (TOML arrays; ``nan``/``inf`` allowed) in the format of ``path``."""
    write_columns(path, _arrays(columns), units or {}, v73)


def takeoff(
    path: Path, rows: int = 3001, v73: bool = False, drop: list[str] | None = None, scale: dict | None = None
) -> None:
    """The golden take-off measurement (1 kHz, 3 s) or its first ``rows``, in the format of
    ``path``; ``drop`` leaves columns out, ``scale`` multiplies columns."""
    frame = pd.read_csv(TAKEOFF).head(rows).drop(columns=drop or [])
    data = {c: frame[c].to_numpy(dtype=float) for c in frame.columns}
    for name, factor in (scale or {}).items():
        data[name] = data[name] * factor
    write_columns(path, data, {}, v73)


def parquet_list_column(path: Path) -> None:
    """A Parquet file whose pump torque column holds lists (defect 8)."""
    table = pa.table(
        {
            "time_s": [0.0, 0.1, 0.2],
            "pump_torque_nm": [[40.0, 41.0], [42.0], [43.0]],
            "turbine_speed_rad_s": [0.0, 1.0, 2.0],
        }
    )
    pq.write_table(table, path)


def parquet_string_column(path: Path) -> None:
    """A Parquet file whose turbine speed column is text."""
    pq.write_table(
        pa.table(
            {"time_s": [0.0, 0.1, 0.2], "pump_torque_nm": [40.0, 41.0, 42.0], "turbine_speed_rad_s": ["0", "x", "2"]}
        ),
        path,
    )


def truncated(path: Path, fmt: str = "mf4", keep: float = 0.5) -> None:
    """A valid measurement file (MDF4, Parquet or .mat) cut to ``keep`` of its bytes (defect 9 for MDF4)."""
    whole = path.with_name(path.name + ".whole." + fmt)
    takeoff(whole, rows=200, v73=(fmt == "v73.mat"))
    data = whole.read_bytes()
    whole.unlink()
    path.write_bytes(data[: int(len(data) * keep)])


def mdf_partial_channel(path: Path) -> None:
    """An MDF4 file whose pump torque covers only the first 10 % of the record (defect 6)."""
    t = np.linspace(0.0, 2.0, 201)
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.linspace(0.0, 180.0, 201), t, name="turbine_speed_rad_s", unit="rad/s")])
    mdf.append([Signal(np.full(21, 40.0), t[:21], name="pump_torque_nm", unit="Nm")])
    mdf.save(path, overwrite=True)
    mdf.close()


def mdf_bad_unit(path: Path) -> None:
    """An MDF4 file whose turbine speed carries a unit that is not a speed."""
    t = np.linspace(0.0, 1.0, 11)
    write_mdf(path, {"pump_torque_nm": np.full(11, 40.0), "turbine_speed_rad_s": t}, {"turbine_speed_rad_s": "bar"}, t)


def mat_complex(path: Path) -> None:
    """A MATLAB v5 file whose turbine speed is complex (defect 10)."""
    t = np.linspace(0.0, 1.0, 11)
    scipy.io.savemat(path, {"time_s": t, "pump_torque_nm": np.full(11, 40.0), "turbine_speed_rad_s": t * 10 + 1j * t})


def mat_struct(path: Path) -> None:
    """A MATLAB v5 file holding one struct with the channels inside (not top-level variables)."""
    t = np.linspace(0.0, 1.0, 11)
    scipy.io.savemat(path, {"log": {"time_s": t, "pump_torque_nm": np.full(11, 40.0), "turbine_speed_rad_s": t}})


def mat_v73_text_channel(path: Path) -> None:
    """A MATLAB v7.3 file whose pump torque is a char array (left out by the reader: missing)."""
    t = np.linspace(0.0, 1.0, 11)
    write_mat_v73(path, {"time_s": t, "turbine_speed_rad_s": t})
    with h5py.File(path, "r+") as f:
        data = np.frombuffer(b"4\x000\x00", np.uint16).reshape(2, 1)
        f.create_dataset("pump_torque_nm", data=data).attrs["MATLAB_class"] = np.bytes_("char")


def noise(path: Path, size: int = 4096, seed: int = 1) -> None:
    """Random bytes (a corrupt binary file)."""
    path.write_bytes(np.random.default_rng(seed).bytes(size))


def hdf5_noise(path: Path) -> None:
    """The HDF5 signature of a MATLAB v7.3 file followed by random bytes."""
    path.write_bytes(_MAT_V73_HEADER.ljust(512, b" ") + b"\x89HDF\r\n\x1a\n" + np.random.default_rng(2).bytes(2048))


def ramp(path: Path, start_s: float = 0.0, step_s: float = 1e-3, rows: int = 50) -> None:
    """A take-off-like measurement: ``rows`` time stamps ``start_s + n * step_s``, pump torque
    40 → 250 N·m and turbine speed 0 → 30 rad/s linearly."""
    time_s = start_s + np.arange(rows) * step_s
    data = {
        "time_s": time_s,
        "pump_torque_nm": np.linspace(40.0, 250.0, rows),
        "turbine_speed_rad_s": np.linspace(0.0, 30.0, rows),
    }
    write_columns(path, data, {}, v73=False)
