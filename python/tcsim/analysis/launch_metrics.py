"""Metrics of a launch that compare a run with the table model's run or split it into its launch
phase and its shifts (docs/launch_summary.md defines each one; :mod:`tcsim.analysis.launch` puts
them into ``summary.csv``). Pure functions of the time series a run wrote: nothing here knows a
model's parameters or the shift schedule, so they follow whatever the run produced.

* **Effective-TR deficit** ``Δ(t) = E_table(t) − E_model(t)`` of the effective torque ratios
  (eqs 3.1–3.4), the table run's linearly interpolated at the model's sample times.
* **Dip**: the largest ``Δ`` over the window of width ``width_s`` after the brake release (the
  model's samples and both window edges), and when it occurs; the **mean deficit** is the time
  average of ``Δ`` over the same window.
* **Recovery time**: from the release until ``|Δ|`` stays within :data:`RECOVERY_BAND` up to the
  end of the launch phase (the first shift of either run, else the end of the shorter run).
* **Shift windows**: maximal runs of samples with ``shifting`` = 1 (or, for a series without that
  column, the two samples either side of a change of ``gear``); a shift's **transient** is its
  window extended by :data:`SHIFT_SETTLE_S` (at most to the next shift's start).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Band of the recovery time: the model's effective TR within this of the table model's [-]
#: (the issue-14 acceptance "within 0.05 of each other").
RECOVERY_BAND = 0.05
#: Time after a shift's end still counted as its transient (the driveline settles on the new
#: gear; about 0.15 s on the bundled vehicle), s.
SHIFT_SETTLE_S = 0.2


@dataclass(frozen=True)
class Shift:
    """One shift of a run: sample indices ``first``..``last`` (inclusive) while shifting, and the
    index ``end`` one past the last sample of its transient."""

    first: int
    last: int
    end: int


def shift_windows(time_s: np.ndarray, shifting: np.ndarray | None, gear: np.ndarray | None) -> list[Shift]:
    """The shifts of a run (module docstring), in time order; none without either column."""
    t = np.asarray(time_s, dtype=float)
    if shifting is not None:
        on = np.asarray(shifting, dtype=float) > 0.5
    elif gear is not None:
        g = np.asarray(gear, dtype=float)
        on = np.zeros(len(g), dtype=bool)
        change = np.flatnonzero(np.diff(g) != 0)
        on[change] = True
        on[change + 1] = True
    else:
        return []
    edges = np.diff(np.concatenate([[0], on.astype(int), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    shifts = []
    for i, (a, b) in enumerate(zip(starts, stops)):
        limit = int(starts[i + 1]) if i + 1 < len(starts) else len(t)
        end = int(np.searchsorted(t, t[b] + SHIFT_SETTLE_S, side="right"))
        shifts.append(Shift(int(a), int(b), min(end, limit)))
    return shifts


def phase_metrics(time_s, accel_m_s2, shifts: list[Shift], release_s: float) -> dict[str, float]:
    """Launch peak (before the first shift after the release) and shift transients of one run:
    ``launch_peak_accel_m_s2``, ``launch_peak_accel_time_s`` (from the release),
    ``shift_count``, ``shift_peak_accel_m_s2`` and ``max_shift_accel_ratio`` (largest over the
    shifts of the peak in the transient over the acceleration at the sample before the shift;
    shifts with a non-positive acceleration before them are left out). NaN where undefined."""
    t = np.asarray(time_s, dtype=float)
    a = np.asarray(accel_m_s2, dtype=float)
    after = [s for s in shifts if t[s.first] >= release_s]
    stop = after[0].first if after else len(t)
    launch = np.flatnonzero((t >= release_s) & np.isfinite(a))
    launch = launch[launch < stop]
    out = {
        "launch_peak_accel_m_s2": math.nan,
        "launch_peak_accel_time_s": math.nan,
        "shift_count": float(len(after)),
        "shift_peak_accel_m_s2": math.nan,
        "max_shift_accel_ratio": math.nan,
    }
    if launch.size:
        k = int(launch[np.argmax(a[launch])])
        out["launch_peak_accel_m_s2"], out["launch_peak_accel_time_s"] = float(a[k]), float(t[k] - release_s)
    peaks, ratios = [], []
    for s in after:
        w = a[s.first : s.end]
        w = w[np.isfinite(w)]
        if not w.size:
            continue
        peaks.append(float(w.max()))
        before = a[s.first - 1] if s.first > 0 else math.nan
        if math.isfinite(before) and before > 0:
            ratios.append(peaks[-1] / float(before))
    if peaks:
        out["shift_peak_accel_m_s2"] = max(peaks)
    if ratios:
        out["max_shift_accel_ratio"] = max(ratios)
    return out


def _deficit(t: np.ndarray, e: np.ndarray, ref_t: np.ndarray, ref_e: np.ndarray, a: float, b: float):
    """Times in [a, b] (the model's samples and both edges) and ``Δ`` there; None if either run
    does not cover [a, b]."""
    tol = 1e-9 * max(1.0, abs(b))
    for tt in (t, ref_t):
        if len(tt) == 0 or tt[0] > a + tol or tt[-1] < b - tol:
            return None
    inside = (t > a) & (t < b)
    tw = np.concatenate([[a], t[inside], [b]])
    model = np.concatenate([[np.interp(a, t, e)], e[inside], [np.interp(b, t, e)]])
    return tw, np.interp(tw, ref_t, ref_e) - model


def dip_metrics(time_s, etr, ref_time_s, ref_etr, release_s: float, width_s: float) -> dict[str, float]:
    """``dip``, ``dip_time_s`` (from the release) and ``mean_deficit`` of the effective TR against
    the table run's over [release, release + width] (module docstring); NaN if not covered."""
    t, e = np.asarray(time_s, dtype=float), np.asarray(etr, dtype=float)
    rt, re = np.asarray(ref_time_s, dtype=float), np.asarray(ref_etr, dtype=float)
    nan = {"dip": math.nan, "dip_time_s": math.nan, "mean_deficit": math.nan}
    d = _deficit(t, e, rt, re, release_s, release_s + width_s)
    if d is None or width_s <= 0:
        return nan
    tw, delta = d
    ok = np.isfinite(delta)
    if not ok.any():
        return nan
    k = int(np.argmax(np.where(ok, delta, -np.inf)))
    mean = float(np.sum(0.5 * (delta[1:] + delta[:-1]) * np.diff(tw)) / width_s) if ok.all() else math.nan
    return {"dip": float(delta[k]), "dip_time_s": float(tw[k] - release_s), "mean_deficit": mean}


def recovery_time(time_s, etr, ref_time_s, ref_etr, release_s: float, phase_end_s: float) -> float:
    """Time from the release until ``|Δ| ≤`` :data:`RECOVERY_BAND` for good up to ``phase_end_s``
    (samples before it), the crossing interpolated linearly; 0 if never outside the band; NaN if
    still outside at the phase's last sample or if the runs do not cover the phase."""
    t, e = np.asarray(time_s, dtype=float), np.asarray(etr, dtype=float)
    rt, re = np.asarray(ref_time_s, dtype=float), np.asarray(ref_etr, dtype=float)
    end = min(phase_end_s, float(t[-1]) if len(t) else -math.inf, float(rt[-1]) if len(rt) else -math.inf)
    if not end > release_s:
        return math.nan
    d = _deficit(t, e, rt, re, release_s, end)
    if d is None:
        return math.nan
    tw, delta = d
    tw, delta = tw[:-1], delta[:-1]  # samples before the phase's end (the next shift's first)
    if len(tw) < 2:
        return math.nan
    return time_back_in_band(tw, delta, RECOVERY_BAND, release_s)


def time_back_in_band(time_s: np.ndarray, gap: np.ndarray, band: float, start_s: float) -> float:
    """Time from ``start_s`` until ``|gap|`` stays within ``band`` to the last sample, the crossing
    interpolated linearly, s; 0 if it never leaves the band, NaN if it is outside at the last sample
    (a NaN gap counts as outside)."""
    out = np.flatnonzero(~(np.abs(gap) <= band))
    if not out.size:
        return 0.0
    k = int(out[-1])
    if k == len(gap) - 1:
        return math.nan
    d0, d1 = abs(gap[k]), abs(gap[k + 1])
    frac = (d0 - band) / (d0 - d1) if math.isfinite(d0) and d0 > d1 else 1.0
    return float(time_s[k] + frac * (time_s[k + 1] - time_s[k]) - start_s)


def deficit_series(time_s, etr, ref_time_s, ref_etr) -> np.ndarray:
    """``Δ`` at the model's samples (NaN outside the table run's time span), for the figures."""
    t, e = np.asarray(time_s, dtype=float), np.asarray(etr, dtype=float)
    rt, re = np.asarray(ref_time_s, dtype=float), np.asarray(ref_etr, dtype=float)
    if not len(rt):
        return np.full_like(t, np.nan)
    ref = np.interp(t, rt, re, left=np.nan, right=np.nan)
    return ref - e
