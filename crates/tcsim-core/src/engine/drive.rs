//! How the isolated converter is driven (drives a, b, c), with the optional lock-up clutch command.

use crate::converter::dynamics::{PUMP, TURBINE};
use crate::engine::lockup::LockupCommand;
use crate::engine::signal::Signal;

/// How the converter is driven (issue: drives a, b, c).
#[derive(Debug, Clone)]
///
/// Each drive may command the lock-up clutch ([`crate::engine::lockup`]) with `lockup`; None is a
/// converter without one (the same run as a command of zero).
pub enum Drive {
    /// (a) Pump torque and turbine speed given (the thesis/VSIM causality): pump speed and
    /// turbine torque come out. A locked clutch makes the pump follow the turbine speed.
    PumpTorqueTurbineSpeed { pump_torque_nm: Signal, turbine_speed_rad_s: Signal, lockup: Option<LockupCommand> },
    /// (b) Both speeds given: the torques come out. The clutch can only slip (no lock events).
    Speeds { pump_speed_rad_s: Signal, turbine_speed_rad_s: Signal, lockup: Option<LockupCommand> },
    /// (c) Pump torque given, the turbine loaded by an inertia and a torque: both speeds come out.
    /// A locked clutch makes pump and turbine one coordinate.
    PumpTorqueLoad { pump_torque_nm: Signal, load: TurbineLoad, lockup: Option<LockupCommand> },
}

/// The load on the turbine in drive (c): `T_load = torque(t) + drag·ω_t|ω_t|`, opposing rotation,
/// with an extra inertia (the driveline reflected to the turbine).
#[derive(Debug, Clone)]
pub struct TurbineLoad {
    pub torque_nm: Signal,
    pub inertia_kg_m2: f64,
    pub drag_nm_s2: f64,
}

impl Drive {
    pub(super) fn given(&self, coordinate: usize) -> Option<&Signal> {
        match (self, coordinate) {
            (Drive::PumpTorqueTurbineSpeed { turbine_speed_rad_s, .. }, TURBINE) => Some(turbine_speed_rad_s),
            (Drive::Speeds { turbine_speed_rad_s, .. }, TURBINE) => Some(turbine_speed_rad_s),
            (Drive::Speeds { pump_speed_rad_s, .. }, PUMP) => Some(pump_speed_rad_s),
            _ => None,
        }
    }

    /// The lock-up clutch's command, if the drive has one.
    pub fn lockup(&self) -> Option<&LockupCommand> {
        match self {
            Drive::PumpTorqueTurbineSpeed { lockup, .. }
            | Drive::Speeds { lockup, .. }
            | Drive::PumpTorqueLoad { lockup, .. } => lockup.as_ref(),
        }
    }

    pub(super) fn pump_torque(&self) -> Option<&Signal> {
        match self {
            Drive::PumpTorqueTurbineSpeed { pump_torque_nm, .. } | Drive::PumpTorqueLoad { pump_torque_nm, .. } => {
                Some(pump_torque_nm)
            }
            Drive::Speeds { .. } => None,
        }
    }

    pub(super) fn load(&self) -> Option<&TurbineLoad> {
        match self {
            Drive::PumpTorqueLoad { load, .. } => Some(load),
            _ => None,
        }
    }

    /// Every input signal of the drive (the lock-up clutch's command included).
    fn signals(&self) -> Vec<&Signal> {
        let mut signals: Vec<&Signal> = match self {
            Drive::PumpTorqueTurbineSpeed { pump_torque_nm, turbine_speed_rad_s, .. } => {
                vec![pump_torque_nm, turbine_speed_rad_s]
            }
            Drive::Speeds { pump_speed_rad_s, turbine_speed_rad_s, .. } => vec![pump_speed_rad_s, turbine_speed_rad_s],
            Drive::PumpTorqueLoad { pump_torque_nm, load, .. } => vec![pump_torque_nm, &load.torque_nm],
        };
        signals.extend(self.lockup().map(|c| &c.capacity_nm));
        signals
    }

    /// Earliest time at which every signal has a sample.
    pub fn start_time(&self) -> f64 {
        self.signals().iter().map(|s| s.times()[0]).fold(f64::NEG_INFINITY, f64::max)
    }

    /// The signals' time stamps, sorted, each once: where the inputs, linear between them, have
    /// kinks, so where the integrator's steps end
    /// ([`crate::engine::segment::run_segment_with_stops`]). Without them a step grown over a
    /// steady phase passed a whole torque pulse (40 → 250 → 40 N·m over 0.15 s) unseen.
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut b: Vec<f64> = self.signals().iter().flat_map(|s| s.times().iter().copied()).collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
}
