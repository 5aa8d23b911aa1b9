//! The vehicle's parameters and the launch scenario, with their one validation (ranges in
//! docs/vehicle.md). The vehicle file ([`super::file`]) is converted into these structs and
//! checked here once; every error names the field as the file writes it (`[body].grade_percent`,
//! `[gearbox].ratios[3]`). The physics that uses them is in [`super::components`].

use super::shift::ShiftControl;
use super::shift_pedal::PedalFilter;
use crate::engine::signal::Signal;
use crate::error::{CoreError, CoreResult};

pub use super::range::{field, Range};

// The six ranges on which the file check and the core once disagreed, settled here. The rule for
// an open or a closed end: an end value is excluded when the model degenerates there, and
// included when the model stays well posed.

/// `[body].grade_percent`, %: from −50 to 50, both included. The plant's `grade()` takes
/// `atan(grade/100)` and could represent any finite grade, but it keeps the static axle loads
/// (no load transfer, docs/vehicle.md *Known limits*): at 50 % (26.6°) a sedan's centre of mass
/// (height about 0.19 of the wheelbase) already moves about 10 % of the weight between the axles.
/// The steepest public roads are about 35 % and hill-start test slopes 30 % or less, so ±50 %
/// covers every road the model is meant for; nothing degenerates at ±50 % itself.
pub const GRADE_PERCENT: Range = Range { low: Some((-50.0, true)), high: Some((50.0, true)) };

/// `[engine].idle_governor_gain_nm_s_per_rad`, N·m·s/rad: greater than 0. Without the governor
/// (gain 0) the engine makes no torque at zero pedal, so no engine speed balances drag and the
/// stalled converter: the braked standstill every launch starts from does not exist.
/// The upper end (1000 N·m·s/rad, 100 times the bundled gain) is issue 10's: against an engine
/// and pump inertia of about 0.3 kg·m² a gain of 1e7 settles in microseconds, faster than a firing
/// interval, and the solver fails on it.
pub const IDLE_GOVERNOR_GAIN: Range = Range { low: Some((0.0, false)), high: Some((1000.0, true)) };

/// `[tyres].front_load_fraction`: greater than 0 and less than 1. Both axles are driven (the AWD
/// split is by shaft stiffness); an axle without load has no tyre force, so its shaft would spin
/// it up without bound. 0 and 1 degenerate the driveline.
pub const FRONT_LOAD_FRACTION: Range = Range { low: Some((0.0, false)), high: Some((1.0, false)) };

/// `[body].air_density_kg_m3`, kg/m³: 0 or more. Density 0 only removes the aerodynamic drag
/// (as `drag_area_m2 = 0` does); the plant stays well posed, so 0 is included.
/// The upper end (10 kg/m³, eight times sea-level air) is issue 10's: 1e30 made the solver fail.
pub const AIR_DENSITY: Range = Range { low: Some((0.0, true)), high: Some((10.0, true)) };

/// `[brake].capacity_nm`, N·m: greater than 0. Every launch starts at a braked standstill with
/// the wheels held by the brake against the stalled converter's torque; a brake of capacity 0
/// cannot hold them and could never hold them again, so the start state degenerates.
pub const BRAKE_CAPACITY: Range = Range::POSITIVE;

/// `[gearbox].input_inertia_kg_m2[k]`, kg·m²: 0 or more. The turbine coordinate's mass is the
/// converter's turbine inertia (validated positive) plus this, so the mass matrix stays positive
/// definite at 0 (the gearbox's inertia lumped into the turbine's): 0 is included.
pub const GEARBOX_INPUT_INERTIA: Range = Range::NON_NEGATIVE;

// The physical ranges: generous bounds from passenger cars to heavy trucks, where a value beyond
// them is not a road vehicle and makes the launch's solver fail (the step size falls below its
// minimum) instead of giving an answer. Each bound keeps a wide margin to the largest real
// vehicle and to the value where the bundled vehicle's launch first fails (docs/vehicle.md).

/// `[body].mass_kg`, kg: at least 50, at most 200 000. The heaviest road vehicles (Nordic
/// 60–76 t combinations, Australian road trains up to about 200 t) are at most 200 t, a 40 t
/// truck is well inside. Beyond, the tyre forces (μ m g) against the axle inertias make the
/// driveline so stiff that the solver fails (1.9e33 kg in the bundled vehicle): 1e30 kg is not a
/// vehicle. At the lower end, a mass of 1.9e-27 kg also makes the solver fail (the aerodynamic drag
/// over the mass), and no road vehicle with a driver is below 50 kg.
pub const BODY_MASS: Range = Range { low: Some((50.0, true)), high: Some((200_000.0, true)) };

/// `[engine].full_load_torque_nm[k]`, N·m: from 0 to 100 000, both included. Heavy-truck diesels
/// make up to about 3 500 N·m and the largest mining-truck engines about 20 000 N·m; 4e32 N·m
/// makes the solver fail at the brake release.
pub const ENGINE_TORQUE: Range = Range { low: Some((0.0, true)), high: Some((100_000.0, true)) };

/// `[engine].fast_time_constant_s` and `[engine].boost_time_constant_s`, s: at least 0.001. An
/// engine's torque cannot follow the pedal faster than a few firing intervals (a firing interval
/// is 5 ms for a four-cylinder at 6 000 rpm), so 1 ms is already faster than any engine; a lag of
/// 1e-32 s is no lag but a stiffness the solver cannot step over.
pub const ENGINE_TIME_CONSTANT: Range = Range { low: Some((0.001, true)), high: None };

/// `[gearbox].ratios[k]`: greater than 0, at most 30. Automatic gearboxes' first gears are 3–7 and
/// heavy trucks' crawler gears up to about 20; at 5.25e6 the turbine is locked to a vehicle whose
/// reflected inertia is 1e13 times its own and the solver fails.
pub const GEAR_RATIO: Range = Range { low: Some((0.0, false)), high: Some((30.0, true)) };

/// `[gearbox].output_inertia_kg_m2`, kg·m²: at least 0.001. An output shaft with its gear or
/// flange is above 0.001 kg·m² even in a small car; at 5e-8 kg·m² the output coordinate between
/// the shift clutch and the shafts is so stiff that the solver fails at the first shift.
pub const GEARBOX_OUTPUT_INERTIA: Range = Range { low: Some((0.001, true)), high: None };

/// `[gearbox].shift_clutch_capacity_nm` and `[lockup].capacity_nm`, N·m: greater than 0, at most
/// 100 000. A clutch is sized to a small multiple of the engine torque (at most about 20 000 N·m,
/// [`ENGINE_TORQUE`]); a lock-up clutch of 6e8 N·m or a shift clutch of 5e32 N·m makes the
/// solver fail when it engages.
pub const CLUTCH_CAPACITY: Range = Range { low: Some((0.0, false)), high: Some((100_000.0, true)) };

/// `[driveline].final_drive_ratio`: greater than 0, at most 50. Passenger cars' final drives are
/// 2.5–4.5, trucks' with hub reduction up to about 10 and mining trucks' wheel drives about 30;
/// at 3.2e6 the solver fails at once.
pub const FINAL_DRIVE_RATIO: Range = Range { low: Some((0.0, false)), high: Some((50.0, true)) };

/// `[driveline].front_shaft_stiffness_nm_per_rad` and `rear_…`, N·m/rad at the propshaft side:
/// greater than 0, at most 1e7. A heavy truck's axle is about 1e6 N·m/rad at the wheels, less at
/// the propshaft side (divided by the final drive ratio squared); 1.6e33 makes the solver fail.
pub const SHAFT_STIFFNESS: Range = Range { low: Some((0.0, false)), high: Some((1e7, true)) };

/// `[driveline].front_shaft_damping_nm_s_per_rad` and `rear_…`, N·m·s/rad: from 0 to 100 000,
/// both included. The critical damping `2√(kJ)` of a heavy truck's shaft-wheel mode is below
/// about 10 000 N·m·s/rad and a shaft's own damping is a few per cent of it; 6e6 makes the solver
/// fail at the brake release.
pub const SHAFT_DAMPING: Range = Range { low: Some((0.0, true)), high: Some((100_000.0, true)) };

/// `[driveline].front_axle_inertia_kg_m2` and `rear_…`, kg·m²: at least 0.01. Two wheels with
/// tyres, hubs and brakes are above 0.5 kg·m² even on a small car; an axle of 2.8e-30 kg·m² makes
/// the tyre slip so stiff that the solver fails at the brake release.
pub const AXLE_INERTIA: Range = Range { low: Some((0.01, true)), high: None };

/// `[tyres].rolling_radius_m`, m: greater than 0, at most 2. Passenger-car tyres are 0.28–0.38 m,
/// truck tyres about 0.5 m and the largest mining-truck tyres (4 m diameter) 2 m; a wheel of
/// 334 km makes the solver fail at the brake release.
pub const ROLLING_RADIUS: Range = Range { low: Some((0.0, false)), high: Some((2.0, true)) };

/// `[tyres].slip_stiffness` (dF_x/dκ over F_z): greater than 0, at most 100. Road tyres are
/// 5–30; 1.5e7 makes the tyre force jump with slips of 1e-7 and the solver fails.
pub const SLIP_STIFFNESS: Range = Range { low: Some((0.0, false)), high: Some((100.0, true)) };

/// `[body].drag_area_m2` (C_d·A), m²: from 0 to 100, both included. A passenger car is 0.5–1 m²
/// and a truck with trailers about 10 m²; 6.7e29 m² makes the solver fail when the vehicle moves.
pub const DRAG_AREA: Range = Range { low: Some((0.0, true)), high: Some((100.0, true)) };

/// A table `y(x)`, linear between points, ends held.
#[derive(Debug, Clone)]
pub struct Curve {
    x: Vec<f64>,
    y: Vec<f64>,
}

impl Curve {
    /// A curve of two or more points with finite, strictly increasing `x` and finite `y`; `x_name`
    /// and `y_name` name the two arrays in errors.
    pub fn new(x_name: &str, y_name: &str, x: Vec<f64>, y: Vec<f64>) -> CoreResult<Self> {
        if x.len() < 2 {
            return Err(CoreError::new(x_name, format!("{} values", x.len()), "two or more points"));
        }
        if y.len() != x.len() {
            return Err(CoreError::new(
                y_name,
                format!("{} values", y.len()),
                format!("{} values (one per {x_name})", x.len()),
            ));
        }
        for (name, v) in [(x_name, &x), (y_name, &y)] {
            if let Some(i) = v.iter().position(|v| !v.is_finite()) {
                return Err(CoreError::new(format!("{name}[{i}]"), v[i], "a finite number"));
            }
        }
        strictly(x_name, &x, true)?;
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

/// Values strictly increasing (or decreasing); the error names the first value out of order.
fn strictly(name: &str, v: &[f64], increasing: bool) -> CoreResult<()> {
    let bad = (1..v.len()).find(|&i| if increasing { v[i] <= v[i - 1] } else { v[i] >= v[i - 1] });
    match bad {
        None => Ok(()),
        Some(i) => Err(CoreError::new(
            format!("{name}[{i}]"),
            v[i],
            format!(
                "strictly {} values (previous value {})",
                if increasing { "increasing" } else { "decreasing" },
                v[i - 1]
            ),
        )),
    }
}

/// Each value of an array in `range`.
fn each(name: &str, v: &[f64], range: Range) -> CoreResult<()> {
    v.iter().enumerate().try_for_each(|(i, &x)| range.check(&format!("{name}[{i}]"), x).map(|_| ()))
}

/// An array of `n` values.
fn length(name: &str, v: &[f64], n: usize, what: &str) -> CoreResult<()> {
    if v.len() == n {
        Ok(())
    } else {
        Err(CoreError::new(name, format!("{} values", v.len()), format!("{n} values ({what})")))
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
        let f = |key: &str| field("engine", key);
        Range::POSITIVE.check(&f("inertia_kg_m2"), self.inertia_kg_m2)?;
        Range::POSITIVE.check(&f("idle_speed_rad_s"), self.idle_speed_rad_s)?;
        each(&f("full_load_speed_rad_s"), self.full_load.x(), Range::NON_NEGATIVE)?;
        each(&f("full_load_torque_nm"), self.full_load.y(), ENGINE_TORQUE)?;
        Range::NON_NEGATIVE.check(&f("drag_torque_nm"), self.drag_torque_nm)?;
        Range::NON_NEGATIVE.check(&f("drag_nm_s_per_rad"), self.drag_nm_s_per_rad)?;
        ENGINE_TIME_CONSTANT.check(&f("fast_time_constant_s"), self.fast_time_constant_s)?;
        ENGINE_TIME_CONSTANT.check(&f("boost_time_constant_s"), self.boost_time_constant_s)?;
        Range::FRACTION.check(&f("boost_fraction"), self.boost_fraction)?;
        IDLE_GOVERNOR_GAIN.check(&f("idle_governor_gain_nm_s_per_rad"), self.idle_governor_gain_nm_s_per_rad)?;
        let speeds = self.full_load.x();
        let (lo, hi) = (speeds[0], speeds[speeds.len() - 1]);
        let idle = self.idle_speed_rad_s;
        if !(lo <= idle && idle < hi) {
            return Err(CoreError::new(
                f("idle_speed_rad_s"),
                idle,
                format!("a speed within the full-load curve's speeds [{lo}, {hi}) rad/s"),
            ));
        }
        let (available, drag) = (self.full_load.at(idle), self.drag(idle));
        if available <= drag {
            return Err(CoreError::new(
                f("full_load_torque_nm"),
                format!("{available} N·m at idle"),
                format!("more than the drag torque at idle ({drag} N·m), or the engine cannot hold idle"),
            ));
        }
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
    /// Shift control of upshifts (torque reduction, on-coming clutch profile): [`super::shift`].
    pub shift_control: ShiftControl,
    /// The TCU's filter of the pedal the shift schedule reads: [`super::shift_pedal`].
    pub shift_pedal: PedalFilter,
}

impl Gearbox {
    pub fn validate(&self) -> CoreResult<()> {
        let f = |key: &str| field("gearbox", key);
        let n = self.ratios.len();
        if n == 0 {
            return Err(CoreError::new(f("ratios"), "[]", "at least one gear"));
        }
        each(&f("ratios"), &self.ratios, GEAR_RATIO)?;
        strictly(&f("ratios"), &self.ratios, false)?;
        let per_gear = format!("one per gear: ratios has {n}");
        length(&f("efficiencies"), &self.efficiencies, n, &per_gear)?;
        each(&f("efficiencies"), &self.efficiencies, Range::EFFICIENCY)?;
        length(&f("input_inertia_kg_m2"), &self.input_inertia_kg_m2, n, &per_gear)?;
        each(&f("input_inertia_kg_m2"), &self.input_inertia_kg_m2, GEARBOX_INPUT_INERTIA)?;
        let pairs = [
            ("upshift_speed_zero_pedal_m_s", &self.upshift_speed_zero_pedal_m_s),
            ("downshift_speed_zero_pedal_m_s", &self.downshift_speed_zero_pedal_m_s),
            ("upshift_speed_full_pedal_m_s", &self.upshift_speed_full_pedal_m_s),
            ("downshift_speed_full_pedal_m_s", &self.downshift_speed_full_pedal_m_s),
        ];
        for (key, v) in pairs {
            let way = if key.starts_with("up") { "upshift from" } else { "downshift into" };
            length(&f(key), v, n - 1, &format!("gears − 1 = {}: {way} gears 1..{}", n - 1, n - 1))?;
            each(&f(key), v, Range::POSITIVE)?;
            strictly(&f(key), v, true)?;
        }
        for [(up_key, up), (down_key, down)] in [[pairs[0], pairs[1]], [pairs[2], pairs[3]]] {
            if let Some(k) = (0..n - 1).find(|&k| down[k] >= up[k]) {
                return Err(CoreError::new(
                    format!("{}[{k}]", f(down_key)),
                    down[k],
                    format!(
                        "a speed below {up_key}[{k}] = {} m/s (downshift {}→{} below upshift {}→{}, or the \
                         gearbox hunts)",
                        up[k],
                        k + 2,
                        k + 1,
                        k + 1,
                        k + 2
                    ),
                ));
            }
        }
        GEARBOX_OUTPUT_INERTIA.check(&f("output_inertia_kg_m2"), self.output_inertia_kg_m2)?;
        CLUTCH_CAPACITY.check(&f("shift_clutch_capacity_nm"), self.shift_clutch_capacity_nm)?;
        Range::POSITIVE.check(&f("shift_handover_s"), self.shift_handover_s)?;
        self.shift_control.validate()?;
        self.shift_pedal.validate()
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
    /// The lock-up clutch of a gearbox with `gears` gears.
    pub fn validate(&self, gears: usize) -> CoreResult<()> {
        let f = |key: &str| field("lockup", key);
        CLUTCH_CAPACITY.check(&f("capacity_nm"), self.capacity_nm)?;
        Range::AT_LEAST_ONE.check(&f("static_to_kinetic"), self.static_to_kinetic)?;
        Range::POSITIVE.check(&f("engage_time_s"), self.engage_time_s)?;
        if !(1..=gears).contains(&self.min_gear) {
            return Err(CoreError::new(
                f("min_gear"),
                self.min_gear,
                format!("a gear from 1 to {gears} ([gearbox].ratios)"),
            ));
        }
        Range::POSITIVE.check(&f("engage_speed_zero_pedal_m_s"), self.engage_speed_zero_pedal_m_s)?;
        Range::POSITIVE.check(&f("engage_speed_full_pedal_m_s"), self.engage_speed_full_pedal_m_s)?;
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
    /// The one check of a vehicle's values; errors name the fields as the vehicle file does.
    pub fn validate(&self) -> CoreResult<()> {
        self.engine.validate()?;
        self.gearbox.validate()?;
        self.lockup.validate(self.gearbox.ratios.len())?;
        let d = &self.driveline;
        FINAL_DRIVE_RATIO.check(&field("driveline", "final_drive_ratio"), d.final_drive_ratio)?;
        for (i, axle) in ["front", "rear"].iter().enumerate() {
            let f = |key: &str| field("driveline", &format!("{axle}_{key}"));
            SHAFT_STIFFNESS.check(&f("shaft_stiffness_nm_per_rad"), d.shaft_stiffness_nm_per_rad[i])?;
            SHAFT_DAMPING.check(&f("shaft_damping_nm_s_per_rad"), d.shaft_damping_nm_s_per_rad[i])?;
            AXLE_INERTIA.check(&f("axle_inertia_kg_m2"), d.axle_inertia_kg_m2[i])?;
        }
        let (t, b) = (&self.tyres, &self.body);
        ROLLING_RADIUS.check(&field("tyres", "rolling_radius_m"), t.rolling_radius_m)?;
        Range::POSITIVE.check(&field("tyres", "friction_coefficient"), t.friction_coefficient)?;
        SLIP_STIFFNESS.check(&field("tyres", "slip_stiffness"), t.slip_stiffness)?;
        FRONT_LOAD_FRACTION.check(&field("tyres", "front_load_fraction"), t.front_load_fraction)?;
        BODY_MASS.check(&field("body", "mass_kg"), b.mass_kg)?;
        DRAG_AREA.check(&field("body", "drag_area_m2"), b.drag_area_m2)?;
        Range::NON_NEGATIVE.check(&field("body", "rolling_resistance"), b.rolling_resistance)?;
        AIR_DENSITY.check(&field("body", "air_density_kg_m3"), b.air_density_kg_m3)?;
        GRADE_PERCENT.check(&field("body", "grade_percent"), b.grade_percent)?;
        BRAKE_CAPACITY.check(&field("brake", "capacity_nm"), self.brake.capacity_nm)?;
        Range::FRACTION.check(&field("brake", "front_fraction"), self.brake.front_fraction)?;
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
    /// The pedal the shift schedule reads (the TCU's filtered pedal, [`super::shift_pedal`]); None:
    /// the accelerator pedal. A launch fills it from the gearbox's filter
    /// ([`super::launch::with_shift_pedal`]), a drive at each control step.
    pub shift_pedal: Option<Signal>,
}

impl Scenario {
    /// The pedals' breakpoints, sorted, each once: where a launch's forcing has a kink, so where
    /// its integrator's steps end ([`crate::engine::segment::run_segment_with_stops`]). The
    /// filtered shift pedal enters only root functions, and a logged engine torque is a
    /// measurement: neither adds stops.
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut b: Vec<f64> = self.accelerator_pedal.times().iter().chain(self.brake_pedal.times()).copied().collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
}

#[cfg(test)]
mod tests {
    use super::super::file::read_vehicle;

    const SEDAN: &str = include_str!("../../tests/data/sedan.toml");

    /// The sedan with the line of `key` in `[section]` replaced by `key = value`.
    fn with(section: &str, key: &str, value: &str) -> String {
        let mut in_section = false;
        let lines = SEDAN.lines().map(|l| {
            if l.starts_with('[') {
                in_section = l == format!("[{section}]");
            }
            match in_section && l.split('=').next().map(str::trim) == Some(key) {
                true => format!("{key} = {value}"),
                false => l.to_string(),
            }
        });
        lines.collect::<Vec<_>>().join("\n")
    }

    /// Section, key, a value at the bound, a value just over it, the field as the error names it,
    /// and what the error says is expected.
    const RANGE_CASES: [(&str, &str, &str, &str, &str, &str); 21] = [
        ("body", "mass_kg", "200000.0", "200001.0", "[body].mass_kg", "at least 50 and at most 200000"),
        ("body", "mass_kg", "50.0", "49.9", "[body].mass_kg", "at least 50 and at most 200000"),
        ("body", "air_density_kg_m3", "10.0", "10.1", "[body].air_density_kg_m3", "at least 0 and at most 10"),
        (
            "engine",
            "idle_governor_gain_nm_s_per_rad",
            "1000.0",
            "1001.0",
            "[engine].idle_governor_gain_nm_s_per_rad",
            "greater than 0 and at most 1000",
        ),
        (
            "engine",
            "full_load_torque_nm",
            "[120.0, 200.0, 300.0, 400.0, 400.0, 350.0, 100000.0]",
            "[120.0, 200.0, 300.0, 400.0, 400.0, 350.0, 100001.0]",
            "[engine].full_load_torque_nm[6]",
            "at least 0 and at most 100000",
        ),
        ("engine", "fast_time_constant_s", "0.001", "0.0009", "[engine].fast_time_constant_s", "at least 0.001"),
        ("engine", "boost_time_constant_s", "0.001", "0.0009", "[engine].boost_time_constant_s", "at least 0.001"),
        (
            "gearbox",
            "ratios",
            "[30.0, 3.03, 1.95, 1.46, 1.22, 1.0, 0.81, 0.67]",
            "[30.5, 3.03, 1.95, 1.46, 1.22, 1.0, 0.81, 0.67]",
            "[gearbox].ratios[0]",
            "greater than 0 and at most 30",
        ),
        ("gearbox", "output_inertia_kg_m2", "0.001", "0.0009", "[gearbox].output_inertia_kg_m2", "at least 0.001"),
        (
            "gearbox",
            "shift_clutch_capacity_nm",
            "100000.0",
            "100001.0",
            "[gearbox].shift_clutch_capacity_nm",
            "greater than 0 and at most 100000",
        ),
        ("lockup", "capacity_nm", "100000.0", "100001.0", "[lockup].capacity_nm", "greater than 0 and at most 100000"),
        (
            "driveline",
            "final_drive_ratio",
            "50.0",
            "50.5",
            "[driveline].final_drive_ratio",
            "greater than 0 and at most 50",
        ),
        (
            "driveline",
            "front_shaft_stiffness_nm_per_rad",
            "1e7",
            "1.1e7",
            "[driveline].front_shaft_stiffness_nm_per_rad",
            "greater than 0 and at most 1e7",
        ),
        (
            "driveline",
            "rear_shaft_stiffness_nm_per_rad",
            "1e7",
            "1.1e7",
            "[driveline].rear_shaft_stiffness_nm_per_rad",
            "greater than 0 and at most 1e7",
        ),
        (
            "driveline",
            "front_shaft_damping_nm_s_per_rad",
            "100000.0",
            "100001.0",
            "[driveline].front_shaft_damping_nm_s_per_rad",
            "at least 0 and at most 100000",
        ),
        (
            "driveline",
            "rear_shaft_damping_nm_s_per_rad",
            "100000.0",
            "100001.0",
            "[driveline].rear_shaft_damping_nm_s_per_rad",
            "at least 0 and at most 100000",
        ),
        (
            "driveline",
            "front_axle_inertia_kg_m2",
            "0.01",
            "0.0099",
            "[driveline].front_axle_inertia_kg_m2",
            "at least 0.01",
        ),
        (
            "driveline",
            "rear_axle_inertia_kg_m2",
            "0.01",
            "0.0099",
            "[driveline].rear_axle_inertia_kg_m2",
            "at least 0.01",
        ),
        ("tyres", "rolling_radius_m", "2.0", "2.01", "[tyres].rolling_radius_m", "greater than 0 and at most 2"),
        ("tyres", "slip_stiffness", "100.0", "100.5", "[tyres].slip_stiffness", "greater than 0 and at most 100"),
        ("body", "drag_area_m2", "100.0", "100.5", "[body].drag_area_m2", "at least 0 and at most 100"),
    ];

    /// The physical ranges: at each new bound the sedan reads; just over it the error names the
    /// field as the file does and says what is expected.
    #[test]
    fn the_physical_ranges_at_and_over_each_bound() {
        for (section, key, ok, bad, name, expected) in RANGE_CASES {
            read_vehicle(&with(section, key, ok)).unwrap_or_else(|e| panic!("{key} = {ok}: {e}"));
            let e = read_vehicle(&with(section, key, bad)).unwrap_err();
            assert_eq!((e.field.as_str(), e.expected.as_str()), (name, format!("a finite number {expected}").as_str()));
        }
    }
}
