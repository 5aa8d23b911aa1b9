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

/// Times below which (in magnitude) [`time_resolution_s`] is [`MIN_TIME_STEP_S`]: 2²³ s, where
/// 1024 ulp is 2⁻²⁰ s (0.95 µs).
const FINE_TIMES_S: f64 = 8_388_608.0;

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
    // one pass over times that pass (every run checks its output times); the passes below find
    // the first fault of each kind, in their order, for the message
    let resolution_ok = |a: f64, b: f64| b - a >= (1.0 - 1e-3) * time_resolution_s(a);
    if time_s.first().is_none_or(|t| t.abs() < FINE_TIMES_S) {
        // the resolution is MIN_TIME_STEP_S at every stamp below FINE_TIMES_S: the same test
        // without the ulp, and without a branch per stamp (`&`, not `&&`)
        let step = (1.0 - 1e-3) * MIN_TIME_STEP_S;
        let mut ok = true;
        for i in 1..time_s.len() {
            let (a, b) = (time_s[i - 1], time_s[i]);
            ok &= (b.abs() < FINE_TIMES_S) & (b - a >= step);
        }
        if ok {
            return Ok(());
        }
    }
    if time_s.first().is_none_or(|t| t.is_finite())
        && time_s.windows(2).all(|w| w[1].is_finite() && w[1] > w[0] && resolution_ok(w[0], w[1]))
    {
        return Ok(());
    }
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
    #[inline]
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

    #[inline]
    fn interpolate(&self, y: &[f64], t: f64) -> f64 {
        crate::interp::linear_held(&self.time_s, y, t)
    }
}

/// Local least-squares slopes over ±window/2 (at least the neighbouring samples), in O(n).
///
/// The window `[a, b]` of sample `i` only moves forward as `i` grows, so the sums of the
/// least-squares fit are kept running: a sample is added when it enters the window and removed
/// when it leaves. The sums are taken about a local origin (a time and a value of a sample near
/// the window) so that large time stamps (1e5 s) or offsets do not cancel the digits of the
/// slope; the origin is moved to the current sample and the sums recomputed from scratch once as
/// many samples entered or left as the window holds, which keeps the rounding of the running sums
/// bounded and the cost O(n) overall (each recomputation is paid for by as many updates).
///
/// A window of at most [`DIRECT_FIT_MAX_SAMPLES`] samples (the default 40 ms window up to a 1.5 kHz
/// logger) is fitted directly instead, at a cost bounded by that number: its slope is then the
/// same, bit for bit, as before the running sums, and results recorded with it do not move.
fn smoothed_rate(t: &[f64], y: &[f64], window_s: f64) -> Vec<f64> {
    let n = t.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let mut sums = SlopeSums::new(t[0], y[0]);
    let (mut a, mut b) = (0usize, 0usize); // the samples in `sums`: a..=b
    sums.add(t[0], y[0]);
    window_bounds(t, window_s)
        .map(|(lo, hi, i)| {
            while b < hi {
                b += 1;
                sums.add(t[b], y[b]);
            }
            while a < lo {
                sums.remove(t[a], y[a]);
                a += 1;
            }
            if b - a < DIRECT_FIT_MAX_SAMPLES {
                return least_squares_slope(&t[a..=b], &y[a..=b]);
            }
            if sums.updates > b - a + 1 {
                sums = SlopeSums::over(&t[a..=b], &y[a..=b], t[i], y[i]);
            }
            sums.slope()
        })
        .collect()
}

/// The largest window (in samples) whose slope is fitted directly rather than from running sums.
const DIRECT_FIT_MAX_SAMPLES: usize = 64;

/// The slope of the least-squares line through the samples, fitted directly about their means.
fn least_squares_slope(t: &[f64], y: &[f64]) -> f64 {
    let m = t.len() as f64;
    let tm = t.iter().sum::<f64>() / m;
    let ym = y.iter().sum::<f64>() / m;
    let (num, den) =
        t.iter().zip(y).fold((0.0, 0.0), |(n, d), (&ti, &yi)| (n + (ti - tm) * (yi - ym), d + (ti - tm) * (ti - tm)));
    num / den
}

/// The window `(a, b, i)` of each sample `i`: the samples within ±window/2 and at least one
/// neighbour on each side where there is one. Both ends never move back.
fn window_bounds(t: &[f64], window_s: f64) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
    let n = t.len();
    // samples at exactly ±window/2 are in, whatever the rounding of the time stamps
    let half = 0.5 * window_s * (1.0 + 1e-9);
    let (mut lo, mut hi) = (0usize, 0usize);
    (0..n).map(move |i| {
        while t[i] - t[lo] > half {
            lo += 1;
        }
        while hi + 1 < n && t[hi + 1] - t[i] <= half {
            hi += 1;
        }
        (lo.min(i.saturating_sub(1)), hi.max((i + 1).min(n - 1)), i)
    })
}

/// Running sums of a least-squares line fit about a local origin `(t0, y0)`.
struct SlopeSums {
    t0: f64,
    y0: f64,
    count: f64,
    st: f64,
    sy: f64,
    stt: f64,
    sty: f64,
    /// Samples added or removed since the sums were last computed from scratch.
    updates: usize,
}

impl SlopeSums {
    fn new(t0: f64, y0: f64) -> Self {
        Self { t0, y0, count: 0.0, st: 0.0, sy: 0.0, stt: 0.0, sty: 0.0, updates: 0 }
    }

    /// The sums over the samples `t`, `y`, about `(t0, y0)`.
    fn over(t: &[f64], y: &[f64], t0: f64, y0: f64) -> Self {
        let mut s = Self::new(t0, y0);
        t.iter().zip(y).for_each(|(&ti, &yi)| s.add(ti, yi));
        s.updates = 0;
        s
    }

    fn add(&mut self, t: f64, y: f64) {
        self.update(t, y, 1.0);
    }

    fn remove(&mut self, t: f64, y: f64) {
        self.update(t, y, -1.0);
    }

    fn update(&mut self, t: f64, y: f64, sign: f64) {
        let (dt, dy) = (t - self.t0, y - self.y0);
        self.count += sign;
        self.st += sign * dt;
        self.sy += sign * dy;
        self.stt += sign * dt * dt;
        self.sty += sign * dt * dy;
        self.updates += 1;
    }

    /// The slope of the least-squares line through the samples in the sums (at least two).
    fn slope(&self) -> f64 {
        let (tm, ym) = (self.st / self.count, self.sy / self.count);
        (self.sty - self.count * tm * ym) / (self.stt - self.count * tm * tm)
    }
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

    /// The slopes as they were computed before the running sums: each window fitted directly, O(n·w).
    fn direct_smoothed_rate(t: &[f64], y: &[f64], window_s: f64) -> Vec<f64> {
        window_bounds(t, window_s).map(|(a, b, _)| least_squares_slope(&t[a..=b], &y[a..=b])).collect()
    }

    /// A reproducible uniform number in [0, 1) (xorshift64*).
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state >> 12;
        *state ^= *state << 25;
        *state ^= *state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn running_slopes_agree_with_the_direct_fit_on_irregular_noisy_samples_far_from_zero() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        for &(offset, step, window, n) in
            // windows of ~400, ~500, every sample (running sums), ~50 and 3 samples (direct fits)
            &[
                (0.0, 1e-4, 0.04, 20_000),
                (1e5, 1e-4, 0.04, 20_000),
                (1e5, 1e-3, 0.5, 5000),
                (-3e4, 1e-3, 1e300, 3000),
                (1e5, 1e-2, 0.5, 3000),
                (-3e4, 2e-4, 0.0, 4000),
            ]
        {
            let mut t = vec![offset];
            for _ in 1..n {
                let dt = step * (0.2 + 1.6 * uniform(&mut state));
                t.push(t.last().unwrap() + dt);
            }
            // a fast ramp with an offset, a slow oscillation and noise of the logger's size
            let y: Vec<f64> = t
                .iter()
                .map(|&ti| {
                    300.0 + 50.0 * (ti - offset) + 20.0 * (3.0 * (ti - offset)).sin() + uniform(&mut state) - 0.5
                })
                .collect();
            let fast = smoothed_rate(&t, &y, window);
            let direct = direct_smoothed_rate(&t, &y, window);
            let scale = direct.iter().fold(0.0f64, |m, r| m.max(r.abs()));
            for (i, (f, d)) in fast.iter().zip(&direct).enumerate() {
                assert!((f - d).abs() <= 1e-9 * scale, "offset {offset}, sample {i}: {f} vs {d}");
            }
        }
    }

    #[test]
    fn running_slopes_are_exact_on_a_line_for_any_window() {
        let t: Vec<f64> = (0..20_000).map(|i| 1e5 + i as f64 * 1e-3 + 3e-4 * ((i * 7919) % 13) as f64 / 13.0).collect();
        let line: Vec<f64> = t.iter().map(|t| -7.0 + 2.5 * (t - 1e5)).collect();
        for window in [0.0, 0.04, 1.0, 1e300] {
            for (i, r) in smoothed_rate(&t, &line, window).iter().enumerate() {
                assert!((r - 2.5).abs() < 1e-9, "window {window}, sample {i}: {r}");
            }
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

    /// The pass for times below `FINE_TIMES_S` (where the resolution is 1 µs) decides as the
    /// definition does, on both sides of that bound and of the spacing's limit.
    #[test]
    fn the_pass_for_fine_times_decides_as_the_definition() {
        let defined = |t: &[f64]| {
            t.iter().all(|x| x.is_finite())
                && t.windows(2).all(|w| w[1] > w[0] && w[1] - w[0] >= (1.0 - 1e-3) * time_resolution_s(w[0]))
        };
        let (mut cases, mut passed) = (0, 0);
        for start in [0.0, -3.0, 1e3, FINE_TIMES_S - 1e-3, FINE_TIMES_S - 2e-5, FINE_TIMES_S, 1e7, -FINE_TIMES_S - 1.0]
        {
            for spacing in [0.998e-6, 0.999e-6, 1.0e-6, 1.001e-6, 1.2e-6, 1e-3] {
                let t: Vec<f64> = (0..40).map(|k| start + k as f64 * spacing).collect();
                let ok = check_time_stamps("t", &t).is_ok();
                assert_eq!(ok, defined(&t), "from {start} every {spacing} s");
                cases += 1;
                passed += usize::from(ok);
            }
        }
        assert!(passed > 0 && passed < cases, "both outcomes are exercised: {passed} of {cases}");
    }

    #[test]
    fn the_one_pass_over_good_time_stamps_lets_no_fault_through() {
        // the fast pass returns Ok only when each of the three checks after it would: a fault at
        // the first, a middle or the last stamp of each kind is refused, naming that stamp
        let good: Vec<f64> = (0..6).map(|n| n as f64 * 0.5).collect();
        assert!(check_time_stamps("t", &good).is_ok() && check_time_stamps("t", &good[..1]).is_ok());
        assert!(check_time_stamps("t", &[]).is_ok());
        for i in 0..good.len() {
            let res = time_resolution_s(good[i.max(1) - 1]);
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1.0, good[i.max(1) - 1] + 0.99 * res] {
                if i == 0 && bad.is_finite() {
                    continue; // a first stamp is only ever refused for not being finite
                }
                let mut t = good.clone();
                t[i] = bad;
                let e = check_time_stamps("t", &t).unwrap_err();
                let first_bad = if !bad.is_finite() { i } else { i.max(1) };
                assert_eq!(e.field, format!("t[{first_bad}]"), "stamp {i} = {bad}");
            }
        }
    }
}
