//! The transient engine: a converter model, a way of driving it, and the BDF solver ([`crate::engine::bdf`]) with
//! root finding for the discrete events.
//!
//! # Coordinates, states and modes
//!
//! A model ([`ConverterDynamics`]) is written over `u = [ω_p, ω_t, ω_s, Q]` as `M u̇ = F(u) + T`.
//! Each coordinate the model has is, at any time, one of:
//!
//! * **free**: a state of the ODE;
//! * **given**: a measured speed from the [`Drive`]; its rate is the signal's smoothed derivative
//!   ([`crate::engine::signal`]);
//! * **held** at zero: the stator while the one-way clutch holds, the flow while it is stalled.
//!
//! The free coordinates `x` obey `M_xx ẋ = F_x(u) + T_x(t, u) − M_xz ż(t)`, handed to the solver in
//! this mass-matrix form with its analytic Jacobian. The external torque on a given or held
//! coordinate is whatever the constraint needs, `T_z = (M u̇ − F)_z`: the turbine torque in drive
//! (a), both torques in drive (b), the stator's holding torque.
//!
//! # Events
//!
//! The system is smooth between events; at an event the engine stops at the root (the solver's root
//! finder), switches the mode and starts a new BDF segment from the state at the root, which is
//! continuous. Root functions per mode:
//!
//! * stator **locked**: the holding torque `T_s`. It crosses zero at the coupling point and the
//!   clutch releases (`T_s ≥ 0` is all a one-way clutch can give).
//! * stator **free-wheeling** (`T_s = 0`): the stator speed. It reaches zero and the clutch locks.
//! * flow with **sign σ = ±1** in the losses (eq 2.19): Q. At Q = 0 the sign is decided as below.
//! * flow **held at zero** (σ = 0): `−d⁺` and `d⁻`, see next.
//!
//! **Flow reversal (sgn Q).** The model has one form for Q > 0 (the thesis's equations) and one
//! for Q < 0 (the reverse-flow form of docs/models.md: the fluid leaves each element across its
//! inlet edge), and the losses carry `sgn Q`, so the net force on the flow may jump at Q = 0. The
//! engine treats the switch as a Filippov system: with `d± = F_Q(0±)` minus the inertial coupling
//! (the flow held), the flow stays at zero while `d⁺ ≤ 0 ≤ d⁻` and starts forwards once `d⁺ > 0`,
//! backwards once `d⁻ < 0` (both: the larger of `d⁺` and `−d⁻`, forwards on a tie). Between
//! events the sign is constant, so the right-hand side is smooth and the energy identity holds
//! exactly (the held flow does no work). This is the state the closed-form steady state calls
//! `no-flow`.

use crate::converter::dynamics::{ConverterDynamics, SteadyPoint, Vec4, FLOW, PUMP, STATOR, TURBINE};
use crate::engine::converter_events::{EventKind, Mode, Sample};
use crate::engine::converter_segment::{flow_sign_at_zero, lock_energies, switch, Root, Segment};
use crate::engine::lockup;
use crate::engine::options::{named_state, SolverOptions, TransientError, TransientResult};
use crate::error::{sig, CoreError, CoreResult, InputSource};

pub use crate::engine::drive::{Drive, TurbineLoad};

/// Optional initial values; what is not given comes from the steady state consistent with the
/// first input sample ([`initial_state`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct InitialState {
    pub pump_speed_rad_s: Option<f64>,
    pub turbine_speed_rad_s: Option<f64>,
    pub stator_speed_rad_s: Option<f64>,
    pub flow_m3_s: Option<f64>,
}

/// Why a run ignores a value of its [`InitialState`] ([`InitialState::ignored`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IgnoredInitial {
    /// The drive gives this speed: the run starts at the drive's first sample of it.
    GivenByDrive,
    /// The model has no such state (the table model's stator speed and flow, the quasi-dynamic
    /// model's stator speed), or the coordinate holds the table model's lag state, which starts at
    /// its steady value.
    NotAState,
}

impl InitialState {
    /// The values given here that a run of `model` under `drive` does not use, by coordinate name
    /// (`pump_speed_rad_s`, ...), with why: the rules of [`initial_state`], which silently passes
    /// over them.
    pub fn ignored(&self, model: &dyn ConverterDynamics, drive: &Drive) -> Vec<(&'static str, IgnoredInitial)> {
        let present = model.coordinates();
        let given = [self.pump_speed_rad_s, self.turbine_speed_rad_s, self.stator_speed_rad_s, self.flow_m3_s];
        (0..4)
            .filter(|&c| given[c].is_some())
            .filter_map(|c| {
                let why = if drive.given(c).is_some() {
                    IgnoredInitial::GivenByDrive
                } else if !present[c] || (c == FLOW && model.lag_state()) {
                    IgnoredInitial::NotAState
                } else {
                    return None;
                };
                Some((COORDINATES[c], why))
            })
            .collect()
    }
}

/// An event: time, kind and the mode after it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    pub time_s: f64,
    pub kind: EventKind,
    pub mode: Mode,
}

/// The result of a run: samples at the requested times, the events, and solver statistics. The
/// samples carry the clutch's columns ([`crate::engine::converter_events::LockupSample`]), the
/// energy the lock events took out of the stored energy among them.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    pub samples: Vec<Sample>,
    pub events: Vec<Event>,
    pub steps: usize,
    /// State and mode at the end time, after any event there (to continue the run).
    pub end_state: Vec4,
    pub end_mode: Mode,
}

// ---------------------------------------------------------------------------------------------

/// The mode a state starts in: the stator locked if it stands and the clutch would hold; the flow
/// sign from Q, or from the held-flow balance when Q = 0; the lock-up clutch not locked, armed
/// unless its slip is below the sync threshold ([`lockup::initial_mode`]).
pub fn initial_mode(model: &dyn ConverterDynamics, drive: &Drive, u: &Vec4, t: f64) -> Mode {
    let mut mode = Mode {
        stator_locked: false,
        flow_sign: if u[FLOW] > 0.0 {
            1.0
        } else if u[FLOW] < 0.0 {
            -1.0
        } else {
            0.0
        },
        lockup: lockup::initial_mode(u[PUMP] - u[TURBINE], t),
    };
    if model.has_flow_sign() && u[FLOW] == 0.0 {
        let stator_locked = mode.stator_locked || u[STATOR] <= 0.0;
        mode.flow_sign = flow_sign_at_zero(model, drive, u, t, Mode { stator_locked, ..mode });
    }
    if model.has_stator_clutch() && u[STATOR] <= 0.0 {
        let locked = Mode { stator_locked: true, ..mode };
        let seg = Segment::new(model, drive, locked);
        let (_, ud, f) = seg.kinematics(&seg.state(u), t);
        mode.stator_locked = seg.external_torques(&ud, &f)[STATOR] >= 0.0;
    }
    mode
}

/// The steady state consistent with the inputs at time `t0` (documented default of
/// `tcsim replay`):
///
/// * drive (b): the steady state at the given speeds;
/// * drive (a): the pump speed whose steady pump torque equals the given pump torque at the given
///   turbine speed (bisection on SR in (0, 1]; the pump torque of a steady state falls with SR);
/// * drive (c): the same with the turbine speed from `init` (default 0, a vehicle at rest).
///
/// Values in `init` override the steady state. Every error names the input it comes from as data:
/// [`InputSource::Initial`] for a value of `init`, [`InputSource::Drive`] for a value of the drive's
/// first sample, with the field `initial <coordinate>`. A state at which the model's torques,
/// power or stored energy are not finite is refused before the solver starts.
pub fn initial_state(
    model: &dyn ConverterDynamics,
    drive: &Drive,
    t0: f64,
    init: &InitialState,
) -> TransientResult<Vec4> {
    let given_wt = drive.given(TURBINE).map(|s| s.value(t0));
    let given_wp = drive.given(PUMP).map(|s| s.value(t0));
    let wt = given_wt.or(init.turbine_speed_rad_s).unwrap_or(0.0);
    let wt_source = if given_wt.is_none() && init.turbine_speed_rad_s.is_some() {
        InputSource::Initial
    } else {
        InputSource::Drive
    };
    check_initial_value(&[("turbine_speed_rad_s", wt)], wt_source)?;
    let wp = match (given_wp, init.pump_speed_rad_s) {
        (Some(w), _) => w,
        (None, Some(w)) => {
            check_initial_value(&[("pump_speed_rad_s", w)], InputSource::Initial)?;
            w
        }
        (None, None) => {
            let tp = drive.pump_torque().map_or(0.0, |s| s.value(t0));
            let wp = steady_pump_speed(model, tp, wt, wt_source)?;
            check_steady_pump_speed(wp, tp)?;
            wp
        }
    };
    // the speeds the steady state starts from: the drive's unless the user gave one
    let from_init = (given_wp.is_none() && init.pump_speed_rad_s.is_some()) || wt_source == InputSource::Initial;
    let speeds_source = if from_init { InputSource::Initial } else { InputSource::Drive };
    let u = steady_start(model, wp, wt, init, speeds_source)?;
    let source_of = |c: usize| {
        let given_by_init = match c {
            PUMP => given_wp.is_none() && init.pump_speed_rad_s.is_some(),
            TURBINE => wt_source == InputSource::Initial,
            STATOR => init.stator_speed_rad_s.is_some(),
            _ => init.flow_m3_s.is_some(),
        };
        if given_by_init {
            InputSource::Initial
        } else {
            speeds_source
        }
    };
    for c in 0..4 {
        if !u[c].is_finite() {
            return Err(
                CoreError::of(source_of(c), format!("initial {}", COORDINATES[c]), u[c], "a finite value").into()
            );
        }
    }
    if model.has_stator_clutch() && u[STATOR] < 0.0 {
        return Err(CoreError::of(
            InputSource::Initial,
            "initial stator_speed_rad_s",
            u[STATOR],
            "zero or more: the one-way clutch stops backward rotation",
        )
        .into());
    }
    check_finite_state(model, &u, source_of)?;
    Ok(u)
}

/// The steady state at the speeds `wp`, `wt` (an error about `source` when there is none), with
/// the values of `init` and the absent coordinates zero.
fn steady_start(
    model: &dyn ConverterDynamics,
    wp: f64,
    wt: f64,
    init: &InitialState,
    source: InputSource,
) -> TransientResult<Vec4> {
    // a lag state is not a flow: it starts at its steady value whatever `init` says of the flow
    let init_flow = if model.lag_state() { None } else { init.flow_m3_s };
    let mut u = if init_flow.is_some() && init.stator_speed_rad_s.is_some() {
        [wp, wt, 0.0, 0.0]
    } else {
        steady_point_scaled(model, wp, wt)
            .map_err(|e| {
                CoreError::of(
                    source,
                    format!("initial {}", e.field),
                    e.value,
                    format!("{}; give the initial state explicitly", e.expected),
                )
            })?
            .u
    };
    u[PUMP] = wp;
    u[TURBINE] = wt;
    if let Some(ws) = init.stator_speed_rad_s {
        u[STATOR] = ws;
    }
    if let Some(q) = init_flow {
        u[FLOW] = q;
    }
    let present = model.coordinates();
    for c in 0..4 {
        if !present[c] {
            u[c] = 0.0;
        }
    }
    Ok(u)
}

/// The coordinates' names, with units, in the order of `u`.
const COORDINATES: [&str; 4] = ["pump_speed_rad_s", "turbine_speed_rad_s", "stator_speed_rad_s", "flow_m3_s"];

/// Finite values (a NaN or an infinite speed from a drive or `init`).
fn check_initial_value(values: &[(&str, f64)], source: InputSource) -> TransientResult<()> {
    match values.iter().find(|(_, v)| !v.is_finite()) {
        Some((name, v)) => Err(CoreError::of(source, format!("initial {name}"), v, "a finite value").into()),
        None => Ok(()),
    }
}

/// The model's torques, power and stored energy at `u` must be finite (a speed of 1e300 rad/s is a
/// finite number whose torques are not): the error blames the coordinate farthest outside its
/// plausible range ([`crate::plausibility`]), whose source `source_of` gives.
fn check_finite_state(
    model: &dyn ConverterDynamics,
    u: &Vec4,
    source_of: impl Fn(usize) -> InputSource,
) -> TransientResult<()> {
    let f = model.forces(u, if u[FLOW] < 0.0 { -1.0 } else { 1.0 });
    let m = model.mass();
    let energy: f64 = (0..4).map(|i| (0..4).map(|j| 0.5 * u[i] * m[i][j] * u[j]).sum::<f64>()).sum();
    let power: f64 = (0..4).map(|i| f[i] * u[i]).sum();
    if f.iter().all(|x| x.is_finite()) && energy.is_finite() && power.is_finite() {
        return Ok(());
    }
    let scale = |c: usize| {
        let q = if c == FLOW { "flow_m3_s" } else { "speed_rad_s" };
        crate::plausibility::range(q).map_or(1.0, |r| r.high)
    };
    let c = (0..4).max_by(|&a, &b| (u[a] / scale(a)).abs().total_cmp(&(u[b] / scale(b)).abs())).unwrap_or(PUMP);
    let range = crate::plausibility::range(if c == FLOW { "flow_m3_s" } else { "speed_rad_s" });
    let plausible =
        range.map_or(String::new(), |r| format!(" (plausible: {} to {} {})", sig(r.low), sig(r.high), r.unit));
    let expected = format!("a value at which the model's torques, power and stored energy are finite{plausible}");
    Err(CoreError::of(source_of(c), format!("initial {}", COORDINATES[c]), u[c], expected).into())
}

/// A steady initial pump speed beyond ten times the plausible speeds ([`crate::plausibility`]) is
/// refused: the first pump torque is a plausible measured value (the readers check it), so a
/// converter that absorbs it only there has parameters beyond any converter (a blade angle of
/// 89.999999999°), and the solver would fail on the start. The error blames the converter.
fn check_steady_pump_speed(wp: f64, pump_torque_nm: f64) -> TransientResult<()> {
    let limit = 10.0 * crate::plausibility::range("speed_rad_s").map_or(1100.0, |r| r.high);
    if wp.abs() <= limit {
        return Ok(());
    }
    let expected = format!(
        "a steady pump speed below {} rad/s for the first pump torque ({} N·m): the converter absorbs almost no \
         torque; check its parameters against their plausible ranges",
        sig(limit),
        sig(pump_torque_nm)
    );
    Err(CoreError::of(InputSource::Converter, "initial pump_speed_rad_s", wp, expected).into())
}

/// Speeds below which [`steady_point_scaled`] solves at speeds scaled up to this, rad/s.
const STEADY_SCALE_RAD_S: f64 = 1.0;

/// The model's steady state at (`wp`, `wt`), defined continuously down to standstill.
///
/// A steady state is homogeneous in speed: the speeds and the flow scale with a factor `s`, the
/// torques with `s²` (the table's `CF(SR)·ω_p|ω_p|`, Hrovat & Tobler's `q ∝ ω_p`). So below
/// `STEADY_SCALE_RAD_S` the state is solved at the speeds scaled to it and scaled back (a speed
/// ratio of two tiny speeds is as well-conditioned as of two large ones), and at rest (both
/// speeds exactly 0) it is the limit of that scaling, all zero, whatever the model.
pub fn steady_point_scaled(model: &dyn ConverterDynamics, wp: f64, wt: f64) -> CoreResult<SteadyPoint> {
    let s = wp.abs().max(wt.abs());
    if s == 0.0 {
        return Ok(SteadyPoint { u: [0.0; 4], pump_torque_nm: 0.0 });
    }
    if s.is_nan() || s >= STEADY_SCALE_RAD_S {
        return model.steady_point(wp, wt);
    }
    let k = STEADY_SCALE_RAD_S / s;
    let p = model.steady_point(wp * k, wt * k)?;
    let mut u = p.u.map(|x| x / k);
    u[PUMP] = wp;
    u[TURBINE] = wt;
    Ok(SteadyPoint { u, pump_torque_nm: p.pump_torque_nm / (k * k) })
}

/// How far below zero a first turbine speed may lie and still count as a standstill, rad/s: the
/// rounding of a held turbine in a simulated log (a launch's brake hold leaves about −1e-13 rad/s),
/// far below any sensor's resolution (1e-9 rad/s is 1e-8 rpm).
pub const STANDSTILL_ROUNDING_RAD_S: f64 = 1e-9;

/// The pump speed at which the steady-state pump torque equals `pump_torque_nm` at turbine
/// speed `wt` ≥ 0 (≥ −[`STANDSTILL_ROUNDING_RAD_S`], taken as 0; from the input `wt_source`).
///
/// With `C(SR)` the steady pump torque at a pump speed of 1 rad/s (homogeneity: `T_p = C(SR)·ω_p²`),
/// the speed ratio solves `SR·√T_p = ω_t·√C(SR)`, whose left side rises and right side falls with
/// SR on [0, 1]: bisection from SR = 0, so that any tiny turbine speed (1e-13 rad/s) converges to
/// the stall solution continuously, and a pump at rest (`T_p = 0`, `ω_t = 0`) gives `ω_p = 0`.
fn steady_pump_speed(
    model: &dyn ConverterDynamics,
    pump_torque_nm: f64,
    wt: f64,
    wt_source: InputSource,
) -> TransientResult<f64> {
    let bad = |expected: &str| {
        TransientError::Input(CoreError::of(
            InputSource::Drive,
            "initial pump_torque_nm",
            pump_torque_nm,
            expected.to_string(),
        ))
    };
    if pump_torque_nm == 0.0 && wt == 0.0 {
        return Ok(0.0); // at rest: the converter stands still with no torque on it
    }
    if !pump_torque_nm.is_finite() || pump_torque_nm <= 0.0 {
        return Err(bad(
            "a positive pump torque at the start for a steady initial state (or zero with the turbine at rest); give \
             the initial pump speed explicitly",
        ));
    }
    if wt < -STANDSTILL_ROUNDING_RAD_S {
        return Err(CoreError::of(
            wt_source,
            "initial turbine_speed_rad_s",
            wt,
            "a turbine speed of zero or more at the start for a steady initial state; give the initial pump speed explicitly",
        )
        .into());
    }
    // a failure of the steady state itself: no steady state at this turbine speed
    let unit_torque = |sr: f64| {
        model.steady_point(1.0, sr).map(|p| p.pump_torque_nm).map_err(|e| {
            TransientError::from(CoreError::of(
                wt_source,
                format!("initial {}", e.field),
                e.value,
                format!("{}; give the initial pump speed explicitly", e.expected),
            ))
        })
    };
    let wt = wt.max(0.0); // a standstill's rounding below zero is the standstill
    let root_tp = pump_torque_nm.sqrt();
    let h = |sr: f64| -> TransientResult<f64> { Ok(sr * root_tp - wt * unit_torque(sr)?.max(0.0).sqrt()) };
    let sr = if wt == 0.0 {
        0.0
    } else {
        if h(1.0)? <= 0.0 {
            return Err(bad("a pump torque above the steady torque at SR = 1 for the first turbine speed (the start is in overrun); give the initial pump speed explicitly"));
        }
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        for _ in 0..2200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi || hi - lo <= 1e-15 * hi {
                break;
            }
            if h(mid)? < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let c = unit_torque(sr)?;
    let wp = if c > 0.0 { (pump_torque_nm / c).sqrt() } else { wt / sr };
    if !wp.is_finite() {
        return Err(bad(
            "a pump torque for which the steady pump speed is finite; give the initial pump speed explicitly",
        ));
    }
    Ok(wp)
}

/// Run `model` under `drive`, sampled at `times_s` (sorted, the first is the start time).
pub fn simulate(
    model: &dyn ConverterDynamics,
    drive: &Drive,
    times_s: &[f64],
    init: &InitialState,
    options: &SolverOptions,
) -> TransientResult<Trajectory> {
    check_times(times_s, true)?;
    let t0 = times_s[0];
    let u0 = initial_state(model, drive, t0, init)?;
    let mode = initial_mode(model, drive, &u0, t0);
    simulate_from(model, drive, times_s, u0, mode, options)
}

/// At least two finite, increasing output times; a run's own (`resolution`) also no closer than the
/// time resolution ([`crate::engine::signal::check_time_stamps`]), which internal runs such as the
/// co-simulation stepper's probe need not be.
fn check_times(times_s: &[f64], resolution: bool) -> TransientResult<()> {
    if times_s.len() < 2 {
        let n = match times_s.len() {
            1 => "1 time stamp".to_string(),
            n => format!("{n} time stamps"),
        };
        return Err(CoreError::of(InputSource::Drive, "time_s", n, "at least two").into());
    }
    if resolution {
        return crate::engine::signal::check_time_stamps("time_s", times_s)
            .map_err(|e| e.about(InputSource::Drive).into());
    }
    // one pass without a branch per time when they pass (`simulate` checked them already); the
    // passes below name the first fault
    let mut ok = times_s[0].is_finite();
    for i in 1..times_s.len() {
        ok &= times_s[i].is_finite() & (times_s[i] > times_s[i - 1]);
    }
    if ok {
        return Ok(());
    }
    if let Some(i) = times_s.iter().position(|t| !t.is_finite()) {
        return Err(CoreError::of(InputSource::Drive, format!("time_s[{i}]"), times_s[i], "finite times").into());
    }
    if let Some(i) = (1..times_s.len()).find(|&i| times_s[i] <= times_s[i - 1]) {
        let expected = "strictly increasing times";
        return Err(CoreError::of(InputSource::Drive, format!("time_s[{i}]"), times_s[i], expected).into());
    }
    Ok(())
}

/// Run from a given state and mode.
pub fn simulate_from(
    model: &dyn ConverterDynamics,
    drive: &Drive,
    times_s: &[f64],
    u0: Vec4,
    mode0: Mode,
    options: &SolverOptions,
) -> TransientResult<Trajectory> {
    check_times(times_s, false)?;
    let t_end = *times_s.last().unwrap_or(&0.0);
    let mut traj = Trajectory::default();
    crate::engine::options::try_reserve(&mut traj.samples, times_s.len())?;
    let (mut t, mut u, mut mode) = (times_s[0], u0, mode0);
    let mut lock_energy_j = (0.0, 0.0);
    let stops = drive.breakpoints();
    loop {
        let mut seg = Segment::new(model, drive, mode).sampling(options.sampled);
        seg.lock_energy_j = lock_energy_j;
        let integrated = t < t_end;
        match run_segment(&seg, &u, t, t_end, &stops, times_s, options, &mut traj)? {
            None => {
                if traj.samples.len() < times_s.len() {
                    let t_last = traj.samples.last().map_or(times_s[0], |s| s.time_s);
                    return Err(TransientError::Solver {
                        time_s: t_last,
                        state: named_state(Some(model), &u),
                        message: format!(
                            "the solver stopped before the last output time ({} of {} samples)",
                            traj.samples.len(),
                            times_s.len()
                        ),
                    });
                }
                traj.end_state = match traj.samples.last() {
                    Some(s) if integrated => s.u,
                    _ => u,
                };
                traj.end_mode = mode;
                return Ok(traj);
            }
            Some((t_root, root, x_root)) => {
                let mut next = seg.full(&x_root, t_root);
                let before = next;
                let (kind, new_mode) = switch(&seg, root, &mut next, t_root);
                if kind == EventKind::LockupLock {
                    // the projection removes the energy of the closing slip: the clutch's loss
                    let (loss, work) = lock_energies(&seg, &before, &next);
                    lock_energy_j = (lock_energy_j.0 + loss, lock_energy_j.1 + work);
                }
                traj.events.push(Event { time_s: t_root, kind, mode: new_mode });
                if traj.events.len() > options.max_events {
                    return Err(TransientError::Solver {
                        time_s: t_root,
                        state: named_state(Some(model), &next),
                        message: format!("more than {} events: the clutch or flow events chatter", options.max_events),
                    });
                }
                t = t_root;
                u = next;
                mode = new_mode;
            }
        }
    }
}

/// Integrate one segment, its steps ending on `stops` (see
/// [`crate::engine::segment::run_segment_with_stops`]).
#[allow(clippy::too_many_arguments)]
fn run_segment(
    seg: &Segment,
    u0: &Vec4,
    t0: f64,
    t_end: f64,
    stops: &[f64],
    times_s: &[f64],
    o: &SolverOptions,
    traj: &mut Trajectory,
) -> TransientResult<Option<(f64, Root, Vec<f64>)>> {
    let (samples, steps) = (&mut traj.samples, &mut traj.steps);
    crate::engine::segment::run_segment_with_stops(seg, seg.state(u0), t0, t_end, stops, times_s, o, samples, steps)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one pass of [`check_times`] over times that pass lets no fault through: a NaN, an
    /// infinite or a repeated time at the first, a middle or the last output time is refused,
    /// naming that time as the passes after it do.
    #[test]
    fn the_one_pass_over_output_times_lets_no_fault_through() {
        let good: Vec<f64> = (0..6).map(|k| 0.5 * k as f64).collect();
        assert!(check_times(&good, false).is_ok());
        for i in 0..good.len() {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, good[i.max(1) - 1]] {
                if i == 0 && bad.is_finite() {
                    continue; // a first time is only refused for not being finite
                }
                let mut t = good.clone();
                t[i] = bad;
                let Err(TransientError::Input(e)) = check_times(&t, false) else { panic!("{t:?} passed") };
                assert_eq!(e.field, format!("time_s[{i}]"), "{t:?}");
            }
        }
    }
}
