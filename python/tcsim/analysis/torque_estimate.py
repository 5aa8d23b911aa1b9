"""An estimated engine torque (the ECM's) against a measured one (a dynamometer's): thesis §3.3.

Signal processing of two measured signals, no converter physics (``docs/torque_estimate.md`` is
the user's description; every rule below is stated there too):

* **Common grid.** Uniform, step ``h`` = the smaller of the two records' median sample intervals,
  from the later start to the earlier end of the two records (their overlap):
  ``t_k = t_start + k·h``. Both signals are linearly interpolated onto it. The overlap must hold
  at least :data:`MIN_COMMON_SAMPLES` grid points and at most :data:`MAX_GRID_POINTS`.
* **Delay.** The delay ``d`` (s, positive: the estimate lags, ``estimate(t) ≈ measured(t − d)``)
  maximises the Pearson correlation of the two gridded signals over their overlapping samples,
  searched over whole grid steps ``|k| ≤ K``, ``K = min(round(max_delay / h), (N − 1) // 2)``,
  then refined by the parabola through the peak and its two neighbours (±½ step). Correlation
  ignores a gain or an offset of the estimate, so they do not bias the delay.
* **Aligned estimate.** ``estimate(t + d)``, linearly interpolated from the estimate's own samples;
  undefined (NaN) where ``t + d`` lies outside its record.
* **Errors.** ``error = estimate − measured`` (N·m) on the grid, as logged and aligned: RMSE, the
  largest error (signed, the one of largest magnitude) and when it occurs, the mean error.
* **Load steps** (:func:`detect_steps`), from the measured signal only, and per step the time at
  which each signal first reaches 90 % of the step (the error of the time to 90 % torque is the
  difference of these times, both counted from the same onset).
* **Coarse sampling.** A warning when the fastest measured 10–90 % rise spans fewer than
  :data:`MIN_SAMPLES_PER_RISE` estimate sample intervals (thesis §3.3, fig. 3.8: the ECM's torque
  sampled too slowly for the transients gives large steps and a large instantaneous error).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.signal import correlate

from ..errors import InputError, TcsimWarning

#: The canonical channel of an engine torque in both files (N·m).
CHANNEL = "engine_torque_nm"
#: The fewest grid points the two records must share.
MIN_COMMON_SAMPLES = 20
#: The most grid points of the common grid (40 MB per signal).
MAX_GRID_POINTS = 5_000_000
#: The default of ``--max-delay``, s.
DEFAULT_MAX_DELAY_S = 1.0
#: Load-step hysteresis, fractions of the measured torque's range (min to max of the record).
STEP_LOW, STEP_HIGH = 0.4, 0.6
#: The initial level of a step is this percentile of its low part (the settled torque before it).
LEVEL_PERCENTILE = 5.0
#: The levels of the rise, fractions of a step (initial to final level).
RISE_FROM, RISE_TO = 0.1, 0.9
#: The fewest estimate sample intervals a measured 10–90 % rise must span without a warning.
MIN_SAMPLES_PER_RISE = 5.0


@dataclass(frozen=True)
class TorqueSignal:
    """A torque over time as read from one file: ``time_s`` strictly increasing, ``torque_nm``."""

    source: str
    time_s: np.ndarray
    torque_nm: np.ndarray

    @property
    def sample_interval_s(self) -> float:
        """The median sample interval, s."""
        return float(np.median(np.diff(self.time_s)))


@dataclass(frozen=True)
class ErrorStats:
    """Errors ``estimate − measured`` over some samples: RMSE, the signed largest one and its time."""

    rmse_nm: float
    largest_nm: float
    largest_time_s: float
    mean_nm: float

    @classmethod
    def of(cls, time_s: np.ndarray, error_nm: np.ndarray) -> ErrorStats:
        """The statistics of the finite errors (all NaN when there are none)."""
        ok = np.isfinite(error_nm)
        if not ok.any():
            return cls(math.nan, math.nan, math.nan, math.nan)
        t, e = time_s[ok], error_nm[ok]
        i = int(np.argmax(np.abs(e)))
        return cls(float(np.sqrt(np.mean(e**2))), float(e[i]), float(t[i]), float(np.mean(e)))


@dataclass(frozen=True)
class LoadStep:
    """One load step: grid samples ``first``..``end - 1`` (:func:`detect_steps`); levels in N·m,
    crossing times in s."""

    first: int
    rise: int
    fall: int
    end: int
    initial_nm: float
    final_nm: float
    measured_t10_s: float
    measured_t90_s: float
    estimate_t90_s: float
    aligned_t90_s: float
    errors: ErrorStats
    aligned_errors: ErrorStats

    @property
    def rise_10_90_s(self) -> float:
        """The measured 10–90 % rise time, s."""
        return self.measured_t90_s - self.measured_t10_s


@dataclass(frozen=True)
class TorqueComparison:
    """The comparison of an estimated with a measured engine torque (see the module's docstring)."""

    estimate: TorqueSignal
    measured: TorqueSignal
    time_s: np.ndarray
    measured_nm: np.ndarray
    estimate_nm: np.ndarray
    aligned_nm: np.ndarray
    max_delay_s: float
    delay_s: float
    correlation: float
    steps: list[LoadStep] = field(default_factory=list)

    @property
    def grid_step_s(self) -> float:
        return float(self.time_s[1] - self.time_s[0])

    def fastest_step(self) -> LoadStep | None:
        """The step with the shortest finite measured 10–90 % rise, if any."""
        timed = [s for s in self.steps if math.isfinite(s.rise_10_90_s) and s.rise_10_90_s > 0]
        return min(timed, key=lambda s: s.rise_10_90_s) if timed else None

    def samples_in_fastest_rise(self) -> float:
        """Estimate sample intervals within the fastest measured 10–90 % rise (NaN without steps)."""
        fastest = self.fastest_step()
        return math.nan if fastest is None else fastest.rise_10_90_s / self.estimate.sample_interval_s

    def timeseries(self) -> pd.DataFrame:
        """The common grid: both signals, the aligned estimate and the errors, N·m."""
        return pd.DataFrame(
            {
                "time_s": self.time_s,
                "measured_engine_torque_nm": self.measured_nm,
                "estimated_engine_torque_nm": self.estimate_nm,
                "estimated_engine_torque_aligned_nm": self.aligned_nm,
                "error_nm": self.estimate_nm - self.measured_nm,
                "error_aligned_nm": self.aligned_nm - self.measured_nm,
            }
        )

    def summary(self) -> pd.DataFrame:
        """One row: the grid, the delay, the overall errors, the steps and the sampling check."""
        frame = self.timeseries()
        raw = ErrorStats.of(self.time_s, frame["error_nm"].to_numpy())
        aligned = ErrorStats.of(self.time_s, frame["error_aligned_nm"].to_numpy())
        fastest = self.fastest_step()
        samples = self.samples_in_fastest_rise()
        row = {
            "estimate_file": self.estimate.source,
            "measured_file": self.measured.source,
            "estimate_sample_interval_s": self.estimate.sample_interval_s,
            "measured_sample_interval_s": self.measured.sample_interval_s,
            "grid_step_s": self.grid_step_s,
            "common_start_s": float(self.time_s[0]),
            "common_end_s": float(self.time_s[-1]),
            "max_delay_s": self.max_delay_s,
            "delay_s": self.delay_s,
            "correlation": self.correlation,
            **_stats_columns(raw, ""),
            **_stats_columns(aligned, "_aligned"),
            "steps": len(self.steps),
            "fastest_rise_10_90_s": math.nan if fastest is None else fastest.rise_10_90_s,
            "estimate_samples_in_fastest_rise": samples,
            "coarse_sampling": int(bool(samples < MIN_SAMPLES_PER_RISE)),
        }
        return pd.DataFrame([row])

    def steps_frame(self) -> pd.DataFrame:
        """One row per load step (``step`` from 1)."""
        rows = []
        for number, s in enumerate(self.steps, start=1):
            rows.append(
                {
                    "step": number,
                    "start_s": float(self.time_s[s.first]),
                    "end_s": float(self.time_s[s.end - 1]),
                    "release_s": float(self.time_s[s.fall]) if s.fall < len(self.time_s) else math.nan,
                    "initial_torque_nm": s.initial_nm,
                    "final_torque_nm": s.final_nm,
                    "measured_t10_s": s.measured_t10_s,
                    "measured_t90_s": s.measured_t90_s,
                    "measured_rise_10_90_s": s.rise_10_90_s,
                    "estimate_t90_s": s.estimate_t90_s,
                    "t90_error_s": s.estimate_t90_s - s.measured_t90_s,
                    "estimate_aligned_t90_s": s.aligned_t90_s,
                    "t90_error_aligned_s": s.aligned_t90_s - s.measured_t90_s,
                    **_stats_columns(s.errors, ""),
                    **_stats_columns(s.aligned_errors, "_aligned"),
                    "estimate_samples_in_rise": s.rise_10_90_s / self.estimate.sample_interval_s,
                }
            )
        return pd.DataFrame(rows, columns=STEP_COLUMNS)


def _stats_columns(stats: ErrorStats, suffix: str) -> dict[str, float]:
    return {
        f"rmse{suffix}_nm": stats.rmse_nm,
        f"largest_error{suffix}_nm": stats.largest_nm,
        f"largest_error{suffix}_time_s": stats.largest_time_s,
        f"mean_error{suffix}_nm": stats.mean_nm,
    }


STEP_COLUMNS = [
    "step",
    "start_s",
    "end_s",
    "release_s",
    "initial_torque_nm",
    "final_torque_nm",
    "measured_t10_s",
    "measured_t90_s",
    "measured_rise_10_90_s",
    "estimate_t90_s",
    "t90_error_s",
    "estimate_aligned_t90_s",
    "t90_error_aligned_s",
    *_stats_columns(ErrorStats(0, 0, 0, 0), ""),
    *_stats_columns(ErrorStats(0, 0, 0, 0), "_aligned"),
    "estimate_samples_in_rise",
]


def check_max_delay(value: float) -> float:
    """``--max-delay``: a finite number of seconds > 0, else an InputError."""
    if not (math.isfinite(value) and value > 0):
        raise InputError("command line", "--max-delay", value, "a finite number of seconds > 0")
    return float(value)


def common_grid(estimate: TorqueSignal, measured: TorqueSignal) -> np.ndarray:
    """The uniform grid over the two records' overlap (see the module's docstring); an InputError
    naming the estimate's file when they share fewer than :data:`MIN_COMMON_SAMPLES` grid points,
    the measured file's when the grid would exceed :data:`MAX_GRID_POINTS`."""
    step = min(estimate.sample_interval_s, measured.sample_interval_s)
    start = max(estimate.time_s[0], measured.time_s[0])
    end = min(estimate.time_s[-1], measured.time_s[-1])
    count = math.floor((end - start) / step * (1 + 1e-12)) + 1 if end >= start else 0
    if count < MIN_COMMON_SAMPLES:
        raise InputError(
            estimate.source,
            "time_s",
            f"{estimate.time_s[0]:g} s to {estimate.time_s[-1]:g} s",
            f"a record overlapping the measured one ({measured.source}: {measured.time_s[0]:g} s to "
            f"{measured.time_s[-1]:g} s) by at least {MIN_COMMON_SAMPLES} samples of the common grid "
            f"({step:g} s); the overlap has {count}",
        )
    if count > MAX_GRID_POINTS:
        raise InputError(
            measured.source,
            "time_s",
            f"{count} samples of {step:g} s in the overlap",
            f"at most {MAX_GRID_POINTS} samples on the common grid (a shorter record or a coarser sampling)",
        )
    return start + step * np.arange(count)


def _require_varying(signal: TorqueSignal, values: np.ndarray) -> None:
    if np.ptp(values) <= 0:
        raise InputError(
            signal.source,
            CHANNEL,
            f"constant {values[0]:g} N·m over the common time",
            "a torque that varies over the time both records cover (the delay is found by correlation)",
        )


def lag_correlation(estimate_nm: np.ndarray, measured_nm: np.ndarray, max_lag: int) -> np.ndarray:
    """Pearson correlation of ``estimate[i + k]`` with ``measured[i]`` over their common samples,
    for ``k = -max_lag … max_lag`` (``NaN`` where either part is constant); via one FFT
    cross-correlation and running sums."""
    n = len(measured_nm)
    e = estimate_nm - estimate_nm.mean()
    m = measured_nm - measured_nm.mean()
    lags = np.arange(-max_lag, max_lag + 1)
    cross = correlate(e, m, mode="full", method="fft")[n - 1 + lags]  # sum_i e[i + k] m[i]
    count = n - np.abs(lags)
    e_lo, e_hi = np.maximum(0, lags), np.minimum(n, n + lags)
    m_lo, m_hi = np.maximum(0, -lags), np.minimum(n, n - lags)

    def windowed(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        s1 = np.concatenate([[0.0], np.cumsum(x)])
        s2 = np.concatenate([[0.0], np.cumsum(x * x)])
        return s1[hi] - s1[lo], s2[hi] - s2[lo]

    se, see = windowed(e, e_lo, e_hi)
    sm, smm = windowed(m, m_lo, m_hi)
    cov = cross - se * sm / count
    var = (see - se**2 / count) * (smm - sm**2 / count)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(var > 0, cov / np.sqrt(np.where(var > 0, var, 1.0)), np.nan)


def best_delay(
    time_s: np.ndarray, estimate_nm: np.ndarray, measured_nm: np.ndarray, max_delay_s: float
) -> tuple[float, float, bool]:
    """The delay (s, positive: the estimate lags), its correlation, and whether it lies at the edge
    of the searched range (then the true delay may lie beyond it)."""
    n = len(time_s)
    step = float(time_s[1] - time_s[0])
    max_lag = max(1, min(round(max_delay_s / step), (n - 1) // 2))
    r = lag_correlation(estimate_nm, measured_nm, max_lag)
    if not np.isfinite(r).any():
        return 0.0, math.nan, False
    j = int(np.nanargmax(r))
    at_edge = j in (0, len(r) - 1)
    offset = 0.0
    if not at_edge and np.isfinite(r[j - 1]) and np.isfinite(r[j + 1]):
        curvature = r[j - 1] - 2 * r[j] + r[j + 1]
        if curvature < 0:
            offset = float(np.clip(0.5 * (r[j - 1] - r[j + 1]) / curvature, -0.5, 0.5))
    return (j - max_lag + offset) * step, float(r[j]), at_edge


def _hysteresis_state(measured_nm: np.ndarray) -> np.ndarray:
    """1 where the measured torque is high, 0 where low: high once above STEP_HIGH of its range,
    low once below STEP_LOW; the first sample by the middle of the range."""
    low, span = float(measured_nm.min()), float(np.ptp(measured_nm))
    mark = np.where(measured_nm >= low + STEP_HIGH * span, 1, np.where(measured_nm <= low + STEP_LOW * span, 0, -1))
    if mark[0] < 0:
        mark[0] = int(measured_nm[0] >= low + 0.5 * span)
    index = np.maximum.accumulate(np.where(mark >= 0, np.arange(len(mark)), 0))
    return mark[index]


def detect_steps(measured_nm: np.ndarray) -> list[tuple[int, int, int, int]]:
    """The load steps of the measured torque, each as grid indices ``(first, rise, fall, end)``.

    A step is a rise of the hysteresis state (:func:`_hysteresis_state`: above 60 % of the
    record's range after having been below 40 %) at ``rise``, held until the next fall below 40 %
    at ``fall`` (or the record's end). Its window, ``first`` to ``end`` (exclusive), runs from
    halfway between the previous fall and the rise (or the record's start) to halfway between its
    fall and the next rise (or the record's end): the windows of the steps tile the record, each
    with its application and its release. Its initial level is the 5th percentile of the measured
    torque from ``first`` to ``rise``, its final level the median of the second half of ``rise``
    to ``fall`` (settled, after any overshoot); :func:`_step`."""
    if np.ptp(measured_nm) <= 0:
        return []
    n = len(measured_nm)
    change = np.diff(_hysteresis_state(measured_nm))
    rises = np.flatnonzero(change > 0) + 1
    falls = np.flatnonzero(change < 0) + 1
    steps = []
    for i, rise in enumerate(rises):
        before, after = falls[falls < rise], falls[falls > rise]
        first = (int(before[-1]) + int(rise)) // 2 if len(before) else 0
        fall = int(after[0]) if len(after) else n
        end = (fall + int(rises[i + 1])) // 2 if i + 1 < len(rises) else n
        steps.append((first, int(rise), fall, end))
    return steps


def first_reach(time_s: np.ndarray, values: np.ndarray, level: float) -> tuple[float, int]:
    """The first time ``values`` rise through ``level`` (from a sample below it to one at or above
    it, linear between them) and the index of the sample after; NaN and -1 when they never do."""
    crossings = np.flatnonzero((values[1:] >= level) & (values[:-1] < level)) + 1
    if not len(crossings):
        return math.nan, -1
    j = int(crossings[0])
    v0, v1 = values[j - 1], values[j]
    return float(time_s[j - 1] + (level - v0) / (v1 - v0) * (time_s[j] - time_s[j - 1])), j


def last_leave(time_s: np.ndarray, values: np.ndarray, level: float, before: int) -> float:
    """The last time before sample ``before`` at which ``values`` rise through ``level`` (linear
    between samples); NaN when they are not below it before then."""
    below = np.flatnonzero(values[:before] < level)
    if not len(below) or below[-1] + 1 >= len(values):
        return math.nan
    j = int(below[-1])
    v0, v1 = values[j], values[j + 1]
    return float(time_s[j] + (level - v0) / (v1 - v0) * (time_s[j + 1] - time_s[j]))


def _step(arrays: tuple[np.ndarray, ...], first: int, rise: int, fall: int, end: int) -> LoadStep | None:
    """The levels, crossing times and errors of one step; None when the step does not rise."""
    t, measured, estimate, aligned = (a[first:end] for a in arrays)
    high = measured[rise - first : fall - first]
    initial = float(np.percentile(measured[: rise - first], LEVEL_PERCENTILE))
    final = float(np.median(high[len(high) // 2 :]))
    if not final > initial:
        return None
    level = initial + RISE_TO * (final - initial)
    t90, j90 = first_reach(t, measured, level)
    t10 = last_leave(t, measured, initial + RISE_FROM * (final - initial), j90) if j90 > 0 else math.nan
    return LoadStep(
        first,
        rise,
        fall,
        end,
        initial,
        final,
        t10,
        t90,
        first_reach(t, estimate, level)[0],
        first_reach(t, aligned, level)[0],
        ErrorStats.of(t, estimate - measured),
        ErrorStats.of(t, aligned - measured),
    )


def compare_torques(
    estimate: TorqueSignal, measured: TorqueSignal, max_delay_s: float = DEFAULT_MAX_DELAY_S
) -> TorqueComparison:
    """Compare an estimated with a measured engine torque (the module's docstring gives the method).

    Raises :class:`InputError` when the records share too little time or either torque is constant
    there. Warns (:class:`TcsimWarning`) when the delay lies at the edge of the searched range and
    when the estimate is sampled too coarsely for the measured rises."""
    max_delay_s = check_max_delay(max_delay_s)
    t = common_grid(estimate, measured)
    measured_nm = np.interp(t, measured.time_s, measured.torque_nm)
    estimate_nm = np.interp(t, estimate.time_s, estimate.torque_nm)
    _require_varying(measured, measured_nm)
    _require_varying(estimate, estimate_nm)
    delay, correlation, at_edge = best_delay(t, estimate_nm, measured_nm, max_delay_s)
    shifted = t + delay
    inside = (shifted >= estimate.time_s[0]) & (shifted <= estimate.time_s[-1])
    aligned = np.where(inside, np.interp(shifted, estimate.time_s, estimate.torque_nm), np.nan)
    arrays = (t, measured_nm, estimate_nm, aligned)
    steps = [s for s in (_step(arrays, *bounds) for bounds in detect_steps(measured_nm)) if s is not None]
    result = TorqueComparison(
        estimate, measured, t, measured_nm, estimate_nm, aligned, max_delay_s, delay, correlation, steps
    )
    weak, negated = _weakness(t, estimate_nm, measured_nm, max_delay_s, correlation)
    if at_edge and not negated:  # a negated estimate's best delay is anywhere: no range helps
        warnings.warn(
            f"{estimate.source}: the best delay, {delay:g} s, lies at the edge of the searched range "
            f"(±{max_delay_s:g} s, or half the common time): the true delay may be larger; raise --max-delay",
            TcsimWarning,
            stacklevel=2,
        )
    _warn_coarse(result)
    if weak:
        warnings.warn(f"{estimate.source}: the estimate {weak}", TcsimWarning, stacklevel=2)
    return result


#: The correlation at the best delay below which the two torques are said not to follow each other.
WEAK_CORRELATION = 0.8


def _weakness(t, estimate_nm, measured_nm, max_delay_s: float, correlation: float) -> tuple[str | None, bool]:
    """What is wrong when the torques barely follow each other at the best delay, and whether the
    estimate negated follows better (its sign convention opposite to the measurement's); a
    correlation below :data:`WEAK_CORRELATION` otherwise (the delay and the errors then mean little)."""
    delay_negated, negated, _ = best_delay(t, -estimate_nm, measured_nm, max_delay_s)
    if negated > correlation:
        return (
            f"follows the measured torque better negated (correlation {negated:.3g} at a delay of "
            f"{delay_negated:.4g} s, against {correlation:.3g}): check the estimate's sign convention"
        ), True
    if correlation < WEAK_CORRELATION:
        return (
            f"barely follows the measured torque (correlation {correlation:.3g} at the best delay, below "
            f"{WEAK_CORRELATION:g}): the delay and the errors mean little; check that both are the same torque"
        ), False
    return None, False


def _warn_coarse(result: TorqueComparison) -> None:
    samples = result.samples_in_fastest_rise()
    fastest = result.fastest_step()
    if fastest is None or not samples < MIN_SAMPLES_PER_RISE:
        return
    number = result.steps.index(fastest) + 1
    warnings.warn(
        f"{result.estimate.source}: sample interval {result.estimate.sample_interval_s:g} s is too coarse for the "
        f"transients: the fastest measured 10-90 % rise (step {number}, {fastest.rise_10_90_s:g} s) spans "
        f"{samples:.2g} estimate samples (fewer than {MIN_SAMPLES_PER_RISE:g}); errors during the rises are "
        "dominated by the sampling (thesis §3.3, fig. 3.8)",
        TcsimWarning,
        stacklevel=2,
    )
