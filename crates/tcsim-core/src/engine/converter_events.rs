//! The converter's discrete events, shared by the isolated engine ([`crate::engine::isolated`],
//! [`crate::engine::mode_view`]) and the vehicle plant ([`crate::vehicle`]).
//!
//! A converter model has two kinds of discrete state ([`Mode`]): the stator's one-way clutch
//! (locked or free-wheeling) and the sign of the flow in the losses (+1, −1, or 0 while the flow is
//! held at zero). This module owns the root kinds of those switches, their root functions, the
//! switch arms, the held-flow balance that decides the direction of a starting flow, and the
//! assembly of the converter's [`Sample`]. A plant hands in what only it knows: the constraint
//! torque on the stator, the net head on a held flow and, at a flow reversal, the held-flow
//! balance of the plant with the flow held (as closures), so that each plant keeps its own
//! arithmetic and the numbers stay those of the plant.
//!
//! See [`crate::engine::isolated`] for the physics of the events (the Filippov treatment of sgn Q).

use crate::converter::dynamics::{quadratic_energy_j, ConverterDynamics, Mat4, Vec4, FLOW, PUMP, STATOR, TURBINE};
use crate::engine::lockup::ClutchMode;
use crate::engine::options::{Hysteresis, Sampled};

/// Discrete state of the piecewise-smooth converter.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Mode {
    pub stator_locked: bool,
    /// Sign of Q in the losses: +1, −1, or 0 while the flow is held at zero. The output column
    /// `flow_direction` ([`crate::engine::outputs::COLUMNS`]) and the events' flow field carry it.
    pub flow_sign: f64,
    /// The lock-up clutch ([`crate::engine::lockup`]); the isolated engine's (the vehicle keeps its
    /// own schedule state and leaves this at its default).
    pub lockup: ClutchMode,
}

/// The lock-up clutch at one instant (all zero, and not `present`, without a clutch command).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LockupSample {
    /// The drive commands a clutch (the output columns are NaN without one).
    pub present: bool,
    /// Torque the clutch transmits from pump to turbine, N·m (locked: the constraint torque).
    pub torque_nm: f64,
    /// 0 open, 1 slipping, 2 locked ([`crate::engine::lockup::state_code`]).
    pub state: f64,
    /// Power the slipping clutch dissipates, `T_lu·(ω_p − ω_t)`, W.
    pub loss_power_w: f64,
    /// Energy the clutch dissipated at the lock events so far, J (cumulative, ≥ 0).
    pub lock_loss_j: f64,
    /// Work of the impulses at the converter's shafts at the lock events so far, J (cumulative):
    /// at the given turbine speed in drive (a), from the load inertia in drive (c).
    pub lock_work_j: f64,
}

/// One sampled instant of the converter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    pub u: Vec4,
    pub u_dot: Vec4,
    /// External torques on pump, turbine, stator: `M u̇ − F` with the converter's own mass.
    pub torque: [f64; 3],
    pub transferred: (f64, f64),
    pub mode: Mode,
    pub loss_power_w: f64,
    pub stored_energy_j: f64,
    pub lockup: LockupSample,
}

/// What a converter event did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    StatorRelease,
    StatorLock,
    FlowZero,
    FlowStart,
    LockupLock,
    LockupSlip,
    LockupArm,
}

impl EventKind {
    /// The event's name in outputs (`stator-release`, `stator-lock`, `flow-zero`, `flow-start`, and
    /// the lock-up clutch's `lockup-lock`, `lockup-slip`, `lockup-slipping`, named like the
    /// vehicle's).
    pub fn name(self) -> &'static str {
        match self {
            EventKind::StatorRelease => "stator-release",
            EventKind::StatorLock => "stator-lock",
            EventKind::FlowZero => "flow-zero",
            EventKind::FlowStart => "flow-start",
            EventKind::LockupLock => "lockup-lock",
            EventKind::LockupSlip => "lockup-slip",
            EventKind::LockupArm => "lockup-slipping",
        }
    }
}

/// The root functions of the converter's switches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConverterRoot {
    /// Stator locked: its holding torque crosses zero and the clutch releases.
    StatorTorque,
    /// Stator free-wheeling: its speed reaches zero and the clutch locks.
    StatorSpeed,
    /// Flow with sign ±1: Q reaches zero.
    Flow,
    /// Flow held at zero: the net force on a starting forward flow, `F_Q(0⁺)`, turns positive.
    FlowStartsPositive,
    /// Flow held at zero: the net force on a starting reverse flow, `F_Q(0⁻)`, turns negative.
    FlowStartsNegative,
}

impl ConverterRoot {
    /// The event this root fires.
    pub fn kind(self) -> EventKind {
        match self {
            ConverterRoot::StatorTorque => EventKind::StatorRelease,
            ConverterRoot::StatorSpeed => EventKind::StatorLock,
            ConverterRoot::Flow => EventKind::FlowZero,
            ConverterRoot::FlowStartsPositive | ConverterRoot::FlowStartsNegative => EventKind::FlowStart,
        }
    }
}

/// Whether `mode` holds the flow of `model` at zero.
pub fn flow_held(model: &dyn ConverterDynamics, mode: Mode) -> bool {
    model.has_flow_sign() && mode.flow_sign == 0.0
}

/// The converter's root functions in `mode` (at most three), in order: the stator's, then the
/// flow's. An iterator: the segments collect them with their own, in one allocation.
pub fn roots(model: &dyn ConverterDynamics, mode: Mode) -> impl Iterator<Item = ConverterRoot> {
    let stator = (model.has_stator_clutch() && model.coordinates()[STATOR]).then_some(if mode.stator_locked {
        ConverterRoot::StatorTorque
    } else {
        ConverterRoot::StatorSpeed
    });
    let flow = match (model.has_flow_sign(), mode.flow_sign == 0.0) {
        (false, _) => [None, None],
        (true, true) => [Some(ConverterRoot::FlowStartsPositive), Some(ConverterRoot::FlowStartsNegative)],
        (true, false) => [Some(ConverterRoot::Flow), None],
    };
    stator.into_iter().chain(flow.into_iter().flatten())
}

/// Whether [`root_value`] of `root` calls its `stator_torque` or `held_flow` (which need the
/// plant's rates and forces).
pub fn root_needs_rates(root: ConverterRoot) -> bool {
    match root {
        ConverterRoot::StatorTorque | ConverterRoot::FlowStartsPositive | ConverterRoot::FlowStartsNegative => true,
        ConverterRoot::StatorSpeed | ConverterRoot::Flow => false,
    }
}

/// The value of `root`, positive while the mode holds (with the hysteresis `h`). `u` holds the
/// converter's coordinates first; `stator_torque` is the constraint torque on the stator and
/// `held_flow` the held-flow balance `(d⁺, d⁻)` ([`held_flow_balance`]) of the plant.
pub fn root_value(
    root: ConverterRoot,
    mode: Mode,
    u: &[f64],
    h: &Hysteresis,
    stator_torque: impl FnOnce() -> f64,
    held_flow: impl FnOnce() -> (f64, f64),
) -> f64 {
    match root {
        ConverterRoot::StatorTorque => stator_torque() + h.stator_torque_nm,
        ConverterRoot::StatorSpeed => u[STATOR] + h.stator_speed_rad_s,
        ConverterRoot::Flow => mode.flow_sign * u[FLOW] + h.flow_m3_s,
        ConverterRoot::FlowStartsPositive => {
            let (forward, _) = held_flow();
            h.head_pa - forward
        }
        ConverterRoot::FlowStartsNegative => {
            let (_, reverse) = held_flow();
            reverse + h.head_pa
        }
    }
}

/// The net force on a held flow starting forwards and backwards, `d± = F_Q(0±) − (M u̇)_Q`
/// ([`ConverterDynamics::zero_flow_head`]), from the converter coordinates `u`, the flow row of
/// the plant's mass matrix and the plant's rates (with the flow held, so the same for both signs).
pub fn held_flow_balance(model: &dyn ConverterDynamics, u: &Vec4, flow_mass_row: &[f64], u_dot: &[f64]) -> (f64, f64) {
    let (forward, reverse) = model.zero_flow_head(u);
    let inertial: f64 = flow_mass_row.iter().zip(u_dot).map(|(m, a)| m * a).sum();
    (forward - inertial, reverse - inertial)
}

/// Sign of the flow that starts from Q = 0, from the held-flow balance `(d⁺, d⁻)`: +1 when only
/// `d⁺ > 0`, −1 when only `d⁻ < 0`, the larger of `d⁺` and `−d⁻` when both (forward on a tie),
/// else 0 (held: `d⁺ ≤ 0 ≤ d⁻`).
pub fn flow_sign_from_balance((forward, reverse): (f64, f64)) -> f64 {
    match (forward > 0.0, reverse < 0.0) {
        (true, true) => {
            if forward >= -reverse {
                1.0
            } else {
                -1.0
            }
        }
        (true, false) => 1.0,
        (false, true) => -1.0,
        (false, false) => 0.0,
    }
}

/// Switch `mode` for `root` and adjust `u` (a locking stator stops, a reversing flow passes zero).
/// `flow_sign_at_zero` gives the sign of the flow that starts from the adjusted `u` (Q = 0).
pub fn switch<const LEN: usize>(
    root: ConverterRoot,
    mode: &mut Mode,
    u: &mut [f64; LEN],
    flow_sign_at_zero: impl FnOnce(&[f64; LEN]) -> f64,
) -> EventKind {
    match root {
        ConverterRoot::StatorTorque => mode.stator_locked = false,
        ConverterRoot::StatorSpeed => {
            mode.stator_locked = true;
            u[STATOR] = 0.0;
        }
        ConverterRoot::Flow => {
            u[FLOW] = 0.0;
            mode.flow_sign = flow_sign_at_zero(u);
        }
        ConverterRoot::FlowStartsPositive => mode.flow_sign = 1.0,
        ConverterRoot::FlowStartsNegative => mode.flow_sign = -1.0,
    }
    root.kind()
}

/// `M u̇ − F` with the converter's own mass `mass`: the external torque on every coordinate.
/// Inlined, with a loop rather than `array::from_fn` (whose closure was a call per sample).
#[inline(always)]
pub fn external_torques(mass: &Mat4, u_dot: &Vec4, f: &Vec4) -> Vec4 {
    let mut e = [0.0; 4];
    for r in 0..4 {
        e[r] = (0..4).map(|c| mass[r][c] * u_dot[c]).sum::<f64>() - f[r];
    }
    e
}

/// What a model's samples need that is the same at every sample, kept once per segment: its mass
/// matrix, its stored energy's matrix ([`ConverterDynamics::energy_mass`]), whether it has a stator
/// coordinate, whether the mode holds its flow, and which optional quantities are wanted.
pub struct SampleConstants<'a> {
    model: &'a dyn ConverterDynamics,
    mode: Mode,
    mass: Mat4,
    energy_mass: Option<Mat4>,
    stator: bool,
    flow_held: bool,
    wanted: Sampled,
}

impl<'a> SampleConstants<'a> {
    /// The constants of `model` in `mode`, with every quantity wanted.
    pub fn new(model: &'a dyn ConverterDynamics, mode: Mode) -> Self {
        let (mass, energy_mass) = (model.mass(), model.energy_mass());
        let (stator, flow_held) = (model.coordinates()[STATOR], flow_held(model, mode));
        Self { model, mode, mass, energy_mass, stator, flow_held, wanted: Sampled::ALL }
    }

    /// The same, with only the quantities `wanted` computed.
    pub fn wanting(self, wanted: Sampled) -> Self {
        Self { wanted, ..self }
    }

    /// The converter's sample at time `t` from its coordinates `u`, rates `u_dot` and forces
    /// `f = F(u)`: external torques with the converter's own mass, the transferred torques (with
    /// the stator reaction that balances them when the model has no stator), the loss power (none
    /// while the flow is held) and the stored kinetic energy.
    #[inline(always)]
    pub fn sample(&self, t: f64, u: Vec4, u_dot: Vec4, f: Vec4) -> Sample {
        let model = self.model;
        let (wanted, not) = (self.wanted, f64::NAN);
        let e = external_torques(&self.mass, &u_dot, &f);
        let stored = if !wanted.stored_energy {
            not
        } else if let Some(m) = &self.energy_mass {
            quadratic_energy_j(m, &u)
        } else {
            model.stored_energy_j(&u)
        };
        let mut torque = [e[PUMP], e[TURBINE], e[STATOR]];
        let transferred = if wanted.transferred || !self.stator { model.transferred(&f) } else { (not, not) };
        if !self.stator {
            // the reaction that balances the transferred torques
            torque[2] = transferred.1 - transferred.0;
        }
        let loss = if !wanted.loss_power {
            not
        } else if self.flow_held {
            0.0
        } else {
            model.loss_power_w(&u, &f)
        };
        let (mode, lockup) = (self.mode, LockupSample::default());
        Sample { time_s: t, u, u_dot, torque, transferred, mode, loss_power_w: loss, stored_energy_j: stored, lockup }
    }
}

/// The converter's sample at time `t` in `mode` ([`SampleConstants::sample`]).
pub fn sample(model: &dyn ConverterDynamics, mode: Mode, t: f64, u: Vec4, u_dot: Vec4, f: Vec4) -> Sample {
    SampleConstants::new(model, mode).sample(t, u, u_dot, f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    /// The segments compute the rates before the root functions only when a root needs them
    /// ([`root_needs_rates`]): it must say so exactly for the roots whose value calls for the
    /// stator's torque or the held flow's balance, in every mode.
    #[test]
    fn a_root_needs_the_rates_exactly_when_its_value_reads_them() {
        let roots = [
            ConverterRoot::StatorTorque,
            ConverterRoot::StatorSpeed,
            ConverterRoot::Flow,
            ConverterRoot::FlowStartsPositive,
            ConverterRoot::FlowStartsNegative,
        ];
        let h = crate::engine::options::SolverOptions::default().hysteresis;
        for root in roots {
            for (stator_locked, flow_sign) in [(false, 1.0), (true, -1.0), (true, 0.0)] {
                let mode = Mode { stator_locked, flow_sign, ..Mode::default() };
                let read = Cell::new(false);
                root_value(
                    root,
                    mode,
                    &[1.0, 0.5, -0.1, 0.01],
                    &h,
                    || {
                        read.set(true);
                        3.0
                    },
                    || {
                        read.set(true);
                        (1.0, -1.0)
                    },
                );
                assert_eq!(read.get(), root_needs_rates(root), "{root:?} in {mode:?}");
            }
        }
    }
}
