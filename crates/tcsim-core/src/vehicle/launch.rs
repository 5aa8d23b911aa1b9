//! A launch run: the braked standstill it starts from, the switches at events, and the run loop
//! (one BDF segment per mode; see [`super`] for the momentum-conserving projection at a closing
//! link).

use super::modes::{
    event_name, LockupState, Root, Shift, VehicleEvent, VehicleMode, LOCKUP_RELEASE_FRACTION, SYNC_SLIP_RAD_S,
};
use super::parameters::{Scenario, Vehicle};
use super::plant::{kinetic_energy, Coords, LaunchSample, Plant};
use super::{GEARBOX_OUT, N_COORDS, SPEED, TORQUE_BOOST, TORQUE_FAST, TWIST_F, TWIST_R};
use crate::converter::dynamics::{ConverterDynamics, PUMP, TURBINE};
use crate::engine::converter_events::{self, Mode as ConverterMode};
use crate::engine::options::{try_reserve, OutputSize, SolverOptions, TransientError, TransientResult};
use crate::engine::segment::{run_segment_with_stops, SmoothSegment};
use crate::error::{CoreError, CoreResult, InputSource};

/// A launch run: samples, events, the kinetic energy removed at clutch locking events
/// (momentum-conserving), and the solver's step count.
#[derive(Debug, Clone, Default)]
pub struct LaunchTrajectory {
    pub samples: Vec<LaunchSample>,
    pub events: Vec<VehicleEvent>,
    pub event_loss_j: Vec<(f64, f64)>,
    pub steps: usize,
}

/// The braked standstill in first gear at idle: engine at the speed where the governor balances
/// drag and the stalled converter, driveline wound up by the stall torque (both shafts equally
/// twisted).
pub fn initial_state(model: &dyn ConverterDynamics, v: &Vehicle, sc: &Scenario) -> TransientResult<Coords> {
    let p = sc.accelerator_pedal.value(0.0);
    let pump_at = |w: f64| -> CoreResult<f64> { Ok(model.steady_point(w, 0.0)?.pump_torque_nm) };
    let balance = |w: f64| -> CoreResult<f64> {
        let crank = match &sc.engine_torque_nm {
            Some(log) => log.value(0.0),
            None => {
                let (fast, boost) = v.engine.targets(p, w);
                fast + boost - v.engine.drag(w)
            }
        };
        Ok(crank - pump_at(w)?)
    };
    let (mut lo, mut hi) = (1.0_f64, v.engine.full_load.x().last().copied().unwrap_or(700.0));
    // a logged engine torque is the scenario's; the engine model is the vehicle's
    let source = if sc.engine_torque_nm.is_some() { InputSource::Scenario } else { InputSource::Vehicle };
    if balance(lo)? <= 0.0 || balance(hi)? >= 0.0 {
        return Err(match &sc.engine_torque_nm {
            Some(log) => CoreError::new("engine_torque_nm[0]", log.value(0.0), "a positive logged engine torque at the start that the stalled converter can absorb"),
            None => CoreError::new("[engine].idle_speed_rad_s", v.engine.idle_speed_rad_s, "an idle governor and full-load curve that can hold the stalled converter (no engine speed balances them)"),
        }
        .about(source)
        .into());
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if balance(mid)? > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let wp = 0.5 * (lo + hi);
    let ss = model.steady_point(wp, 0.0)?;
    let (fast, boost) = v.engine.targets(p, wp);
    // stalled turbine: its transferred torque winds up the shafts (no gear loss at standstill)
    let turbine = model.transferred(&model.forces(&ss.u, 1.0)).1;
    let k = &v.driveline.shaft_stiffness_nm_per_rad;
    let twist = turbine * v.gearbox.ratios[0] / (k[0] + k[1]);
    let mut u = [0.0; N_COORDS];
    u[..4].copy_from_slice(&ss.u);
    u[PUMP] = wp;
    u[TWIST_F] = twist;
    u[TWIST_R] = twist;
    u[TORQUE_FAST] = fast;
    u[TORQUE_BOOST] = boost;
    Ok(u)
}

/// The mode after `root`, and the sign of the slip to synchronise (shifts, lock-up).
pub(super) fn switch(plant: &Plant, root: Root, u: &mut Coords, t: f64) -> (VehicleMode, f64) {
    let mut m = plant.mode;
    let mut sync = plant.sync_sign;
    let gb = &plant.v.gearbox;
    match root {
        Root::Converter(r) => {
            converter_events::switch(r, &mut m.converter, u, |u| flow_sign_at_zero(plant, u, t));
        }
        Root::BrakeRelease => m.wheels_held = false,
        Root::BrakeHold => m.wheels_held = true,
        Root::Upshift | Root::Downshift => {
            let to = if root == Root::Upshift { m.gear + 1 } else { m.gear - 1 };
            let start_input_nm = plant.gearbox_input_nm(u, t);
            m.shift = Some(Shift { from: m.gear, to, since_s: t, handed_over: false, start_input_nm });
            // an engaging clutch restarts after an upshift; a downshift opens it
            if m.lockup != LockupState::Locked || root == Root::Downshift {
                m.lockup = LockupState::Open;
            }
        }
        Root::ShiftHandover => {
            let to = m.shift.map_or(m.gear, |s| s.to);
            let slip = u[TURBINE] - gb.ratios[to] * u[GEARBOX_OUT];
            if slip.abs() <= SYNC_SLIP_RAD_S {
                *u = plant.lock_shift_clutch(u, gb.ratios[to]);
                m.gear = to;
                m.shift = None;
            } else {
                m.shift = m.shift.map(|s| Shift { handed_over: true, ..s });
                sync = slip.signum();
            }
        }
        Root::ShiftSync => {
            if let Some(s) = m.shift {
                *u = plant.lock_shift_clutch(u, gb.ratios[s.to]);
                m.gear = s.to;
            }
            m.shift = None;
        }
        Root::LockupEngage => m.lockup = LockupState::Engaging { since_s: t, ramped: false, armed: false },
        // the ramp is over, or a clutch that broke away has slipped long enough: lock now or arm
        Root::LockupRamped | Root::LockupArm => {
            let slip = u[PUMP] - u[TURBINE];
            if slip.abs() <= SYNC_SLIP_RAD_S {
                m.lockup = LockupState::Locked;
            } else {
                m.lockup =
                    LockupState::Engaging { since_s: t - plant.v.lockup.engage_time_s, ramped: true, armed: true };
                sync = slip.signum();
            }
        }
        Root::LockupLock => m.lockup = LockupState::Locked,
        Root::LockupRelease => m.lockup = LockupState::Open,
        Root::LockupSlip => {
            // the slip develops in the direction of the torque the clutch could not hold
            // it slips for REARM_DELAY_S at full capacity before it may lock again
            m.lockup = LockupState::Engaging { since_s: t - plant.v.lockup.engage_time_s, ramped: true, armed: false };
        }
        Root::Stop => {}
    }
    (m, sync)
}

/// The name of the event `root` fired, given the mode it switched to (a handover that
/// synchronised at once ends the shift; a ramp or an arming that locked locks).
/// [`switch`] at `root`, and the kinetic energy from which the next mode's event loss is booked:
/// a shift clutch's lock moves the state (its impulse), so the energy before it is booked; any
/// other switch books from the energy after it.
pub(super) fn switch_and_booking(plant: &Plant, root: Root, u: &mut Coords, t: f64) -> (VehicleMode, f64, f64) {
    let before_switch = kinetic_energy(plant, u);
    let (new_mode, new_sync) = switch(plant, root, u, t);
    let shift_locks = matches!(root, Root::ShiftSync | Root::ShiftHandover) && new_mode.shift.is_none();
    let booked = if shift_locks { before_switch } else { kinetic_energy(plant, u) };
    (new_mode, new_sync, booked)
}

pub(super) fn event_kind(root: Root, new_mode: &VehicleMode) -> &'static str {
    match root {
        Root::ShiftHandover if new_mode.shift.is_none() => "shift-end",
        Root::LockupRamped | Root::LockupArm if new_mode.lockup == LockupState::Locked => "lockup-lock",
        _ => event_name(root),
    }
}

fn flow_sign_at_zero(plant: &Plant, u: &Coords, t: f64) -> f64 {
    let mode = VehicleMode { converter: ConverterMode { flow_sign: 0.0, ..plant.mode.converter }, ..plant.mode };
    let held = Plant::new(plant.model, plant.v, plant.sc, mode, plant.sync_sign);
    let (uu, ud, _, _) = held.kinematics(&held.state_of(u), t);
    converter_events::flow_sign_from_balance(held.held_flow_balance(&uu, &ud))
}

/// A switch whose condition already holds when a mode starts (root functions only see
/// crossings): the stop speed, a due shift, a due lock-up engagement.
pub(super) fn pending_switch(plant: &Plant, u: &Coords, t: f64) -> Option<Root> {
    let m = &plant.mode;
    let p = plant.sc.accelerator_pedal.value(t);
    let gb = &plant.v.gearbox;
    if plant.sc.stop_speed_m_s.is_some_and(|v| u[SPEED] >= v) {
        return Some(Root::Stop);
    }
    if m.wheels_held {
        let (_, ud, f, _) = plant.kinematics(&plant.state_of(u), t);
        if plant.brake_margin(&ud, &f, t) < 0.0 {
            return Some(Root::BrakeRelease);
        }
    }
    if m.lockup != LockupState::Open
        && (m.gear + 1 < plant.v.lockup.min_gear || u[SPEED] < LOCKUP_RELEASE_FRACTION * plant.v.lockup.engage_speed(p))
    {
        return Some(Root::LockupRelease);
    }
    if m.shift.is_none() && !m.wheels_held {
        let p_shift = plant.sc.shift_pedal_at(t);
        if m.gear + 1 < gb.ratios.len() && u[SPEED] > gb.upshift_speed(m.gear, p_shift) {
            return Some(Root::Upshift);
        }
        if m.gear > 0 && u[SPEED] < gb.downshift_speed(m.gear, p_shift) {
            return Some(Root::Downshift);
        }
        if m.lockup == LockupState::Open
            && m.gear + 1 >= plant.v.lockup.min_gear
            && u[SPEED] > plant.v.lockup.engage_speed(p)
        {
            return Some(Root::LockupEngage);
        }
    }
    None
}

/// The default output step of a launch, s (the binding's `output_step_s`).
pub const DEFAULT_OUTPUT_STEP_S: f64 = 0.01;

/// The number of output samples of a launch of `sc` every `output_step_s` (validating the end time
/// and the step, which must be no finer than the time resolution
/// [`crate::engine::signal::time_resolution_s`] at the end time).
pub fn launch_output_samples(sc: &Scenario, output_step_s: f64) -> CoreResult<f64> {
    if !(sc.end_time_s.is_finite() && sc.end_time_s > 0.0) {
        return Err(CoreError::of(InputSource::Scenario, "end_time_s", sc.end_time_s, "a finite, positive end time"));
    }
    let resolution = crate::engine::signal::time_resolution_s(sc.end_time_s);
    if !(output_step_s.is_finite() && output_step_s >= resolution) {
        let expected = format!(
            "a finite output step of at least {} s (the time resolution: 1 µs, or 1024 ulp of the end time when coarser)",
            crate::error::sig(resolution)
        );
        return Err(CoreError::of(InputSource::Options, "output_step_s", output_step_s, expected));
    }
    Ok((sc.end_time_s / output_step_s).round() + 1.0)
}

/// The size of the output of `runs` launches of `sc` every `output_step_s`, checked against the
/// limit of `options` before anything runs: an error about the scenario (its end time), or about
/// the options when the output step is finer than the default.
pub fn check_launch_output(sc: &Scenario, output_step_s: f64, runs: usize, options: &SolverOptions) -> CoreResult<()> {
    let size = OutputSize {
        runs,
        samples: launch_output_samples(sc, output_step_s)?,
        columns: super::outputs::launch_column_names().len(),
        state_bytes: std::mem::size_of::<LaunchSample>(),
        max_events: options.max_events,
        event_bytes: std::mem::size_of::<VehicleEvent>(),
    };
    let source = if output_step_s < DEFAULT_OUTPUT_STEP_S { InputSource::Options } else { InputSource::Scenario };
    size.check(source, options.max_output_bytes)
}

/// The output times of a launch (validating the vehicle, the end time, the step and the output's
/// size).
fn output_times(v: &Vehicle, sc: &Scenario, output_step_s: f64, options: &SolverOptions) -> TransientResult<Vec<f64>> {
    v.validate().map_err(|e| e.about(InputSource::Vehicle))?;
    check_launch_output(sc, output_step_s, 1, options)?;
    let n_out = launch_output_samples(sc, output_step_s)? as usize;
    let mut times = Vec::new();
    try_reserve(&mut times, n_out)?;
    times.extend((0..n_out).map(|i| (i as f64 * output_step_s).min(sc.end_time_s)));
    Ok(times)
}

/// The mode of the braked standstill: first gear, lock-up open, the wheels held while the brake
/// pedal is pressed, the stator locked (stalled turbine) and the flow forwards. A model without a
/// flow sign ignores the sign; it is +1 for all models.
pub(super) fn initial_mode(model: &dyn ConverterDynamics, sc: &Scenario) -> VehicleMode {
    VehicleMode {
        converter: ConverterMode {
            stator_locked: model.has_stator_clutch(),
            flow_sign: 1.0,
            ..ConverterMode::default()
        },
        gear: 0,
        shift: None,
        lockup: LockupState::Open,
        wheels_held: sc.brake_pedal.value(0.0) > 0.0,
    }
}

/// `sc` with the pedal the shift schedule reads: the accelerator pedal through the gearbox's
/// TCU filter from its value at 0 to the end time ([`super::shift_pedal`]); `sc` itself if the
/// filter passes the pedal unchanged or the scenario already has a shift pedal.
pub fn with_shift_pedal(v: &Vehicle, sc: &Scenario) -> CoreResult<Scenario> {
    let filter = &v.gearbox.shift_pedal;
    if filter.is_identity() || sc.shift_pedal.is_some() {
        return Ok(sc.clone());
    }
    let pedal = &sc.accelerator_pedal;
    let (signal, _) = filter.filtered(pedal, pedal.value(0.0), 0.0, sc.end_time_s)?;
    Ok(Scenario { shift_pedal: Some(signal), ..sc.clone() })
}

/// Run a launch from the braked standstill ([`initial_state`]), sampled every `output_step_s`
/// until the stop speed or the end time.
pub fn simulate_launch(
    model: &dyn ConverterDynamics,
    v: &Vehicle,
    sc: &Scenario,
    output_step_s: f64,
    options: &SolverOptions,
) -> TransientResult<LaunchTrajectory> {
    let times = output_times(v, sc, output_step_s, options)?;
    let filtered = with_shift_pedal(v, sc)?;
    let sc = &filtered;
    let u0 = initial_state(model, v, sc)?;
    let mut mode = initial_mode(model, sc);
    let mut traj = LaunchTrajectory::default();
    try_reserve(&mut traj.samples, times.len())?;
    let (mut t, mut u, mut sync) = (0.0, u0, 1.0);
    let mut energy_before: Option<f64> = None;
    let stops = sc.breakpoints();
    loop {
        let plant = Plant::new(model, v, sc, mode, sync);
        let x0 = plant.state_of(&u);
        if let Some(before) = energy_before {
            // a closing link removes kinetic energy (momentum is conserved): the clutch's last slip,
            // booked here; the gearbox's inertia is continuous through a shift (super::shift)
            traj.event_loss_j.push((t, before - kinetic_energy(&plant, &plant.full(&x0))));
        }
        let end = match pending_switch(&plant, &plant.full(&x0), t) {
            Some(root) => Some((t, root, x0)),
            None => run_segment_with_stops(
                &plant,
                x0,
                t,
                sc.end_time_s,
                &stops,
                &times,
                options,
                &mut traj.samples,
                &mut traj.steps,
            )?,
        };
        match end {
            None => return Ok(traj),
            Some((t_root, root, x)) => {
                let mut next = plant.full(&x);
                if root == Root::Stop {
                    traj.events.push(VehicleEvent { time_s: t_root, kind: event_name(root), gear: mode.gear + 1 });
                    traj.samples.push(plant.sample(&x, t_root));
                    return Ok(traj);
                }
                let (new_mode, new_sync, booked) = switch_and_booking(&plant, root, &mut next, t_root);
                energy_before = Some(booked);
                let kind = event_kind(root, &new_mode);
                traj.events.push(VehicleEvent { time_s: t_root, kind, gear: new_mode.gear + 1 });
                if traj.events.len() > options.max_events {
                    return Err(TransientError::Solver {
                        time_s: t_root,
                        state: crate::engine::options::named_state(Some(plant.model), &next),
                        message: format!("more than {} events: events chatter", options.max_events),
                    });
                }
                t = t_root;
                u = next;
                mode = new_mode;
                sync = new_sync;
            }
        }
    }
}
