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

use crate::error::{CoreError, CoreResult};

/// Default width of the derivative window: 40 ms, i.e. ±20 ms around each sample. It removes
/// sample-to-sample noise of a 100 Hz–1 kHz logger while keeping a 0.2 s torque rise.
pub const DEFAULT_DERIVATIVE_WINDOW_S: f64 = 0.04;

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
    pub fn new(name: &str, time_s: Vec<f64>, value: Vec<f64>, derivative_window_s: f64) -> CoreResult<Self> {
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
    }
}
