//! Drive cycles: a driver ([`Driver`]) follows a speed trace ([`Trace`]) with the whole-vehicle
//! plant of a launch, the converter in all four quadrants, gears and lock-up by the vehicle's own
//! schedules.
//!
//! The driver is a sampled controller (every [`Driver::control_step_s`]): between two control
//! instants the accelerator and brake pedals are held, the plant runs its smooth segments and
//! events exactly as in a launch ([`super::launch`]). At each control instant `t_k` with the
//! vehicle speed `v` and the trace `v*(t)`:
//!
//! * `a_ff = (v*(t_k + τ + Δt) − v*(t_k + τ)) / Δt`, the trace's acceleration one step long, read
//!   [`Driver::preview_s`] `τ` ahead (the engine's torque builds up with a lag);
//! * `e = v*(t_k) − v`, `I ← I + e Δt` (not while the pedal or the brake is saturated the same
//!   way), `a = a_ff + k_p e + k_i I`;
//! * the force at the tyres `F = m a + F_res`, with `F_res = ΣF_tyre − m v̇` the resistance the plant
//!   showed at `t_k` (aerodynamic, rolling, grade: measured, not modelled twice);
//! * the crank torque for `F` through the gear in mesh, the final drive and the converter's current
//!   torque ratio (1 when the lock-up is locked), and the pedal whose engine target gives it;
//! * when even the closed pedal (engine braking) gives more force than `F`, the brake supplies the
//!   rest: engine braking first;
//! * at a stop of the trace (`v*` below [`STOP_SPEED_M_S`] now and `τ + Δt` ahead) and the vehicle
//!   slower than [`Driver::hold_speed_m_s`]: pedal 0, brake [`Driver::hold_brake`], `I = 0`; the
//!   creep torque of the idling engine through the stalled converter is held by the brake.
//!
//! Energy: the engine's work, the losses (all, and those of the converter, the lock-up clutch and
//! the brakes) are integrated (trapezoidal rule) over samples every [`ENERGY_STEP_S`] within each
//! smooth segment ([`FINE_ENERGY_STEP_S`] while a shift or lock-up clutch slips), whose ends are
//! samples too; the kinetic energy removed at a closing link is
//! booked at its event as in a launch.

use super::components::brake_torque_nm;
use super::launch::{event_kind, initial_mode, initial_state, pending_switch, switch_and_booking, LaunchTrajectory};
use super::modes::{LockupState, VehicleEvent};
use super::parameters::{Scenario, Vehicle};
use super::plant::{kinetic_energy, LaunchSample, Plant};
use super::{FRONT, REAR, SPEED};
use crate::converter::dynamics::{ConverterDynamics, PUMP, TURBINE};
use crate::engine::lockup;
use crate::engine::options::{try_reserve, OutputSize, SolverOptions, TransientError, TransientResult};
use crate::engine::segment::{run_segment, SmoothSegment};
use crate::engine::signal::Signal;
use crate::error::{CoreError, CoreResult, InputSource};
use crate::interp::linear_held;

/// Trace speed below which the trace stands still, m/s.
pub const STOP_SPEED_M_S: f64 = 0.05;
/// Step of the samples the energies are integrated over, s.
pub const ENERGY_STEP_S: f64 = 0.01;
/// The step while a clutch slips (a shift, a lock-up engagement): their synchronisation is fast, s.
pub const FINE_ENERGY_STEP_S: f64 = 0.0005;
/// Relative tolerance of a drive's solver unless the options give one: the energy balance of a
/// whole cycle closes to about 1e-5 of the engine's work with it.
pub const DRIVE_RTOL: f64 = 1e-7;
/// More events than this in one control step is reported as chattering.
pub const MAX_EVENTS_PER_STEP: usize = 1000;
/// Largest grade of a trace, percent.
pub const MAX_GRADE_PERCENT: f64 = 30.0;
/// Largest speed of a trace, m/s (250 km/h).
pub const MAX_TRACE_SPEED_M_S: f64 = 250.0 / 3.6;

/// A speed trace: vehicle speed and road grade against time, linear between samples.
#[derive(Debug, Clone)]
pub struct Trace {
    time_s: Vec<f64>,
    speed_m_s: Vec<f64>,
    grade_percent: Vec<f64>,
}

impl Trace {
    /// A trace from samples: at least two, times finite and strictly increasing from 0, speeds
    /// finite in [0, [`MAX_TRACE_SPEED_M_S`]] starting at rest, grades finite within
    /// ±[`MAX_GRADE_PERCENT`] (zero when `None`). Errors name the column and index.
    pub fn new(time_s: Vec<f64>, speed_m_s: Vec<f64>, grade_percent: Option<Vec<f64>>) -> CoreResult<Self> {
        let bad = |f: String, v: f64, e: &str| Err(CoreError::of(InputSource::Scenario, f, v, e.to_string()));
        let n = time_s.len();
        if n < 2 {
            return bad("time_s".into(), n as f64, "at least two samples");
        }
        let grade = grade_percent.unwrap_or_else(|| vec![0.0; n]);
        if speed_m_s.len() != n || grade.len() != n {
            return bad("vehicle_speed_m_s".into(), speed_m_s.len() as f64, "one value per time stamp");
        }
        if time_s[0] != 0.0 {
            return bad("time_s[0]".into(), time_s[0], "0 (a trace starts at time 0)");
        }
        for i in 1..n {
            if !(time_s[i].is_finite() && time_s[i] > time_s[i - 1]) {
                return bad(format!("time_s[{i}]"), time_s[i], "finite, strictly increasing times");
            }
        }
        for (i, &v) in speed_m_s.iter().enumerate() {
            if !(v.is_finite() && (0.0..=MAX_TRACE_SPEED_M_S).contains(&v)) {
                return bad(format!("vehicle_speed_m_s[{i}]"), v, "a finite speed of at least 0 and at most 69.44 m/s");
            }
        }
        if speed_m_s[0] > STOP_SPEED_M_S {
            return bad("vehicle_speed_m_s[0]".into(), speed_m_s[0], "a trace that starts at rest (0 m/s)");
        }
        for (i, &g) in grade.iter().enumerate() {
            if !(g.is_finite() && g.abs() <= MAX_GRADE_PERCENT) {
                return bad(format!("grade_percent[{i}]"), g, "a finite grade of at least -30 and at most 30 %");
            }
        }
        Ok(Self { time_s, speed_m_s, grade_percent: grade })
    }
    /// The trace's speed at `t`, m/s.
    pub fn speed(&self, t: f64) -> f64 {
        linear_held(&self.time_s, &self.speed_m_s, t)
    }
    /// The trace's grade at `t`, percent.
    pub fn grade(&self, t: f64) -> f64 {
        linear_held(&self.time_s, &self.grade_percent, t)
    }
    /// The trace's last time, s.
    pub fn end_time_s(&self) -> f64 {
        self.time_s[self.time_s.len() - 1]
    }
}

/// The driver's gains and settings.
#[derive(Debug, Clone, Copy)]
pub struct Driver {
    /// Proportional gain on the speed error, 1/s (m/s² per m/s).
    pub kp_per_s: f64,
    /// Integral gain on the speed error, 1/s² (m/s² per m).
    pub ki_per_s2: f64,
    /// Control step (pedals held between control instants), s; also the output step.
    pub control_step_s: f64,
    /// Preview of the feed-forward: the driver reads the trace's acceleration this far ahead, s.
    pub preview_s: f64,
    /// Brake pedal that holds the vehicle at a stop, 0–1.
    pub hold_brake: f64,
    /// Below this speed the vehicle is held at a stop of the trace, m/s.
    pub hold_speed_m_s: f64,
    /// Largest integral action, m/s².
    pub max_integral_m_s2: f64,
}

impl Default for Driver {
    fn default() -> Self {
        Self {
            kp_per_s: 2.0,
            ki_per_s2: 0.5,
            control_step_s: 0.1,
            preview_s: 0.5,
            hold_brake: 0.3,
            hold_speed_m_s: 0.5,
            max_integral_m_s2: 2.0,
        }
    }
}

impl Driver {
    /// Checks the gains: finite and positive (the integral gain may be 0), the hold brake in (0, 1],
    /// the control step in [0.01, 1] s.
    pub fn validate(&self) -> CoreResult<()> {
        let bad = |f: &str, v: f64, e: &str| Err(CoreError::of(InputSource::Options, f, v, e.to_string()));
        if !(self.kp_per_s.is_finite() && self.kp_per_s > 0.0) {
            return bad("driver_kp_per_s", self.kp_per_s, "a finite, positive gain");
        }
        if !(self.ki_per_s2.is_finite() && self.ki_per_s2 >= 0.0) {
            return bad("driver_ki_per_s2", self.ki_per_s2, "a finite gain of at least 0");
        }
        if !(self.control_step_s.is_finite() && (0.01..=1.0).contains(&self.control_step_s)) {
            return bad(
                "driver_control_step_s",
                self.control_step_s,
                "a control step of at least 0.01 and at most 1 s",
            );
        }
        if !(self.preview_s.is_finite() && (0.0..=2.0).contains(&self.preview_s)) {
            return bad("driver_preview_s", self.preview_s, "a preview of at least 0 and at most 2 s");
        }
        if !(self.hold_brake.is_finite() && self.hold_brake > 0.0 && self.hold_brake <= 1.0) {
            return bad("driver_hold_brake", self.hold_brake, "a brake pedal above 0 and at most 1");
        }
        Ok(())
    }

    /// The pedals `(accelerator, brake)` at the control instant `t` from the sample `s` there,
    /// updating the integral `integral` (m).
    pub(super) fn command(
        &self,
        v: &Vehicle,
        trace: &Trace,
        t: f64,
        s: &LaunchSample,
        integral: &mut f64,
    ) -> (f64, f64) {
        let dt = self.control_step_s;
        let (target, ahead) = (trace.speed(t), trace.speed(t + self.preview_s + dt));
        let speed = s.u[SPEED];
        if target <= STOP_SPEED_M_S && ahead <= STOP_SPEED_M_S && speed < self.hold_speed_m_s {
            *integral = 0.0;
            return (0.0, self.hold_brake);
        }
        let m = v.body.mass_kg;
        let e = target - speed;
        let ki_i = (self.ki_per_s2 * *integral).clamp(-self.max_integral_m_s2, self.max_integral_m_s2);
        let preview = trace.speed(t + self.preview_s);
        let accel = (ahead - preview) / dt + self.kp_per_s * e + ki_i;
        let resistance = s.tyre_force_n[0] + s.tyre_force_n[1] - m * s.u_dot[SPEED];
        let force = m * accel + resistance;
        let (pedal, brake) = self.pedals(v, s, force);
        let saturated = (pedal >= 1.0 && e > 0.0) || (brake >= 1.0 && e < 0.0);
        if !saturated && self.ki_per_s2 > 0.0 {
            let limit = self.max_integral_m_s2 / self.ki_per_s2;
            *integral = (*integral + e * dt).clamp(-limit, limit);
        }
        (pedal, brake)
    }

    /// The pedals for the tyre force `force` (N): the crank torque through the gear, the final drive
    /// and the converter's torque ratio, then the pedal whose engine target gives it; the brake for
    /// the force the closed pedal cannot take away.
    fn pedals(&self, v: &Vehicle, s: &LaunchSample, force: f64) -> (f64, f64) {
        let r = v.tyres.rolling_radius_m;
        let gear = s.mode.shift.map_or(s.mode.gear, |sh| sh.from);
        let ratio = v.gearbox.ratios[gear] * v.driveline.final_drive_ratio;
        let tr = converter_ratio(s);
        let w = s.u[PUMP];
        let crank = |p: f64| {
            let (fast, boost) = v.engine.targets(p, w);
            fast + boost - v.engine.drag(w)
        };
        let needed = force * r / (ratio * tr);
        let closed = crank(0.0);
        if needed <= closed {
            let brake = ((closed * ratio * tr / r - force) * r / v.brake.capacity_nm).clamp(0.0, 1.0);
            return (0.0, brake);
        }
        if crank(1.0) <= needed {
            return (1.0, 0.0);
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if crank(mid) < needed {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (0.5 * (lo + hi), 0.0)
    }
}

/// The converter's torque ratio as the driver knows it: 1 with the lock-up locked or no torque to
/// speak of, else the transferred turbine over pump torque, within [1, 3].
fn converter_ratio(s: &LaunchSample) -> f64 {
    let (pump, turbine) = s.converter.transferred;
    if s.mode.lockup == LockupState::Locked || pump.abs() < 5.0 {
        return 1.0;
    }
    (turbine / pump).abs().clamp(1.0, 3.0)
}

/// Cumulative energies of a drive, J.
#[derive(Debug, Clone, Copy, Default)]
pub struct Energies {
    pub engine_work_j: f64,
    /// Every loss of the plant (converter, lock-up, gears, shafts, tyres, brakes, aerodynamic,
    /// rolling, grade), without the event losses.
    pub loss_j: f64,
    pub converter_loss_j: f64,
    pub lockup_loss_j: f64,
    pub brake_j: f64,
    /// Kinetic energy removed at closing links (lock-up, shifts), booked at their events.
    pub event_loss_j: f64,
}

/// A drive: the output samples (every control step) with the events and event losses, the pedals
/// and energies at each sample, and the trace's speed there.
#[derive(Debug, Clone, Default)]
pub struct DriveTrajectory {
    pub run: LaunchTrajectory,
    pub pedals: Vec<(f64, f64)>,
    pub energies: Vec<Energies>,
    pub target_m_s: Vec<f64>,
    pub grade_percent: Vec<f64>,
}

/// The loss powers (converter, lock-up clutch, brakes) of `plant` at its sample `s`, W.
fn loss_parts(plant: &Plant, s: &LaunchSample) -> [f64; 3] {
    let slip = s.u[PUMP] - s.u[TURBINE];
    let t_lu = lockup::slipping_torque_nm(plant.lockup_capacity(s.time_s), slip);
    let lockup_w = if plant.mode.lockup == LockupState::Locked { 0.0 } else { lockup::dissipation_w(t_lu, slip) };
    let brake = plant.sc.brake_pedal.value(s.time_s).clamp(0.0, 1.0) * plant.v.brake.capacity_nm;
    let share = plant.v.brake.front_fraction;
    let brake_w = if plant.mode.wheels_held {
        0.0
    } else {
        [(FRONT, share), (REAR, 1.0 - share)].iter().map(|&(a, f)| brake_torque_nm(brake * f, s.u[a]) * s.u[a]).sum()
    };
    [s.converter.loss_power_w, lockup_w, brake_w]
}

/// Adds the trapezoidal integrals over `samples` (one smooth segment of `plant`) to `e`.
fn integrate(plant: &Plant, samples: &[LaunchSample], e: &mut Energies) {
    let parts: Vec<[f64; 3]> = samples.iter().map(|s| loss_parts(plant, s)).collect();
    for i in 1..samples.len() {
        let (a, b) = (&samples[i - 1], &samples[i]);
        let h = 0.5 * (b.time_s - a.time_s);
        e.engine_work_j += h * (a.engine_power_w + b.engine_power_w);
        e.loss_j += h * (a.loss_power_w + b.loss_power_w);
        e.converter_loss_j += h * (parts[i - 1][0] + parts[i][0]);
        e.lockup_loss_j += h * (parts[i - 1][1] + parts[i][1]);
        e.brake_j += h * (parts[i - 1][2] + parts[i][2]);
    }
}

/// The scenario of one control step: the pedals held, no stop speed.
fn held_scenario(pedal: f64, brake: f64, end_time_s: f64) -> Scenario {
    Scenario {
        accelerator_pedal: Signal::constant(pedal),
        brake_pedal: Signal::constant(brake),
        end_time_s,
        stop_speed_m_s: None,
        engine_torque_nm: None,
        shift_pedal: None,
    }
}

/// The sampling times of a segment from `t0` to `t1`: `t0`, the multiples of `step` between, and
/// `t1`.
fn segment_times(t0: f64, t1: f64, step: f64) -> Vec<f64> {
    let mut times = vec![t0];
    let mut k = (t0 / step).floor() + 1.0;
    while k * step < t1 - 1e-9 {
        times.push(k * step);
        k += 1.0;
    }
    times.push(t1);
    times
}

/// The state carried from one control step to the next.
struct Carry {
    t: f64,
    u: super::plant::Coords,
    mode: super::modes::VehicleMode,
    sync: f64,
    energies: Energies,
}

/// Runs the plant of vehicle `v` under the held scenario `sc` from `c` to `t_end`, events and
/// all, integrating the energies; returns the sample at `c.t` (start of the step).
fn run_step(
    model: &dyn ConverterDynamics,
    v: &Vehicle,
    sc: &Scenario,
    c: &mut Carry,
    t_end: f64,
    options: &crate::engine::options::SolverOptions,
    traj: &mut LaunchTrajectory,
) -> TransientResult<LaunchSample> {
    let first = {
        let plant = Plant::new(model, v, sc, c.mode, c.sync);
        plant.sample(&plant.state_of(&c.u), c.t)
    };
    let mut booked_before: Option<f64> = None;
    let mut events_in_step = 0;
    // the solver's step budget (`options.max_steps`) holds for each control step, as the events'
    let mut steps_in_step = 0;
    loop {
        let plant = Plant::new(model, v, sc, c.mode, c.sync);
        let x0 = plant.state_of(&c.u);
        if let Some(before) = booked_before.take() {
            let removed = before - kinetic_energy(&plant, &plant.full(&x0));
            traj.event_loss_j.push((c.t, removed));
            c.energies.event_loss_j += removed;
        }
        let end = match pending_switch(&plant, &plant.full(&x0), c.t) {
            Some(root) => Some((c.t, root, x0)),
            None => {
                let slipping = c.mode.shift.is_some() || matches!(c.mode.lockup, LockupState::Engaging { .. });
                let times = segment_times(c.t, t_end, if slipping { FINE_ENERGY_STEP_S } else { ENERGY_STEP_S });
                let mut samples = Vec::new();
                let end = run_segment(&plant, x0, c.t, t_end, &times, options, &mut samples, &mut steps_in_step)?;
                if let Some((t_root, _, x)) = &end {
                    samples.push(plant.sample(x, *t_root));
                }
                integrate(&plant, &samples, &mut c.energies);
                if end.is_none() {
                    let last = samples.last().expect("a segment to its end time samples its end");
                    c.u = last.u;
                    c.t = t_end;
                    traj.steps += steps_in_step;
                    return Ok(first);
                }
                end
            }
        };
        let Some((t_root, root, x)) = end else { unreachable!("handled above") };
        let mut next = plant.full(&x);
        let (new_mode, new_sync, booked) = switch_and_booking(&plant, root, &mut next, t_root);
        booked_before = Some(booked);
        traj.events.push(VehicleEvent { time_s: t_root, kind: event_kind(root, &new_mode), gear: new_mode.gear + 1 });
        events_in_step += 1;
        if events_in_step > options.max_events.min(MAX_EVENTS_PER_STEP) {
            return Err(TransientError::Solver {
                time_s: t_root,
                state: crate::engine::options::named_state(Some(plant.model), &next),
                message: format!("more than {} events in one control step: events chatter", events_in_step - 1),
            });
        }
        (c.t, c.u, c.mode, c.sync) = (t_root, next, new_mode, new_sync);
    }
}

/// The number of output samples of a drive of `trace` with the control step `control_step_s` (one
/// per control instant, the trace's end included).
pub fn drive_output_samples(trace: &Trace, control_step_s: f64) -> f64 {
    (trace.end_time_s() / control_step_s).ceil() + 1.0
}

/// The size of the output of `runs` drives of `trace` with `driver`, checked against the limit of
/// `options` before anything runs (the launch's [`OutputSize`]): an error about the trace (its
/// length), or about the options when the control step is finer than the default.
pub fn check_drive_output(trace: &Trace, driver: &Driver, runs: usize, options: &SolverOptions) -> CoreResult<()> {
    driver.validate()?;
    let per_sample = std::mem::size_of::<LaunchSample>()
        + std::mem::size_of::<(f64, f64)>()
        + std::mem::size_of::<Energies>()
        + 2 * std::mem::size_of::<f64>();
    let size = OutputSize {
        runs,
        samples: drive_output_samples(trace, driver.control_step_s),
        columns: drive_column_names().len(),
        state_bytes: per_sample,
        max_events: options.max_events,
        event_bytes: std::mem::size_of::<VehicleEvent>() + std::mem::size_of::<(f64, f64)>(),
    };
    let finer = driver.control_step_s < Driver::default().control_step_s;
    size.check(if finer { InputSource::Options } else { InputSource::Scenario }, options.max_output_bytes)
}

/// Follow `trace` with `driver` in vehicle `v` (its grade replaced by the trace's at each control
/// step) and converter `model`, from the braked standstill in first gear at idle.
pub fn simulate_drive(
    model: &dyn ConverterDynamics,
    v: &Vehicle,
    trace: &Trace,
    driver: &Driver,
    options: &SolverOptions,
) -> TransientResult<DriveTrajectory> {
    v.validate().map_err(|e| e.about(InputSource::Vehicle))?;
    check_drive_output(trace, driver, 1, options)?;
    let end = trace.end_time_s();
    let dt = driver.control_step_s;
    let n_steps = (end / dt).ceil() as usize;
    let sc0 = held_scenario(0.0, driver.hold_brake, end);
    let mut c = Carry {
        t: 0.0,
        u: initial_state(model, v, &sc0)?,
        mode: initial_mode(model, &sc0),
        sync: 1.0,
        energies: Energies::default(),
    };
    let mut out = DriveTrajectory::default();
    for buf in [&mut out.target_m_s, &mut out.grade_percent] {
        try_reserve(buf, n_steps + 1)?;
    }
    try_reserve(&mut out.run.samples, n_steps + 1)?;
    let mut integral = 0.0;
    // the TCU's filtered pedal for the shift schedule, from the standstill's closed pedal
    let mut shift_pedal = 0.0;
    let mut sample = {
        let plant = Plant::new(model, v, &sc0, c.mode, c.sync);
        plant.sample(&plant.state_of(&c.u), 0.0)
    };
    let mut veh = v.clone();
    for k in 0..=n_steps {
        let t_k = c.t;
        let (pedal, brake) = driver.command(v, trace, t_k, &sample, &mut integral);
        veh.body.grade_percent = trace.grade(t_k);
        let mut sc = held_scenario(pedal, brake, end);
        let energies = c.energies;
        let t_next = ((k + 1) as f64 * dt).min(end);
        if !v.gearbox.shift_pedal.is_identity() && t_next > t_k {
            let (signal, next) = v.gearbox.shift_pedal.filtered(&Signal::constant(pedal), shift_pedal, t_k, t_next)?;
            (sc.shift_pedal, shift_pedal) = (Some(signal), next);
        }
        let first = if k == n_steps || t_next <= t_k {
            let plant = Plant::new(model, &veh, &sc, c.mode, c.sync);
            plant.sample(&plant.state_of(&c.u), t_k)
        } else {
            run_step(model, &veh, &sc, &mut c, t_next, options, &mut out.run)?
        };
        out.run.samples.push(first);
        out.pedals.push((pedal, brake));
        out.energies.push(energies);
        out.target_m_s.push(trace.speed(t_k));
        out.grade_percent.push(veh.body.grade_percent);
        if k == n_steps || t_next <= t_k {
            break;
        }
        let plant = Plant::new(model, &veh, &sc, c.mode, c.sync);
        sample = plant.sample(&plant.state_of(&c.u), c.t);
    }
    Ok(out)
}

/// Columns of a drive after the launch's ([`super::outputs::launch_column_names`], whose pedal
/// columns hold the driver's commands): the trace's speed and grade, the speed error (trace minus
/// vehicle) and the cumulative energies.
pub const DRIVE_COLUMNS: [&str; 9] = [
    "target_speed_m_s",
    "speed_error_m_s",
    "grade_percent",
    "engine_work_j",
    "vehicle_loss_j",
    "converter_loss_j",
    "lockup_loss_j",
    "brake_energy_j",
    "booked_event_loss_j",
];

/// All columns of a drive: the launch's, then [`DRIVE_COLUMNS`].
pub fn drive_column_names() -> Vec<&'static str> {
    super::outputs::launch_column_names().into_iter().chain(DRIVE_COLUMNS).collect()
}

/// The drive as columns in the order of [`drive_column_names`].
pub fn drive_columns(model: &dyn ConverterDynamics, traj: &DriveTrajectory) -> TransientResult<Vec<Vec<f64>>> {
    let names = super::outputs::launch_column_names();
    let end = traj.run.samples.last().map_or(1.0, |s| s.time_s.max(1.0));
    let mut cols = super::outputs::launch_columns(model, &held_scenario(0.0, 0.0, end), &traj.run)?;
    let pedal = names.iter().position(|n| *n == "accelerator_pedal").expect("a launch has a pedal column");
    let brake = names.iter().position(|n| *n == "brake_pedal").expect("a launch has a brake column");
    cols[pedal] = traj.pedals.iter().map(|p| p.0).collect();
    cols[brake] = traj.pedals.iter().map(|p| p.1).collect();
    let s = &traj.run.samples;
    let e = &traj.energies;
    let extra: [Vec<f64>; 9] = [
        traj.target_m_s.clone(),
        traj.target_m_s.iter().zip(s).map(|(t, s)| t - s.u[SPEED]).collect(),
        traj.grade_percent.clone(),
        e.iter().map(|e| e.engine_work_j).collect(),
        e.iter().map(|e| e.loss_j).collect(),
        e.iter().map(|e| e.converter_loss_j).collect(),
        e.iter().map(|e| e.lockup_loss_j).collect(),
        e.iter().map(|e| e.brake_j).collect(),
        e.iter().map(|e| e.event_loss_j).collect(),
    ];
    cols.extend(extra);
    Ok(cols)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drive_output_above_the_limit_is_refused_before_running() {
        let (driver, options) = (Driver::default(), SolverOptions::default());
        let day = Trace::new(vec![0.0, 1e6], vec![0.0, 0.0], None).unwrap();
        let e = check_drive_output(&day, &driver, 3, &options).unwrap_err();
        assert_eq!(
            (e.source, e.field.as_str(), e.value.as_str()),
            (InputSource::Scenario, "output_samples", "10000001")
        );
        assert!(e.expected.contains("max_output_bytes = 2e9 bytes"), "{}", e.expected);
        let fine = Driver { control_step_s: 0.01, ..driver };
        let hour = Trace::new(vec![0.0, 3600.0], vec![0.0, 0.0], None).unwrap();
        assert!(check_drive_output(&hour, &driver, 3, &options).is_ok());
        let small = SolverOptions { max_output_bytes: 1e6, ..options };
        assert_eq!(check_drive_output(&hour, &fine, 1, &small).unwrap_err().source, InputSource::Options);
        assert_eq!(drive_output_samples(&hour, 0.1), 36001.0);
    }

    #[test]
    fn trace_edges_are_refused() {
        assert!(Trace::new(vec![0.0], vec![0.0], None).is_err());
        let e = Trace::new(vec![0.0, 1.0, 1.0], vec![0.0, 1.0, 2.0], None).unwrap_err();
        assert_eq!(e.field, "time_s[2]");
        let e = Trace::new(vec![0.0, 1.0], vec![0.0, -1.0], None).unwrap_err();
        assert_eq!(e.field, "vehicle_speed_m_s[1]");
        let e = Trace::new(vec![0.0, 1.0], vec![0.0, f64::NAN], None).unwrap_err();
        assert_eq!(e.field, "vehicle_speed_m_s[1]");
        let e = Trace::new(vec![0.0, 1.0], vec![3.0, 3.0], None).unwrap_err();
        assert_eq!(e.field, "vehicle_speed_m_s[0]");
        let e = Trace::new(vec![0.0, 1.0], vec![0.0, 1.0], Some(vec![0.0, 31.0])).unwrap_err();
        assert_eq!(e.field, "grade_percent[1]");
    }
}
