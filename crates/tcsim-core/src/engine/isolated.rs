//! The transient engine: a converter model, a way of driving it, and diffsol's BDF solver with
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
//! The free coordinates `x` obey `M_xx ẋ = F_x(u) + T_x(t, u) − M_xz ż(t)`, handed to diffsol in
//! this mass-matrix form with its analytic Jacobian. The external torque on a given or held
//! coordinate is whatever the constraint needs, `T_z = (M u̇ − F)_z`: the turbine torque in drive
//! (a), both torques in drive (b), the stator's holding torque.
//!
//! # Events
//!
//! The system is smooth between events; at an event the engine stops at the root (diffsol's root
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

use crate::converter::dynamics::{ConverterDynamics, Mat4, SteadyPoint, Vec4, FLOW, PUMP, STATOR, TURBINE};
use crate::engine::converter_events::{self, ConverterRoot};
use crate::engine::converter_events::{EventKind, Mode, Sample};
use crate::engine::options::{Hysteresis, SolverOptions, TransientError, TransientResult};
use crate::engine::segment::SmoothSegment;
use crate::engine::signal::Signal;
use crate::error::{sig, CoreError, CoreResult, InputSource};

/// How the converter is driven (issue: drives a, b, c).
#[derive(Debug, Clone)]
pub enum Drive {
    /// (a) Pump torque and turbine speed given (the thesis/VSIM causality): pump speed and
    /// turbine torque come out.
    PumpTorqueTurbineSpeed { pump_torque_nm: Signal, turbine_speed_rad_s: Signal },
    /// (b) Both speeds given: the torques come out.
    Speeds { pump_speed_rad_s: Signal, turbine_speed_rad_s: Signal },
    /// (c) Pump torque given, the turbine loaded by an inertia and a torque: both speeds come out.
    PumpTorqueLoad { pump_torque_nm: Signal, load: TurbineLoad },
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

    fn pump_torque(&self) -> Option<&Signal> {
        match self {
            Drive::PumpTorqueTurbineSpeed { pump_torque_nm, .. } | Drive::PumpTorqueLoad { pump_torque_nm, .. } => {
                Some(pump_torque_nm)
            }
            Drive::Speeds { .. } => None,
        }
    }

    fn load(&self) -> Option<&TurbineLoad> {
        match self {
            Drive::PumpTorqueLoad { load, .. } => Some(load),
            _ => None,
        }
    }

    /// Earliest time at which every signal has a sample.
    pub fn start_time(&self) -> f64 {
        let signals: Vec<&Signal> = match self {
            Drive::PumpTorqueTurbineSpeed { pump_torque_nm, turbine_speed_rad_s } => {
                vec![pump_torque_nm, turbine_speed_rad_s]
            }
            Drive::Speeds { pump_speed_rad_s, turbine_speed_rad_s } => vec![pump_speed_rad_s, turbine_speed_rad_s],
            Drive::PumpTorqueLoad { pump_torque_nm, load } => vec![pump_torque_nm, &load.torque_nm],
        };
        signals.iter().map(|s| s.times()[0]).fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Optional initial values; what is not given comes from the steady state consistent with the
/// first input sample ([`initial_state`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct InitialState {
    pub pump_speed_rad_s: Option<f64>,
    pub turbine_speed_rad_s: Option<f64>,
    pub stator_speed_rad_s: Option<f64>,
    pub flow_m3_s: Option<f64>,
}

/// An event: time, kind and the mode after it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    pub time_s: f64,
    pub kind: EventKind,
    pub mode: Mode,
}

/// The result of a run: samples at the requested times, the events, and solver statistics.
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

#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    Free,
    Given,
    Held,
    Absent,
}

/// One smooth piece of a run: a mode, the roles of the coordinates and the reduced mass matrix.
pub(super) struct Segment<'a> {
    model: &'a dyn ConverterDynamics,
    drive: &'a Drive,
    /// The model's mass matrix.
    mass: Mat4,
    /// The mass matrix of the dynamics (with the load inertia on the turbine in drive c).
    dyn_mass: Mat4,
    mode: Mode,
    role: [Role; 4],
    free: Vec<usize>,
    /// Inverse of `M_xx`.
    inv: Mat4,
    pub(super) roots: Vec<ConverterRoot>,
}

impl<'a> Segment<'a> {
    pub(super) fn new(model: &'a dyn ConverterDynamics, drive: &'a Drive, mode: Mode) -> Self {
        let present = model.coordinates();
        let role: [Role; 4] = std::array::from_fn(|c| {
            if !present[c] {
                Role::Absent
            } else if drive.given(c).is_some() {
                Role::Given
            } else if (c == STATOR && mode.stator_locked) || (c == FLOW && converter_events::flow_held(model, mode)) {
                Role::Held
            } else {
                Role::Free
            }
        });
        let free: Vec<usize> = (0..4).filter(|&c| role[c] == Role::Free).collect();
        let mass = model.mass();
        let mut dyn_mass = mass;
        if let Some(load) = drive.load() {
            dyn_mass[TURBINE][TURBINE] += load.inertia_kg_m2;
        }
        let n = free.len();
        let mut sub = [[0.0; 4]; 4];
        for (i, &r) in free.iter().enumerate() {
            for (j, &c) in free.iter().enumerate() {
                sub[i][j] = dyn_mass[r][c];
            }
        }
        let inv = invert(n, &sub).expect("the reduced mass matrix of a positive-definite M is invertible");
        let roots = converter_events::roots(model, mode);
        Self { model, drive, mass, dyn_mass, mode, role, free, inv, roots }
    }

    /// Number of ODE states (one dummy state when every coordinate is given or held).
    fn n_states(&self) -> usize {
        self.free.len().max(1)
    }

    pub(super) fn full(&self, x: &[f64], t: f64) -> Vec4 {
        let mut u = [0.0; 4];
        for (i, &c) in self.free.iter().enumerate() {
            u[c] = x[i];
        }
        for (c, value) in u.iter_mut().enumerate() {
            if self.role[c] == Role::Given {
                *value = self.drive.given(c).map_or(0.0, |s| s.value(t));
            }
        }
        u
    }

    pub(super) fn state(&self, u: &Vec4) -> Vec<f64> {
        if self.free.is_empty() {
            vec![0.0]
        } else {
            self.free.iter().map(|&c| u[c]).collect()
        }
    }

    fn given_rates(&self, t: f64) -> Vec4 {
        std::array::from_fn(|c| {
            if self.role[c] == Role::Given {
                self.drive.given(c).map_or(0.0, |s| s.rate(t))
            } else {
                0.0
            }
        })
    }

    /// External torques acting on the free coordinates, and their derivative with respect to ω_t.
    fn external(&self, u: &Vec4, t: f64) -> (Vec4, f64) {
        let mut e = [0.0; 4];
        let mut de_dwt = 0.0;
        if self.role[PUMP] == Role::Free {
            e[PUMP] = self.drive.pump_torque().map_or(0.0, |s| s.value(t));
        }
        if let (Some(load), Role::Free) = (self.drive.load(), self.role[TURBINE]) {
            let w = u[TURBINE];
            e[TURBINE] = -(load.torque_nm.value(t) + load.drag_nm_s2 * w * w.abs());
            de_dwt = -2.0 * load.drag_nm_s2 * w.abs();
        }
        (e, de_dwt)
    }

    /// Right-hand side of the reduced system, `F_x + T_x − M_xz ż`, given `u` and `f = F(u)`.
    fn reduced_rhs(&self, u: &Vec4, f: &Vec4, t: f64, out: &mut [f64]) {
        let (e, _) = self.external(u, t);
        let zd = self.given_rates(t);
        for (i, &r) in self.free.iter().enumerate() {
            let coupling: f64 = (0..4).map(|c| self.dyn_mass[r][c] * zd[c]).sum();
            out[i] = f[r] + e[r] - coupling;
        }
    }

    fn rhs(&self, x: &[f64], t: f64, out: &mut [f64]) {
        if self.free.is_empty() {
            out[0] = 0.0;
            return;
        }
        let u = self.full(x, t);
        let f = self.model.forces(&u, self.mode.flow_sign);
        self.reduced_rhs(&u, &f, t, out);
    }

    fn jacobian_times(&self, x: &[f64], t: f64, v: &[f64], out: &mut [f64]) {
        if self.free.is_empty() {
            out[0] = 0.0;
            return;
        }
        let u = self.full(x, t);
        let j = self.model.force_jacobian(&u, self.mode.flow_sign);
        let (_, de_dwt) = self.external(&u, t);
        for (i, &r) in self.free.iter().enumerate() {
            out[i] = self
                .free
                .iter()
                .enumerate()
                .map(|(k, &c)| (j[r][c] + if r == TURBINE && c == TURBINE { de_dwt } else { 0.0 }) * v[k])
                .sum();
        }
    }

    fn mass_times(&self, v: &[f64], beta: f64, y: &mut [f64]) {
        if self.free.is_empty() {
            y[0] = v[0] + beta * y[0];
            return;
        }
        for (i, &r) in self.free.iter().enumerate() {
            let mv: f64 = self.free.iter().enumerate().map(|(k, &c)| self.dyn_mass[r][c] * v[k]).sum();
            y[i] = mv + beta * y[i];
        }
    }

    /// All coordinates, their rates and the forces at (x, t).
    pub(super) fn kinematics(&self, x: &[f64], t: f64) -> (Vec4, Vec4, Vec4) {
        let u = self.full(x, t);
        let f = self.model.forces(&u, self.mode.flow_sign);
        let mut ud = self.given_rates(t);
        let n = self.free.len();
        if n > 0 {
            let mut r = [0.0; 4];
            self.reduced_rhs(&u, &f, t, &mut r[..n]);
            for (i, &c) in self.free.iter().enumerate() {
                ud[c] = (0..n).map(|k| self.inv[i][k] * r[k]).sum();
            }
        }
        (u, ud, f)
    }

    /// `M u̇ − F` with the converter's own mass: the external torque on every coordinate.
    fn external_torques(&self, ud: &Vec4, f: &Vec4) -> Vec4 {
        converter_events::external_torques(&self.mass, ud, f)
    }

    /// The net force on a held flow starting forwards and backwards, `d± = F_Q(0±) − (M u̇)_Q`.
    fn held_flow_balance(&self, u: &Vec4, ud: &Vec4) -> (f64, f64) {
        converter_events::held_flow_balance(self.model, u, &self.mass[FLOW], ud)
    }

    /// Root functions, each positive while the mode holds (with the hysteresis `h`).
    pub(super) fn root_values(&self, x: &[f64], t: f64, h: &Hysteresis, out: &mut [f64]) {
        let (u, ud, f) = self.kinematics(x, t);
        for (k, root) in self.roots.iter().enumerate() {
            out[k] = converter_events::root_value(
                *root,
                self.mode,
                &u,
                h,
                || self.external_torques(&ud, &f)[STATOR],
                || self.held_flow_balance(&u, &ud),
            );
        }
    }

    pub(super) fn sample(&self, x: &[f64], t: f64) -> Sample {
        let (u, ud, f) = self.kinematics(x, t);
        converter_events::sample(self.model, self.mode, t, u, ud, f)
    }

    fn atol(&self, o: &SolverOptions) -> Vec<f64> {
        if self.free.is_empty() {
            return vec![1.0];
        }
        self.free.iter().map(|&c| if c == FLOW { o.flow_atol_m3_s } else { o.speed_atol_rad_s }).collect()
    }
}

/// Inverse of the leading n×n block.
fn invert(n: usize, a: &Mat4) -> Option<Mat4> {
    let block: Vec<Vec<f64>> = a.iter().take(n).map(|row| row[..n].to_vec()).collect();
    let inv = crate::linalg::invert(&block)?;
    let mut out = [[0.0; 4]; 4];
    for (r, row) in inv.iter().enumerate() {
        out[r][..n].copy_from_slice(row);
    }
    Some(out)
}

// ---------------------------------------------------------------------------------------------

/// The mode a state starts in: the stator locked if it stands and the clutch would hold; the flow
/// sign from Q, or from the held-flow balance when Q = 0.
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
    };
    if model.has_flow_sign() && u[FLOW] == 0.0 {
        mode.flow_sign = flow_sign_at_zero(model, drive, u, t, mode.stator_locked || u[STATOR] <= 0.0);
    }
    if model.has_stator_clutch() && u[STATOR] <= 0.0 {
        let locked = Mode { stator_locked: true, ..mode };
        let seg = Segment::new(model, drive, locked);
        let (_, ud, f) = seg.kinematics(&seg.state(u), t);
        mode.stator_locked = seg.external_torques(&ud, &f)[STATOR] >= 0.0;
    }
    mode
}

/// Sign of the flow that starts from Q = 0 ([`converter_events::flow_sign_from_balance`]).
fn flow_sign_at_zero(model: &dyn ConverterDynamics, drive: &Drive, u: &Vec4, t: f64, stator_locked: bool) -> f64 {
    let seg = Segment::new(model, drive, Mode { stator_locked, flow_sign: 0.0 });
    let mut u0 = *u;
    u0[FLOW] = 0.0;
    let (uu, ud, _) = seg.kinematics(&seg.state(&u0), t);
    converter_events::flow_sign_from_balance(seg.held_flow_balance(&uu, &ud))
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
/// [`STEADY_SCALE_RAD_S`] the state is solved at the speeds scaled to it and scaled back (a speed
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

/// The pump speed at which the steady-state pump torque equals `pump_torque_nm` at turbine
/// speed `wt` ≥ 0 (from the input `wt_source`).
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
    if wt < 0.0 {
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
        let n = format!("{} samples", times_s.len());
        return Err(CoreError::of(InputSource::Drive, "time_s", n, "at least two output times").into());
    }
    if resolution {
        return crate::engine::signal::check_time_stamps("time_s", times_s)
            .map_err(|e| e.about(InputSource::Drive).into());
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
    loop {
        let seg = Segment::new(model, drive, mode);
        let integrated = t < t_end;
        match run_segment(&seg, &u, t, t_end, times_s, options, &mut traj)? {
            None => {
                if traj.samples.len() < times_s.len() {
                    let t_last = traj.samples.last().map_or(times_s[0], |s| s.time_s);
                    return Err(TransientError::Solver {
                        time_s: t_last,
                        state: u.to_vec(),
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
                let (kind, new_mode) = switch(&seg, root, &mut next, t_root);
                traj.events.push(Event { time_s: t_root, kind, mode: new_mode });
                if traj.events.len() > options.max_events {
                    return Err(TransientError::Solver {
                        time_s: t_root,
                        state: next.to_vec(),
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

/// The mode after `root` fired, with the state adjusted (a locking stator stops, a reversing flow
/// passes zero).
pub(super) fn switch(seg: &Segment, root: ConverterRoot, u: &mut Vec4, t: f64) -> (EventKind, Mode) {
    let mut mode = seg.mode;
    let stator_locked = seg.mode.stator_locked;
    let kind =
        converter_events::switch(root, &mut mode, u, |u| flow_sign_at_zero(seg.model, seg.drive, u, t, stator_locked));
    (kind, mode)
}

impl SmoothSegment for Segment<'_> {
    type Root = ConverterRoot;
    type Sample = Sample;
    fn n_states(&self) -> usize {
        Segment::n_states(self)
    }
    fn atol(&self, o: &SolverOptions) -> Vec<f64> {
        Segment::atol(self, o)
    }
    fn rhs(&self, x: &[f64], t: f64, out: &mut [f64]) {
        Segment::rhs(self, x, t, out)
    }
    fn jacobian_times(&self, x: &[f64], t: f64, v: &[f64], out: &mut [f64]) {
        Segment::jacobian_times(self, x, t, v, out)
    }
    fn mass_times(&self, v: &[f64], beta: f64, y: &mut [f64]) {
        Segment::mass_times(self, v, beta, y)
    }
    fn roots(&self) -> &[ConverterRoot] {
        &self.roots
    }
    fn root_values(&self, x: &[f64], t: f64, h: &Hysteresis, out: &mut [f64]) {
        Segment::root_values(self, x, t, h, out)
    }
    fn sample(&self, x: &[f64], t: f64) -> Sample {
        Segment::sample(self, x, t)
    }
    fn coordinates(&self, x: &[f64], t: f64) -> Vec<f64> {
        self.full(x, t).to_vec()
    }
}

/// Integrate one segment (see [`crate::engine::segment::run_segment`]).
fn run_segment(
    seg: &Segment,
    u0: &Vec4,
    t0: f64,
    t_end: f64,
    times_s: &[f64],
    o: &SolverOptions,
    traj: &mut Trajectory,
) -> TransientResult<Option<(f64, ConverterRoot, Vec<f64>)>> {
    crate::engine::segment::run_segment(seg, seg.state(u0), t0, t_end, times_s, o, &mut traj.samples, &mut traj.steps)
}
