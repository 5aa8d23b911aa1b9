//! The vehicle's parameters and the launch scenario, with their validation (ranges in
//! docs/vehicle.md). The physics that uses them is in [`super::components`].

use crate::engine::signal::Signal;
use crate::error::{CoreError, CoreResult};

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
    /// The speeds of the curve's points.
    pub fn x(&self) -> &[f64] {
        &self.x
    }
    /// The values of the curve's points.
    pub fn y(&self) -> &[f64] {
        &self.y
    }
}

pub(super) fn positive(name: &str, v: f64) -> CoreResult<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(CoreError::new(name, v, "a finite, positive value"))
    }
}

pub(super) fn non_negative(name: &str, v: f64) -> CoreResult<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(CoreError::new(name, v, "a finite value of zero or more"))
    }
}

pub(super) fn fraction(name: &str, v: f64) -> CoreResult<f64> {
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
