//! The lock-up clutch of the converter: one owner of its physics, used by the isolated engine
//! ([`crate::engine::isolated`]) and the vehicle ([`crate::vehicle`]).
//!
//! The clutch sits between pump and turbine. It is driven by a capacity command `C(t)` (N·m ≥ 0,
//! the torque it can transmit while slipping) and is in one of three states (output column
//! `lockup_state`):
//!
//! * **open** (0): `C = 0`, no torque;
//! * **slipping** (1): `T_lu = C·tanh(s / s_c)` with the slip `s = ω_p − ω_t` and the regularising
//!   slip [`CLUTCH_SLIP_RAD_S`]; `T_lu` acts on the turbine and `−T_lu` on the pump, and the clutch
//!   dissipates `T_lu·s ≥ 0` (it never delivers power);
//! * **locked** (2): `ω_p = ω_t`; `T_lu` is the constraint torque that keeps the slip at zero.
//!
//! Events ([`LockupRoot`]): a slipping clutch **locks** (`lockup-lock`) when `|s|` falls below
//! [`SYNC_SLIP_RAD_S`] with `C > 0` and the locked clutch can hold the torque at once; a locked
//! clutch **breaks away** (`lockup-slip`) when `|T_lu| > k_s·C` (static-to-kinetic friction ratio
//! `k_s` ≥ 1), which includes the command falling to zero. After a breakaway (or a lock it could
//! not hold) the clutch is not *armed*: it may lock again only once the slip has exceeded the sync
//! threshold or after [`REARM_DELAY_S`] (`lockup-slipping`), which keeps a clutch at its capacity
//! from chattering between lock and slip.

use crate::engine::signal::Signal;
use crate::error::{CoreError, CoreResult, InputSource};

/// Slip scale of the regularised clutch friction (tanh), rad/s: a clutch carrying 96 % of its
/// capacity slips by `2·CLUTCH_SLIP_RAD_S`.
pub const CLUTCH_SLIP_RAD_S: f64 = 0.2;
/// Slip below which a synchronising clutch locks, rad/s: with the regularised friction a clutch
/// carrying 96 % of its capacity slips by 2·[`CLUTCH_SLIP_RAD_S`], so a smaller slip means it holds.
pub const SYNC_SLIP_RAD_S: f64 = 0.5;
/// After a breakaway the lock-up clutch slips at least this long before it may lock again, s.
pub const REARM_DELAY_S: f64 = 0.1;
/// Default ratio of static to kinetic friction of the lock-up clutch (the vehicle's default too).
pub const DEFAULT_STATIC_TO_KINETIC: f64 = 1.2;

/// Largest capacity command, N·m. A clutch needs a few times the engine torque to lock (the bundled
/// vehicle: 600 N·m); commands of 10⁸ N·m engaged at hundreds of rad/s of slip make the friction
/// torque too stiff for the integrator (measured: solver failure at 10⁸ N·m, 600 rad/s of slip), so
/// 10⁶ N·m, a hundred times any automotive converter's torque and ten times below that, is the limit.
pub const MAX_CAPACITY_NM: f64 = 1.0e6;
/// What a capacity command must be (the one wording of the limit, for every reader).
pub const CAPACITY_EXPECTED: &str = "a finite lock-up capacity from 0 to 1e6 N·m";

/// The command of the clutch in a drive: the capacity against time, N·m (0 to
/// [`MAX_CAPACITY_NM`], checked by [`LockupCommand::new`]), and the static-to-kinetic friction ratio
/// (≥ 1).
#[derive(Debug, Clone)]
pub struct LockupCommand {
    pub capacity_nm: Signal,
    pub static_to_kinetic: f64,
}

impl LockupCommand {
    /// A command with its values checked: every capacity finite, in 0..=[`MAX_CAPACITY_NM`]
    /// (field `lockup_capacity_nm[i]`), and a finite static-to-kinetic ratio ≥ 1
    /// (`lockup_static_to_kinetic`); errors are the drive's.
    pub fn new(capacity_nm: Signal, static_to_kinetic: f64) -> CoreResult<Self> {
        let values = capacity_nm.values();
        if let Some((i, &v)) = values.iter().enumerate().find(|(_, v)| !(0.0..=MAX_CAPACITY_NM).contains(*v)) {
            let field =
                if values.len() == 1 { "lockup_capacity_nm".to_string() } else { format!("lockup_capacity_nm[{i}]") };
            return Err(CoreError::of(InputSource::Drive, field, v, CAPACITY_EXPECTED));
        }
        if !(static_to_kinetic.is_finite() && static_to_kinetic >= 1.0) {
            return Err(CoreError::of(
                InputSource::Drive,
                "lockup_static_to_kinetic",
                static_to_kinetic,
                "a finite static-to-kinetic friction ratio of 1 or more",
            ));
        }
        Ok(Self { capacity_nm, static_to_kinetic })
    }

    /// The capacity at `t`, N·m (negative commands count as zero).
    pub fn capacity(&self, t: f64) -> f64 {
        self.capacity_nm.value(t).max(0.0)
    }

    /// Whether the command ever has a capacity: a command of zero throughout has no events, so
    /// that its run is the run without a clutch.
    pub fn engages(&self) -> bool {
        self.capacity_nm.values().iter().any(|&v| v > 0.0)
    }
}

/// The clutch's discrete state in a smooth segment.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ClutchMode {
    /// Not locked; locks when the slip falls below [`SYNC_SLIP_RAD_S`] with a capacity.
    #[default]
    Armed,
    /// Not locked, and may not lock until armed (after a breakaway at `since_s`).
    Unarmed { since_s: f64 },
    /// Pump and turbine turn together.
    Locked,
}

impl ClutchMode {
    pub fn is_locked(self) -> bool {
        self == ClutchMode::Locked
    }
}

/// The clutch's root functions, each positive while its mode holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LockupRoot {
    /// Armed: the slip closes below the sync threshold with a capacity.
    Lock,
    /// Unarmed: the slip exceeds the sync threshold or the re-arm delay is over.
    Arm,
    /// Locked: the torque through the clutch exceeds static friction.
    Breakaway,
}

/// Torque the slipping clutch transmits from pump to turbine, N·m: `C·tanh(s/s_c)`.
pub fn slipping_torque_nm(capacity_nm: f64, slip_rad_s: f64) -> f64 {
    capacity_nm * (slip_rad_s / CLUTCH_SLIP_RAD_S).tanh()
}

/// `∂T_lu/∂s` of [`slipping_torque_nm`], N·m·s/rad.
pub fn slipping_torque_slope(capacity_nm: f64, slip_rad_s: f64) -> f64 {
    let th = (slip_rad_s / CLUTCH_SLIP_RAD_S).tanh();
    capacity_nm * (1.0 - th * th) / CLUTCH_SLIP_RAD_S
}

/// Power the clutch dissipates, W: `T_lu·s` (≥ 0 while slipping, 0 when locked).
pub fn dissipation_w(torque_nm: f64, slip_rad_s: f64) -> f64 {
    torque_nm * slip_rad_s
}

/// Lock root: `|s| − s_sync` with a capacity, a constant `s_sync` without (never fires).
pub fn lock_root(capacity_nm: f64, slip_rad_s: f64) -> f64 {
    if capacity_nm > 0.0 {
        slip_rad_s.abs() - SYNC_SLIP_RAD_S
    } else {
        SYNC_SLIP_RAD_S
    }
}

/// Arm root of a clutch unarmed since `since_s`: `min(s_sync − |s|, since + delay − t)`.
pub fn arm_root(since_s: f64, slip_rad_s: f64, t: f64) -> f64 {
    (SYNC_SLIP_RAD_S - slip_rad_s.abs()).min(since_s + REARM_DELAY_S - t)
}

/// Breakaway root: `k_s·C − |T_lu|` for the constraint torque `T_lu` through the locked clutch;
/// −1 without capacity (a clutch without capacity is not locked).
pub fn breakaway_root(capacity_nm: f64, static_to_kinetic: f64, locked_torque_nm: f64) -> f64 {
    if capacity_nm > 0.0 {
        static_to_kinetic * capacity_nm - locked_torque_nm.abs()
    } else {
        -1.0
    }
}

/// Whether a locked clutch of `capacity_nm` holds `locked_torque_nm` (the lock test at a lock).
pub fn holds(capacity_nm: f64, static_to_kinetic: f64, locked_torque_nm: f64) -> bool {
    breakaway_root(capacity_nm, static_to_kinetic, locked_torque_nm) > 0.0
}

/// The output code of the state: 0 open (no capacity), 1 slipping, 2 locked.
pub fn state_code(mode: ClutchMode, capacity_nm: f64) -> f64 {
    match mode {
        ClutchMode::Locked => 2.0,
        _ if capacity_nm > 0.0 => 1.0,
        _ => 0.0,
    }
}

/// The mode a clutch starts in at slip `slip_rad_s` and time `t`: armed when the slip is beyond the
/// sync threshold, else unarmed since `t` (a start at small slip locks after the re-arm delay).
pub fn initial_mode(slip_rad_s: f64, t: f64) -> ClutchMode {
    if slip_rad_s.abs() >= SYNC_SLIP_RAD_S {
        ClutchMode::Armed
    } else {
        ClutchMode::Unarmed { since_s: t }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_is_checked_once_for_every_reader() {
        let ok = |v: f64| LockupCommand::new(Signal::constant(v), DEFAULT_STATIC_TO_KINETIC).is_ok();
        assert!(ok(0.0) && ok(350.0) && ok(MAX_CAPACITY_NM));
        for bad in [-1e-300, -5.0, MAX_CAPACITY_NM * (1.0 + f64::EPSILON), 1e10, f64::NAN, f64::INFINITY] {
            let e = LockupCommand::new(Signal::constant(bad), 1.2).unwrap_err();
            assert_eq!((e.field.as_str(), e.expected.as_str()), ("lockup_capacity_nm", CAPACITY_EXPECTED), "{bad}");
        }
        for ratio in [0.99, f64::NAN, f64::INFINITY] {
            let e = LockupCommand::new(Signal::constant(10.0), ratio).unwrap_err();
            assert_eq!(e.field, "lockup_static_to_kinetic");
        }
    }

    #[test]
    fn torque_law_is_odd_bounded_and_dissipative() {
        for c in [0.0, 1.0, 350.0] {
            for s in [-30.0, -0.3, -1e-9, 0.0, 1e-9, 0.1, 0.5, 40.0] {
                let t = slipping_torque_nm(c, s);
                assert_eq!(t, -slipping_torque_nm(c, -s));
                assert!(t.abs() <= c);
                assert!(dissipation_w(t, s) >= 0.0, "the clutch never delivers power");
                assert!(slipping_torque_slope(c, s) >= 0.0);
            }
        }
        // + on the turbine for ω_p > ω_t: the torque has the sign of the slip
        assert!(slipping_torque_nm(100.0, 0.4) > 0.0 && slipping_torque_nm(100.0, -0.4) < 0.0);
        assert!((slipping_torque_nm(100.0, 2.0 * CLUTCH_SLIP_RAD_S) - 100.0 * 2f64.tanh()).abs() < 1e-12);
        let (c, s, h) = (250.0, 0.13, 1e-6);
        let fd = (slipping_torque_nm(c, s + h) - slipping_torque_nm(c, s - h)) / (2.0 * h);
        assert!((fd - slipping_torque_slope(c, s)).abs() < 1e-6 * fd.abs());
    }

    #[test]
    fn roots_in_all_slip_directions() {
        for sign in [1.0, -1.0] {
            assert!(lock_root(10.0, sign * 0.6) > 0.0);
            assert!(lock_root(10.0, sign * 0.4) < 0.0);
            assert!(lock_root(0.0, sign * 0.0) > 0.0, "no capacity: never locks");
            assert!(arm_root(1.0, sign * 0.2, 1.05) > 0.0);
            assert!(arm_root(1.0, sign * 0.6, 1.05) < 0.0, "armed by a slip beyond the sync threshold");
            assert!(arm_root(1.0, sign * 0.2, 1.0 + REARM_DELAY_S + 1e-9) < 0.0, "armed after the delay");
            assert!(breakaway_root(100.0, 1.2, sign * 119.0) > 0.0);
            assert!(breakaway_root(100.0, 1.2, sign * 121.0) < 0.0);
            assert!(holds(100.0, 1.2, sign * 100.0) && !holds(100.0, 1.2, sign * 120.5));
        }
        assert!(breakaway_root(0.0, 1.2, 0.0) < 0.0, "a clutch without capacity breaks away");
        assert_eq!(state_code(ClutchMode::Locked, 5.0), 2.0);
        assert_eq!(state_code(ClutchMode::Armed, 5.0), 1.0);
        assert_eq!(state_code(ClutchMode::Unarmed { since_s: 0.0 }, 0.0), 0.0);
        assert_eq!(initial_mode(-0.7, 0.0), ClutchMode::Armed);
        assert_eq!(initial_mode(0.1, 2.0), ClutchMode::Unarmed { since_s: 2.0 });
        let columns = &crate::engine::outputs::COLUMNS[crate::engine::outputs::LOCKUP_COLUMNS_START..];
        assert_eq!(columns[0], "lockup_torque_nm");
        assert!(columns.iter().all(|c| c.starts_with("lockup_")));
    }
}
