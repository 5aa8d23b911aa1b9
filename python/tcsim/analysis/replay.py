"""``tcsim replay``: an isolated converter driven by measured signals, compared with the measurement.

This is the thesis's "mode 2" (Li & Sundén 2016, §3.1.2, §3.4, §3.5.2.1): the converter alone,
fed with measured inputs instead of a vehicle model, so that the models' outputs can be compared
with the measured ones without feedback errors from the rest of a driveline.

::

    tcsim replay CONVERTER MEASUREMENT [--model M ...] [--out DIR] [--drive pump-torque|speeds]
                 [--channel TARGET=COLUMN ...] [--initial NAME=VALUE ...] [--window S]
                 [--metrics-window S] [--allow-implausible]

Input channels
--------------
The measurement is a CSV, Parquet, MATLAB ``.mat`` (v5, v7.3) or ASAM MDF4 (``.mf4``/``.mdf``)
file, read by :func:`tcsim.measurement.read_measurement`. Channels are found by their canonical,
unit-suffixed names (``time_s``, ``pump_torque_nm``, ``pump_speed_rad_s``, ``turbine_speed_rad_s``,
``turbine_torque_nm``), by the same quantity with another unit suffix (``time_ms``,
``turbine_speed_rpm``, ``pump_torque_knm``, ...; converted), or through an explicit mapping
``--channel TARGET=COLUMN`` (repeatable, e.g. ``--channel pump_torque_nm=EngTrq``). MDF4 channel
units decide the conversion when present. Missing channels, NaN, time going backwards and values
that look like the wrong unit (a speed column in rpm named ``*_rad_s``: the plausibility ranges,
overridable with ``--allow-implausible``) are input errors (exit 2).

Drives
------
``--drive pump-torque`` (default; drive (a), the thesis's and VSIM's causality): inputs
``time_s``, ``pump_torque_nm``, ``turbine_speed_rad_s``; the models compute the pump speed and the
turbine torque. Measured ``pump_speed_rad_s`` and ``turbine_torque_nm``, when present, are the
reference outputs.

``--drive speeds`` (drive (b)): inputs ``time_s``, ``pump_speed_rad_s``, ``turbine_speed_rad_s``;
the models compute the pump and turbine torques. Measured ``pump_torque_nm`` and
``turbine_torque_nm``, when present, are the reference outputs.

A channel mapped with ``--channel`` that a model also outputs (for example
``--channel flow_m3_s=Q``) is compared as well.

Lock-up clutch
--------------
An optional input channel ``lockup_capacity_nm`` (found like the others: ``lockup_capacity_knm``,
``--channel lockup_capacity_nm=LuCap``, ...) commands the converter's lock-up clutch, its torque
capacity against time (N·m, zero or more; a negative or non-finite value is an input error naming
the file, the column and the value). Without it the converter has no clutch. See docs/lockup.md:
the clutch slips, locks and breaks away, and the outputs gain its torque, state and slip.

Models
------
``--model`` is repeatable: ``table``, ``hrovat-tobler``, ``quasi-dynamic``. By default every
model the converter has the sections for is run (and a model whose transient sections are missing,
such as ``[inertia]``, is left out; if none is left, the first one's error is reported). An
explicitly requested model whose sections are missing is an input error.

Initial state
-------------
By default each model starts from the steady state consistent with the first input sample.
``--initial NAME=VALUE`` (repeatable) overrides one coordinate, SI units: ``pump_speed_rad_s``,
``turbine_speed_rad_s``, ``stator_speed_rad_s``, ``flow_m3_s``; the others stay consistent with
the first sample. A coordinate prescribed by the drive (the turbine speed in drive (a), both
speeds in drive (b)) or absent from a model is not a state and is ignored, with a warning.

Derivative window
-----------------
A prescribed speed enters the equations with its derivative (the inertia and shape-effect
terms). ``--window S`` (default :data:`tcsim.models.drives.DERIVATIVE_WINDOW_S`, 0.04 s) sets the
smoothing of that derivative: at each sample, the slope of the straight line fitted by least
squares to all samples within ±S/2 (at least the neighbouring samples; a first-order
Savitzky–Golay filter on non-uniform samples). ``--window 0`` gives the central difference, as
does any window shorter than the sample spacing. A window longer than the record's span is refused
(the default never is). The *same* local least-squares slope, with the same window, differentiates the measured speeds
for the measured effective torques below (:func:`tcsim.analysis.effective.smoothed_rate`).

Outputs (in DIR, default ``replay``; written all at once, nothing on error)
---------------------------------------------------------------------------
* ``<model>.csv`` per model, sampled at the measurement's time stamps, all the columns of
  :meth:`tcsim.transient.TransientResult.frame`: at least ``time_s``, ``pump_speed_rad_s``,
  ``turbine_speed_rad_s``, ``pump_torque_nm``, ``turbine_torque_nm``, ``speed_ratio``,
  ``torque_ratio`` and the inertia, fluid, transferred and effective torques; the dynamic models add
  ``flow_m3_s``, Hrovat & Tobler also ``stator_speed_rad_s``.
* ``events.csv``: ``model, time_s, kind, stator_locked, flow_direction`` (stator release and lock,
  flow reaching zero and restarting).
* ``measurement.csv``: the measured channels in SI, with the measured effective torques where the
  measurement allows them.
* ``metrics.csv`` when the measurement has reference outputs: one row per model × channel × window
  with ``model, channel, window, window_start_s, window_end_s, rmse, nrmse, max_abs_error,
  max_abs_error_time_s, n``. ``window`` is ``all`` for the whole record, else the number of a
  consecutive window of ``--metrics-window`` seconds (default 1 s; the last one may be shorter;
  windows without a sample are left out). An explicit ``--metrics-window`` shorter than the
  median sample spacing or longer than the record's span is refused (:func:`check_record_windows`).
  The error is simulated − measured; RMSE = √mean(error²); NRMSE = RMSE / (max − min of the
  measured channel in the window), NaN when that range is zero or below :data:`FLAT_RANGE` of the
  channel's largest magnitude (constant to round-off); ``n`` is the number of samples.
* Plots (PNG): ``inputs.png`` (the input signals, thesis figures 3.11/3.12); per reference output
  ``pump_speed.png`` and ``turbine_torque.png`` (drive (a), figures 3.14 and 3.13) or
  ``pump_torque.png`` and ``turbine_torque.png`` (drive (b)); ``effective_pump_torque.png`` (figure
  3.16) and ``effective_turbine_torque.png`` (figure 3.17). The measurement is drawn where it has
  the channel, else only the model curves are.

Effective torques (thesis eqs 3.1–3.4)
--------------------------------------
The torque that reaches the fluid, and the torque that leaves it, without the component inertias:

* effective pump input torque ``T_p − I_p·ω̇_p`` (eq 3.3), measured when the measurement has
  ``pump_torque_nm`` and ``pump_speed_rad_s``;
* effective turbine output torque ``T_t + I_t·ω̇_t`` (eq 3.4), measured when it has
  ``turbine_torque_nm`` (the turbine speed is always an input).

``I_p``, ``I_t`` are the converter's ``[inertia]``; ``ω̇`` is the smoothed derivative of the measured
speed (see *Derivative window*). The models report ``effective_pump_torque_nm`` and
``effective_turbine_torque_nm`` from their own states. Both are compared in ``metrics.csv`` as
channels ``effective_pump_torque_nm`` and ``effective_turbine_torque_nm``.

Errors: anything wrong in the command line, the converter or the measurement is an
:class:`~tcsim.errors.InputError` (exit 2); a solver failure is a
:class:`~tcsim.transient.SolverError` (exit 1).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..errors import InputError
from ..models import drives
from ..models.converter import Converter
from ..models.drives import DERIVATIVE_WINDOW_S, Drive
from ..models.dynamic import DynamicModel, select_models
from ..models.measurement import Measurement
from ..models.plausibility import check_plausible
from ..simulation import transient
from .effective import measured_effective_torques

#: Default width of the consecutive metric windows, s.
METRICS_WINDOW_S = 1.0
#: Keys of ``--initial``: those of the API's ``initial``.
INITIAL_KEYS = transient.INITIAL_KEYS
METRIC_COLUMNS = [
    "model",
    "channel",
    "window",
    "window_start_s",
    "window_end_s",
    "rmse",
    "nrmse",
    "max_abs_error",
    "max_abs_error_time_s",
    "n",
]
EVENT_COLUMNS = ["model", "time_s", "kind", "stator_locked", "flow_direction"]
#: The optional input channel that commands the converter's lock-up clutch (N·m, docs/lockup.md).
LOCKUP_CHANNEL = "lockup_capacity_nm"


@dataclass(frozen=True)
class DriveKind:
    """A drive of ``--drive``: its input channels (after time) and the outputs it leaves to the model."""

    name: str
    inputs: tuple[str, str]
    outputs: tuple[str, str]
    cls: type

    def make(self, meas: Measurement, window_s: float) -> Drive:
        a, b = (meas.channels[c] for c in self.inputs)
        lockup = meas.channels.get(LOCKUP_CHANNEL)
        return self.cls(meas.time_s, a, b, derivative_window_s=window_s, lockup_capacity_nm=lockup)


DRIVES: dict[str, DriveKind] = {
    "pump-torque": DriveKind(
        "pump-torque",
        ("pump_torque_nm", "turbine_speed_rad_s"),
        ("pump_speed_rad_s", "turbine_torque_nm"),
        drives.PumpTorqueTurbineSpeed,
    ),
    "speeds": DriveKind(
        "speeds", ("pump_speed_rad_s", "turbine_speed_rad_s"), ("pump_torque_nm", "turbine_torque_nm"), drives.Speeds
    ),
}


# ---------------------------------------------------------------------------------------------
# command-line items


def drive_kind(name: str) -> DriveKind:
    """The drive named on the command line."""
    if name not in DRIVES:
        raise InputError("command line", "--drive", name, f"one of {', '.join(DRIVES)}")
    return DRIVES[name]


def parse_initial(items: Sequence[str], allow_implausible: bool = False) -> dict[str, float]:
    """``["pump_speed_rad_s=150", ...]`` -> ``{"pump_speed_rad_s": 150.0}``; finite values, known keys,
    speeds and flows in their plausible ranges (``speed_rad_s``, ``flow_m3_s``) unless
    ``allow_implausible`` (``--allow-implausible``), which warns instead."""
    expected = f"NAME=VALUE with NAME one of {', '.join(INITIAL_KEYS)} (each at most once) and VALUE a finite number"
    out: dict[str, float] = {}
    for item in items:
        key, sep, text = (part.strip() for part in item.partition("="))
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not sep or key not in INITIAL_KEYS or key in out or not math.isfinite(value):
            raise InputError("command line", "--initial", item, expected)
        quantity = "flow_m3_s" if key == "flow_m3_s" else "speed_rad_s"
        check_plausible(quantity, value, "command line", f"--initial {key}", allow_implausible)
        out[key] = value
    return out


def check_window(option: str, value: float, positive: bool) -> float:
    ok = math.isfinite(value) and (value > 0 if positive else value >= 0)
    if not ok:
        raise InputError(
            "command line", option, value, f"a finite {'positive' if positive else 'non-negative'} number of seconds"
        )
    return float(value)


def check_record_windows(meas: Measurement, window_s: float | None, metrics_window_s: float | None) -> None:
    """Refuse windows the record cannot hold (an :class:`InputError` naming the option):

    * ``--window`` (the derivative window, s) longer than the record's span (a window shorter than
      the sample spacing is allowed: it uses the neighbouring samples, the central difference);
    * ``--metrics-window`` (s) shorter than the median sample spacing (windows of one sample or
      none) or longer than the record's span, unless it is the default
      :data:`METRICS_WINDOW_S` (a record shorter than that has one window).

    ``None`` is the default derivative window, or no metric windows; both are never refused."""
    t = meas.time_s
    span = float(t[-1] - t[0])
    spacing = float(np.median(np.diff(t)))
    where = f"the record's span {span:g} s of {meas.source}"
    slack = 1.0 + 1e-9  # time stamps written in decimal: a window "equal" to the span or the spacing is in
    if window_s is not None and math.isfinite(window_s) and window_s > span * slack:
        raise InputError(
            "command line",
            "--window",
            window_s,
            f"a derivative window from 0 s to {where} (shorter than the sample spacing uses the neighbouring samples)",
        )
    if metrics_window_s is None or metrics_window_s == METRICS_WINDOW_S or not math.isfinite(metrics_window_s):
        return
    if not (spacing <= metrics_window_s * slack and metrics_window_s <= span * slack):
        raise InputError(
            "command line",
            "--metrics-window",
            metrics_window_s,
            f"a metrics window from the median sample spacing {spacing:g} s to {where}",
        )


# ---------------------------------------------------------------------------------------------
# runs


def run_models(
    models: Sequence[DynamicModel], drive: Drive, initial: dict[str, float] | None = None, drive_file: str = "drive"
) -> dict[str, transient.TransientResult]:
    """Each model under the drive, sampled at the drive's time stamps. An error the core finds in
    the drive's samples (its ``core_source`` ``drive``) names ``drive_file``, the measurement; one
    in a value of ``initial`` names ``--initial`` on the command line. The runs' warnings (the
    overrun extension of a table) are shown only when every model ran: a failure is one line."""
    results = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for m in models:
            try:
                results[m.name] = transient.simulate(m, drive, initial=initial or None, files={"drive": drive_file})
            except InputError as e:
                if e.core_source == "initial":
                    field = f"--{e.field}"
                    raise InputError("command line", field, e.value, e.expected, core_source="initial") from None
                raise
    shown = set()
    for w in caught:  # a value of --initial that a run ignores: once, named as on the command line
        text = str(w.message)
        if text.startswith("initial ") and " is ignored" in text:
            text = f"--{text}"
        if text not in shown:
            shown.add(text)
            warnings.warn_explicit(text, w.category, w.filename, w.lineno)
    return results


# ---------------------------------------------------------------------------------------------
# measured effective torques


def reference_channels(meas: Measurement, drive: DriveKind, effective: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The measured channels to compare with the models: every measured channel that is not an input
    of the drive (the models output all of them), then the measured effective torques."""
    refs = {c: v for c, v in meas.channels.items() if c not in drive.inputs and c != LOCKUP_CHANNEL}
    refs.update(effective)
    return refs


# ---------------------------------------------------------------------------------------------
# metrics (pure)


#: A measured range below this fraction of the channel's largest magnitude is no range: the channel
#: is constant to round-off there, and its NRMSE is NaN (a fresh-eyes trial found 5.7e12 where a
#: constant channel's range was 1e-13 of rounding).
FLAT_RANGE = 1e-9


def _flat_below(measured: np.ndarray) -> float:
    """The range below which ``measured`` (a channel, or a window of it) counts as constant."""
    finite = np.abs(measured[np.isfinite(measured)])
    return FLAT_RANGE * float(finite.max(initial=0.0))


def _stats(time_s: np.ndarray, measured: np.ndarray, simulated: np.ndarray) -> dict[str, float]:
    err = simulated - measured
    rmse = float(np.sqrt(np.mean(err * err)))
    span = float(np.max(measured) - np.min(measured))
    j = int(np.argmax(np.abs(err)))
    return {
        "rmse": rmse,
        "nrmse": rmse / span if span > _flat_below(measured) else math.nan,
        "max_abs_error": float(abs(err[j])),
        "max_abs_error_time_s": float(time_s[j]),
        "n": int(len(err)),
    }


def _window_stats(time_s: np.ndarray, measured: np.ndarray, simulated: np.ndarray, starts: np.ndarray) -> pd.DataFrame:
    """:func:`_stats` of consecutive segments beginning at the indices ``starts`` (the first 0), all
    at once: O(n) whatever the number of segments."""
    err = simulated - measured
    counts = np.diff(np.append(starts, len(err)))
    rmse = np.sqrt(np.add.reduceat(err * err, starts) / counts)
    span = np.maximum.reduceat(measured, starts) - np.minimum.reduceat(measured, starts)
    size = np.abs(err)
    key = np.where(np.isnan(size), np.inf, size)  # the first NaN is the largest, as for np.argmax
    segment = np.repeat(np.arange(len(starts)), counts)
    hits = np.flatnonzero(key == np.maximum.reduceat(key, starts)[segment])
    first = hits[np.unique(segment[hits], return_index=True)[1]]
    ranged = span > _flat_below(measured)  # against the whole channel's magnitude
    with np.errstate(divide="ignore", invalid="ignore"):
        nrmse = np.where(ranged, rmse / np.where(ranged, span, 1.0), math.nan)
    return pd.DataFrame(
        {
            "rmse": rmse,
            "nrmse": nrmse,
            "max_abs_error": size[first],
            "max_abs_error_time_s": time_s[first],
            "n": counts,
        }
    )


def metric_windows(time_s: np.ndarray, window_s: float | None) -> list[tuple[str, float, float, slice]]:
    """("all", start, end, samples) then consecutive windows of ``window_s`` from the first sample:
    [start, start + window_s), the last one closed at the last sample; empty windows left out.
    ``samples`` is the slice of the samples in the window. O(n) whatever the window."""
    t = np.asarray(time_s, dtype=float)
    out = [("all", float(t[0]), float(t[-1]), slice(0, len(t)))]
    if not window_s or len(t) < 2:
        return out
    count = max(1, math.ceil((t[-1] - t[0]) / window_s - 1e-9))
    k = np.clip(np.floor((t - t[0]) / window_s + 1e-9), 0, count - 1).astype(np.int64)
    starts = np.flatnonzero(np.diff(k, prepend=-1))
    for lo, hi in zip(starts, np.append(starts[1:], len(t)), strict=True):
        start = float(t[0] + int(k[lo]) * window_s)
        out.append((str(int(k[lo]) + 1), start, float(min(start + window_s, t[-1])), slice(int(lo), int(hi))))
    return out


def error_metrics(time_s, measured, simulated, window_s: float | None = METRICS_WINDOW_S) -> pd.DataFrame:
    """Errors of ``simulated`` against ``measured`` (same samples) over the whole record and over
    consecutive windows of ``window_s``: columns ``window, window_start_s, window_end_s, rmse,
    nrmse, max_abs_error, max_abs_error_time_s, n``. Error = simulated − measured; NRMSE = RMSE /
    (max − min of measured in the window), NaN when that is zero or below :data:`FLAT_RANGE` of the
    channel's largest magnitude."""
    t, m, s = (np.asarray(a, dtype=float) for a in (time_s, measured, simulated))
    if not (len(t) == len(m) == len(s)) or len(t) == 0:
        raise ValueError(f"time, measured and simulated need the same non-zero length ({len(t)}, {len(m)}, {len(s)})")
    windows = metric_windows(t, window_s)
    whole = pd.DataFrame([{"window": "all", "window_start_s": t[0], "window_end_s": t[-1], **_stats(t, m, s)}])
    if len(windows) == 1:
        return whole[METRIC_COLUMNS[2:]]
    names, starts, ends, segments = zip(*windows[1:], strict=True)
    parts = _window_stats(t, m, s, np.array([seg.start for seg in segments]))
    parts.insert(0, "window", list(names))
    parts.insert(1, "window_start_s", list(starts))
    parts.insert(2, "window_end_s", list(ends))
    return pd.concat([whole, parts], ignore_index=True)[METRIC_COLUMNS[2:]]


def metrics_table(
    time_s: np.ndarray,
    results: dict[str, transient.TransientResult],
    references: dict[str, np.ndarray],
    window_s: float | None,
) -> pd.DataFrame:
    """:func:`error_metrics` for every model × reference channel the model outputs."""
    parts = []
    for name, result in results.items():
        frame = result.frame()
        for channel, measured in references.items():
            if channel in frame.columns:
                df = error_metrics(time_s, measured, frame[channel].to_numpy(), window_s)
                parts.append(df.assign(model=name, channel=channel))
    if not parts:
        return pd.DataFrame(columns=METRIC_COLUMNS)
    return pd.concat(parts, ignore_index=True)[METRIC_COLUMNS]


def events_table(results: dict[str, transient.TransientResult]) -> pd.DataFrame:
    """All models' events: ``model, time_s, kind, stator_locked, flow_direction``."""
    rows = [
        {
            "model": name,
            "time_s": e.time_s,
            "kind": e.kind,
            "stator_locked": e.stator_locked,
            "flow_direction": e.flow_direction,
        }
        for name, r in results.items()
        for e in r.events
    ]
    return pd.DataFrame(rows, columns=EVENT_COLUMNS)


# ---------------------------------------------------------------------------------------------
# the whole replay


@dataclass
class Replay:
    """Everything a replay produced (see the module docstring for the files)."""

    converter: str
    drive: DriveKind
    measurement: Measurement
    results: dict[str, transient.TransientResult]
    measured_effective: dict[str, np.ndarray] = field(default_factory=dict)
    metrics: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=METRIC_COLUMNS))

    @property
    def events(self) -> pd.DataFrame:
        return events_table(self.results)

    def measured_frame(self) -> pd.DataFrame:
        return self.measurement.to_frame().assign(**self.measured_effective)


def replay_measurement(
    conv: Converter,
    meas: Measurement,
    models: Sequence[str] = (),
    kind: DriveKind = DRIVES["pump-torque"],
    initial: dict[str, float] | None = None,
    window_s: float | None = None,
    metrics_window_s: float | None = METRICS_WINDOW_S,
) -> Replay:
    """Run the replay of a measurement read with the channels of ``kind`` (no files): simulate every
    model, measure the errors. ``window_s`` (s) defaults to :data:`DERIVATIVE_WINDOW_S`; both
    windows are checked against the record (:func:`check_record_windows`)."""
    check_record_windows(meas, window_s, metrics_window_s)
    window_s = DERIVATIVE_WINDOW_S if window_s is None else check_window("--window", window_s, positive=False)
    if metrics_window_s is not None:
        metrics_window_s = check_window("--metrics-window", metrics_window_s, positive=True)
    dyn = select_models(conv, models)
    results = run_models(dyn, kind.make(meas, window_s), initial, meas.source)
    inertia = dyn[0].spec["inertia_kg_m2"]
    effective = {
        k: v
        for k, v in measured_effective_torques(meas, inertia[1], inertia[0], window_s).items()
        if k.startswith("effective_") and k != "effective_torque_ratio"
    }
    metrics = metrics_table(meas.time_s, results, reference_channels(meas, kind, effective), metrics_window_s)
    return Replay(conv.name, kind, meas, results, effective, metrics)
