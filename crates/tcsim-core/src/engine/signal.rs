//! Input signals: sampled time series, interpolated linearly, with a smoothed derivative.
//!
//! A measured speed that drives the converter (a prescribed pump or turbine speed) enters the
//! equations through its derivative as well (the inertia and shape-effect terms). Differentiating
//! noisy samples directly amplifies the noise, so the derivative is a **local linear least-squares
//! slope** (a first-order Savitzky–Golay filter on non-uniform samples): at each sample, the slope
//! of the straight line fitted to all samples within ±`window_s/2`. Between samples both the value
//! and the smoothed derivative are interpolated linearly, so both are continuous in time.
//! A window of zero, or one holding fewer than three samples, gives the central difference (the
//! one-sided difference at the ends). The default window is [`DEFAULT_DERIVATIVE_WINDOW_S`].
//!
//! Before the first sample and after the last, the end values are held and the derivative is zero.

use crate::error::{sig, CoreError, CoreResult};

/// Default width of the derivative window: 40 ms, i.e. ±20 ms around each sample. It removes
/// sample-to-sample noise of a 100 Hz–1 kHz logger while keeping a 0.2 s torque rise.
pub const DEFAULT_DERIVATIVE_WINDOW_S: f64 = 0.04;

/// The finest spacing of time stamps the engines accept, s: 1 µs (a logger at 1 MHz).
pub const MIN_TIME_STEP_S: f64 = 1e-6;

/// Near large times the resolution is coarser: consecutive time stamps must also be at least this
/// many units in the last place (ulp) of the time apart (1024 ulp is 2.3e-13 of the time: 0.24 ms
/// at 1e9 s). Closer time stamps leave the solver's steps at the resolution of the floating-point
/// numbers, where it fails ("step size too small").
pub const MIN_TIME_STEP_ULPS: f64 = 1024.0;

/// The finest spacing accepted after time stamp `t`, s: `max(MIN_TIME_STEP_S, MIN_TIME_STEP_ULPS ·
/// ulp(t))`.
pub fn time_resolution_s(t: f64) -> f64 {
    let a = t.abs();
    let ulp = f64::from_bits(a.to_bits() + 1) - a;
    MIN_TIME_STEP_S.max(MIN_TIME_STEP_ULPS * ulp)
}

/// Time stamps that are finite, strictly increasing and at least [`time_resolution_s`] apart (less
/// 0.1 % for the rounding of the time stamps); the
/// error names `{name}[i]`, the first sample at fault, with the spacing found.
pub fn check_time_stamps(name: &str, time_s: &[f64]) -> CoreResult<()> {
    if let Some(i) = time_s.iter().position(|t| !t.is_finite()) {
        return Err(CoreError::new(format!("{name}[{i}]"), time_s[i], "a finite time"));
    }
    if let Some(i) = (1..time_s.len()).find(|&i| time_s[i] <= time_s[i - 1]) {
        return Err(CoreError::new(format!("{name}[{i}]"), time_s[i], "strictly increasing times"));
    }
    // a record logged at exactly the resolution passes despite the rounding of its time stamps
    let too_close =
        (1..time_s.len()).find(|&i| time_s[i] - time_s[i - 1] < (1.0 - 1e-3) * time_resolution_s(time_s[i - 1]));
    if let Some(i) = too_close {
        let (dt, res) = (time_s[i] - time_s[i - 1], time_resolution_s(time_s[i - 1]));
        return Err(CoreError::new(
            format!("{name}[{i}]"),
            time_s[i],
            format!(
                "time stamps at least {} s apart (the time resolution: 1 µs, or 1024 ulp of the time when coarser), but sample {i} is {} s after sample {}: resample the record",
                sig(res),
                sig(dt),
                i - 1
            ),
        ));
    }
    Ok(())
}

/// A sampled signal.
#[derive(Debug, Clone, PartialEq)]
pub struct Signal {
    time_s: Vec<f64>,
    value: Vec<f64>,
    rate: Vec<f64>,
}

impl Signal {
    /// A signal from samples. `name` is used in error messages. Times must be finite and strictly
    /// increasing, values finite; at least one sample.
    /// The time stamps must also be no closer than the time resolution ([`check_time_stamps`]).
    pub fn new(name: &str, time_s: Vec<f64>, value: Vec<f64>, derivative_window_s: f64) -> CoreResult<Self> {
        Self::build(name, time_s, value, derivative_window_s, true)
    }

    /// A signal whose samples are only differentiated, never integrated by the solver (the measured
    /// effective torques): any strictly increasing time stamps.
    pub fn new_any_spacing(
        name: &str,
        time_s: Vec<f64>,
        value: Vec<f64>,
        derivative_window_s: f64,
    ) -> CoreResult<Self> {
        Self::build(name, time_s, value, derivative_window_s, false)
    }

    /// A host's communication interval `[t, t + h]` in co-simulation, with the values at its ends:
    /// any positive length (the host chooses its steps; the time resolution is for recorded signals).
    pub fn interval(name: &str, time_s: [f64; 2], value: [f64; 2]) -> CoreResult<Self> {
        Self::build(name, time_s.to_vec(), value.to_vec(), 0.0, false)
    }

    fn build(
        name: &str,
        time_s: Vec<f64>,
        value: Vec<f64>,
        derivative_window_s: f64,
        resolution: bool,
    ) -> CoreResult<Self> {
        if time_s.is_empty() || time_s.len() != value.len() {
            return Err(CoreError::new(
                name,
                format!("{} times, {} values", time_s.len(), value.len()),
                "as many values as times, at least one",
            ));
        }
        if let Some(i) = time_s.iter().position(|t| !t.is_finite()) {
            return Err(CoreError::new(format!("{name}.time_s[{i}]"), time_s[i], "a finite time"));
        }
        if let Some(i) = value.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::new(format!("{name}[{i}]"), value[i], "a finite value"));
        }
        if let Some(i) = (1..time_s.len()).find(|&i| time_s[i] <= time_s[i - 1]) {
            return Err(CoreError::new(format!("{name}.time_s[{i}]"), time_s[i], "strictly increasing times"));
        }
        if resolution {
            check_time_stamps(&format!("{name}.time_s"), &time_s)?;
        }
        if !(derivative_window_s.is_finite() && derivative_window_s >= 0.0) {
            return Err(CoreError::new(
                "derivative_window_s",
                derivative_window_s,
                "a finite window of zero or more seconds",
            ));
        }
        let rate = smoothed_rate(&time_s, &value, derivative_window_s);
        Ok(Self { time_s, value, rate })
    }

    /// A constant signal.
    pub fn constant(value: f64) -> Self {
        Self { time_s: vec![0.0], value: vec![value], rate: vec![0.0] }
    }

    /// A constant signal named `name` in errors: its value must be finite.
    pub fn constant_named(name: &str, value: f64) -> CoreResult<Self> {
        if value.is_finite() {
            Ok(Self::constant(value))
        } else {
            Err(CoreError::new(name, value, "a finite value"))
        }
    }

    pub fn times(&self) -> &[f64] {
        &self.time_s
    }

    pub fn values(&self) -> &[f64] {
        &self.value
    }

    /// Value at time `t` (linear interpolation, end values held).
    pub fn value(&self, t: f64) -> f64 {
        self.interpolate(&self.value, t)
    }

    /// Smoothed derivative at time `t` (zero outside the samples).
    pub fn rate(&self, t: f64) -> f64 {
        let n = self.time_s.len();
        if n < 2 || t < self.time_s[0] || t > self.time_s[n - 1] {
            return 0.0;
        }
        self.interpolate(&self.rate, t)
    }

    fn interpolate(&self, y: &[f64], t: f64) -> f64 {
        crate::interp::linear_held(&self.time_s, y, t)
    }
}

/// Local least-squares slopes over ±window/2 (at least the neighbouring samples).
fn smoothed_rate(t: &[f64], y: &[f64], window_s: f64) -> Vec<f64> {
    let n = t.len();
    if n < 2 {
        return vec![0.0; n];
    }
    // samples at exactly ±window/2 are in, whatever the rounding of the time stamps
    let half = 0.5 * window_s * (1.0 + 1e-9);
    let (mut lo, mut hi) = (0usize, 0usize);
    (0..n)
        .map(|i| {
            while t[i] - t[lo] > half {
                lo += 1;
            }
            while hi + 1 < n && t[hi + 1] - t[i] <= half {
                hi += 1;
            }
            // at least one neighbour on each side where there is one
            let a = lo.min(i.saturating_sub(1));
            let b = hi.max((i + 1).min(n - 1));
            least_squares_slope(&t[a..=b], &y[a..=b])
        })
        .collect()
}

fn least_squares_slope(t: &[f64], y: &[f64]) -> f64 {
    let m = t.len() as f64;
    let tm = t.iter().sum::<f64>() / m;
    let ym = y.iter().sum::<f64>() / m;
    let (num, den) =
        t.iter().zip(y).fold((0.0, 0.0), |(n, d), (&ti, &yi)| (n + (ti - tm) * (yi - ym), d + (ti - tm) * (ti - tm)));
    num / den
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_holds_ends() {
        let s = Signal::new("x", vec![0.0, 1.0, 3.0], vec![1.0, 3.0, 7.0], 0.0).unwrap();
        assert_eq!(s.value(-1.0), 1.0);
        assert_eq!(s.value(0.5), 2.0);
        assert_eq!(s.value(2.0), 5.0);
        assert_eq!(s.value(9.0), 7.0);
        assert_eq!(s.rate(9.0), 0.0);
    }

    #[test]
    fn derivative_is_exact_on_a_line_and_smooths_noise() {
        let t: Vec<f64> = (0..=1000).map(|i| i as f64 * 1e-3).collect();
        let line: Vec<f64> = t.iter().map(|t| 3.0 + 40.0 * t).collect();
        let s = Signal::new("w", t.clone(), line, DEFAULT_DERIVATIVE_WINDOW_S).unwrap();
        for &tq in &[0.0, 0.0105, 0.5, 0.9999, 1.0] {
            assert!((s.rate(tq) - 40.0).abs() < 1e-9, "{tq}: {}", s.rate(tq));
        }
        // ±0.5 rad/s alternating noise on a ramp: the raw difference is off by 1000 rad/s², the
        // smoothed derivative by less than 1 %
        let noisy: Vec<f64> =
            t.iter().enumerate().map(|(i, t)| 40.0 * t + if i % 2 == 0 { 0.5 } else { -0.5 }).collect();
        let s = Signal::new("w", t.clone(), noisy, DEFAULT_DERIVATIVE_WINDOW_S).unwrap();
        assert!((s.rate(0.5) - 40.0).abs() < 0.4, "{}", s.rate(0.5));
        // symmetric windows at every inner sample, so the slope of a parabola is exact there
        let parabola: Vec<f64> = t.iter().map(|t| t * t).collect();
        let s = Signal::new("w", t.clone(), parabola, DEFAULT_DERIVATIVE_WINDOW_S).unwrap();
        for &i in &[25usize, 290, 500, 975] {
            assert!((s.rate(t[i]) - 2.0 * t[i]).abs() < 1e-9, "{}: {}", t[i], s.rate(t[i]));
        }
    }

    #[test]
    fn bad_samples_are_errors_naming_the_sample() {
        let e = Signal::new("pump_torque_nm", vec![0.0, 1.0, 1.0], vec![0.0; 3], 0.0).unwrap_err();
        assert_eq!(e.field, "pump_torque_nm.time_s[2]");
        let e = Signal::new("pump_torque_nm", vec![0.0, 1.0], vec![0.0, f64::NAN], 0.0).unwrap_err();
        assert_eq!(e.field, "pump_torque_nm[1]");
        let e = Signal::constant_named("pump_torque_nm", f64::NAN).unwrap_err();
        assert_eq!((e.field.as_str(), e.value.as_str()), ("pump_torque_nm", "NaN"));
    }

    #[test]
    fn time_stamps_finer_than_the_resolution_are_refused() {
        // 1 ns apart after 1e5 s (68 ulp) and 1 ps apart: the solver failed on both
        let near: Vec<f64> = (0..10).map(|n| 1e5 + n as f64 * 1e-9).collect();
        let e = Signal::new("turbine_speed_rad_s", near, vec![1.0; 10], 0.0).unwrap_err();
        assert_eq!(e.field, "turbine_speed_rad_s.time_s[1]");
        assert!(e.expected.contains("at least 1e-6 s apart") && e.expected.contains("sample 1 is"), "{}", e.expected);
        let fine: Vec<f64> = (0..10).map(|n| n as f64 * 1e-12).collect();
        assert!(check_time_stamps("time_s", &fine).is_err());
        // 1 MHz from 0 and 1 kHz at 1.7e9 s (a Unix time) pass; 1 kHz at 1e13 s (1024 ulp = 2 s) not
        let mhz: Vec<f64> = (0..10).map(|n| n as f64 * 1e-6).collect();
        assert!(check_time_stamps("time_s", &mhz).is_ok());
        let unix: Vec<f64> = (0..10).map(|n| 1.7e9 + n as f64 * 1e-3).collect();
        assert!(check_time_stamps("time_s", &unix).is_ok());
        let far: Vec<f64> = (0..10).map(|n| 1e13 + n as f64 * 1e-3).collect();
        assert!(check_time_stamps("time_s", &far).is_err());
        assert_eq!(time_resolution_s(0.0), MIN_TIME_STEP_S);
        assert_eq!(time_resolution_s(1e13), 1024.0 * 2f64.powi(-9));
    }
}
