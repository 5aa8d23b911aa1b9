//! The vehicle's discrete state (gear, shift, lock-up, brake hold, and the converter's own mode),
//! the roots that switch it, and the thresholds of those switches.

use crate::engine::converter_events::{ConverterRoot, Mode as ConverterMode};

/// State of the lock-up clutch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LockupState {
    Open,
    /// Capacity ramping in since `since_s` (full once `ramped`), slipping. An `armed` clutch locks
    /// when the slip falls below the sync threshold; one that broke away from locked is armed after
    /// slipping for `REARM_DELAY_S`.
    Engaging {
        since_s: f64,
        ramped: bool,
        armed: bool,
    },
    Locked,
}

/// A gear shift in progress: from the off-going to the on-coming gear (0-based).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shift {
    pub from: usize,
    pub to: usize,
    pub since_s: f64,
    /// The torque handover is over: the on-coming clutch has its full capacity.
    pub handed_over: bool,
    /// The torque into the gearbox when the shift started, N·m (the on-coming clutch's feed-forward
    /// in an upshift's inertia phase, [`super::shift`]).
    pub start_input_nm: f64,
}

/// The discrete state of the vehicle in one smooth segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleMode {
    pub converter: ConverterMode,
    /// Gear in mesh (0-based); during a shift, the off-going gear.
    pub gear: usize,
    pub shift: Option<Shift>,
    pub lockup: LockupState,
    pub wheels_held: bool,
}

/// The root functions of a launch: the converter's own ([`ConverterRoot`]) and the vehicle's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Root {
    Converter(ConverterRoot),
    BrakeRelease,
    BrakeHold,
    Upshift,
    Downshift,
    ShiftHandover,
    ShiftSync,
    LockupEngage,
    LockupRamped,
    LockupArm,
    LockupLock,
    LockupSlip,
    LockupRelease,
    Stop,
}

/// Events of a launch run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleEvent {
    pub time_s: f64,
    pub kind: &'static str,
    pub gear: usize,
}

/// The sync threshold and the re-arm delay of the lock-up clutch component (the sync threshold
/// also closes the gearbox's shift clutches).
pub(super) use crate::engine::lockup::{REARM_DELAY_S, SYNC_SLIP_RAD_S};
/// The lock-up clutch opens below this fraction of its engage speed (hysteresis), and on a
/// downshift.
pub(super) const LOCKUP_RELEASE_FRACTION: f64 = 0.7;
/// Axle and wheel-rim speed below which a braked axle is held (exact standstill), rad/s.
pub(super) const HOLD_SPEED_RAD_S: f64 = 0.005;

/// The name of the event `root` fires (the converter's from [`ConverterRoot::kind`]).
pub(super) fn event_name(root: Root) -> &'static str {
    match root {
        Root::Converter(r) => r.kind().name(),
        Root::BrakeRelease => "brake-release",
        Root::BrakeHold => "brake-hold",
        Root::Upshift => "upshift-start",
        Root::Downshift => "downshift-start",
        Root::ShiftHandover => "shift-handover",
        Root::ShiftSync => "shift-end",
        Root::LockupEngage => "lockup-engage",
        Root::LockupRamped => "lockup-applied",
        Root::LockupArm => "lockup-slipping",
        Root::LockupLock => "lockup-lock",
        Root::LockupSlip => "lockup-slip",
        Root::LockupRelease => "lockup-release",
        Root::Stop => "stop-speed",
    }
}
