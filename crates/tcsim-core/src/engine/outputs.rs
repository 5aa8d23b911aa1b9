//! Named output channels of a transient run (names per tcsim conventions: unit in every name).
//!
//! Effective torques follow Li & Sundén (2016) eqs 3.1–3.4 and figure 3.15:
//!
//! ```text
//!     T_p = T_inertia,p + T_fluid,p + T_transfer,p          T_inertia,p = I_p ω̇_p, T_fluid,p = ρS_p Q̇
//!     T_transfer,t = T_inertia,t + T_fluid,t + T_t          T_inertia,t = I_t ω̇_t, T_fluid,t = ρS_t Q̇
//!     effective pump input torque     = T_p − I_p ω̇_p  = T_fluid,p + T_transfer,p
//!     effective turbine output torque = T_t + I_t ω̇_t  = T_transfer,t − T_fluid,t
//!     effective TR = effective turbine output torque / effective pump input torque
//! ```
//!
//! `T_t` is the torque delivered to the transmission (`turbine_torque_nm`). With the lock-up clutch
//! ([`crate::engine::lockup`]) `T_p` and `T_t` are the torques at the converter's shafts, the
//! clutch's torque included; the energy identity of the columns is
//!
//! ```text
//!     ∫ converter_input_power_w dt + lockup_lock_work_j(end)
//!         = Δ stored_energy_j + ∫ (fluid_loss_power_w + lockup_loss_power_w) dt + lockup_lock_loss_j(end)
//! ```

use crate::converter::dynamics::{ConverterDynamics, FLOW, PUMP, STATOR, TURBINE};
use crate::engine::converter_events::Sample;
use crate::engine::isolated::Trajectory;
use crate::engine::options::{try_reserve, OutputSize, SolverOptions, TransientResult};

/// Index in [`COLUMNS`] of the first lock-up clutch column (the clutch's columns come last).
pub const LOCKUP_COLUMNS_START: usize = 27;

/// Column names, in order.
pub const COLUMNS: [&str; 33] = [
    "time_s",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
    "stator_speed_rad_s",
    "flow_m3_s",
    "pump_accel_rad_s2",
    "turbine_accel_rad_s2",
    "flow_rate_of_change_m3_s2",
    "pump_torque_nm",
    "turbine_torque_nm",
    "stator_torque_nm",
    "speed_ratio",
    "torque_ratio",
    "stator_mode",
    "flow_direction",
    "pump_inertia_torque_nm",
    "pump_fluid_torque_nm",
    "pump_transferred_torque_nm",
    "turbine_inertia_torque_nm",
    "turbine_fluid_torque_nm",
    "turbine_transferred_torque_nm",
    "effective_pump_torque_nm",
    "effective_turbine_torque_nm",
    "effective_torque_ratio",
    "fluid_loss_power_w",
    "stored_energy_j",
    "converter_input_power_w",
    "lockup_torque_nm",
    "lockup_state",
    "lockup_slip_rad_s",
    "lockup_loss_power_w",
    "lockup_lock_loss_j",
    "lockup_lock_work_j",
];

fn ratio(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        f64::NAN
    } else {
        a / b
    }
}

/// One sample as a row in the order of [`COLUMNS`]. Coordinates the model lacks are NaN, and so
/// are the stator mode (0 locked, 1 free-wheeling) and the flow direction (+1, −1, 0 held) of
/// models without them. The table model's lag state (in the fourth coordinate,
/// [`ConverterDynamics::lag_state`]) is no flow: the flow columns stay NaN. The lock-up columns are
/// NaN without a clutch command (so a run without one has the columns of a converter without a
/// clutch).
pub fn row(model: &dyn ConverterDynamics, s: &Sample) -> [f64; 33] {
    let mut present = model.coordinates();
    present[FLOW] &= !model.lag_state();
    let m = model.mass();
    let coord = |c: usize, v: f64| if present[c] { v } else { f64::NAN };
    let lockup = |v: f64| if s.lockup.present { v } else { f64::NAN };
    let (u, ud) = (s.u, s.u_dot);
    let pump = s.torque[0];
    let turbine = -s.torque[1];
    let inertia_p = m[PUMP][PUMP] * ud[PUMP];
    let inertia_t = m[TURBINE][TURBINE] * ud[TURBINE];
    let fluid_p = m[PUMP][FLOW] * ud[FLOW];
    let fluid_t = m[TURBINE][FLOW] * ud[FLOW];
    let eff_p = pump - inertia_p;
    let eff_t = turbine + inertia_t;
    let input = pump * u[PUMP] + s.torque[1] * u[TURBINE] + if present[STATOR] { s.torque[2] * u[STATOR] } else { 0.0 };
    [
        s.time_s,
        u[PUMP],
        u[TURBINE],
        coord(STATOR, u[STATOR]),
        coord(FLOW, u[FLOW]),
        ud[PUMP],
        ud[TURBINE],
        coord(FLOW, ud[FLOW]),
        pump,
        turbine,
        s.torque[2],
        ratio(u[TURBINE], u[PUMP]),
        ratio(turbine, pump),
        if model.has_stator_clutch() {
            if s.mode.stator_locked {
                0.0
            } else {
                1.0
            }
        } else {
            f64::NAN
        },
        if model.has_flow_sign() { s.mode.flow_sign } else { f64::NAN },
        inertia_p,
        fluid_p,
        s.transferred.0,
        inertia_t,
        fluid_t,
        s.transferred.1,
        eff_p,
        eff_t,
        ratio(eff_t, eff_p),
        s.loss_power_w,
        s.stored_energy_j,
        input,
        lockup(s.lockup.torque_nm),
        lockup(s.lockup.state),
        lockup(u[PUMP] - u[TURBINE]),
        lockup(s.lockup.loss_power_w),
        lockup(s.lockup.lock_loss_j),
        lockup(s.lockup.lock_work_j),
    ]
}

/// The size of the output of `runs` isolated runs of `samples` output times each (see
/// [`OutputSize`]): the binding checks a batch with it before running.
pub fn isolated_output_size(runs: usize, samples: usize, options: &SolverOptions) -> OutputSize {
    OutputSize {
        runs,
        samples: samples as f64,
        columns: COLUMNS.len(),
        state_bytes: std::mem::size_of::<Sample>(),
        max_events: options.max_events,
        event_bytes: std::mem::size_of::<crate::engine::isolated::Event>(),
    }
}

/// The run as columns in the order of [`COLUMNS`] (see [`row`]); an error, not an abort, when
/// their memory cannot be had.
pub fn columns(model: &dyn ConverterDynamics, traj: &Trajectory) -> TransientResult<Vec<Vec<f64>>> {
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for _ in 0..COLUMNS.len() {
        let mut c = Vec::new();
        try_reserve(&mut c, traj.samples.len())?;
        cols.push(c);
    }
    for s in &traj.samples {
        for (c, v) in cols.iter_mut().zip(row(model, s)) {
            c.push(v);
        }
    }
    Ok(cols)
}
