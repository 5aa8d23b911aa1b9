//! The output columns of a launch.

use super::launch::LaunchTrajectory;
use super::modes::LockupState;
use super::parameters::Scenario;
use super::{FRONT, GEARBOX_OUT, REAR, SPEED};
use crate::converter::dynamics::ConverterDynamics;
use crate::engine::options::{try_reserve, TransientResult};
use crate::engine::outputs::LOCKUP_COLUMNS_START;

/// Columns of a launch after the converter's [`crate::engine::outputs::COLUMNS`] (whose `pump_*` refer to
/// the converter pump, which turns with the engine).
pub const LAUNCH_COLUMNS: [&str; 18] = [
    "vehicle_speed_m_s",
    "vehicle_accel_m_s2",
    "gear",
    "shifting",
    "lockup_state",
    "engine_torque_nm",
    "gearbox_output_speed_rad_s",
    "front_axle_speed_rad_s",
    "rear_axle_speed_rad_s",
    "front_shaft_torque_nm",
    "rear_shaft_torque_nm",
    "front_tyre_force_n",
    "rear_tyre_force_n",
    "accelerator_pedal",
    "brake_pedal",
    "engine_power_w",
    "vehicle_loss_power_w",
    "vehicle_stored_energy_j",
];

/// All columns of a launch: the converter's (without the isolated converter's lock-up columns, the
/// vehicle has its own `lockup_state`), then [`LAUNCH_COLUMNS`], then
/// `event_energy_loss_j` (cumulative energy booked at switching events).
pub fn launch_column_names() -> Vec<&'static str> {
    crate::engine::outputs::COLUMNS[..LOCKUP_COLUMNS_START]
        .iter()
        .chain(LAUNCH_COLUMNS.iter())
        .chain(std::iter::once(&"event_energy_loss_j"))
        .copied()
        .collect()
}

/// The run as columns in the order of [`launch_column_names`]. `gear` is 1-based (the off-going
/// gear during a shift); `lockup_state` is 0 open, 1 slipping, 2 locked.
/// An error, not an abort, when their memory cannot be had.
pub fn launch_columns(
    model: &dyn ConverterDynamics,
    sc: &Scenario,
    traj: &LaunchTrajectory,
) -> TransientResult<Vec<Vec<f64>>> {
    let names = launch_column_names();
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for _ in 0..names.len() {
        let mut c = Vec::new();
        try_reserve(&mut c, traj.samples.len())?;
        cols.push(c);
    }
    let mut booked = 0.0;
    let mut next_event = 0;
    for s in &traj.samples {
        while next_event < traj.event_loss_j.len() && traj.event_loss_j[next_event].0 <= s.time_s {
            booked += traj.event_loss_j[next_event].1;
            next_event += 1;
        }
        let conv = crate::engine::outputs::row(model, &s.converter);
        let lockup = match s.mode.lockup {
            LockupState::Open => 0.0,
            LockupState::Engaging { .. } => 1.0,
            LockupState::Locked => 2.0,
        };
        let extra = [
            s.u[SPEED],
            s.u_dot[SPEED],
            (s.mode.gear + 1) as f64,
            if s.mode.shift.is_some() { 1.0 } else { 0.0 },
            lockup,
            s.engine_torque_nm,
            s.u[GEARBOX_OUT],
            s.u[FRONT],
            s.u[REAR],
            s.shaft_torque_nm[0],
            s.shaft_torque_nm[1],
            s.tyre_force_n[0],
            s.tyre_force_n[1],
            sc.accelerator_pedal.value(s.time_s),
            sc.brake_pedal.value(s.time_s),
            s.engine_power_w,
            s.loss_power_w,
            s.stored_energy_j,
        ];
        let conv = &conv[..LOCKUP_COLUMNS_START];
        for (c, v) in cols.iter_mut().zip(conv.iter().chain(extra.iter()).chain(std::iter::once(&booked))) {
            c.push(*v);
        }
    }
    Ok(cols)
}
