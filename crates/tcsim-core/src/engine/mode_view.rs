//! The model as a host's ODE (Model Exchange): one mode of a converter under a drive, seen from
//! outside.

use crate::converter::dynamics::{ConverterDynamics, Vec4};
use crate::engine::converter_events::{ConverterRoot, EventKind, Mode, Sample};
use crate::engine::converter_segment::{switch, Root, Segment};
use crate::engine::isolated::Drive;
use crate::engine::options::Hysteresis;

/// Number of event indicators of a model in [`ModeView`]: the stator clutch, two for the flow
/// direction, and the lock-up clutch (its lock, arm or breakaway root, whichever the clutch's mode
/// has); for models or drives without them, indicators that never change sign.
pub const EVENT_INDICATORS: usize = 4;
/// The slot of the lock-up clutch's indicator in [`ModeView::indicators`].
pub const LOCKUP_INDICATOR: usize = 3;

/// One mode of a model under a drive, seen from outside: the coordinates that are states in some
/// mode, their rates, the event indicators and the mode switches. This is what a Model Exchange
/// FMU exposes; the engine's own runs use the same functions.
pub struct ModeView<'a> {
    seg: Segment<'a>,
}

impl<'a> ModeView<'a> {
    pub fn new(model: &'a dyn ConverterDynamics, drive: &'a Drive, mode: Mode) -> Self {
        Self { seg: Segment::new(model, drive, mode) }
    }

    /// The coordinates that are states in some mode of this model and drive (fixed for a host).
    pub fn state_coordinates(model: &dyn ConverterDynamics, drive: &Drive) -> Vec<usize> {
        let present = model.coordinates();
        (0..4).filter(|&c| present[c] && drive.given(c).is_none()).collect()
    }

    /// All coordinates from the given ones (drive at `t`) and `u`'s free ones; held ones are zero.
    pub fn coordinates(&self, u: &Vec4, t: f64) -> Vec4 {
        self.seg.full(&self.seg.state(u), t)
    }

    /// Rates of all coordinates at (u, t); a held coordinate's rate is zero.
    pub fn rates(&self, u: &Vec4, t: f64) -> Vec4 {
        self.seg.kinematics(&self.seg.state(u), t).1
    }

    /// Event indicators: positive while the mode holds.
    pub fn indicators(&self, u: &Vec4, t: f64, h: &Hysteresis) -> [f64; EVENT_INDICATORS] {
        let mut g = [1.0; EVENT_INDICATORS];
        let mut values = vec![0.0; self.seg.roots.len()];
        self.seg.root_values(&self.seg.state(u), t, h, &mut values);
        for (root, v) in self.seg.roots.iter().zip(values) {
            let slot = match root {
                Root::Converter(ConverterRoot::StatorTorque | ConverterRoot::StatorSpeed) => 0,
                Root::Converter(ConverterRoot::Flow | ConverterRoot::FlowStartsPositive) => 1,
                Root::Converter(ConverterRoot::FlowStartsNegative) => 2,
                Root::Lockup(_) => LOCKUP_INDICATOR,
            };
            g[slot] = v;
        }
        g
    }

    /// The switch due at (u, t), if an indicator has reached zero: the event, the new mode, and
    /// `u` adjusted (a locking stator stops, a reversing flow passes zero).
    pub fn event(&self, u: &mut Vec4, t: f64, h: &Hysteresis) -> Option<(EventKind, Mode)> {
        let mut values = vec![0.0; self.seg.roots.len()];
        self.seg.root_values(&self.seg.state(u), t, h, &mut values);
        let (i, _) = values.iter().enumerate().filter(|(_, v)| **v <= 0.0).min_by(|a, b| a.1.total_cmp(b.1))?;
        let mut full = self.coordinates(u, t);
        let (kind, mode) = switch(&self.seg, self.seg.roots[i], &mut full, t);
        *u = full;
        Some((kind, mode))
    }

    /// The sample (torques, effective torques, energy) at (u, t).
    pub fn sample(&self, u: &Vec4, t: f64) -> Sample {
        self.seg.sample(&self.seg.state(u), t)
    }
}
