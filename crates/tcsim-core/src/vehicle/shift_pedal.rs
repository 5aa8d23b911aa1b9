//! The pedal the shift schedule reads: the accelerator pedal through the transmission control
//! unit's (TCU's) first-order filter.
//!
//! A TCU evaluates its shift map with a filtered accelerator pedal, not the raw one: a short lift
//! of the pedal does not upshift and a pedal that moves back and forth does not make the gearbox
//! hunt between two gears. The filter here is a first-order low-pass with separate time constants
//! for a rising pedal (`[gearbox].shift_pedal_rise_s`) and a falling one
//! (`[gearbox].shift_pedal_fall_s`, the longer: a lift holds the gear), discretised with the TCU's
//! period [`TCU_STEP_S`] (zero-order hold of the pedal over each period); a full pedal, the
//! kickdown ([`KICKDOWN_PEDAL`]), passes at once:
//!
//! `y_j = y_{j−1} + (1 − exp(−h/τ)) (p(t_j) − y_{j−1})`, `τ` the rise time constant when
//! `p(t_j) > y_{j−1}`, else the fall time constant, `h = t_j − t_{j−1}` (`τ = 0` or
//! `p(t_j) ≥ 1`: `y_j = p(t_j)`).
//!
//! The filtered pedal is a given signal of time for the plant ([`super::parameters::Scenario`]'s
//! `shift_pedal`), linear between the TCU's samples: it has no power and enters only the shift
//! schedule's root functions, so the energy balance and the event logic are those of any other
//! scenario signal. The lock-up schedule and the engine read the accelerator pedal itself.

use super::range::{field, Range};
use crate::engine::signal::Signal;
use crate::error::CoreResult;

/// `[gearbox].shift_pedal_rise_s` and `[gearbox].shift_pedal_fall_s`, s: from 0 to 10.
pub const PEDAL_TIME_CONSTANT: Range = Range { low: Some((0.0, true)), high: Some((10.0, true)) };
/// A pedal at least this far down passes the filter at once: the kickdown (the switch at the end
/// of the pedal's travel; full pedal asks for the lowest gear the schedule allows without delay).
pub const KICKDOWN_PEDAL: f64 = 1.0;
/// The filter has settled on the pedal when they differ by no more than this.
pub const SETTLED: f64 = 1e-12;
/// The TCU's period: the filter's sample time, s (a TCU's shift strategy runs every 10 ms).
pub const TCU_STEP_S: f64 = 0.01;

/// The TCU's pedal filter: first-order, its time constant depending on the pedal's direction.
/// The default (both 0) passes the pedal unfiltered.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PedalFilter {
    /// Time constant while the pedal is above the filtered value (pressed), s.
    pub rise_s: f64,
    /// Time constant while the pedal is below the filtered value (released), s.
    pub fall_s: f64,
}

impl PedalFilter {
    /// The fields' ranges, errors named as the vehicle file names them.
    pub fn validate(&self) -> CoreResult<()> {
        PEDAL_TIME_CONSTANT.check(&field("gearbox", "shift_pedal_rise_s"), self.rise_s)?;
        PEDAL_TIME_CONSTANT.check(&field("gearbox", "shift_pedal_fall_s"), self.fall_s)?;
        Ok(())
    }

    /// Whether the filter passes the pedal unchanged (both time constants 0).
    pub fn is_identity(&self) -> bool {
        self.rise_s == 0.0 && self.fall_s == 0.0
    }

    /// The filtered pedal `h` seconds after it was `y`, the pedal `p` held over `h`; a pedal at
    /// [`KICKDOWN_PEDAL`] passes at once.
    pub fn step(&self, y: f64, p: f64, h: f64) -> f64 {
        let tau = if p > y { self.rise_s } else { self.fall_s };
        if tau == 0.0 || p >= KICKDOWN_PEDAL {
            return p;
        }
        y + (1.0 - (-h / tau).exp()) * (p - y)
    }

    /// The filtered pedal from `t0` (where it is `y0`) to `t1` > `t0` with the pedal signal `pedal`:
    /// sampled at `t0`, the multiples of [`TCU_STEP_S`] between, and `t1`, linear between the
    /// samples (held beyond them); with its value at `t1`. Where the filter has settled
    /// ([`SETTLED`]) on a pedal that stays constant to its next sample, the samples skip to the last
    /// TCU period before it (exact: the filter stays at the pedal), so a long run with a few pedal
    /// steps needs few samples.
    pub fn filtered(&self, pedal: &Signal, y0: f64, t0: f64, t1: f64) -> CoreResult<(Signal, f64)> {
        let (mut times, mut values) = (vec![t0], vec![y0]);
        let breaks = pedal.times();
        let mut k = (t0 / TCU_STEP_S).floor() + 1.0;
        while k * TCU_STEP_S <= t0 + 1e-9 {
            k += 1.0;
        }
        let (mut t, mut y) = (t0, y0);
        while t < t1 {
            let p = pedal.value(t);
            if (y - p).abs() <= SETTLED {
                let next = breaks.get(breaks.partition_point(|&b| b <= t + 1e-9)).copied();
                let constant_to = match next {
                    None => t1,
                    Some(b) if pedal.value(b) == p => ((b / TCU_STEP_S).floor() * TCU_STEP_S).min(t1),
                    Some(_) => t,
                };
                if constant_to > t + 1e-9 {
                    (t, y) = (constant_to, p);
                    times.push(t);
                    values.push(y);
                    k = (t / TCU_STEP_S).round() + 1.0;
                    continue;
                }
            }
            let t_next = if k * TCU_STEP_S < t1 - 1e-9 { k * TCU_STEP_S } else { t1 };
            y = self.step(y, pedal.value(t_next), t_next - t);
            t = t_next;
            times.push(t);
            values.push(y);
            k += 1.0;
        }
        Ok((Signal::new_any_spacing("shift_pedal", times, values, 0.0)?, y))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_release_decays_with_the_fall_time_constant_and_a_press_passes() {
        let f = PedalFilter { rise_s: 0.0, fall_s: 2.0 };
        // a press passes at once
        assert_eq!(f.step(0.2, 0.9, 0.01), 0.9);
        // a release: after one time constant 1/e of the step is left, whatever the sample time
        let (signal, end) = f.filtered(&Signal::constant(0.0), 1.0, 0.0, 2.0).unwrap();
        assert!((end - (-1.0_f64).exp()).abs() < 1e-12, "{end}");
        assert!((signal.value(1.0) - (-0.5_f64).exp()).abs() < 1e-12);
        assert_eq!(signal.times().len(), 201);
        // the filter is exact for a held pedal: one step of 0.1 s is ten of 0.01 s
        let coarse = f.step(0.8, 0.3, 0.1);
        let fine = (0..10).fold(0.8, |y, _| f.step(y, 0.3, 0.01));
        assert!((coarse - fine).abs() < 1e-12);
        // a pedal that moves back and forth at 1 Hz reaches the schedule as (nearly) its peak
        let times: Vec<f64> = (0..=1000).map(|j| j as f64 * 0.01).collect();
        let wobble = times.iter().map(|t| if (t % 1.0) < 0.5 { 0.6 } else { 0.2 }).collect();
        let (signal, _) = f.filtered(&Signal::new("pedal", times, wobble, 0.0).unwrap(), 0.6, 0.0, 10.0).unwrap();
        let low = signal.values().iter().fold(f64::INFINITY, |a, &b| a.min(b));
        assert!(low > 0.6 - 0.4 * (1.0 - (-0.25_f64).exp()) - 1e-9, "{low}");
    }

    #[test]
    fn the_identity_passes_the_pedal_and_a_rise_time_filters_a_press() {
        let none = PedalFilter::default();
        assert!(none.is_identity());
        let ramp = Signal::new("pedal", vec![0.0, 10.0], vec![0.0, 1.0], 0.0).unwrap();
        let (signal, end) = none.filtered(&ramp, 0.0, 0.0, 10.0).unwrap();
        assert!((end - 1.0).abs() < 1e-15 && (signal.value(5.0) - 0.5).abs() < 1e-12);
        let slow = PedalFilter { rise_s: 0.5, fall_s: 0.0 };
        assert!((slow.step(0.0, 0.8, 0.5) - 0.8 * (1.0 - (-1.0_f64).exp())).abs() < 1e-15);
        // the kickdown passes at once
        assert_eq!(slow.step(0.0, 1.0, 0.01), 1.0);
        assert_eq!(slow.step(1.0, 0.0, 0.01), 0.0);
        // starting between two TCU samples, ending at one
        let (signal, _) = slow.filtered(&Signal::constant(0.5), 0.0, 0.005, 0.03).unwrap();
        assert_eq!(signal.times(), &[0.005, 0.01, 0.02, 0.03]);
        // settled on a constant pedal, the samples skip to its next step: a pedal step at 5 s and
        // 10 000 s of run need no more than the settling after each step
        let steps = Signal::new("pedal", vec![0.0, 5.0, 5.05, 1e4], vec![0.0, 0.0, 0.6, 0.6], 0.0).unwrap();
        let (signal, end) = slow.filtered(&steps, 0.0, 0.0, 1e4).unwrap();
        assert!(signal.times().len() < 2000, "{}", signal.times().len());
        assert_eq!((signal.value(4.99), end), (0.0, 0.6));
        assert!((signal.value(9e3) - 0.6).abs() <= SETTLED);
        // 0.5 s after the ramp: between the responses to a step at its end and (one TCU period
        // early) at its start
        let y = signal.value(5.55);
        let after = |s: f64| 0.6 * (1.0 - (-s / 0.5_f64).exp());
        assert!(after(0.5) < y && y < after(0.56), "{y}");
    }

    #[test]
    fn validation_names_the_field() {
        let bad = PedalFilter { rise_s: -0.1, fall_s: 1.0 };
        assert_eq!(bad.validate().unwrap_err().field, "[gearbox].shift_pedal_rise_s");
        let bad = PedalFilter { rise_s: 0.0, fall_s: f64::NAN };
        assert_eq!(bad.validate().unwrap_err().field, "[gearbox].shift_pedal_fall_s");
        let bad = PedalFilter { rise_s: 0.0, fall_s: 10.5 };
        assert_eq!(bad.validate().unwrap_err().field, "[gearbox].shift_pedal_fall_s");
        PedalFilter { rise_s: 0.0, fall_s: 10.0 }.validate().unwrap();
    }
}
