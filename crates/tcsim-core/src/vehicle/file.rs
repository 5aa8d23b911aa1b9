//! The vehicle file: its schema, owned here, read once and validated once.
//!
//! A vehicle file is TOML; [`VehicleFile`] mirrors it exactly (top-level `name`, `source`,
//! optional `description`, `converter`, sections `[engine] [gearbox] [lockup] [driveline]
//! [tyres] [body] [brake]` and optional `[sources]`). Every quantity is SI with its unit in its
//! name. [`SCHEMA`] lists every key with its unit, default, range and meaning; the ranges are the
//! validator's own constants ([`super::parameters`], [`super::shift`], [`super::shift_pedal`]), a
//! test checks each row at its bounds against [`read_vehicle`], and the documentation's vehicle
//! file reference is generated from it (through the binding's `vehicle_schema()`).
//!
//! [`read_vehicle`] parses the text, checks the shape (unknown keys, missing keys, wrong types)
//! while deserialising, converts the sections into the plant's [`Vehicle`] and checks the values
//! once with [`Vehicle::validate`]. Every error is a [`CoreError`] naming the field as the file
//! writes it (`[body].grade_percent`, `[gearbox].ratios[3]`, `converter`), with the value and what
//! was expected; a TOML syntax error keeps its line and column (field `(syntax)`).

use std::fmt;

use indexmap::IndexMap;
use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, SeqAccess, Unexpected, Visitor};
use serde::{Deserialize, Serialize};

use super::parameters::{
    self as p, field, Body, Brake, Curve, Driveline, Engine, Gearbox, Lockup, Range, Tyres, Vehicle,
};
use super::shift::{self, ShiftControl};
use super::shift_pedal::{self, PedalFilter};
use crate::error::{CoreError, CoreResult};

/// The sections of a vehicle file that hold the vehicle's values, in file order.
pub const SECTIONS: [&str; 7] = ["engine", "gearbox", "lockup", "driveline", "tyres", "body", "brake"];

/// One key of a vehicle file as the documentation lists it: a row of [`SCHEMA`].
#[derive(Debug, Clone, Copy)]
pub struct KeySpec {
    /// The section (`engine`, …), `""` for the top level.
    pub section: &'static str,
    /// The key as the file writes it.
    pub key: &'static str,
    /// The unit (SI, as the key's name carries it), `""` for a number without unit or a text.
    pub unit: &'static str,
    /// `None`: required; `Some(text)`: optional, and what its absence means.
    pub default: Option<&'static str>,
    /// The range of the value (of each value of an array) that [`read_vehicle`] enforces; `None`
    /// for a text or an integer.
    pub range: Option<Range>,
    /// What else is checked (lengths, order, cross-checks with other keys), `""` if nothing.
    pub rule: &'static str,
    /// What the key means.
    pub meaning: &'static str,
}

impl KeySpec {
    /// The allowed values in words: the range's text and the rule, `; `-separated.
    pub fn range_text(&self) -> String {
        let range = self.range.map(|r| r.expected());
        [range.as_deref().unwrap_or(""), self.rule]
            .iter()
            .filter(|t| !t.is_empty())
            .copied()
            .collect::<Vec<_>>()
            .join("; ")
    }
}

const fn key(
    section: &'static str,
    key: &'static str,
    unit: &'static str,
    range: Option<Range>,
    rule: &'static str,
    meaning: &'static str,
) -> KeySpec {
    KeySpec { section, key, unit, default: None, range, rule, meaning }
}

const fn optional(
    section: &'static str,
    key: &'static str,
    unit: &'static str,
    default: &'static str,
    range: Range,
    meaning: &'static str,
) -> KeySpec {
    KeySpec { section, key, unit, default: Some(default), range: Some(range), rule: "", meaning }
}

const SPEEDS: &str = "gears − 1 values, strictly increasing";
const DOWN_SPEEDS: &str = "gears − 1 values, strictly increasing, each below the upshift speed of the same index";

/// Every key of a vehicle file (but the free-form `[sources]`), in file order: the one schema the
/// documentation is generated from. The ranges are the constants [`Vehicle::validate`] checks with.
pub const SCHEMA: &[KeySpec] = &[
    key("", "name", "", None, "text", "The vehicle's name."),
    key("", "source", "", None, "text", "Where the vehicle's values come from, in one sentence."),
    KeySpec { section: "", key: "description", unit: "", default: Some("none"), range: None, rule: "text", meaning: "Free text." },
    key("", "converter", "", None, "text", "A bundled converter's name, or a converter `.toml` path relative to the vehicle file."),
    key("engine", "inertia_kg_m2", "kg·m²", Some(Range::POSITIVE), "", "Crank and flywheel inertia (the converter pump's inertia is the converter's)."),
    key("engine", "idle_speed_rad_s", "rad/s", Some(Range::POSITIVE), "within [full_load_speed_rad_s[0], full_load_speed_rad_s[-1]), where the full-load torque exceeds the drag", "Idle speed, held by the idle governor."),
    key("engine", "full_load_speed_rad_s", "rad/s", Some(Range::NON_NEGATIVE), "two or more values, strictly increasing", "Speeds of the full-load curve."),
    key("engine", "full_load_torque_nm", "N·m", Some(p::ENGINE_TORQUE), "one per speed; more than the drag torque at idle", "Full-load torque at those speeds."),
    key("engine", "drag_torque_nm", "N·m", Some(Range::NON_NEGATIVE), "", "Constant part of the engine's drag."),
    key("engine", "drag_nm_s_per_rad", "N·m·s/rad", Some(Range::NON_NEGATIVE), "", "Viscous part of the engine's drag."),
    key("engine", "fast_time_constant_s", "s", Some(p::ENGINE_TIME_CONSTANT), "", "Time constant of the aspirated torque part."),
    key("engine", "boost_time_constant_s", "s", Some(p::ENGINE_TIME_CONSTANT), "", "Time constant of the boost torque part (\"time to torque\", thesis §3.3)."),
    key("engine", "boost_fraction", "", Some(Range::FRACTION), "", "Share of the pedal torque built up by boost."),
    key("engine", "idle_governor_gain_nm_s_per_rad", "N·m·s/rad", Some(p::IDLE_GOVERNOR_GAIN), "", "Idle governor gain. Without the governor no engine speed balances drag and the stalled converter (no braked standstill to start from); above 1000 it settles faster than a firing interval and the solver fails."),
    key("gearbox", "ratios", "", Some(p::GEAR_RATIO), "at least one value, gear 1 first, strictly decreasing", "Ratio of each gear."),
    key("gearbox", "efficiencies", "", Some(Range::EFFICIENCY), "one per gear", "Efficiency of each gear."),
    key("gearbox", "input_inertia_kg_m2", "kg·m²", Some(p::GEARBOX_INPUT_INERTIA), "one per gear", "Inertia of each gear at the gearbox input; 0 lumps it into the converter's turbine inertia."),
    key("gearbox", "output_inertia_kg_m2", "kg·m²", Some(p::GEARBOX_OUTPUT_INERTIA), "", "Inertia of the gearbox output side."),
    key("gearbox", "shift_clutch_capacity_nm", "N·m", Some(p::CLUTCH_CAPACITY), "", "Capacity of each shift clutch, at the gearbox input."),
    key("gearbox", "shift_handover_s", "s", Some(Range::POSITIVE), "", "Torque handover time of a shift."),
    optional("gearbox", "upshift_torque_reduction", "", "0", shift::TORQUE_REDUCTION, "Fraction of the engine's torque withheld in the inertia phase of an upshift (typical 0.3–0.6)."),
    optional("gearbox", "upshift_inertia_phase_s", "s", "none: the on-coming clutch keeps `shift_clutch_capacity_nm`", shift::INERTIA_PHASE, "Target duration of an upshift's inertia phase, for the on-coming clutch's feed-forward (typical 0.2–0.5 s)."),
    optional("gearbox", "upshift_power_on_nm", "N·m", "0 (any positive input torque)", shift::POWER_ON_THRESHOLD, "The TCU's power-on/power-off decision, at the gearbox input: an upshift is power-on (controlled on-coming capacity and torque reduction) when the input torque at its command is above it, power-off (constant capacity, no torque reduction) otherwise."),
    optional("gearbox", "shift_pedal_rise_s", "s", "0 (at once)", shift_pedal::PEDAL_TIME_CONSTANT, "Time constant with which the pedal the shift schedule reads follows a pressed pedal (the TCU's filter; a full pedal, the kickdown, passes at once)."),
    optional("gearbox", "shift_pedal_fall_s", "s", "0 (no filter)", shift_pedal::PEDAL_TIME_CONSTANT, "The same for a released pedal (the TCU holds the gear when the driver lifts). Both 0: the schedule reads the accelerator pedal itself."),
    key("gearbox", "upshift_speed_zero_pedal_m_s", "m/s", Some(Range::POSITIVE), SPEEDS, "Vehicle speed of the upshift from gear k at zero pedal."),
    key("gearbox", "upshift_speed_full_pedal_m_s", "m/s", Some(Range::POSITIVE), SPEEDS, "As `upshift_speed_zero_pedal_m_s`, at full pedal."),
    key("gearbox", "downshift_speed_zero_pedal_m_s", "m/s", Some(Range::POSITIVE), DOWN_SPEEDS, "Vehicle speed of the downshift from gear k + 1 into k at zero pedal."),
    key("gearbox", "downshift_speed_full_pedal_m_s", "m/s", Some(Range::POSITIVE), DOWN_SPEEDS, "As `downshift_speed_zero_pedal_m_s`, at full pedal."),
    key("lockup", "capacity_nm", "N·m", Some(p::CLUTCH_CAPACITY), "", "Kinetic friction capacity of the lock-up clutch."),
    key("lockup", "static_to_kinetic", "", Some(Range::AT_LEAST_ONE), "", "Static over kinetic capacity."),
    key("lockup", "engage_time_s", "s", Some(Range::POSITIVE), "", "Engagement ramp."),
    key("lockup", "min_gear", "", None, "an integer from 1 to the number of gears", "Lowest gear with lock-up."),
    key("lockup", "engage_speed_zero_pedal_m_s", "m/s", Some(Range::POSITIVE), "", "Vehicle speed above which the lock-up engages at zero pedal."),
    key("lockup", "engage_speed_full_pedal_m_s", "m/s", Some(Range::POSITIVE), "", "As `engage_speed_zero_pedal_m_s`, at full pedal."),
    key("driveline", "final_drive_ratio", "", Some(p::FINAL_DRIVE_RATIO), "", "Final drive ratio (both axles)."),
    key("driveline", "front_shaft_stiffness_nm_per_rad", "N·m/rad", Some(p::SHAFT_STIFFNESS), "", "Front shaft torsional stiffness at the propshaft side (referred to the gearbox output, before the final drive: a wheel-side stiffness k_w is k_w / final_drive_ratio² here; thesis §4.3.1)."),
    key("driveline", "rear_shaft_stiffness_nm_per_rad", "N·m/rad", Some(p::SHAFT_STIFFNESS), "", "Rear shaft torsional stiffness, at the propshaft side."),
    key("driveline", "front_shaft_damping_nm_s_per_rad", "N·m·s/rad", Some(p::SHAFT_DAMPING), "", "Front shaft damping."),
    key("driveline", "rear_shaft_damping_nm_s_per_rad", "N·m·s/rad", Some(p::SHAFT_DAMPING), "", "Rear shaft damping."),
    key("driveline", "front_axle_inertia_kg_m2", "kg·m²", Some(p::AXLE_INERTIA), "", "Front axle inertia (both wheels, hubs, brakes, half shafts)."),
    key("driveline", "rear_axle_inertia_kg_m2", "kg·m²", Some(p::AXLE_INERTIA), "", "Rear axle inertia."),
    key("tyres", "rolling_radius_m", "m", Some(p::ROLLING_RADIUS), "", "Rolling radius."),
    key("tyres", "friction_coefficient", "", Some(Range::POSITIVE), "", "Friction coefficient μ."),
    key("tyres", "slip_stiffness", "", Some(p::SLIP_STIFFNESS), "", "Slip stiffness: dF_x/dκ over F_z at zero slip."),
    key("tyres", "front_load_fraction", "", Some(p::FRONT_LOAD_FRACTION), "", "Front axle's share of the static load. Both axles are driven: an axle without load has no tyre force and its shaft would spin it up without bound."),
    key("body", "mass_kg", "kg", Some(p::BODY_MASS), "", "Vehicle mass."),
    key("body", "drag_area_m2", "m²", Some(p::DRAG_AREA), "", "Drag area C_d·A."),
    key("body", "rolling_resistance", "", Some(Range::NON_NEGATIVE), "", "Rolling resistance coefficient."),
    key("body", "air_density_kg_m3", "kg/m³", Some(p::AIR_DENSITY), "", "Air density; 0 only removes the aerodynamic drag (as `drag_area_m2 = 0` does)."),
    key("body", "grade_percent", "%", Some(p::GRADE_PERCENT), "", "Road grade. The axle loads are static (no load transfer): at 50 % a sedan already moves about 10 % of its weight between the axles; the steepest public roads (about 35 %) are inside."),
    key("brake", "capacity_nm", "N·m", Some(p::BRAKE_CAPACITY), "", "Total wheel brake torque at full pedal: every launch starts with the wheels held by the brake against the stalled converter."),
    key("brake", "front_fraction", "", Some(Range::FRACTION), "", "Front axle's share of the brake torque."),
];

/// A vehicle file as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleFile {
    /// The vehicle's name.
    pub name: String,
    /// Where the vehicle's values come from, in one sentence.
    pub source: String,
    /// Optional free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// A bundled converter's name, or a converter `.toml` path relative to the vehicle file.
    pub converter: String,
    pub engine: EngineSection,
    pub gearbox: GearboxSection,
    pub lockup: LockupSection,
    pub driveline: DrivelineSection,
    pub tyres: TyresSection,
    pub body: BodySection,
    pub brake: BrakeSection,
    /// Where each value comes from: `"section.key" = "text"` (`"assumed: why"` where assumed).
    /// Each key names a value of this file.
    #[serde(default, skip_serializing_if = "IndexMap::is_empty")]
    pub sources: IndexMap<String, String>,
}

/// `[engine]`: full-load curve, drag, torque build-up (aspirated and boost parts, thesis §3.3),
/// idle governor. The converter pump's inertia is the converter's.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct EngineSection {
    /// Crank and flywheel inertia, kg·m², > 0.
    pub inertia_kg_m2: f64,
    /// Idle speed, rad/s, > 0, within `[full_load_speed_rad_s[0], full_load_speed_rad_s[-1])`,
    /// where the full-load torque exceeds the drag.
    pub idle_speed_rad_s: f64,
    /// Speeds of the full-load curve, rad/s, ≥ 0, two or more, strictly increasing.
    pub full_load_speed_rad_s: Vec<f64>,
    /// Full-load torque at those speeds, N·m, from 0 to 100 000, one per speed
    /// ([`super::parameters::ENGINE_TORQUE`]).
    pub full_load_torque_nm: Vec<f64>,
    /// Constant part of the drag, N·m, ≥ 0.
    pub drag_torque_nm: f64,
    /// Viscous part of the drag, N·m·s/rad, ≥ 0.
    pub drag_nm_s_per_rad: f64,
    /// Time constant of the aspirated torque part, s, ≥ 0.001
    /// ([`super::parameters::ENGINE_TIME_CONSTANT`]).
    pub fast_time_constant_s: f64,
    /// Time constant of the boost torque part ("time to torque"), s, ≥ 0.001.
    pub boost_time_constant_s: f64,
    /// Share of the pedal torque built up by boost, from 0 to 1.
    pub boost_fraction: f64,
    /// Idle governor gain, N·m·s/rad, > 0 ([`super::parameters::IDLE_GOVERNOR_GAIN`]).
    pub idle_governor_gain_nm_s_per_rad: f64,
}

/// `[gearbox]`: ratios, efficiency and inertia per gear, shift clutches and shift schedule.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GearboxSection {
    /// Ratio of each gear, gear 1 first, > 0 and ≤ 30 ([`super::parameters::GEAR_RATIO`]), strictly
    /// decreasing, at least one.
    pub ratios: Vec<f64>,
    /// Efficiency of each gear, > 0 and ≤ 1, one per gear.
    pub efficiencies: Vec<f64>,
    /// Inertia of each gear at the gearbox input, kg·m², ≥ 0, one per gear
    /// ([`super::parameters::GEARBOX_INPUT_INERTIA`]).
    pub input_inertia_kg_m2: Vec<f64>,
    /// Output-side inertia, kg·m², ≥ 0.001 ([`super::parameters::GEARBOX_OUTPUT_INERTIA`]).
    pub output_inertia_kg_m2: f64,
    /// Capacity of each shift clutch at the input, N·m, > 0 and ≤ 100 000
    /// ([`super::parameters::CLUTCH_CAPACITY`]).
    pub shift_clutch_capacity_nm: f64,
    /// Torque handover time of a shift, s, > 0.
    pub shift_handover_s: f64,
    /// Fraction of the engine's torque withheld in the inertia phase of an upshift, 0–0.9
    /// ([`super::shift::TORQUE_REDUCTION`]); absent: 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upshift_torque_reduction: Option<f64>,
    /// Target inertia phase of an upshift, s, 0.05–2 ([`super::shift::INERTIA_PHASE`]); absent: the
    /// on-coming clutch keeps `shift_clutch_capacity_nm` ([`super::shift`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upshift_inertia_phase_s: Option<f64>,
    /// Input torque above which an upshift is power-on, N·m, ≥ 0
    /// ([`super::shift::POWER_ON_THRESHOLD`]); absent: 0 (any positive input torque).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upshift_power_on_nm: Option<f64>,
    /// Time constant of the TCU's filter of the pedal the shift schedule reads while the pedal
    /// rises, s, 0–10 ([`super::shift_pedal::PEDAL_TIME_CONSTANT`]); absent: 0 (at once).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shift_pedal_rise_s: Option<f64>,
    /// As `shift_pedal_rise_s`, while the pedal falls; absent: 0 (no filter).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shift_pedal_fall_s: Option<f64>,
    /// Vehicle speed of the upshift from gear k at zero pedal, m/s, > 0, gears − 1 values,
    /// strictly increasing.
    pub upshift_speed_zero_pedal_m_s: Vec<f64>,
    /// As `upshift_speed_zero_pedal_m_s`, at full pedal.
    pub upshift_speed_full_pedal_m_s: Vec<f64>,
    /// Vehicle speed of the downshift from gear k + 1 into k at zero pedal, m/s, > 0, gears − 1
    /// values, strictly increasing, each below the upshift speed of the same index.
    pub downshift_speed_zero_pedal_m_s: Vec<f64>,
    /// As `downshift_speed_zero_pedal_m_s`, at full pedal.
    pub downshift_speed_full_pedal_m_s: Vec<f64>,
}

/// `[lockup]`: the lock-up clutch's capacity, engagement ramp and schedule.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LockupSection {
    /// Kinetic friction capacity, N·m, > 0 and ≤ 100 000 ([`super::parameters::CLUTCH_CAPACITY`]).
    pub capacity_nm: f64,
    /// Static over kinetic capacity, ≥ 1.
    pub static_to_kinetic: f64,
    /// Engagement ramp, s, > 0.
    pub engage_time_s: f64,
    /// Lowest gear with lock-up, from 1 to the number of gears.
    pub min_gear: usize,
    /// Vehicle speed above which it engages at zero pedal, m/s, > 0.
    pub engage_speed_zero_pedal_m_s: f64,
    /// As `engage_speed_zero_pedal_m_s`, at full pedal.
    pub engage_speed_full_pedal_m_s: f64,
}

/// `[driveline]`: final drive and the two branches of the AWD split, each at the propshaft side
/// (referred to the gearbox output, before the final drive).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DrivelineSection {
    /// Final drive ratio, > 0 and ≤ 50 ([`super::parameters::FINAL_DRIVE_RATIO`]).
    pub final_drive_ratio: f64,
    /// Front shaft torsional stiffness, N·m/rad, > 0 and ≤ 1e7 ([`super::parameters::SHAFT_STIFFNESS`]).
    pub front_shaft_stiffness_nm_per_rad: f64,
    /// Rear shaft torsional stiffness, N·m/rad, > 0 and ≤ 1e7.
    pub rear_shaft_stiffness_nm_per_rad: f64,
    /// Front shaft damping, N·m·s/rad, from 0 to 100 000 ([`super::parameters::SHAFT_DAMPING`]).
    pub front_shaft_damping_nm_s_per_rad: f64,
    /// Rear shaft damping, N·m·s/rad, from 0 to 100 000.
    pub rear_shaft_damping_nm_s_per_rad: f64,
    /// Front axle inertia (both wheels, hubs, brakes, half shafts), kg·m², ≥ 0.01
    /// ([`super::parameters::AXLE_INERTIA`]).
    pub front_axle_inertia_kg_m2: f64,
    /// Rear axle inertia, kg·m², ≥ 0.01.
    pub rear_axle_inertia_kg_m2: f64,
}

/// `[tyres]`: rolling radius and the saturating longitudinal force.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TyresSection {
    /// Rolling radius, m, > 0 and ≤ 2 ([`super::parameters::ROLLING_RADIUS`]).
    pub rolling_radius_m: f64,
    /// Friction coefficient μ, > 0.
    pub friction_coefficient: f64,
    /// Slip stiffness (dF_x/dκ over F_z at zero slip), > 0 and ≤ 100
    /// ([`super::parameters::SLIP_STIFFNESS`]).
    pub slip_stiffness: f64,
    /// Front axle's share of the static load, > 0 and < 1
    /// ([`super::parameters::FRONT_LOAD_FRACTION`]).
    pub front_load_fraction: f64,
}

/// `[body]`: mass, aerodynamic drag, rolling resistance, road grade.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BodySection {
    /// Vehicle mass, kg, > 0 and ≤ 200 000 ([`super::parameters::BODY_MASS`]).
    pub mass_kg: f64,
    /// Drag area C_d·A, m², from 0 to 100 ([`super::parameters::DRAG_AREA`]).
    pub drag_area_m2: f64,
    /// Rolling resistance coefficient, ≥ 0.
    pub rolling_resistance: f64,
    /// Air density, kg/m³, ≥ 0 ([`super::parameters::AIR_DENSITY`]).
    pub air_density_kg_m3: f64,
    /// Road grade, %, from −50 to 50 ([`super::parameters::GRADE_PERCENT`]).
    pub grade_percent: f64,
}

/// `[brake]`: the service brake.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BrakeSection {
    /// Total wheel brake torque at full pedal, N·m, > 0 ([`super::parameters::BRAKE_CAPACITY`]).
    pub capacity_nm: f64,
    /// Front axle's share of it, from 0 to 1.
    pub front_fraction: f64,
}

/// A vehicle file read and validated: the file as written and the plant's parameters.
#[derive(Debug, Clone)]
pub struct VehicleDocument {
    pub file: VehicleFile,
    pub vehicle: Vehicle,
}

/// Read a vehicle file's text: parse, check its shape and convert, validate the values once.
pub fn read_vehicle(text: &str) -> CoreResult<VehicleDocument> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| syntax_error(text, &e))?;
    let file = VehicleFile::deserialize(At(&toml::Value::Table(table))).map_err(FileError::into_core)?;
    let vehicle = file.to_vehicle()?;
    vehicle.validate()?;
    file.check_sources()?;
    Ok(VehicleDocument { file, vehicle })
}

impl VehicleFile {
    /// The plant's parameters (the full-load curve is checked for its shape here; the values by
    /// [`Vehicle::validate`]).
    pub fn to_vehicle(&self) -> CoreResult<Vehicle> {
        let (e, g, l, d) = (&self.engine, &self.gearbox, &self.lockup, &self.driveline);
        Ok(Vehicle {
            engine: Engine {
                inertia_kg_m2: e.inertia_kg_m2,
                idle_speed_rad_s: e.idle_speed_rad_s,
                full_load: Curve::new(
                    &field("engine", "full_load_speed_rad_s"),
                    &field("engine", "full_load_torque_nm"),
                    e.full_load_speed_rad_s.clone(),
                    e.full_load_torque_nm.clone(),
                )?,
                drag_torque_nm: e.drag_torque_nm,
                drag_nm_s_per_rad: e.drag_nm_s_per_rad,
                fast_time_constant_s: e.fast_time_constant_s,
                boost_time_constant_s: e.boost_time_constant_s,
                boost_fraction: e.boost_fraction,
                idle_governor_gain_nm_s_per_rad: e.idle_governor_gain_nm_s_per_rad,
            },
            gearbox: Gearbox {
                ratios: g.ratios.clone(),
                efficiencies: g.efficiencies.clone(),
                input_inertia_kg_m2: g.input_inertia_kg_m2.clone(),
                output_inertia_kg_m2: g.output_inertia_kg_m2,
                shift_clutch_capacity_nm: g.shift_clutch_capacity_nm,
                shift_handover_s: g.shift_handover_s,
                upshift_speed_zero_pedal_m_s: g.upshift_speed_zero_pedal_m_s.clone(),
                upshift_speed_full_pedal_m_s: g.upshift_speed_full_pedal_m_s.clone(),
                downshift_speed_zero_pedal_m_s: g.downshift_speed_zero_pedal_m_s.clone(),
                downshift_speed_full_pedal_m_s: g.downshift_speed_full_pedal_m_s.clone(),
                shift_control: ShiftControl {
                    torque_reduction: g.upshift_torque_reduction.unwrap_or(0.0),
                    inertia_phase_s: g.upshift_inertia_phase_s,
                    power_on_nm: g.upshift_power_on_nm.unwrap_or(0.0),
                },
                shift_pedal: PedalFilter {
                    rise_s: g.shift_pedal_rise_s.unwrap_or(0.0),
                    fall_s: g.shift_pedal_fall_s.unwrap_or(0.0),
                },
            },
            lockup: Lockup {
                capacity_nm: l.capacity_nm,
                static_to_kinetic: l.static_to_kinetic,
                engage_time_s: l.engage_time_s,
                min_gear: l.min_gear,
                engage_speed_zero_pedal_m_s: l.engage_speed_zero_pedal_m_s,
                engage_speed_full_pedal_m_s: l.engage_speed_full_pedal_m_s,
            },
            driveline: Driveline {
                final_drive_ratio: d.final_drive_ratio,
                shaft_stiffness_nm_per_rad: [d.front_shaft_stiffness_nm_per_rad, d.rear_shaft_stiffness_nm_per_rad],
                shaft_damping_nm_s_per_rad: [d.front_shaft_damping_nm_s_per_rad, d.rear_shaft_damping_nm_s_per_rad],
                axle_inertia_kg_m2: [d.front_axle_inertia_kg_m2, d.rear_axle_inertia_kg_m2],
            },
            tyres: Tyres {
                rolling_radius_m: self.tyres.rolling_radius_m,
                friction_coefficient: self.tyres.friction_coefficient,
                slip_stiffness: self.tyres.slip_stiffness,
                front_load_fraction: self.tyres.front_load_fraction,
            },
            body: Body {
                mass_kg: self.body.mass_kg,
                drag_area_m2: self.body.drag_area_m2,
                rolling_resistance: self.body.rolling_resistance,
                air_density_kg_m3: self.body.air_density_kg_m3,
                grade_percent: self.body.grade_percent,
            },
            brake: Brake { capacity_nm: self.brake.capacity_nm, front_fraction: self.brake.front_fraction },
        })
    }

    /// The file as a TOML table, in file order (the validated values; for the binding's
    /// `to_dict()`).
    pub fn to_table(&self) -> toml::Table {
        match toml::Value::try_from(self) {
            Ok(toml::Value::Table(t)) => t,
            _ => unreachable!("a vehicle file serialises to a table"),
        }
    }

    /// Each `[sources]` key names a value of this file (`"section.key"`).
    fn check_sources(&self) -> CoreResult<()> {
        let table = self.to_table();
        for key in self.sources.keys() {
            let (section, name) = key.split_once('.').unwrap_or((key, ""));
            let known = SECTIONS.contains(&section)
                && table.get(section).and_then(|s| s.as_table()).is_some_and(|s| s.contains_key(name));
            if !known {
                return Err(CoreError::new(
                    format!("[sources].{}", toml_key(key)),
                    format!("{key:?}"),
                    "a key \"section.name\" naming a value of this vehicle",
                ));
            }
        }
        Ok(())
    }
}

fn syntax_error(text: &str, e: &toml::de::Error) -> CoreError {
    let at = e.span().map_or(0, |s| s.start).min(text.len());
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    let message = e.message().trim().replace('\n', "; ");
    CoreError::new("(syntax)", format!("line {line}, column {column}"), format!("valid TOML ({message})"))
}

/// A key as TOML writes it: bare when it can be, else quoted.
fn toml_key(key: &str) -> String {
    let bare = !key.is_empty() && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare {
        key.to_string()
    } else {
        format!("{key:?}")
    }
}

// ---------------------------------------------------------------------------------------------
// Deserialising a parsed TOML value with errors in the file's dialect

/// One step of the path to a field: a key or an array index.
#[derive(Debug, Clone)]
enum Step {
    Key(String),
    /// A key whose value is a table (a section at the top level).
    Table(String),
    Index(usize),
}

#[derive(Debug, Clone)]
enum Problem {
    /// A key the table does not know; the keys it knows.
    Unknown(&'static [&'static str]),
    /// A required key (of the table at the path) is missing.
    Missing(&'static str),
    /// Anything else: what was expected.
    Expected(String),
}

/// A shape error while deserialising; the path is built outward as it propagates.
#[derive(Debug, Clone)]
struct FileError {
    path: Vec<Step>,
    value: Option<String>,
    problem: Problem,
}

impl FileError {
    fn new(value: Option<String>, expected: String) -> Self {
        Self { path: Vec::new(), value, problem: Problem::Expected(expected) }
    }

    fn at(mut self, step: Step, value: &toml::Value) -> Self {
        let step = match step {
            Step::Key(k) if value.is_table() => Step::Table(k),
            other => other,
        };
        self.path.insert(0, step);
        if self.value.is_none() && matches!(self.problem, Problem::Unknown(_)) {
            self.value = Some(show(value));
        }
        self
    }

    fn into_core(self) -> CoreError {
        let value = self.value.clone().unwrap_or_else(|| "missing".into());
        match self.problem {
            Problem::Unknown(known) => {
                let parent = match self.path.len() {
                    0 | 1 => "the top level".to_string(),
                    n => name(&self.path[..n - 1]),
                };
                let known = known.join(", ");
                CoreError::new(
                    name(&self.path),
                    value,
                    format!("a known key of {parent}: {known} (this key is unknown)"),
                )
            }
            Problem::Missing(key) => {
                let mut path = self.path;
                path.push(Step::Key(key.to_string()));
                let what =
                    if path.len() == 1 && (SECTIONS.contains(&key) || key == "sources") { "section" } else { "key" };
                CoreError::new(name(&path), "missing", format!("this required {what}"))
            }
            Problem::Expected(expected) => CoreError::new(name(&self.path), value, expected),
        }
    }
}

/// A path as the file writes it: `converter`, `[brake]`, `[gearbox].ratios[3]`.
fn name(path: &[Step]) -> String {
    let mut out = String::new();
    for (i, step) in path.iter().enumerate() {
        match step {
            Step::Key(k) | Step::Table(k)
                if i == 0 && (path.len() > 1 || SECTIONS.contains(&k.as_str()) || k == "sources") =>
            {
                out.push_str(&format!("[{}]", toml_key(k)))
            }
            Step::Table(k) if i == 0 => out.push_str(&format!("[{}]", toml_key(k))),
            Step::Key(k) if i == 0 => out.push_str(&toml_key(k)),
            Step::Key(k) | Step::Table(k) => out.push_str(&format!(".{}", toml_key(k))),
            Step::Index(n) => out.push_str(&format!("[{n}]")),
        }
    }
    if out.is_empty() {
        "(file)".into()
    } else {
        out
    }
}

/// A value as the file writes it, short.
fn show(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => format!("{s:?}"),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::Float(f) => format!("{f:?}"),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Datetime(d) => d.to_string(),
        toml::Value::Array(a) => {
            let text = format!("[{}]", a.iter().map(show).collect::<Vec<_>>().join(", "));
            if text.len() <= 60 {
                text
            } else {
                format!("an array of {} values", a.len())
            }
        }
        toml::Value::Table(t) => format!("a table of {} key{}", t.len(), if t.len() == 1 { "" } else { "s" }),
    }
}

/// What a deserialiser expects, in the file's words.
fn words(expected: &dyn de::Expected) -> String {
    let text = expected.to_string();
    match text.as_str() {
        "f64" | "f32" => "a number".into(),
        "usize" | "u64" | "u32" | "u16" | "u8" | "i64" | "i32" => "an integer".into(),
        "a sequence" => "an array".into(),
        "a map" => "a table".into(),
        t if t.starts_with("struct ") => "a table (section)".into(),
        _ => text,
    }
}

/// An unexpected value: its kind and how the file writes it.
fn unexpected(u: &Unexpected<'_>) -> (String, String) {
    match u {
        Unexpected::Str(s) => ("a string".into(), format!("{s:?}")),
        Unexpected::Float(f) => ("a float".into(), format!("{f:?}")),
        Unexpected::Signed(i) => ("an integer".into(), i.to_string()),
        Unexpected::Unsigned(i) => ("an integer".into(), i.to_string()),
        Unexpected::Bool(b) => ("a boolean".into(), b.to_string()),
        Unexpected::Seq => ("an array".into(), "an array".into()),
        Unexpected::Map => ("a table".into(), "a table".into()),
        other => (other.to_string(), other.to_string()),
    }
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.clone().into_core())
    }
}

impl std::error::Error for FileError {}

impl de::Error for FileError {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Self::new(None, msg.to_string())
    }
    fn invalid_type(unexp: Unexpected<'_>, exp: &dyn de::Expected) -> Self {
        let (kind, value) = unexpected(&unexp);
        let shown = if kind == value { String::new() } else { format!(" ({value})") };
        Self::new(Some(value), format!("{}, not {kind}{shown}", words(exp)))
    }
    fn invalid_value(unexp: Unexpected<'_>, exp: &dyn de::Expected) -> Self {
        let (_, value) = unexpected(&unexp);
        let expected = match words(exp).as_str() {
            "an integer" => "an integer of 0 or more".to_string(),
            w => w.to_string(),
        };
        Self::new(Some(value), expected)
    }
    fn unknown_field(_field: &str, expected: &'static [&'static str]) -> Self {
        Self { path: Vec::new(), value: None, problem: Problem::Unknown(expected) }
    }
    fn missing_field(field: &'static str) -> Self {
        Self { path: Vec::new(), value: None, problem: Problem::Missing(field) }
    }
}

/// A deserialiser over a parsed TOML value with [`FileError`]s.
struct At<'a>(&'a toml::Value);

impl<'de> Deserializer<'de> for At<'de> {
    type Error = FileError;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, FileError> {
        match self.0 {
            toml::Value::String(s) => visitor.visit_borrowed_str(s),
            toml::Value::Integer(i) => visitor.visit_i64(*i),
            toml::Value::Float(f) => visitor.visit_f64(*f),
            toml::Value::Boolean(b) => visitor.visit_bool(*b),
            toml::Value::Datetime(d) => Err(FileError::new(
                Some(d.to_string()),
                format!("{}, not a date-time", words(&visitor as &dyn de::Expected)),
            )),
            toml::Value::Array(a) => visitor.visit_seq(Elements { items: a.iter().enumerate() }),
            toml::Value::Table(t) => visitor.visit_map(Entries { items: t.iter(), value: None }),
        }
    }

    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, FileError> {
        visitor.visit_some(self)
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, FileError> {
        match self.0 {
            toml::Value::Table(_) => self.deserialize_any(visitor),
            other => Err(FileError::new(Some(show(other)), "a table (section)".into())),
        }
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf unit
        unit_struct newtype_struct seq tuple tuple_struct map enum identifier ignored_any
    }
}

struct Elements<'a> {
    items: std::iter::Enumerate<std::slice::Iter<'a, toml::Value>>,
}

impl<'de> SeqAccess<'de> for Elements<'de> {
    type Error = FileError;

    fn next_element_seed<T: DeserializeSeed<'de>>(&mut self, seed: T) -> Result<Option<T::Value>, FileError> {
        match self.items.next() {
            None => Ok(None),
            Some((i, v)) => seed.deserialize(At(v)).map(Some).map_err(|e| e.at(Step::Index(i), v)),
        }
    }
}

struct Entries<'a> {
    items: toml::map::Iter<'a, String, toml::Value>,
    value: Option<(&'a String, &'a toml::Value)>,
}

impl<'de> MapAccess<'de> for Entries<'de> {
    type Error = FileError;

    fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> Result<Option<K::Value>, FileError> {
        let Some((k, v)) = self.items.next() else { return Ok(None) };
        self.value = Some((k, v));
        seed.deserialize(de::value::BorrowedStrDeserializer::<FileError>::new(k))
            .map(Some)
            .map_err(|e| e.at(Step::Key(k.clone()), v))
    }

    fn next_value_seed<T: DeserializeSeed<'de>>(&mut self, seed: T) -> Result<T::Value, FileError> {
        let (k, v) = self.value.take().expect("a value follows its key");
        seed.deserialize(At(v)).map_err(|e| e.at(Step::Key(k.clone()), v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SEDAN: &str = include_str!("../../tests/data/sedan.toml");

    fn edited(section: &str, line_start: &str, new_line: &str) -> String {
        let mut in_section = section.is_empty();
        SEDAN
            .lines()
            .map(|l| {
                if l.starts_with('[') {
                    in_section = l == format!("[{section}]");
                }
                if in_section && l.starts_with(line_start) {
                    new_line.to_string()
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    fn error(text: &str) -> CoreError {
        read_vehicle(text).unwrap_err()
    }

    #[test]
    fn the_sedan_reads_and_round_trips() {
        let doc = read_vehicle(SEDAN).unwrap();
        assert_eq!(doc.file.name, "sedan");
        assert_eq!(doc.vehicle.gearbox.ratios.len(), 8);
        let t = doc.file.to_table();
        let keys: Vec<&str> = t.keys().map(|k| k.as_str()).collect();
        assert_eq!(keys[..3], ["name", "source", "converter"]);
        assert_eq!(keys[3..], SECTIONS);
        assert_eq!(t["lockup"]["min_gear"].as_integer(), Some(3));
    }

    #[test]
    fn shape_errors_name_the_field_as_the_file_does() {
        let e = error(&edited("engine", "inertia_kg_m2", "inertia_kgm2 = 0.2"));
        assert_eq!(e.field, "[engine].inertia_kgm2");
        assert!(e.expected.contains("a known key of [engine]: inertia_kg_m2,"), "{e}");
        let e = error(&format!("{SEDAN}\n[turbo]\nlag_s = 1.0\n"));
        assert_eq!((e.field.as_str(), e.value.as_str()), ("[turbo]", "a table of 1 key"));
        assert!(e.expected.contains("the top level"), "{e}");
        let e = error(&edited("body", "mass_kg", ""));
        assert_eq!(
            (e.field.as_str(), e.value.as_str(), e.expected.as_str()),
            ("[body].mass_kg", "missing", "this required key")
        );
        let e = error(&edited("body", "mass_kg", "mass_kg = \"1930\""));
        assert_eq!((e.field.as_str(), e.value.as_str()), ("[body].mass_kg", "\"1930\""));
        assert_eq!(e.expected, "a number, not a string (\"1930\")");
        let e = error(&edited("lockup", "min_gear", "min_gear = 3.0"));
        assert_eq!((e.field.as_str(), e.expected.as_str()), ("[lockup].min_gear", "an integer, not a float (3.0)"));
        let e = error(&edited("lockup", "min_gear", "min_gear = -1"));
        assert_eq!((e.field.as_str(), e.value.as_str()), ("[lockup].min_gear", "-1"));
        let e = error(&edited("gearbox", "ratios", "ratios = [5.25, \"x\"]"));
        assert_eq!(e.field, "[gearbox].ratios[1]");
        let e = error(&edited("", "converter", ""));
        assert_eq!((e.field.as_str(), e.value.as_str()), ("converter", "missing"));
        let e = error(&SEDAN.replace("[brake]", "[brakes]"));
        assert_eq!(e.field, "[brakes]");
        let text = SEDAN.split("[brake]").next().unwrap();
        let e = error(text);
        assert_eq!((e.field.as_str(), e.expected.as_str()), ("[brake]", "this required section"));
        let e = error(&format!("{SEDAN}\n[sources]\n\"engine.turbo_lag_s\" = \"assumed: x\"\n"));
        assert_eq!(e.field, "[sources].\"engine.turbo_lag_s\"");
    }

    #[test]
    fn value_errors_name_the_field_as_the_file_does() {
        let e = error(&edited("gearbox", "ratios", "ratios = [5.25, 3.03, 1.95, 1.46, 1.22, 1.0, 0.81, 0.81]"));
        assert_eq!(e.field, "[gearbox].ratios[7]");
        assert!(e.expected.starts_with("strictly decreasing"), "{e}");
        let e = error(&edited(
            "engine",
            "full_load_torque_nm",
            "full_load_torque_nm = [120.0, 200.0, inf, 400.0, 400.0, 350.0, 280.0]",
        ));
        assert_eq!((e.field.as_str(), e.expected.as_str()), ("[engine].full_load_torque_nm[2]", "a finite number"));
        let e = error(&edited("tyres", "slip_stiffness", "slip_stiffness = nan"));
        assert_eq!((e.field.as_str(), e.value.as_str()), ("[tyres].slip_stiffness", "NaN"));
        let e = error(&edited("lockup", "min_gear", "min_gear = 9"));
        assert_eq!(
            (e.field.as_str(), e.expected.as_str()),
            ("[lockup].min_gear", "a gear from 1 to 8 ([gearbox].ratios)")
        );
    }

    #[test]
    fn syntax_errors_keep_line_and_column() {
        let e = error("name = \"x\"\n[engine\n");
        assert_eq!(e.field, "(syntax)");
        assert!(e.value.starts_with("line 2, column"), "{e}");
        assert!(!e.expected.contains('\n'));
    }

    /// The six ranges the file check and the core once disagreed on: at the bound and over it,
    /// one answer each, naming the field as the file does.
    #[test]
    fn the_six_settled_ranges() {
        let cases = [
            ("body", "grade_percent", "50.0", "60.0", "a finite number at least -50 and at most 50"),
            ("body", "grade_percent", "-50.0", "-50.5", "a finite number at least -50 and at most 50"),
            (
                "engine",
                "idle_governor_gain_nm_s_per_rad",
                "1e-3",
                "0.0",
                "a finite number greater than 0 and at most 1000",
            ),
            ("tyres", "front_load_fraction", "0.999", "1.0", "a finite number greater than 0 and less than 1"),
            ("tyres", "front_load_fraction", "0.001", "0.0", "a finite number greater than 0 and less than 1"),
            ("body", "air_density_kg_m3", "0.0", "-0.1", "a finite number at least 0 and at most 10"),
            ("brake", "capacity_nm", "1e-3", "0.0", "a finite number greater than 0"),
        ];
        for (section, key, ok, bad, expected) in cases {
            read_vehicle(&edited(section, key, &format!("{key} = {ok}"))).unwrap();
            let e = error(&edited(section, key, &format!("{key} = {bad}")));
            assert_eq!((e.field, e.expected.as_str()), (format!("[{section}].{key}"), expected));
        }
        let ok = "input_inertia_kg_m2 = [0.0, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05]";
        read_vehicle(&edited("gearbox", "input_inertia_kg_m2", ok)).unwrap();
        let bad = "input_inertia_kg_m2 = [-0.01, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05]";
        let e = error(&edited("gearbox", "input_inertia_kg_m2", bad));
        assert_eq!(
            (e.field.as_str(), e.expected.as_str()),
            ("[gearbox].input_inertia_kg_m2[0]", "a finite number at least 0")
        );
    }

    /// The sedan with `key = value` in `[section]`: the key's line replaced, or added at the
    /// section's top when the sedan does not set it (an optional key).
    fn with_key(section: &str, key: &str, value: &str) -> String {
        let (header, line) = (format!("[{section}]"), format!("{key} = {value}"));
        let mut in_section = false;
        let mut out = Vec::new();
        for l in SEDAN.lines() {
            if l.starts_with('[') {
                in_section = l == header;
            }
            if in_section && l.split('=').next().map(str::trim) == Some(key) {
                continue;
            }
            out.push(l.to_string());
            if l == header {
                out.push(line.clone());
            }
        }
        out.join("\n")
    }

    /// `v` as TOML writes it: an array (the sedan's, with the element at `index` set to `v`) or a number.
    fn probe_value(sedan: &toml::Value, index: Option<usize>, v: f64) -> String {
        match (sedan, index) {
            (toml::Value::Array(a), Some(i)) => {
                let mut values: Vec<f64> = a.iter().map(|x| x.as_float().unwrap()).collect();
                values[i] = v;
                format!("[{}]", values.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(", "))
            }
            _ => format!("{v:?}"),
        }
    }

    /// Every row of [`SCHEMA`] with a range is the validator's: just beyond each end (the end
    /// itself when it is open) the file is refused on that key with exactly the range's text, and
    /// at the end (just inside when it is open) that range does not refuse it. For an array the
    /// probe is its smallest (lower end) or largest (upper end) element.
    #[test]
    fn every_schema_range_is_the_validators() {
        let sedan: toml::Table = SEDAN.parse().unwrap();
        for row in SCHEMA {
            let Some(range) = row.range else { continue };
            let name = field(row.section, row.key);
            let value = sedan.get(row.section).and_then(|s| s.get(row.key)).cloned().unwrap_or(toml::Value::Float(0.0));
            let numbers: Vec<f64> = match &value {
                toml::Value::Array(a) => a.iter().map(|x| x.as_float().unwrap()).collect(),
                v => vec![v.as_float().unwrap_or(0.0)],
            };
            let arg = |pick: fn(f64, f64) -> bool| {
                let i = (0..numbers.len()).fold(0, |b, i| if pick(numbers[i], numbers[b]) { i } else { b });
                value.is_array().then_some(i)
            };
            let ends = [(range.low, -1.0, arg(|a, b| a < b)), (range.high, 1.0, arg(|a, b| a > b))];
            for (end, outward, index) in ends {
                let Some((bound, closed)) = end else { continue };
                let delta = 1e-6 * bound.abs().max(1.0) * outward;
                let (outside, inside) = if closed { (bound + delta, bound) } else { (bound, bound - delta) };
                let text = with_key(row.section, row.key, &probe_value(&value, index, outside));
                let e = read_vehicle(&text).expect_err(&format!("{name} = {outside} must be refused"));
                assert!(e.field == name || e.field.starts_with(&format!("{name}[")), "{name} = {outside}: {e}");
                assert_eq!(e.expected, range.expected(), "{name} = {outside}");
                if let Err(e) = read_vehicle(&with_key(row.section, row.key, &probe_value(&value, index, inside))) {
                    let on_key = e.field == name || e.field.starts_with(&format!("{name}["));
                    assert!(!(on_key && e.expected.starts_with("a finite number")), "{name} = {inside}: {e}");
                }
            }
        }
    }

    /// [`SCHEMA`] lists every key the file's deserialiser knows, section by section, in file order.
    #[test]
    fn the_schema_lists_every_key() {
        for section in ["", "engine", "gearbox", "lockup", "driveline", "tyres", "body", "brake"] {
            let text = if section.is_empty() {
                format!("unknown_key = 1\n{SEDAN}")
            } else {
                with_key(section, "unknown_key", "1")
            };
            let e = error(&text);
            let known = e.expected.split(": ").nth(1).unwrap().split(" (").next().unwrap();
            let known: Vec<&str> = known.split(", ").filter(|k| !SECTIONS.contains(k) && *k != "sources").collect();
            let rows: Vec<&str> = SCHEMA.iter().filter(|r| r.section == section).map(|r| r.key).collect();
            assert_eq!(rows, known, "[{section}]");
        }
        assert_eq!(
            SCHEMA.iter().find(|r| r.key == "mass_kg").unwrap().range_text(),
            "a finite number at least 50 and at most 200000"
        );
    }
}
