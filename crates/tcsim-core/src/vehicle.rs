//! Whole-vehicle take-off: engine, lock-up clutch, torque converter (any of the three models,
//! unchanged), automatic gearbox with timed shifts, compliant AWD driveline, tyres, body, brake.
//!
//! The plant is written over twelve coordinates, in the same mass-matrix form as the converter
//! models (`M u̇ = F(u, t)`):
//!
//! | index | coordinate | unit |
//! |---|---|---|
//! | 0–3 | ω_p (engine + pump), ω_t (turbine + gearbox input), ω_s, Q | rad/s, m³/s |
//! | 4 | ω_o, gearbox output (propshaft) | rad/s |
//! | 5, 6 | ω_f, ω_r, front and rear axle (wheels) | rad/s |
//! | 7 | v, vehicle speed | m/s |
//! | 8, 9 | θ_f, θ_r, front and rear shaft twist at the propshaft side | rad |
//! | 10, 11 | fast (aspirated) and boost parts of the engine torque | N·m |
//!
//! Modes link or hold coordinates: a gear in mesh links `ω_t = i_k ω_o`, a locked lock-up clutch
//! `ω_p = ω_t`, a held brake holds the axles at zero, and the converter's own modes hold the stator
//! or the flow. The states of a mode are generalised coordinates `x` with `u = P x`; the reduced
//! system `PᵀMP ẋ = PᵀF` goes to diffsol's BDF. When a link closes (lock-up locks, a shift
//! synchronises) the new state is the momentum-conserving projection `(PᵀMP) x = PᵀM u`, and the
//! kinetic energy it removes is booked as a clutch loss, so the energy balance closes exactly.
//! Equations and parameters: docs/vehicle.md.

use crate::dynamics::{ConverterDynamics, Vec4, FLOW, PUMP, STATOR, TURBINE};
use crate::error::{CoreError, CoreResult};
use crate::linalg::invert;
use crate::segment::{run_segment, SmoothSegment};
use crate::signal::Signal;
use crate::transient::{
    Hysteresis, Mode as ConverterMode, Sample as ConverterSample, SolverOptions, TransientError, TransientResult,
};

pub const N: usize = 12;
pub const GEARBOX_OUT: usize = 4;
pub const FRONT: usize = 5;
pub const REAR: usize = 6;
pub const SPEED: usize = 7;
pub const TWIST_F: usize = 8;
pub const TWIST_R: usize = 9;
pub const TORQUE_FAST: usize = 10;
pub const TORQUE_BOOST: usize = 11;

const G: f64 = 9.81;

/// A table `y(x)`, linear between points, ends held.
#[derive(Debug, Clone)]
pub struct Curve {
    x: Vec<f64>,
    y: Vec<f64>,
}

impl Curve {
    pub fn new(name: &str, x: Vec<f64>, y: Vec<f64>) -> CoreResult<Self> {
        if x.len() < 2 || x.len() != y.len() {
            return Err(CoreError::new(
                name,
                format!("{} and {} points", x.len(), y.len()),
                "two or more points, as many values as speeds",
            ));
        }
        if let Some(i) = (1..x.len()).find(|&i| x[i].partial_cmp(&x[i - 1]) != Some(std::cmp::Ordering::Greater)) {
            return Err(CoreError::new(format!("{name}[{i}]"), x[i], "strictly increasing"));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::new(format!("{name}[{i}]"), y[i], "a finite value"));
        }
        Ok(Self { x, y })
    }
    pub fn at(&self, x: f64) -> f64 {
        let n = self.x.len();
        if x <= self.x[0] {
            return self.y[0];
        }
        if x >= self.x[n - 1] {
            return self.y[n - 1];
        }
        let i = self.x.partition_point(|&v| v <= x).clamp(1, n - 1);
        let w = (x - self.x[i - 1]) / (self.x[i] - self.x[i - 1]);
        (1.0 - w) * self.y[i - 1] + w * self.y[i]
    }
}

fn positive(name: &str, v: f64) -> CoreResult<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(CoreError::new(name, v, "a finite, positive value"))
    }
}

fn non_negative(name: &str, v: f64) -> CoreResult<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(CoreError::new(name, v, "a finite value of zero or more"))
    }
}

fn fraction(name: &str, v: f64) -> CoreResult<f64> {
    if v.is_finite() && (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(CoreError::new(name, v, "a fraction from 0 to 1"))
    }
}

/// Engine: full-load curve, pedal, torque build-up in an aspirated and a boost part (thesis §3.3,
/// "time to torque"), idle governor, drag and inertia.
#[derive(Debug, Clone)]
pub struct Engine {
    pub inertia_kg_m2: f64,
    pub idle_speed_rad_s: f64,
    pub full_load: Curve,
    pub drag_torque_nm: f64,
    pub drag_nm_s_per_rad: f64,
    pub fast_time_constant_s: f64,
    pub boost_time_constant_s: f64,
    pub boost_fraction: f64,
    pub idle_governor_gain_nm_s_per_rad: f64,
}

impl Engine {
    pub fn validate(&self) -> CoreResult<()> {
        positive("engine.inertia_kg_m2", self.inertia_kg_m2)?;
        positive("engine.idle_speed_rad_s", self.idle_speed_rad_s)?;
        non_negative("engine.drag_torque_nm", self.drag_torque_nm)?;
        non_negative("engine.drag_nm_s_per_rad", self.drag_nm_s_per_rad)?;
        positive("engine.fast_time_constant_s", self.fast_time_constant_s)?;
        positive("engine.boost_time_constant_s", self.boost_time_constant_s)?;
        fraction("engine.boost_fraction", self.boost_fraction)?;
        non_negative("engine.idle_governor_gain_nm_s_per_rad", self.idle_governor_gain_nm_s_per_rad)?;
        Ok(())
    }
    /// Rev limiter: the full-load torque falls linearly to zero over the 5 % of speed above the
    /// full-load curve's last point.
    pub fn fuel_cut(&self, w: f64) -> f64 {
        let top = self.full_load.x.last().copied().unwrap_or(f64::INFINITY);
        ((1.05 * top - w) / (0.05 * top)).clamp(0.0, 1.0)
    }
    /// Friction and pumping drag, opposing rotation.
    pub fn drag(&self, w: f64) -> f64 {
        self.drag_torque_nm * (w / 1.0).tanh() + self.drag_nm_s_per_rad * w
    }
    /// Targets of the aspirated and boost torque parts for pedal `p` at speed `w`.
    pub fn targets(&self, p: f64, w: f64) -> (f64, f64) {
        let full = self.full_load.at(w).max(0.0) * self.fuel_cut(w);
        let governor = self.idle_governor_gain_nm_s_per_rad * (self.idle_speed_rad_s - w).max(0.0);
        let boost = self.boost_fraction * p * full;
        ((p * full + governor).min(full) - boost, boost)
    }
}

/// Automatic gearbox: ratios, efficiency and input-side inertia per gear, shift schedule by
/// vehicle speed and pedal, shifts of finite duration with torque handover between two clutches.
#[derive(Debug, Clone)]
pub struct Gearbox {
    pub ratios: Vec<f64>,
    pub efficiencies: Vec<f64>,
    pub input_inertia_kg_m2: Vec<f64>,
    pub output_inertia_kg_m2: f64,
    pub shift_clutch_capacity_nm: f64,
    pub shift_handover_s: f64,
    pub upshift_speed_zero_pedal_m_s: Vec<f64>,
    pub upshift_speed_full_pedal_m_s: Vec<f64>,
    pub downshift_speed_zero_pedal_m_s: Vec<f64>,
    pub downshift_speed_full_pedal_m_s: Vec<f64>,
}

impl Gearbox {
    pub fn validate(&self) -> CoreResult<()> {
        let n = self.ratios.len();
        if n == 0 {
            return Err(CoreError::new("gearbox.ratios", "[]", "at least one gear"));
        }
        for (name, v) in
            [("gearbox.efficiencies", &self.efficiencies), ("gearbox.input_inertia_kg_m2", &self.input_inertia_kg_m2)]
        {
            if v.len() != n {
                return Err(CoreError::new(name, format!("{} values", v.len()), format!("{n} values, one per gear")));
            }
        }
        for (name, v) in [
            ("gearbox.upshift_speed_zero_pedal_m_s", &self.upshift_speed_zero_pedal_m_s),
            ("gearbox.upshift_speed_full_pedal_m_s", &self.upshift_speed_full_pedal_m_s),
            ("gearbox.downshift_speed_zero_pedal_m_s", &self.downshift_speed_zero_pedal_m_s),
            ("gearbox.downshift_speed_full_pedal_m_s", &self.downshift_speed_full_pedal_m_s),
        ] {
            if v.len() != n - 1 {
                return Err(CoreError::new(
                    name,
                    format!("{} values", v.len()),
                    format!("{} values, one per shift", n - 1),
                ));
            }
            for (i, &x) in v.iter().enumerate() {
                positive(&format!("{name}[{i}]"), x)?;
            }
        }
        for i in 0..n {
            positive(&format!("gearbox.ratios[{i}]"), self.ratios[i])?;
            let e = self.efficiencies[i];
            if !(e.is_finite() && e > 0.0 && e <= 1.0) {
                return Err(CoreError::new(format!("gearbox.efficiencies[{i}]"), e, "an efficiency in (0, 1]"));
            }
            non_negative(&format!("gearbox.input_inertia_kg_m2[{i}]"), self.input_inertia_kg_m2[i])?;
        }
        for i in 0..n - 1 {
            for (lo, hi, name) in [
                (
                    self.downshift_speed_zero_pedal_m_s[i],
                    self.upshift_speed_zero_pedal_m_s[i],
                    "gearbox.downshift_speed_zero_pedal_m_s",
                ),
                (
                    self.downshift_speed_full_pedal_m_s[i],
                    self.upshift_speed_full_pedal_m_s[i],
                    "gearbox.downshift_speed_full_pedal_m_s",
                ),
            ] {
                if lo >= hi {
                    return Err(CoreError::new(
                        format!("{name}[{i}]"),
                        lo,
                        format!("below the upshift speed {hi} m/s (hysteresis)"),
                    ));
                }
            }
        }
        positive("gearbox.output_inertia_kg_m2", self.output_inertia_kg_m2)?;
        positive("gearbox.shift_clutch_capacity_nm", self.shift_clutch_capacity_nm)?;
        positive("gearbox.shift_handover_s", self.shift_handover_s)?;
        Ok(())
    }
    fn lerp(zero: &[f64], full: &[f64], k: usize, p: f64) -> f64 {
        zero[k] + p.clamp(0.0, 1.0) * (full[k] - zero[k])
    }
    /// Vehicle speed of the upshift from gear `k` (0-based) at pedal `p`.
    pub fn upshift_speed(&self, k: usize, p: f64) -> f64 {
        Self::lerp(&self.upshift_speed_zero_pedal_m_s, &self.upshift_speed_full_pedal_m_s, k, p)
    }
    /// Vehicle speed of the downshift from gear `k` ≥ 1 to `k − 1` at pedal `p`.
    pub fn downshift_speed(&self, k: usize, p: f64) -> f64 {
        Self::lerp(&self.downshift_speed_zero_pedal_m_s, &self.downshift_speed_full_pedal_m_s, k - 1, p)
    }
}

/// Lock-up clutch: kinetic torque capacity ramped in over `engage_time_s` once scheduled (gear and
/// speed), locked when the slip closes, released when the torque through it exceeds the static
/// capacity.
#[derive(Debug, Clone)]
pub struct Lockup {
    pub capacity_nm: f64,
    pub static_to_kinetic: f64,
    pub engage_time_s: f64,
    pub min_gear: usize,
    pub engage_speed_zero_pedal_m_s: f64,
    pub engage_speed_full_pedal_m_s: f64,
}

impl Lockup {
    pub fn validate(&self) -> CoreResult<()> {
        positive("lockup.capacity_nm", self.capacity_nm)?;
        if !(self.static_to_kinetic.is_finite() && self.static_to_kinetic >= 1.0) {
            return Err(CoreError::new("lockup.static_to_kinetic", self.static_to_kinetic, "a ratio of 1 or more"));
        }
        positive("lockup.engage_time_s", self.engage_time_s)?;
        positive("lockup.engage_speed_zero_pedal_m_s", self.engage_speed_zero_pedal_m_s)?;
        positive("lockup.engage_speed_full_pedal_m_s", self.engage_speed_full_pedal_m_s)?;
        if self.min_gear < 1 {
            return Err(CoreError::new("lockup.min_gear", self.min_gear, "a gear number of 1 or more"));
        }
        Ok(())
    }
    pub fn engage_speed(&self, p: f64) -> f64 {
        self.engage_speed_zero_pedal_m_s
            + p.clamp(0.0, 1.0) * (self.engage_speed_full_pedal_m_s - self.engage_speed_zero_pedal_m_s)
    }
}

/// Compliant AWD driveline: final drive on both axles, front and rear shafts with torsional
/// stiffness and damping (thesis §4.3.1), axle inertias.
#[derive(Debug, Clone)]
pub struct Driveline {
    pub final_drive_ratio: f64,
    pub shaft_stiffness_nm_per_rad: [f64; 2],
    pub shaft_damping_nm_s_per_rad: [f64; 2],
    pub axle_inertia_kg_m2: [f64; 2],
}

/// Tyres: longitudinal slip with a saturating force, `F = μF_z tanh(Cκ/μ)`,
/// `κ = (rω − v)/√(v² + v₀²)` (v₀ regularises standstill).
#[derive(Debug, Clone)]
pub struct Tyres {
    pub rolling_radius_m: f64,
    pub friction_coefficient: f64,
    pub slip_stiffness: f64,
    pub front_load_fraction: f64,
}

/// Speed below which the slip is regularised, m/s.
pub const SLIP_SPEED_M_S: f64 = 0.5;

#[derive(Debug, Clone)]
pub struct Body {
    pub mass_kg: f64,
    pub drag_area_m2: f64,
    pub rolling_resistance: f64,
    pub air_density_kg_m3: f64,
    pub grade_percent: f64,
}

#[derive(Debug, Clone)]
pub struct Brake {
    pub capacity_nm: f64,
    pub front_fraction: f64,
}

/// The vehicle around the converter.
#[derive(Debug, Clone)]
pub struct Vehicle {
    pub engine: Engine,
    pub gearbox: Gearbox,
    pub lockup: Lockup,
    pub driveline: Driveline,
    pub tyres: Tyres,
    pub body: Body,
    pub brake: Brake,
}

impl Vehicle {
    pub fn validate(&self) -> CoreResult<()> {
        self.engine.validate()?;
        self.gearbox.validate()?;
        self.lockup.validate()?;
        let d = &self.driveline;
        positive("driveline.final_drive_ratio", d.final_drive_ratio)?;
        for (i, axle) in ["front", "rear"].iter().enumerate() {
            positive(&format!("driveline.{axle}_shaft_stiffness_nm_per_rad"), d.shaft_stiffness_nm_per_rad[i])?;
            non_negative(&format!("driveline.{axle}_shaft_damping_nm_s_per_rad"), d.shaft_damping_nm_s_per_rad[i])?;
            positive(&format!("driveline.{axle}_axle_inertia_kg_m2"), d.axle_inertia_kg_m2[i])?;
        }
        positive("tyres.rolling_radius_m", self.tyres.rolling_radius_m)?;
        positive("tyres.friction_coefficient", self.tyres.friction_coefficient)?;
        positive("tyres.slip_stiffness", self.tyres.slip_stiffness)?;
        fraction("tyres.front_load_fraction", self.tyres.front_load_fraction)?;
        positive("body.mass_kg", self.body.mass_kg)?;
        non_negative("body.drag_area_m2", self.body.drag_area_m2)?;
        non_negative("body.rolling_resistance", self.body.rolling_resistance)?;
        non_negative("body.air_density_kg_m3", self.body.air_density_kg_m3)?;
        if !self.body.grade_percent.is_finite() || self.body.grade_percent.abs() > 50.0 {
            return Err(CoreError::new("body.grade_percent", self.body.grade_percent, "a grade from −50 to 50 %"));
        }
        non_negative("brake.capacity_nm", self.brake.capacity_nm)?;
        fraction("brake.front_fraction", self.brake.front_fraction)?;
        Ok(())
    }
    fn grade(&self) -> (f64, f64) {
        let a = (self.body.grade_percent / 100.0).atan();
        (a.sin(), a.cos())
    }
}

/// Pedal and brake against time; the run ends at `end_time_s` or when the vehicle reaches
/// `stop_speed_m_s`.
#[derive(Debug, Clone)]
pub struct Scenario {
    pub accelerator_pedal: Signal,
    pub brake_pedal: Signal,
    pub end_time_s: f64,
    pub stop_speed_m_s: Option<f64>,
    /// A logged engine (crank) torque replayed instead of the engine model, as the thesis did in
    /// its complete-vehicle simulation (§3.5.2.2). The pedal then only drives the shift and lock-up
    /// schedules.
    pub engine_torque_nm: Option<Signal>,
}

impl Scenario {
    /// Net crank torque, the engine's (indicated) power and its drag loss at `u`, `t`.
    fn engine(&self, e: &Engine, u: &[f64; N], t: f64) -> (f64, f64, f64) {
        let w = u[PUMP];
        match &self.engine_torque_nm {
            Some(log) => {
                let torque = log.value(t);
                (torque, torque * w, 0.0)
            }
            None => {
                let drag = e.drag(w);
                let indicated = u[TORQUE_FAST] + u[TORQUE_BOOST];
                (indicated - drag, indicated * w, drag * w)
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Modes

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

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shift {
    pub from: usize,
    pub to: usize,
    pub since_s: f64,
    /// The torque handover is over: the on-coming clutch has its full capacity.
    pub handed_over: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleMode {
    pub converter: ConverterMode,
    /// Gear in mesh (0-based); during a shift, the off-going gear.
    pub gear: usize,
    pub shift: Option<Shift>,
    pub lockup: LockupState,
    pub wheels_held: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Root {
    StatorTorque,
    StatorSpeed,
    Flow,
    FlowStartsPositive,
    FlowStartsNegative,
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

/// Slip scale of the regularised clutch friction (tanh), rad/s.
const CLUTCH_SLIP_RAD_S: f64 = 0.2;
/// Slip below which a synchronising clutch locks, rad/s: with the regularised friction a clutch
/// carrying 96 % of its capacity slips by 2·CLUTCH_SLIP_RAD_S, so a smaller slip means it holds.
const SYNC_SLIP_RAD_S: f64 = 0.5;
/// Scale of the regularised brake and drag signs, rad/s and m/s.
const BRAKE_SPEED_RAD_S: f64 = 0.002;
/// After a breakaway the lock-up clutch slips at least this long before it may lock again, s.
const REARM_DELAY_S: f64 = 0.1;
/// The lock-up clutch opens below this fraction of its engage speed (hysteresis), and on a
/// downshift.
const LOCKUP_RELEASE_FRACTION: f64 = 0.7;
/// Axle and wheel-rim speed below which a braked axle is held (exact standstill), rad/s.
const HOLD_SPEED_RAD_S: f64 = 0.005;
const ROLL_SPEED_M_S: f64 = 0.01;

// ---------------------------------------------------------------------------------------------
// The plant in one mode

struct Plant<'a> {
    model: &'a dyn ConverterDynamics,
    v: &'a Vehicle,
    sc: &'a Scenario,
    mode: VehicleMode,
    /// Full mass matrix of the mode (per-gear inertia).
    mass: [[f64; N]; N],
    /// `u_c = factor·x[column]` for linked coordinates, None for held ones.
    rep: [Option<(usize, f64)>; N],
    n: usize,
    /// `PᵀMP`.
    reduced_mass: Vec<Vec<f64>>,
    reduced_inv: Vec<Vec<f64>>,
    roots: Vec<Root>,
    /// Sign of the synchronising slip at the start of a shift or an engagement.
    sync_sign: f64,
}

/// Terms of the power balance at one instant.
#[derive(Debug, Clone, Copy, Default)]
struct Powers {
    engine_w: f64,
    loss_w: f64,
}

impl<'a> Plant<'a> {
    fn new(
        model: &'a dyn ConverterDynamics,
        v: &'a Vehicle,
        sc: &'a Scenario,
        mode: VehicleMode,
        sync_sign: f64,
    ) -> Self {
        let present = model.coordinates();
        let conv_mass = model.mass();
        let mut mass = [[0.0; N]; N];
        for r in 0..4 {
            for c in 0..4 {
                mass[r][c] = conv_mass[r][c];
            }
        }
        let gear_inertia = match mode.shift {
            Some(s) => v.gearbox.input_inertia_kg_m2[s.from],
            None => v.gearbox.input_inertia_kg_m2[mode.gear],
        };
        mass[PUMP][PUMP] += v.engine.inertia_kg_m2;
        mass[TURBINE][TURBINE] += gear_inertia;
        mass[GEARBOX_OUT][GEARBOX_OUT] = v.gearbox.output_inertia_kg_m2;
        mass[FRONT][FRONT] = v.driveline.axle_inertia_kg_m2[0];
        mass[REAR][REAR] = v.driveline.axle_inertia_kg_m2[1];
        mass[SPEED][SPEED] = v.body.mass_kg;
        for c in [TWIST_F, TWIST_R, TORQUE_FAST, TORQUE_BOOST] {
            mass[c][c] = 1.0;
        }
        // generalised coordinates
        let mut rep: [Option<(usize, f64)>; N] = [None; N];
        let mut n = 0;
        let mut own = |rep: &mut [Option<(usize, f64)>; N], c: usize| {
            rep[c] = Some((n, 1.0));
            n += 1;
        };
        own(&mut rep, GEARBOX_OUT);
        if mode.shift.is_some() {
            own(&mut rep, TURBINE);
        } else {
            rep[TURBINE] = rep[GEARBOX_OUT].map(|(col, f)| (col, f * v.gearbox.ratios[mode.gear]));
        }
        if mode.lockup == LockupState::Locked {
            rep[PUMP] = rep[TURBINE];
        } else {
            own(&mut rep, PUMP);
        }
        if present[STATOR] && !mode.converter.stator_locked {
            own(&mut rep, STATOR);
        }
        if present[FLOW] && !(model.has_flow_sign() && mode.converter.flow_sign == 0.0) {
            own(&mut rep, FLOW);
        }
        if !mode.wheels_held {
            own(&mut rep, FRONT);
            own(&mut rep, REAR);
        }
        for c in [SPEED, TWIST_F, TWIST_R, TORQUE_FAST, TORQUE_BOOST] {
            own(&mut rep, c);
        }
        let mut reduced_mass = vec![vec![0.0; n]; n];
        for r in 0..N {
            for c in 0..N {
                if let (Some((a, fa)), Some((b, fb))) = (rep[r], rep[c]) {
                    reduced_mass[a][b] += fa * mass[r][c] * fb;
                }
            }
        }
        let reduced_inv =
            invert(&reduced_mass).expect("the reduced mass matrix of a positive-definite M is invertible");
        let mut roots = Vec::new();
        if model.has_stator_clutch() {
            roots.push(if mode.converter.stator_locked { Root::StatorTorque } else { Root::StatorSpeed });
        }
        if model.has_flow_sign() {
            if mode.converter.flow_sign == 0.0 {
                roots.extend([Root::FlowStartsPositive, Root::FlowStartsNegative]);
            } else {
                roots.push(Root::Flow);
            }
        }
        roots.push(if mode.wheels_held { Root::BrakeRelease } else { Root::BrakeHold });
        match mode.shift {
            Some(s) => roots.push(if s.handed_over { Root::ShiftSync } else { Root::ShiftHandover }),
            None => {
                if mode.gear + 1 < v.gearbox.ratios.len() {
                    roots.push(Root::Upshift);
                }
                if mode.gear > 0 {
                    roots.push(Root::Downshift);
                }
            }
        }
        match mode.lockup {
            LockupState::Open if mode.gear + 1 >= v.lockup.min_gear && mode.shift.is_none() => {
                roots.push(Root::LockupEngage)
            }
            LockupState::Engaging { ramped: false, .. } => roots.push(Root::LockupRamped),
            LockupState::Engaging { armed: false, .. } => roots.push(Root::LockupArm),
            LockupState::Engaging { .. } => roots.push(Root::LockupLock),
            LockupState::Locked => roots.push(Root::LockupSlip),
            _ => {}
        }
        if mode.lockup != LockupState::Open {
            roots.push(Root::LockupRelease);
        }
        if sc.stop_speed_m_s.is_some() {
            roots.push(Root::Stop);
        }
        Self { model, v, sc, mode, mass, rep, n, reduced_mass, reduced_inv, roots, sync_sign }
    }

    fn full(&self, x: &[f64]) -> [f64; N] {
        std::array::from_fn(|c| self.rep[c].map_or(0.0, |(col, f)| f * x[col]))
    }

    fn state_of(&self, u: &[f64; N]) -> Vec<f64> {
        // momentum-conserving projection: (PᵀMP) x = PᵀM u
        let mut b = vec![0.0; self.n];
        for r in 0..N {
            if let Some((a, fa)) = self.rep[r] {
                b[a] += fa * (0..N).map(|c| self.mass[r][c] * u[c]).sum::<f64>();
            }
        }
        (0..self.n).map(|i| (0..self.n).map(|k| self.reduced_inv[i][k] * b[k]).sum()).collect()
    }

    fn lockup_capacity(&self, t: f64) -> f64 {
        match self.mode.lockup {
            LockupState::Engaging { since_s, .. } => {
                self.v.lockup.capacity_nm * ((t - since_s) / self.v.lockup.engage_time_s).clamp(0.0, 1.0)
            }
            _ => 0.0,
        }
    }

    fn shift_capacities(&self, t: f64) -> (f64, f64) {
        match self.mode.shift {
            Some(s) => {
                let w = ((t - s.since_s) / self.v.gearbox.shift_handover_s).clamp(0.0, 1.0);
                let c = self.v.gearbox.shift_clutch_capacity_nm;
                (c * (1.0 - w), c * w)
            }
            None => (0.0, 0.0),
        }
    }

    /// Forces `F(u, t)` and the power terms.
    fn forces(&self, u: &[f64; N], t: f64) -> ([f64; N], Powers) {
        let v = self.v;
        let mut f = [0.0; N];
        let mut loss = 0.0;
        let uc: Vec4 = [u[0], u[1], u[2], u[3]];
        let fc = self.model.forces(&uc, self.mode.converter.flow_sign);
        f[..4].copy_from_slice(&fc);
        if !(self.model.has_flow_sign() && self.mode.converter.flow_sign == 0.0) {
            loss += self.model.loss_power_w(&uc, &fc);
        }
        // engine
        let wp = u[PUMP];
        let p = self.sc.accelerator_pedal.value(t);
        let (net, engine_power, drag_loss) = self.sc.engine(&v.engine, u, t);
        f[PUMP] += net;
        loss += drag_loss;
        let (fast, boost) = v.engine.targets(p, wp);
        f[TORQUE_FAST] = (fast - u[TORQUE_FAST]) / v.engine.fast_time_constant_s;
        f[TORQUE_BOOST] = (boost - u[TORQUE_BOOST]) / v.engine.boost_time_constant_s;
        // lock-up clutch while it slips
        let slip = u[PUMP] - u[TURBINE];
        let t_lu = self.lockup_capacity(t) * (slip / CLUTCH_SLIP_RAD_S).tanh();
        f[PUMP] -= t_lu;
        f[TURBINE] += t_lu;
        loss += t_lu * slip;
        // gearbox
        let gb = &v.gearbox;
        match self.mode.shift {
            None => {
                let k = self.mode.gear;
                let input = if self.mode.lockup == LockupState::Locked { net } else { fc[TURBINE] + t_lu };
                let t_loss = (1.0 - gb.efficiencies[k]) * input.max(0.0) * (u[TURBINE] / 1.0).tanh();
                f[TURBINE] -= t_loss;
                loss += t_loss * u[TURBINE];
            }
            Some(s) => {
                let (c_off, c_on) = self.shift_capacities(t);
                let s_off = u[TURBINE] - gb.ratios[s.from] * u[GEARBOX_OUT];
                let s_on = u[TURBINE] - gb.ratios[s.to] * u[GEARBOX_OUT];
                let t_off = c_off * (s_off / CLUTCH_SLIP_RAD_S).tanh();
                let t_on = c_on * (s_on / CLUTCH_SLIP_RAD_S).tanh();
                f[TURBINE] -= t_off + t_on;
                f[GEARBOX_OUT] += gb.ratios[s.from] * t_off + gb.ratios[s.to] * t_on;
                loss += t_off * s_off + t_on * s_on;
            }
        }
        // driveline shafts
        let d = &v.driveline;
        for (axle, twist, i) in [(FRONT, TWIST_F, 0), (REAR, TWIST_R, 1)] {
            let rate = u[GEARBOX_OUT] - d.final_drive_ratio * u[axle];
            let torque = d.shaft_stiffness_nm_per_rad[i] * u[twist] + d.shaft_damping_nm_s_per_rad[i] * rate;
            f[twist] = rate;
            f[GEARBOX_OUT] -= torque;
            f[axle] += d.final_drive_ratio * torque;
            loss += d.shaft_damping_nm_s_per_rad[i] * rate * rate;
        }
        // tyres, brake, body
        let ty = &v.tyres;
        let (sin_g, cos_g) = v.grade();
        let weight = v.body.mass_kg * G * cos_g;
        let brake = self.sc.brake_pedal.value(t).clamp(0.0, 1.0) * v.brake.capacity_nm;
        let vs = u[SPEED];
        for (axle, load, share) in [
            (FRONT, ty.front_load_fraction, v.brake.front_fraction),
            (REAR, 1.0 - ty.front_load_fraction, 1.0 - v.brake.front_fraction),
        ] {
            let slip_speed = ty.rolling_radius_m * u[axle] - vs;
            let kappa = slip_speed / (vs * vs + SLIP_SPEED_M_S * SLIP_SPEED_M_S).sqrt();
            let mu = ty.friction_coefficient;
            let force = mu * load * weight * (ty.slip_stiffness * kappa / mu).tanh();
            f[axle] -= ty.rolling_radius_m * force;
            f[SPEED] += force;
            loss += force * slip_speed;
            if !self.mode.wheels_held {
                let t_b = brake * share * (u[axle] / BRAKE_SPEED_RAD_S).tanh();
                f[axle] -= t_b;
                loss += t_b * u[axle];
            }
        }
        let aero = 0.5 * v.body.air_density_kg_m3 * v.body.drag_area_m2 * vs * vs.abs();
        let roll = v.body.rolling_resistance * weight * (vs / ROLL_SPEED_M_S).tanh();
        let climb = v.body.mass_kg * G * sin_g;
        f[SPEED] -= aero + roll + climb;
        loss += (aero + roll + climb) * vs;
        (f, Powers { engine_w: engine_power, loss_w: loss })
    }

    fn reduced_rhs(&self, f: &[f64; N]) -> Vec<f64> {
        let mut out = vec![0.0; self.n];
        for (c, r) in self.rep.iter().enumerate() {
            if let Some((a, fa)) = r {
                out[*a] += fa * f[c];
            }
        }
        out
    }

    /// Coordinates, rates, forces and powers at (x, t).
    fn kinematics(&self, x: &[f64], t: f64) -> ([f64; N], [f64; N], [f64; N], Powers) {
        let u = self.full(x);
        let (f, p) = self.forces(&u, t);
        let r = self.reduced_rhs(&f);
        let xd: Vec<f64> = (0..self.n).map(|i| (0..self.n).map(|k| self.reduced_inv[i][k] * r[k]).sum()).collect();
        let ud = self.full(&xd);
        (u, ud, f, p)
    }

    /// `M u̇ − F`: the constraint torque on each coordinate.
    fn reactions(&self, ud: &[f64; N], f: &[f64; N]) -> [f64; N] {
        std::array::from_fn(|r| (0..N).map(|c| self.mass[r][c] * ud[c]).sum::<f64>() - f[r])
    }

    /// Front and rear shaft torques.
    fn shaft_torques(&self, u: &[f64; N], f: &[f64; N]) -> [f64; 2] {
        let d = &self.v.driveline;
        [(TWIST_F, 0), (TWIST_R, 1)]
            .map(|(tw, i)| d.shaft_stiffness_nm_per_rad[i] * u[tw] + d.shaft_damping_nm_s_per_rad[i] * f[tw])
    }

    /// Brake capacity left on the weaker held axle (negative: the brake cannot hold).
    fn brake_margin(&self, ud: &[f64; N], f: &[f64; N], t: f64) -> f64 {
        let r = self.reactions(ud, f);
        let cap = self.sc.brake_pedal.value(t).clamp(0.0, 1.0) * self.v.brake.capacity_nm;
        let share = self.v.brake.front_fraction;
        (cap * share - r[FRONT].abs()).min(cap * (1.0 - share) - r[REAR].abs())
    }

    fn held_flow_balance(&self, u: &[f64; N], ud: &[f64; N]) -> (f64, f64) {
        let (head, shock) = self.model.zero_flow_head(&[u[0], u[1], u[2], u[3]]);
        let inertial: f64 = (0..N).map(|c| self.mass[FLOW][c] * ud[c]).sum();
        (head - inertial, shock)
    }
}

/// One sampled instant of a launch.
#[derive(Debug, Clone, Copy)]
pub struct LaunchSample {
    pub time_s: f64,
    pub u: [f64; N],
    pub u_dot: [f64; N],
    pub mode: VehicleMode,
    /// The converter's own sample (torques on the converter, effective torques).
    pub converter: ConverterSample,
    pub engine_torque_nm: f64,
    pub engine_power_w: f64,
    pub loss_power_w: f64,
    pub stored_energy_j: f64,
    pub shaft_torque_nm: [f64; 2],
    pub tyre_force_n: [f64; 2],
}

impl SmoothSegment for Plant<'_> {
    type Root = Root;
    type Sample = LaunchSample;
    fn n_states(&self) -> usize {
        self.n
    }
    fn atol(&self, o: &SolverOptions) -> Vec<f64> {
        let mut a = vec![o.speed_atol_rad_s; self.n];
        for (c, r) in self.rep.iter().enumerate() {
            if let Some((col, _)) = r {
                a[*col] = match c {
                    FLOW => o.flow_atol_m3_s,
                    SPEED => o.speed_atol_rad_s * 0.1,
                    TWIST_F | TWIST_R => 1e-7,
                    TORQUE_FAST | TORQUE_BOOST => 1e-4,
                    _ => a[*col],
                };
            }
        }
        a
    }
    fn rhs(&self, x: &[f64], t: f64, out: &mut [f64]) {
        let (f, _) = self.forces(&self.full(x), t);
        out.copy_from_slice(&self.reduced_rhs(&f));
    }
    fn jacobian_times(&self, x: &[f64], t: f64, v: &[f64], out: &mut [f64]) {
        // forward difference of the reduced right-hand side along v
        let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        if norm == 0.0 {
            out.iter_mut().for_each(|o| *o = 0.0);
            return;
        }
        let scale = x.iter().zip(v).map(|(a, b)| a.abs() * b.abs()).sum::<f64>() / norm;
        let h = 1e-7 * (1.0 + scale) / norm;
        let xp: Vec<f64> = x.iter().zip(v).map(|(a, b)| a + h * b).collect();
        let (f0, _) = self.forces(&self.full(x), t);
        let (f1, _) = self.forces(&self.full(&xp), t);
        let (r0, r1) = (self.reduced_rhs(&f0), self.reduced_rhs(&f1));
        for i in 0..out.len() {
            out[i] = (r1[i] - r0[i]) / h;
        }
    }
    fn mass_times(&self, v: &[f64], beta: f64, y: &mut [f64]) {
        for (yi, row) in y.iter_mut().zip(&self.reduced_mass) {
            *yi = row.iter().zip(v).map(|(m, x)| m * x).sum::<f64>() + beta * *yi;
        }
    }
    fn roots(&self) -> &[Root] {
        &self.roots
    }
    fn root_values(&self, x: &[f64], t: f64, h: &Hysteresis, out: &mut [f64]) {
        let (u, ud, f, _) = self.kinematics(x, t);
        let p = self.sc.accelerator_pedal.value(t);
        let gb = &self.v.gearbox;
        for (k, root) in self.roots.iter().enumerate() {
            out[k] = match root {
                Root::StatorTorque => self.reactions(&ud, &f)[STATOR] + h.stator_torque_nm,
                Root::StatorSpeed => u[STATOR] + h.stator_speed_rad_s,
                Root::Flow => self.mode.converter.flow_sign * u[FLOW] + h.flow_m3_s,
                Root::FlowStartsPositive => {
                    let (d, p0) = self.held_flow_balance(&u, &ud);
                    p0 - d + h.head_pa
                }
                Root::FlowStartsNegative => {
                    let (d, p0) = self.held_flow_balance(&u, &ud);
                    p0 + d + h.head_pa
                }
                Root::BrakeRelease => self.brake_margin(&ud, &f, t) + 1e-9,
                Root::BrakeHold => {
                    // hold once the axles have (nearly) stopped and the brake can hold the driveline
                    let rim = u[SPEED] / self.v.tyres.rolling_radius_m;
                    let spin = (u[FRONT] * u[FRONT] + u[REAR] * u[REAR] + rim * rim).sqrt() - HOLD_SPEED_RAD_S;
                    let cap = self.sc.brake_pedal.value(t).clamp(0.0, 1.0) * self.v.brake.capacity_nm;
                    let (share, fd) = (self.v.brake.front_fraction, self.v.driveline.final_drive_ratio);
                    let shaft = self.shaft_torques(&u, &f);
                    // with a 20 % margin, so that a brake that just let go does not grab again
                    let short =
                        (fd * shaft[0].abs() - 0.8 * cap * share).max(fd * shaft[1].abs() - 0.8 * cap * (1.0 - share));
                    spin.max(short)
                }
                Root::Upshift => gb.upshift_speed(self.mode.gear, p) - u[SPEED],
                Root::Downshift => u[SPEED] - gb.downshift_speed(self.mode.gear, p),
                Root::ShiftHandover => self.mode.shift.map_or(1.0, |s| s.since_s + gb.shift_handover_s - t),
                Root::ShiftSync => self.mode.shift.map_or(1.0, |s| {
                    self.sync_sign * (u[TURBINE] - gb.ratios[s.to] * u[GEARBOX_OUT]) - SYNC_SLIP_RAD_S
                }),
                Root::LockupEngage => self.v.lockup.engage_speed(p) - u[SPEED],
                Root::LockupRamped => match self.mode.lockup {
                    LockupState::Engaging { since_s, .. } => since_s + self.v.lockup.engage_time_s - t,
                    _ => 1.0,
                },
                Root::LockupArm => match self.mode.lockup {
                    LockupState::Engaging { since_s, .. } => since_s + self.v.lockup.engage_time_s + REARM_DELAY_S - t,
                    _ => 1.0,
                },
                Root::LockupLock => self.sync_sign * (u[PUMP] - u[TURBINE]) - SYNC_SLIP_RAD_S,
                Root::LockupSlip => {
                    // torque through the locked clutch: the engine side's constraint torque
                    let r = self.reactions(&ud, &f);
                    self.v.lockup.static_to_kinetic * self.v.lockup.capacity_nm - r[PUMP].abs()
                }
                Root::LockupRelease => u[SPEED] - LOCKUP_RELEASE_FRACTION * self.v.lockup.engage_speed(p),
                Root::Stop => self.sc.stop_speed_m_s.unwrap_or(f64::INFINITY) - u[SPEED],
            };
        }
    }
    fn sample(&self, x: &[f64], t: f64) -> LaunchSample {
        let (u, ud, f, powers) = self.kinematics(x, t);
        let uc: Vec4 = [u[0], u[1], u[2], u[3]];
        let udc: Vec4 = [ud[0], ud[1], ud[2], ud[3]];
        let fc = self.model.forces(&uc, self.mode.converter.flow_sign);
        let cm = self.model.mass();
        let torque_c: Vec4 = std::array::from_fn(|r| (0..4).map(|c| cm[r][c] * udc[c]).sum::<f64>() - fc[r]);
        let present = self.model.coordinates();
        let mut torque = [torque_c[PUMP], torque_c[TURBINE], torque_c[STATOR]];
        let transferred = self.model.transferred(&fc);
        if !present[STATOR] {
            torque[2] = transferred.1 - transferred.0;
        }
        let held_flow = self.model.has_flow_sign() && self.mode.converter.flow_sign == 0.0;
        let converter = ConverterSample {
            time_s: t,
            u: uc,
            u_dot: udc,
            torque,
            transferred,
            mode: self.mode.converter,
            loss_power_w: if held_flow { 0.0 } else { self.model.loss_power_w(&uc, &fc) },
            stored_energy_j: 0.5 * (0..4).map(|r| uc[r] * (0..4).map(|c| cm[r][c] * uc[c]).sum::<f64>()).sum::<f64>(),
        };
        let d = &self.v.driveline;
        let kinetic: f64 =
            0.5 * (0..=SPEED).map(|r| u[r] * (0..=SPEED).map(|c| self.mass[r][c] * u[c]).sum::<f64>()).sum::<f64>();
        let spring = 0.5
            * (d.shaft_stiffness_nm_per_rad[0] * u[TWIST_F].powi(2)
                + d.shaft_stiffness_nm_per_rad[1] * u[TWIST_R].powi(2));
        let shaft = self.shaft_torques(&u, &f);
        let ty = &self.v.tyres;
        let tyre = [FRONT, REAR].map(|a| {
            let load = if a == FRONT { ty.front_load_fraction } else { 1.0 - ty.front_load_fraction };
            let (_, cos_g) = self.v.grade();
            let kappa = (ty.rolling_radius_m * u[a] - u[SPEED])
                / (u[SPEED] * u[SPEED] + SLIP_SPEED_M_S * SLIP_SPEED_M_S).sqrt();
            ty.friction_coefficient
                * load
                * self.v.body.mass_kg
                * G
                * cos_g
                * (ty.slip_stiffness * kappa / ty.friction_coefficient).tanh()
        });
        LaunchSample {
            time_s: t,
            u,
            u_dot: ud,
            mode: self.mode,
            converter,
            engine_torque_nm: self.sc.engine(&self.v.engine, &u, t).0,
            engine_power_w: powers.engine_w,
            loss_power_w: powers.loss_w,
            stored_energy_j: kinetic + spring,
            shaft_torque_nm: shaft,
            tyre_force_n: tyre,
        }
    }
    fn coordinates(&self, x: &[f64], _t: f64) -> Vec<f64> {
        self.full(x).to_vec()
    }
}

// ---------------------------------------------------------------------------------------------
// Runs

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
pub fn initial_state(model: &dyn ConverterDynamics, v: &Vehicle, sc: &Scenario) -> TransientResult<[f64; N]> {
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
    let (mut lo, mut hi) = (1.0_f64, v.engine.full_load.x.last().copied().unwrap_or(700.0));
    if balance(lo)? <= 0.0 || balance(hi)? >= 0.0 {
        return Err(match &sc.engine_torque_nm {
            Some(log) => CoreError::new("engine_torque_nm[0]", log.value(0.0), "a positive logged engine torque at the start that the stalled converter can absorb"),
            None => CoreError::new("engine.idle_speed_rad_s", v.engine.idle_speed_rad_s, "an idle governor and full-load curve that can hold the stalled converter (no engine speed balances them)"),
        }
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
    let mut u = [0.0; N];
    u[..4].copy_from_slice(&ss.u);
    u[PUMP] = wp;
    u[TWIST_F] = twist;
    u[TWIST_R] = twist;
    u[TORQUE_FAST] = fast;
    u[TORQUE_BOOST] = boost;
    Ok(u)
}

fn event_name(root: Root) -> &'static str {
    match root {
        Root::StatorTorque => "stator-release",
        Root::StatorSpeed => "stator-lock",
        Root::Flow => "flow-zero",
        Root::FlowStartsPositive | Root::FlowStartsNegative => "flow-start",
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

/// The mode after `root`, and the sign of the slip to synchronise (shifts, lock-up).
fn switch(plant: &Plant, root: Root, u: &mut [f64; N], t: f64) -> (VehicleMode, f64) {
    let mut m = plant.mode;
    let mut sync = plant.sync_sign;
    let gb = &plant.v.gearbox;
    match root {
        Root::StatorTorque => m.converter.stator_locked = false,
        Root::StatorSpeed => {
            m.converter.stator_locked = true;
            u[STATOR] = 0.0;
        }
        Root::Flow => {
            u[FLOW] = 0.0;
            m.converter.flow_sign = flow_sign_at_zero(plant, u, t);
        }
        Root::FlowStartsPositive => m.converter.flow_sign = 1.0,
        Root::FlowStartsNegative => m.converter.flow_sign = -1.0,
        Root::BrakeRelease => m.wheels_held = false,
        Root::BrakeHold => m.wheels_held = true,
        Root::Upshift | Root::Downshift => {
            let to = if root == Root::Upshift { m.gear + 1 } else { m.gear - 1 };
            m.shift = Some(Shift { from: m.gear, to, since_s: t, handed_over: false });
            // an engaging clutch restarts after an upshift; a downshift opens it
            if m.lockup != LockupState::Locked || root == Root::Downshift {
                m.lockup = LockupState::Open;
            }
        }
        Root::ShiftHandover => {
            let to = m.shift.map_or(m.gear, |s| s.to);
            let slip = u[TURBINE] - gb.ratios[to] * u[GEARBOX_OUT];
            if slip.abs() <= SYNC_SLIP_RAD_S {
                m.gear = to;
                m.shift = None;
            } else {
                m.shift = m.shift.map(|s| Shift { handed_over: true, ..s });
                sync = slip.signum();
            }
        }
        Root::ShiftSync => {
            if let Some(s) = m.shift {
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

fn flow_sign_at_zero(plant: &Plant, u: &[f64; N], t: f64) -> f64 {
    let mode = VehicleMode { converter: ConverterMode { flow_sign: 0.0, ..plant.mode.converter }, ..plant.mode };
    let held = Plant::new(plant.model, plant.v, plant.sc, mode, plant.sync_sign);
    let (uu, ud, _, _) = held.kinematics(&held.state_of(u), t);
    let (d, p0) = held.held_flow_balance(&uu, &ud);
    if d > p0 {
        1.0
    } else if d < -p0 {
        -1.0
    } else {
        0.0
    }
}

/// A switch whose condition already holds when a mode starts (root functions only see
/// crossings): the stop speed, a due shift, a due lock-up engagement.
fn due(plant: &Plant, u: &[f64; N], t: f64) -> Option<Root> {
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
        if m.gear + 1 < gb.ratios.len() && u[SPEED] > gb.upshift_speed(m.gear, p) {
            return Some(Root::Upshift);
        }
        if m.gear > 0 && u[SPEED] < gb.downshift_speed(m.gear, p) {
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

/// Kinetic energy of `u` with `plant`'s masses.
fn kinetic_energy(plant: &Plant, u: &[f64; N]) -> f64 {
    0.5 * (0..=SPEED).map(|r| u[r] * (0..=SPEED).map(|c| plant.mass[r][c] * u[c]).sum::<f64>()).sum::<f64>()
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
    v.validate()?;
    if !(sc.end_time_s.is_finite() && sc.end_time_s > 0.0) {
        return Err(CoreError::new("end_time_s", sc.end_time_s, "a finite, positive end time").into());
    }
    if !(output_step_s.is_finite() && output_step_s > 0.0) {
        return Err(CoreError::new("output_step_s", output_step_s, "a finite, positive output step").into());
    }
    let n_out = (sc.end_time_s / output_step_s).round() as usize + 1;
    let times: Vec<f64> = (0..n_out).map(|i| (i as f64 * output_step_s).min(sc.end_time_s)).collect();
    let u0 = initial_state(model, v, sc)?;
    let held = sc.brake_pedal.value(0.0) > 0.0;
    let mut mode = VehicleMode {
        converter: ConverterMode {
            stator_locked: model.has_stator_clutch(),
            flow_sign: if model.has_flow_sign() { 1.0 } else { 0.0 },
        },
        gear: 0,
        shift: None,
        lockup: LockupState::Open,
        wheels_held: held,
    };
    if !model.has_flow_sign() {
        mode.converter.flow_sign = 1.0;
    }
    let mut traj = LaunchTrajectory::default();
    let (mut t, mut u, mut sync) = (0.0, u0, 1.0);
    let mut energy_before: Option<f64> = None;
    loop {
        let plant = Plant::new(model, v, sc, mode, sync);
        let x0 = plant.state_of(&u);
        if let Some(before) = energy_before {
            // a closing link removes kinetic energy (momentum is conserved); a change of the
            // gearbox's inertia with the gear changes it too: both are booked here
            traj.event_loss_j.push((t, before - kinetic_energy(&plant, &plant.full(&x0))));
        }
        let end = match due(&plant, &plant.full(&x0), t) {
            Some(root) => Some((t, root, x0)),
            None => run_segment(&plant, x0, t, sc.end_time_s, &times, options, &mut traj.samples, &mut traj.steps)?,
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
                let (new_mode, new_sync) = switch(&plant, root, &mut next, t_root);
                energy_before = Some(kinetic_energy(&plant, &next));
                let kind = match root {
                    Root::ShiftHandover if new_mode.shift.is_none() => "shift-end",
                    Root::LockupRamped | Root::LockupArm if new_mode.lockup == LockupState::Locked => "lockup-lock",
                    _ => event_name(root),
                };
                traj.events.push(VehicleEvent { time_s: t_root, kind, gear: new_mode.gear + 1 });
                if traj.events.len() > options.max_events {
                    return Err(TransientError::Solver {
                        time_s: t_root,
                        state: next.to_vec(),
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

// ---------------------------------------------------------------------------------------------
// Output columns

/// Columns of a launch after the converter's [`crate::outputs::COLUMNS`] (whose `pump_*` refer to
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

/// All columns of a launch: the converter's, then [`LAUNCH_COLUMNS`], then
/// `event_energy_loss_j` (cumulative energy booked at switching events).
pub fn launch_column_names() -> Vec<&'static str> {
    crate::outputs::COLUMNS
        .iter()
        .chain(LAUNCH_COLUMNS.iter())
        .chain(std::iter::once(&"event_energy_loss_j"))
        .copied()
        .collect()
}

/// The run as columns in the order of [`launch_column_names`]. `gear` is 1-based (the off-going
/// gear during a shift); `lockup_state` is 0 open, 1 slipping, 2 locked.
pub fn launch_columns(model: &dyn ConverterDynamics, sc: &Scenario, traj: &LaunchTrajectory) -> Vec<Vec<f64>> {
    let names = launch_column_names();
    let mut cols: Vec<Vec<f64>> = (0..names.len()).map(|_| Vec::with_capacity(traj.samples.len())).collect();
    let mut booked = 0.0;
    let mut next_event = 0;
    for s in &traj.samples {
        while next_event < traj.event_loss_j.len() && traj.event_loss_j[next_event].0 <= s.time_s {
            booked += traj.event_loss_j[next_event].1;
            next_event += 1;
        }
        let conv = crate::outputs::row(model, &s.converter);
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
        for (c, v) in cols.iter_mut().zip(conv.iter().chain(extra.iter()).chain(std::iter::once(&booked))) {
            c.push(*v);
        }
    }
    cols
}

#[cfg(test)]
mod tests {
    use super::*;

    fn engine() -> Engine {
        Engine {
            inertia_kg_m2: 0.2,
            idle_speed_rad_s: 78.5,
            full_load: Curve::new("full_load", vec![60.0, 230.0, 500.0, 700.0], vec![150.0, 400.0, 400.0, 280.0])
                .unwrap(),
            drag_torque_nm: 15.0,
            drag_nm_s_per_rad: 0.05,
            fast_time_constant_s: 0.06,
            boost_time_constant_s: 0.8,
            boost_fraction: 0.4,
            idle_governor_gain_nm_s_per_rad: 10.0,
        }
    }

    #[test]
    fn curve_interpolates_holds_ends_and_refuses_bad_tables() {
        let c = Curve::new("c", vec![0.0, 1.0, 3.0], vec![0.0, 2.0, 6.0]).unwrap();
        assert_eq!((c.at(-1.0), c.at(0.5), c.at(2.0), c.at(9.0)), (0.0, 1.0, 4.0, 6.0));
        assert_eq!(Curve::new("c", vec![0.0, 1.0, 1.0], vec![0.0; 3]).unwrap_err().field, "c[2]");
    }

    #[test]
    fn engine_splits_pedal_torque_and_governs_idle() {
        let e = engine();
        // full pedal at 230 rad/s: 400 N·m, 40 % of it through the boost path
        let (fast, boost) = e.targets(1.0, 230.0);
        assert!((fast - 240.0).abs() < 1e-12 && (boost - 160.0).abs() < 1e-12);
        // no pedal above idle: nothing; below idle the governor pushes, limited by full load
        assert_eq!(e.targets(0.0, 100.0), (0.0, 0.0));
        let (fast, boost) = e.targets(0.0, 70.0);
        assert!((fast - 85.0).abs() < 1e-12 && boost == 0.0);
        assert!((e.targets(0.0, 0.0).0 - 150.0).abs() < 1e-12);
        // drag opposes rotation and vanishes at rest
        assert!(e.drag(100.0) > 15.0 && e.drag(0.0) == 0.0 && e.drag(-100.0) < 0.0);
        let mut bad = engine();
        bad.boost_fraction = 1.5;
        assert_eq!(bad.validate().unwrap_err().field, "engine.boost_fraction");
    }

    #[test]
    fn gearbox_schedule_interpolates_in_pedal_and_is_validated() {
        let g = Gearbox {
            ratios: vec![4.0, 2.0, 1.0],
            efficiencies: vec![0.95, 0.96, 0.97],
            input_inertia_kg_m2: vec![0.05, 0.04, 0.03],
            output_inertia_kg_m2: 0.05,
            shift_clutch_capacity_nm: 500.0,
            shift_handover_s: 0.25,
            upshift_speed_zero_pedal_m_s: vec![4.0, 8.0],
            upshift_speed_full_pedal_m_s: vec![12.0, 24.0],
            downshift_speed_zero_pedal_m_s: vec![2.0, 5.0],
            downshift_speed_full_pedal_m_s: vec![8.0, 16.0],
        };
        g.validate().unwrap();
        assert_eq!((g.upshift_speed(0, 0.5), g.upshift_speed(1, 1.0), g.downshift_speed(2, 0.0)), (8.0, 24.0, 5.0));
        let mut bad = g.clone();
        bad.downshift_speed_full_pedal_m_s[1] = 30.0;
        assert_eq!(bad.validate().unwrap_err().field, "gearbox.downshift_speed_full_pedal_m_s[1]");
        let mut bad = g.clone();
        bad.efficiencies.pop();
        assert_eq!(bad.validate().unwrap_err().field, "gearbox.efficiencies");
        let mut bad = g;
        bad.ratios[1] = -2.0;
        assert_eq!(bad.validate().unwrap_err().field, "gearbox.ratios[1]");
    }

    #[test]
    fn lockup_engage_speed_and_validation() {
        let l = Lockup {
            capacity_nm: 600.0,
            static_to_kinetic: 1.2,
            engage_time_s: 0.5,
            min_gear: 3,
            engage_speed_zero_pedal_m_s: 12.0,
            engage_speed_full_pedal_m_s: 25.0,
        };
        assert_eq!(l.engage_speed(0.0), 12.0);
        assert_eq!(l.engage_speed(2.0), 25.0);
        let bad = Lockup { static_to_kinetic: 0.9, ..l };
        assert_eq!(bad.validate().unwrap_err().field, "lockup.static_to_kinetic");
    }
}
