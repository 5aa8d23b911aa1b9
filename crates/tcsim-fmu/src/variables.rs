//! The FMU's variable table: the one owner of every variable's value reference, name, causality,
//! variability, unit, description and start value, of which variables are continuous states and
//! derivatives, of the tunable parameters (value references from [`FIRST_PARAMETER`]), of the
//! number of event indicators and of the unit definitions.
//!
//! The instance (`instance.rs`) dispatches `fmi2GetReal`/`fmi2SetReal` and sizes its arrays with
//! it; `tcsim export-fmu` writes `modelDescription.xml` from it (through `tcsim._core`'s
//! `fmu_variables`, `fmu_units`, `fmu_causalities` and `fmu_event_indicators`). Signals keep their
//! value reference whatever the model and the causality; a model lists the signals it has.

use tcsim_core::converter::hrovat_tobler::HtParam;
use tcsim_core::converter::spec::LAG_KEY;
use tcsim_core::engine::lockup::DEFAULT_STATIC_TO_KINETIC;
use tcsim_core::engine::mode_view::{EVENT_INDICATORS, LOCKUP_INDICATOR};
use tcsim_core::engine::stepper::Causality;

/// `modelIdentifier` of the FMU: the binary is `binaries/<platform>/tcsim_converter.<ext>`.
pub const MODEL_IDENTIFIER: &str = "tcsim_converter";
/// Value reference of the first tunable parameter; parameter i has `FIRST_PARAMETER + i`.
pub const FIRST_PARAMETER: u32 = 100;
/// Value reference of the derivative of state coordinate 0 (pump speed); coordinate c has
/// `FIRST_DERIVATIVE + c` (1 turbine speed, 2 stator speed, 3 flow).
pub const FIRST_DERIVATIVE: u32 = 20;
/// Number of coordinates of a converter model (pump, turbine, stator speed, flow).
pub const COORDINATES: u32 = 4;
/// Value references of the signals and the input rates: `0..SIGNAL_SLOTS`.
pub const SIGNAL_SLOTS: usize = 20;

/// Value references of the signals.
pub mod vr {
    pub const PUMP_TORQUE: u32 = 0;
    pub const PUMP_SPEED: u32 = 1;
    pub const TURBINE_SPEED: u32 = 2;
    pub const TURBINE_TORQUE: u32 = 3;
    pub const SPEED_RATIO: u32 = 4;
    pub const TORQUE_RATIO: u32 = 5;
    pub const FLOW: u32 = 6;
    pub const STATOR_SPEED: u32 = 7;
    pub const STATOR_TORQUE: u32 = 8;
    pub const EFFECTIVE_PUMP_TORQUE: u32 = 9;
    pub const EFFECTIVE_TURBINE_TORQUE: u32 = 10;
    pub const EFFECTIVE_TORQUE_RATIO: u32 = 11;
    pub const PUMP_ACCEL: u32 = 12;
    pub const TURBINE_ACCEL: u32 = 13;
    pub const LOAD_TORQUE: u32 = 14;
    pub const LOCKUP_CAPACITY: u32 = 15;
    pub const LOCKUP_TORQUE: u32 = 16;
    pub const LOCKUP_STATE: u32 = 17;
    pub const LOCKUP_SLIP: u32 = 18;
    pub const LAG_TORQUE: u32 = 19;
    pub const START_FROM_STEADY_STATE: u32 = 30;
    pub const INITIAL_PUMP_SPEED: u32 = 31;
    pub const INITIAL_STATOR_SPEED: u32 = 32;
    pub const INITIAL_FLOW: u32 = 33;
    pub const INITIAL_TURBINE_SPEED: u32 = 34;
    pub const LOAD_INERTIA: u32 = 35;
    pub const LOAD_DRAG: u32 = 36;
    pub const LOCKUP_STATIC_TO_KINETIC: u32 = 37;
}

/// The converter models an FMU can hold (`kind` of the model specification).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    Table,
    HrovatTobler,
    QuasiDynamic,
}

impl Model {
    pub const ALL: [Model; 3] = [Model::Table, Model::HrovatTobler, Model::QuasiDynamic];

    /// The model of a specification's `kind`.
    pub fn from_kind(kind: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.kind() == kind)
    }

    pub fn kind(self) -> &'static str {
        match self {
            Model::Table => "table",
            Model::HrovatTobler => "hrovat-tobler",
            Model::QuasiDynamic => "quasi-dynamic",
        }
    }

    /// Event indicators in Model Exchange: the stator clutch and the flow direction (Hrovat &
    /// Tobler, the only model with a stator clutch), then the lock-up clutch (every model).
    pub fn event_indicators(self) -> usize {
        self.indicator_slots().len()
    }

    /// The slots of `tcsim_core::engine::mode_view::ModeView::indicators` that are the FMU's event
    /// indicators, in order: all of them for Hrovat & Tobler, the lock-up clutch's for the others.
    pub fn indicator_slots(self) -> Vec<usize> {
        match self {
            Model::HrovatTobler => (0..EVENT_INDICATORS).collect(),
            Model::Table | Model::QuasiDynamic => vec![LOCKUP_INDICATOR],
        }
    }
}

/// The `--causality` choices, by name, with the value references of their two inputs (the drive's;
/// every causality has the lock-up capacity input [`vr::LOCKUP_CAPACITY`] besides).
pub const CAUSALITIES: [(&str, Causality, [u32; 2]); 3] = [
    ("pump-torque", Causality::PumpTorqueTurbineSpeed, [vr::PUMP_TORQUE, vr::TURBINE_SPEED]),
    ("speeds", Causality::Speeds, [vr::PUMP_SPEED, vr::TURBINE_SPEED]),
    ("torques", Causality::Torques, [vr::PUMP_TORQUE, vr::LOAD_TORQUE]),
];

/// The inputs of every causality besides its two: the lock-up clutch's capacity.
pub const COMMON_INPUTS: [u32; 1] = [vr::LOCKUP_CAPACITY];

/// Every input of a causality: its two, then [`COMMON_INPUTS`].
pub fn all_inputs(causality: Causality) -> Vec<u32> {
    inputs(causality).into_iter().chain(COMMON_INPUTS).collect()
}

/// The causality of a `--causality` name.
pub fn causality_of(name: &str) -> Option<Causality> {
    CAUSALITIES.iter().find(|c| c.0 == name).map(|c| c.1)
}

/// The value references of the two inputs of a causality.
pub fn inputs(causality: Causality) -> [u32; 2] {
    CAUSALITIES.iter().find(|c| c.1 == causality).map(|c| c.2).expect("every causality is in CAUSALITIES")
}

/// A signal: an input or an output, depending on the causality.
#[derive(Debug, Clone, Copy)]
pub struct SignalDef {
    pub vr: u32,
    /// Name (conventions.md), also the engine's output column.
    pub name: &'static str,
    pub unit: &'static str,
    pub description: &'static str,
    /// The models that have the signal.
    pub models: &'static [Model],
    /// The model coordinate, when the signal is a continuous state (when it is not an input).
    pub state: Option<usize>,
    /// The start value when the signal is an input.
    pub start: Option<f64>,
    /// The causality the signal belongs to, if only one has it (the load torque).
    pub only: Option<Causality>,
    /// Only in an FMU of the table model with the lag ([`has_lag`]): the lag state.
    pub lag: bool,
}

const ALL: &[Model] = &Model::ALL;

const fn signal(vr: u32, name: &'static str, unit: &'static str, description: &'static str) -> SignalDef {
    SignalDef { vr, name, unit, description, models: ALL, state: None, start: None, only: None, lag: false }
}

/// The signals in value-reference order (a part-load stall as the inputs' start: 50 N·m at the
/// pump, or the pump at 150 rad/s; no load torque, an open lock-up clutch).
pub const SIGNALS: [SignalDef; 18] = [
    SignalDef {
        start: Some(50.0),
        ..signal(vr::PUMP_TORQUE, "pump_torque_nm", "N.m", "Torque on the pump (engine torque at the converter input)")
    },
    SignalDef {
        state: Some(0),
        start: Some(150.0),
        ..signal(vr::PUMP_SPEED, "pump_speed_rad_s", "rad/s", "Pump (impeller) speed")
    },
    SignalDef {
        state: Some(1),
        start: Some(0.0),
        ..signal(vr::TURBINE_SPEED, "turbine_speed_rad_s", "rad/s", "Turbine speed (transmission input speed)")
    },
    signal(
        vr::TURBINE_TORQUE,
        "turbine_torque_nm",
        "N.m",
        "Torque delivered by the turbine to the transmission (positive in drive)",
    ),
    signal(vr::SPEED_RATIO, "speed_ratio", "1", "Speed ratio SR = turbine speed / pump speed"),
    signal(vr::TORQUE_RATIO, "torque_ratio", "1", "Torque ratio TR = turbine torque / pump torque"),
    SignalDef {
        models: &[Model::HrovatTobler, Model::QuasiDynamic],
        state: Some(3),
        ..signal(vr::FLOW, "flow_m3_s", "m3/s", "Volume flow through the torus")
    },
    SignalDef {
        models: &[Model::HrovatTobler],
        state: Some(2),
        ..signal(
            vr::STATOR_SPEED,
            "stator_speed_rad_s",
            "rad/s",
            "Stator speed (zero while the one-way clutch holds it)",
        )
    },
    signal(vr::STATOR_TORQUE, "stator_torque_nm", "N.m", "Torque of the stator one-way clutch on the stator"),
    signal(
        vr::EFFECTIVE_PUMP_TORQUE,
        "effective_pump_torque_nm",
        "N.m",
        "Effective pump input torque T_p - I_p dw_p/dt (LS16 eq 3.3)",
    ),
    signal(
        vr::EFFECTIVE_TURBINE_TORQUE,
        "effective_turbine_torque_nm",
        "N.m",
        "Effective turbine output torque T_t + I_t dw_t/dt (LS16 eq 3.4)",
    ),
    signal(
        vr::EFFECTIVE_TORQUE_RATIO,
        "effective_torque_ratio",
        "1",
        "Effective torque ratio: effective turbine / effective pump torque",
    ),
    SignalDef {
        start: Some(0.0),
        only: Some(Causality::Torques),
        ..signal(
            vr::LOAD_TORQUE,
            "load_torque_nm",
            "N.m",
            "Load torque on the turbine shaft (the driveline's, reflected to the turbine), opposing forward \
             rotation: positive decelerates the turbine",
        )
    },
    SignalDef {
        start: Some(0.0),
        ..signal(
            vr::LOCKUP_CAPACITY,
            "lockup_capacity_nm",
            "N.m",
            "Lock-up clutch capacity command (>= 0; 0 open): the torque it transmits while slipping",
        )
    },
    signal(
        vr::LOCKUP_TORQUE,
        "lockup_torque_nm",
        "N.m",
        "Torque the lock-up clutch transmits from pump to turbine (included in pump and turbine torque)",
    ),
    signal(vr::LOCKUP_STATE, "lockup_state", "1", "Lock-up clutch state: 0 open, 1 slipping, 2 locked"),
    signal(vr::LOCKUP_SLIP, "lockup_slip_rad_s", "rad/s", "Lock-up clutch slip: pump speed - turbine speed"),
    SignalDef {
        models: &[Model::Table],
        state: Some(3),
        lag: true,
        ..signal(
            vr::LAG_TORQUE,
            "lagged_pump_torque_nm",
            "N.m",
            "Lag state T_lag of the table model's first-order lag: the lagged steady pump torque (docs/lag.md)",
        )
    },
];

/// Whether an FMU with these tunable parameters is of a table model with the first-order lag (its
/// specification has `lag_time_constant_s`): the lag state is then a continuous state.
pub fn has_lag(parameters: &[Parameter]) -> bool {
    parameters.iter().any(|p| p.key == LAG_KEY)
}

/// The unit of the time derivative of a quantity of unit `unit`.
pub fn derivative_unit(unit: &str) -> String {
    match unit {
        "N.m" => "N.m/s".to_string(),
        _ => format!("{unit}2"),
    }
}

/// A rate of a speed input, for Model Exchange: an optional input, zero when not connected.
/// Co-Simulation takes the rates from `fmi2SetRealInputDerivatives` or from the last
/// communication interval instead.
#[derive(Debug, Clone, Copy)]
pub struct RateDef {
    pub vr: u32,
    pub name: &'static str,
    /// The input whose rate it is.
    pub of: u32,
    pub description: &'static str,
}

/// Unit and start value of the input rates.
pub const RATE_UNIT: &str = "rad/s2";
pub const RATE_START: f64 = 0.0;

pub const RATES: [RateDef; 2] = [
    RateDef {
        vr: vr::PUMP_ACCEL,
        name: "pump_accel_rad_s2",
        of: vr::PUMP_SPEED,
        description: "Rate of the pump speed input (0 if not connected; Co-Simulation: over the coming step, else the last interval's)",
    },
    RateDef {
        vr: vr::TURBINE_ACCEL,
        name: "turbine_accel_rad_s2",
        of: vr::TURBINE_SPEED,
        description: "Rate of the turbine speed input (0 if not connected; Co-Simulation: over the coming step, else the last interval's)",
    },
];

/// A start-value parameter (value references 30–33, fixed after initialisation).
#[derive(Debug, Clone, Copy)]
pub struct StartDef {
    pub vr: u32,
    /// The state signal it gives the initial value of (none: the `start_from_steady_state` flag).
    pub of: Option<u32>,
    pub start: f64,
}

/// `start_from_steady_state` (1: the steady state consistent with the inputs, as `tcsim replay`;
/// 0: the `initial_*` values), then the initial pump speed, stator speed, flow and turbine speed
/// (the last only where the turbine speed is a state, [`Causality::Torques`]: there it is the
/// start's turbine speed whatever `start_from_steady_state`, as drive (c)'s; 0, a vehicle at rest).
pub const START_PARAMETERS: [StartDef; 5] = [
    StartDef { vr: vr::START_FROM_STEADY_STATE, of: None, start: 1.0 },
    StartDef { vr: vr::INITIAL_PUMP_SPEED, of: Some(vr::PUMP_SPEED), start: 150.0 },
    StartDef { vr: vr::INITIAL_STATOR_SPEED, of: Some(vr::STATOR_SPEED), start: 0.0 },
    StartDef { vr: vr::INITIAL_FLOW, of: Some(vr::FLOW), start: 0.05 },
    StartDef { vr: vr::INITIAL_TURBINE_SPEED, of: Some(vr::TURBINE_SPEED), start: 0.0 },
];
const START_FROM_STEADY_STATE: &str = "start_from_steady_state";
const START_FROM_STEADY_STATE_DESCRIPTION: &str =
    "1: start at the steady state consistent with the inputs (as tcsim replay); 0: at the initial_* values";

/// A fixed parameter of the drive (value references 35–37, fixed after initialisation): the load of
/// [`Causality::Torques`] and the lock-up clutch's friction ratio.
#[derive(Debug, Clone, Copy)]
pub struct DriveParameterDef {
    pub vr: u32,
    pub name: &'static str,
    pub unit: &'static str,
    pub description: &'static str,
    pub start: f64,
    /// The least value allowed (the value must be finite too).
    pub min: f64,
    /// The causality that has it, if only one does.
    pub only: Option<Causality>,
}

/// The drive's fixed parameters.
pub const DRIVE_PARAMETERS: [DriveParameterDef; 3] = [
    DriveParameterDef {
        vr: vr::LOAD_INERTIA,
        name: "load_inertia_kg_m2",
        unit: "kg.m2",
        description: "Load inertia on the turbine (driveline reflected to the turbine; 0: the host's model has it)",
        start: 0.0,
        min: 0.0,
        only: Some(Causality::Torques),
    },
    DriveParameterDef {
        vr: vr::LOAD_DRAG,
        name: "load_drag_nm_s2",
        unit: "N.m.s2/rad2",
        description: "Load drag on the turbine: drag * w_t * |w_t| opposing rotation, added to load_torque_nm",
        start: 0.0,
        min: 0.0,
        only: Some(Causality::Torques),
    },
    DriveParameterDef {
        vr: vr::LOCKUP_STATIC_TO_KINETIC,
        name: "lockup_static_to_kinetic",
        unit: "1",
        description: "Lock-up clutch: static-to-kinetic friction ratio (a locked clutch breaks away above it \
                      times lockup_capacity_nm)",
        start: DEFAULT_STATIC_TO_KINETIC,
        min: 1.0,
        only: None,
    },
];

/// The drive parameter of value reference `vr`: its position in [`DRIVE_PARAMETERS`].
pub fn drive_parameter(vr: u32) -> Option<usize> {
    DRIVE_PARAMETERS.iter().position(|d| d.vr == vr)
}

/// The start-value parameter of value reference `vr`: its position in [`START_PARAMETERS`].
pub fn start_parameter(vr: u32) -> Option<usize> {
    START_PARAMETERS.iter().position(|s| s.vr == vr)
}

/// The signal of value reference `vr`.
pub fn signal_def(vr: u32) -> Option<&'static SignalDef> {
    SIGNALS.iter().find(|s| s.vr == vr)
}

/// The name of signal or input rate `vr` (`0..SIGNAL_SLOTS`).
pub fn signal_name(vr: u32) -> Option<&'static str> {
    signal_def(vr).map(|s| s.name).or_else(|| RATES.iter().find(|r| r.vr == vr).map(|r| r.name))
}

/// Whether `vr` may be set under `causality`: one of its inputs or the rate of a speed input.
pub fn is_input(causality: Causality, vr: u32) -> bool {
    let inputs = all_inputs(causality);
    inputs.contains(&vr) || RATES.iter().any(|r| r.vr == vr && inputs.contains(&r.of))
}

/// Whether signal `vr` is a variable of the FMU under `causality` (not another causality's own).
pub fn has_signal(causality: Causality, vr: u32) -> bool {
    signal_def(vr).is_some_and(|s| s.only.is_none_or(|c| c == causality))
}

/// Whether `vr` is the derivative of a model coordinate.
pub fn is_derivative(vr: u32) -> bool {
    (FIRST_DERIVATIVE..FIRST_DERIVATIVE + COORDINATES).contains(&vr)
}

/// The continuous states of a model (with the table model's lag or not) under a causality in Model
/// Exchange: (signal, coordinate), in coordinate order.
pub fn states(model: Model, causality: Causality, lag: bool) -> Vec<(&'static SignalDef, usize)> {
    let inputs = inputs(causality);
    let mut states: Vec<_> = SIGNALS
        .iter()
        .filter(|s| s.models.contains(&model) && !inputs.contains(&s.vr) && (lag || !s.lag))
        .filter_map(|s| s.state.map(|c| (s, c)))
        .collect();
    states.sort_by_key(|&(_, c)| c);
    states
}

// ---------------------------------------------------------------------------------------------
// Units

/// A unit of `<UnitDefinitions>`: FMI name, SI base-unit exponents, display units with factors.
#[derive(Debug, Clone, Copy)]
pub struct UnitDef {
    pub name: &'static str,
    pub base: &'static [(&'static str, i32)],
    pub display: &'static [(&'static str, f64)],
}

const fn unit(name: &'static str, base: &'static [(&'static str, i32)]) -> UnitDef {
    UnitDef { name, base, display: &[] }
}

pub const UNITS: [UnitDef; 14] = [
    unit("N.m", &[("kg", 1), ("m", 2), ("s", -2)]),
    UnitDef { display: &[("rpm", 30.0 / std::f64::consts::PI)], ..unit("rad/s", &[("s", -1), ("rad", 1)]) },
    unit("m3/s", &[("m", 3), ("s", -1)]),
    unit("rad/s2", &[("s", -2), ("rad", 1)]),
    unit("m3/s2", &[("m", 3), ("s", -2)]),
    unit("N.m/s", &[("kg", 1), ("m", 2), ("s", -3)]),
    unit("kg.m2", &[("kg", 1), ("m", 2)]),
    unit("N.m.s2/rad2", &[("kg", 1), ("m", 2), ("rad", -2)]),
    unit("m", &[("m", 1)]),
    unit("m2", &[("m", 2)]),
    unit("kg/m3", &[("kg", 1), ("m", -3)]),
    UnitDef { display: &[("deg", 180.0 / std::f64::consts::PI)], ..unit("rad", &[("rad", 1)]) },
    unit("s", &[("s", 1)]),
    unit("1", &[]),
];

/// Unit-suffix conventions (conventions.md) → FMI unit; the first suffix that matches wins.
const SUFFIX_UNITS: [(&str, &str); 10] = [
    ("_nm_s2", "N.m.s2/rad2"),
    ("_kg_m2", "kg.m2"),
    ("_kg_m3", "kg/m3"),
    ("_m3_s", "m3/s"),
    ("_rad_s", "rad/s"),
    ("_nm", "N.m"),
    ("_m2", "m2"),
    ("_rad", "rad"),
    ("_m", "m"),
    ("_s", "s"),
];

/// The FMI unit of a unit-suffixed name (`pump_exit_radius_m` → `m`, `table_speed_ratio[3]` →
/// `1`); `1` without suffix.
pub fn unit_of(name: &str) -> &'static str {
    let base = match name.strip_suffix(']').and_then(|s| s.rsplit_once('[')) {
        Some((base, digits)) if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) => base,
        _ => name,
    };
    SUFFIX_UNITS.iter().find(|(suffix, _)| base.ends_with(suffix)).map_or("1", |&(_, unit)| unit)
}

/// A number as `modelDescription.xml` writes it: the shortest text that reads back to the same
/// value, in Python's `repr` style (`0.05`, `150.0`, `1e-06`).
pub fn xml_number(value: f64) -> String {
    let text = format!("{value:?}");
    match text.split_once('e') {
        Some((mantissa, exponent)) => {
            let (sign, digits) = exponent.strip_prefix('-').map_or(("+", exponent), |d| ("-", d));
            format!("{mantissa}e{sign}{digits:0>2}")
        }
        None => text,
    }
}

// ---------------------------------------------------------------------------------------------
// Parameters

/// A numeric entry of the model specification: a scalar or an array of numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum SpecValue {
    Scalar(f64),
    Array(Vec<f64>),
}

/// A tunable parameter: the spec value `model[key]` (scalar, `index` 0) or `model[key][index]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    pub vr: u32,
    pub name: String,
    pub key: String,
    pub index: usize,
    pub start: f64,
    pub unit: &'static str,
    pub description: String,
}

const TRIPLE: [&str; 3] = ["pump", "turbine", "stator"];
const GEOMETRY_DESCRIPTIONS: [(&str, &str); 9] = [
    ("flow_area_m2", "Flow area A of the torus"),
    ("fluid_density_kg_m3", "Fluid density"),
    ("pump_exit_radius_m", "Pump exit radius"),
    ("turbine_exit_radius_m", "Turbine exit radius"),
    ("stator_exit_radius_m", "Stator exit radius"),
    ("pump_shock_loss", "Shock loss coefficient at the pump inlet"),
    ("turbine_shock_loss", "Shock loss coefficient at the turbine inlet"),
    ("stator_shock_loss", "Shock loss coefficient at the stator inlet"),
    ("friction_loss", "Friction loss coefficient"),
];
const TABLE_KEYS: [(&str, &str); 3] = [
    ("speed_ratio", "speed ratio SR"),
    ("torque_ratio", "torque ratio TR"),
    ("capacity_factor_nm_s2", "capacity factor CF = pump torque / pump speed^2"),
];
const SCALAR_DESCRIPTIONS: [(&str, &str); 4] = [
    ("fluid_length_m", "Mean length L_f of the fluid path around the torus"),
    ("fluid_density_kg_m3", "Fluid density (flow estimate of the quasi-dynamic model)"),
    ("pump_exit_radius_m", "Pump exit radius (flow estimate of the quasi-dynamic model)"),
    ("flow_time_constant_s", "Time constant tau_Q of the flow lag at stall and 2000 rpm (quasi-dynamic model)"),
];

fn lookup(table: &[(&'static str, &'static str)], key: &str) -> Option<&'static str> {
    table.iter().find(|(k, _)| *k == key).map(|&(_, v)| v)
}

/// Name and description of element `index` of array `key` (of `size` elements).
fn element_name(key: &str, index: usize, size: usize) -> (String, String) {
    let geometry = HtParam::ALL;
    if key == "inertia_kg_m2" && size == 3 {
        return (format!("{}_inertia_kg_m2", TRIPLE[index]), format!("Moment of inertia of the {}", TRIPLE[index]));
    }
    if key == "shape_effect_m2" && size <= 3 {
        let part = TRIPLE[index];
        return (
            format!("{part}_shape_effect_m2"),
            format!("Shape effect S of the {part} (signed, LS16 eqs 2.16-2.18)"),
        );
    }
    if key == "geometry" && size == geometry.len() {
        let name = geometry[index].key();
        if let Some((blade, place)) = name.strip_suffix("_angle_rad").and_then(|s| s.split_once('_')) {
            return (name.to_string(), format!("Blade angle at the {blade} {place}"));
        }
        let description = lookup(&GEOMETRY_DESCRIPTIONS, name).map_or_else(|| name.replace('_', " "), str::to_string);
        return (name.to_string(), description);
    }
    if let Some(what) = lookup(&TABLE_KEYS, key) {
        let row = index + 1;
        return (format!("table_{key}[{row}]"), format!("Characteristic table, row {row}: {what}"));
    }
    (format!("{key}[{}]", index + 1), format!("{}, element {}", key.replace('_', " "), index + 1))
}

/// Every numeric entry of the model specification (scalars, and each element of the non-empty
/// arrays) as a tunable parameter, in the specification's key order, with value references from
/// [`FIRST_PARAMETER`]. An error when two parameters would have the same name.
pub fn parameters(spec: &[(String, SpecValue)]) -> Result<Vec<Parameter>, String> {
    let mut out: Vec<Parameter> = Vec::new();
    for (key, value) in spec {
        let items: Vec<(Option<usize>, f64)> = match value {
            SpecValue::Scalar(v) => vec![(None, *v)],
            SpecValue::Array(a) => a.iter().copied().enumerate().map(|(i, v)| (Some(i), v)).collect(),
        };
        let size = items.len();
        for (index, start) in items {
            let (name, description) = match index {
                Some(i) => element_name(key, i, size),
                None => (
                    key.clone(),
                    lookup(&SCALAR_DESCRIPTIONS, key).map_or_else(|| key.replace('_', " "), str::to_string),
                ),
            };
            if out.iter().any(|p| p.name == name) {
                return Err(format!("parameter names are not unique: {name} twice"));
            }
            let vr = FIRST_PARAMETER + out.len() as u32;
            let unit = unit_of(&name);
            out.push(Parameter { vr, name, key: key.clone(), index: index.unwrap_or(0), start, unit, description });
        }
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// The variables of an FMU

/// One `<ScalarVariable>` (all of type Real), in the order of `<ModelVariables>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    pub vr: u32,
    pub name: String,
    /// `input`, `output`, `parameter` or `local`.
    pub causality: &'static str,
    /// `continuous`, `fixed` or `tunable`.
    pub variability: &'static str,
    /// `calculated`, `exact`, or none (the FMI default).
    pub initial: Option<&'static str>,
    pub unit: String,
    pub display_unit: Option<&'static str>,
    pub description: String,
    pub start: Option<f64>,
    /// `start` as written in the XML (`1` for the flag, `0` for the rates, else [`xml_number`]).
    pub start_text: Option<String>,
    /// For `der(x)`: the value reference of the state `x`.
    pub derivative_of: Option<u32>,
    /// For an output: the inputs it depends on directly (none for a state).
    pub dependencies: Option<Vec<u32>>,
    /// For a tunable parameter: the specification entry `(key, index)`.
    pub parameter: Option<(String, usize)>,
}

impl Variable {
    fn new(vr: u32, name: &str, causality: &'static str, variability: &'static str, unit: &str) -> Self {
        Variable {
            vr,
            name: name.to_string(),
            causality,
            variability,
            initial: None,
            unit: unit.to_string(),
            display_unit: None,
            description: String::new(),
            start: None,
            start_text: None,
            derivative_of: None,
            dependencies: None,
            parameter: None,
        }
    }

    fn describe(mut self, description: impl Into<String>) -> Self {
        self.description = description.into();
        self
    }

    fn start(mut self, value: f64, text: String) -> Self {
        self.start = Some(value);
        self.start_text = Some(text);
        self
    }
}

/// The signals: inputs of the causality, else outputs.
fn signal_variables(model: Model, causality: Causality, lag: bool) -> Vec<Variable> {
    let inputs = all_inputs(causality);
    let signals =
        SIGNALS.iter().filter(|s| s.models.contains(&model) && has_signal(causality, s.vr) && (lag || !s.lag));
    signals
        .map(|s| {
            if inputs.contains(&s.vr) {
                let start = s.start.expect("an input signal has a start value");
                Variable::new(s.vr, s.name, "input", "continuous", s.unit)
                    .describe(s.description)
                    .start(start, xml_number(start))
            } else {
                let mut v = Variable::new(s.vr, s.name, "output", "continuous", s.unit).describe(s.description);
                v.initial = Some("calculated");
                v.dependencies = Some(direct_dependencies(model, causality, s));
                v
            }
        })
        .collect()
}

/// The inputs an output depends on directly (`<ModelStructure>`; measured in Model Exchange by
/// tests/integration/test_fmu_conformance.py). A state (pump speed, flow, stator speed): none. Any
/// other output: the speed inputs, and for each rotor whose external torque the output contains
/// (pump torque: the pump; turbine torque: the turbine; torque ratio: both; for Hrovat & Tobler,
/// whose mass matrix couples the rotors through the flow, every torque contains both) the rate
/// input of its speed when the speed is an input, else the torque input that drives it.
pub fn direct_dependencies(model: Model, causality: Causality, s: &SignalDef) -> Vec<u32> {
    if s.state.is_some() && !inputs(causality).contains(&s.vr) {
        return vec![];
    }
    let inputs = inputs(causality);
    let torque_inputs = [vr::PUMP_TORQUE, vr::LOAD_TORQUE];
    let mut deps: Vec<u32> = inputs.iter().copied().filter(|i| !torque_inputs.contains(i)).collect();
    match s.vr {
        // the clutch's slip is of the speeds only; its state code (0 open, 1 slipping) follows the
        // command; its torque is C·tanh(slip/s_c) slipping, the constraint torque locked: every input
        vr::LOCKUP_SLIP => return deps,
        vr::LOCKUP_STATE => return COMMON_INPUTS.to_vec(),
        vr::LOCKUP_TORQUE => {
            let mut all: Vec<u32> = all_inputs(causality).into_iter().chain(rate_inputs(causality)).collect();
            all.sort_unstable();
            return all;
        }
        // the fluid's stator torque sees the clutch only through Hrovat & Tobler's coupled mass
        // matrix, and only where a rotor speed is free
        vr::SPEED_RATIO => {}
        vr::STATOR_TORQUE if model != Model::HrovatTobler || causality == Causality::Speeds => {}
        _ => deps.extend(COMMON_INPUTS),
    }
    let rotors: &[u32] = match s.vr {
        vr::SPEED_RATIO => &[],
        _ if model == Model::HrovatTobler => &[vr::PUMP_SPEED, vr::TURBINE_SPEED],
        vr::PUMP_TORQUE => &[vr::PUMP_SPEED],
        vr::TURBINE_TORQUE => &[vr::TURBINE_SPEED],
        vr::TORQUE_RATIO => &[vr::PUMP_SPEED, vr::TURBINE_SPEED],
        _ => &[],
    };
    for &rotor in rotors {
        match RATES.iter().find(|r| r.of == rotor) {
            Some(rate) if inputs.contains(&rotor) => deps.push(rate.vr),
            _ if rotor == vr::PUMP_SPEED && inputs.contains(&vr::PUMP_TORQUE) => deps.push(vr::PUMP_TORQUE),
            _ if rotor == vr::TURBINE_SPEED && inputs.contains(&vr::LOAD_TORQUE) => deps.push(vr::LOAD_TORQUE),
            _ => {}
        }
    }
    deps.sort_unstable();
    deps.dedup();
    deps
}

/// The rate inputs of a causality's speed inputs (Model Exchange).
fn rate_inputs(causality: Causality) -> Vec<u32> {
    let inputs = inputs(causality);
    RATES.iter().filter(|r| inputs.contains(&r.of)).map(|r| r.vr).collect()
}

/// The input rates of the speed inputs, then the start-value parameters of the model's states.
fn rate_and_start_variables(model: Model, causality: Causality) -> Vec<Variable> {
    let inputs = inputs(causality);
    let mut out: Vec<Variable> = inputs
        .iter()
        .filter_map(|&i| RATES.iter().find(|r| r.of == i))
        .map(|r| {
            Variable::new(r.vr, r.name, "input", "continuous", RATE_UNIT)
                .describe(r.description)
                .start(RATE_START, format!("{}", RATE_START as i64))
        })
        .collect();
    let fixed = |vr: u32, name: &str, unit: &str| {
        let mut v = Variable::new(vr, name, "parameter", "fixed", unit);
        v.initial = Some("exact");
        v
    };
    for s in &START_PARAMETERS {
        let variable = match s.of.and_then(signal_def) {
            None => fixed(s.vr, START_FROM_STEADY_STATE, "1")
                .describe(START_FROM_STEADY_STATE_DESCRIPTION)
                .start(s.start, format!("{}", s.start as i64)),
            Some(sig) if sig.models.contains(&model) && !inputs.contains(&sig.vr) => {
                let spaced = sig.name.replace('_', " ");
                let words = spaced.rsplitn(3, ' ').last().unwrap_or_default();
                let when = if sig.vr == vr::TURBINE_SPEED {
                    "whatever start_from_steady_state (the steady start is at this turbine speed)"
                } else {
                    "when start_from_steady_state = 0"
                };
                fixed(s.vr, &format!("initial_{}", sig.name), sig.unit)
                    .describe(format!("Initial {words} {when}"))
                    .start(s.start, xml_number(s.start))
            }
            Some(_) => continue,
        };
        out.push(variable);
    }
    for d in DRIVE_PARAMETERS.iter().filter(|d| d.only.is_none_or(|c| c == causality)) {
        out.push(fixed(d.vr, d.name, d.unit).describe(d.description).start(d.start, xml_number(d.start)));
    }
    out
}

/// `der(x)` of each continuous state `x`, in coordinate order.
fn derivative_variables(model: Model, causality: Causality, lag: bool) -> Vec<Variable> {
    states(model, causality, lag)
        .into_iter()
        .map(|(s, c)| {
            let mut v = Variable::new(
                FIRST_DERIVATIVE + c as u32,
                &format!("der({})", s.name),
                "local",
                "continuous",
                &derivative_unit(s.unit),
            )
            .describe(format!("Time derivative of {}", s.name));
            v.initial = Some("calculated");
            v.derivative_of = Some(s.vr);
            v
        })
        .collect()
}

/// The tunable parameters as variables.
fn parameter_variables(parameters: &[Parameter]) -> Vec<Variable> {
    parameters
        .iter()
        .map(|p| {
            let mut v = Variable::new(p.vr, &p.name, "parameter", "tunable", p.unit)
                .describe(p.description.clone())
                .start(p.start, xml_number(p.start));
            v.display_unit = (p.unit == "rad").then_some("deg");
            v.parameter = Some((p.key.clone(), p.index));
            v
        })
        .collect()
}

/// Every variable of the FMU of `model` under `causality` with `parameters`, in the order of
/// `<ModelVariables>`: the signals by value reference, the input rates, the start-value
/// parameters, the derivatives of the states, the tunable parameters.
pub fn variables(model: Model, causality: Causality, parameters: &[Parameter]) -> Vec<Variable> {
    let lag = has_lag(parameters);
    let mut out = signal_variables(model, causality, lag);
    out.extend(rate_and_start_variables(model, causality));
    out.extend(derivative_variables(model, causality, lag));
    out.extend(parameter_variables(parameters));
    out
}

// ---------------------------------------------------------------------------------------------
// FMI 3.0 only: the independent variable and the event indicators as variables

/// Value reference of `time`, the independent variable FMI 3.0 declares.
pub const TIME: u32 = 50;
/// Value reference of event indicator 0 (FMI 3.0 declares each as a variable); indicator i has
/// `FIRST_EVENT_INDICATOR + i`.
pub const FIRST_EVENT_INDICATOR: u32 = 40;
/// Name and description of each event indicator, in the engine's order
/// (`tcsim_core::engine::mode_view::ModeView::indicators`).
pub const EVENT_INDICATOR_NAMES: [(&str, &str); EVENT_INDICATORS] = [
    ("stator_clutch_indicator", "Event indicator of the stator one-way clutch (positive while its state holds)"),
    ("flow_indicator", "Event indicator of the flow direction (positive while it holds)"),
    ("reverse_flow_indicator", "Event indicator of flow starting in reverse (positive while it does not)"),
    ("lockup_clutch_indicator", "Event indicator of the lock-up clutch (positive while its state holds)"),
];

/// The event indicator of value reference `vr`: its slot in the engine's indicators (the variable
/// exists for the models whose [`Model::indicator_slots`] hold it).
pub fn event_indicator(vr: u32) -> Option<usize> {
    vr.checked_sub(FIRST_EVENT_INDICATOR).map(|i| i as usize).filter(|&i| i < EVENT_INDICATORS)
}

/// The event indicators of a model as FMI 3.0 variables (`local`, `continuous`, `calculated`, no
/// unit: each is a torque, a speed or a flow, by the mode); none for a model without them.
pub fn event_indicator_variables(model: Model) -> Vec<Variable> {
    model
        .indicator_slots()
        .into_iter()
        .map(|i| {
            let (name, description) = EVENT_INDICATOR_NAMES[i];
            let mut v =
                Variable::new(FIRST_EVENT_INDICATOR + i as u32, name, "local", "continuous", "").describe(description);
            v.initial = Some("calculated");
            v
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_references_are_unique_and_in_their_ranges() {
        for model in Model::ALL {
            for (_, causality, _) in CAUSALITIES {
                let params = parameters(&[("inertia_kg_m2".into(), SpecValue::Array(vec![0.1, 0.05, 0.01]))]).unwrap();
                let vars = variables(model, causality, &params);
                let mut vrs: Vec<u32> = vars.iter().map(|v| v.vr).collect();
                vrs.sort();
                vrs.dedup();
                assert_eq!(vrs.len(), vars.len());
                assert!(vars.iter().all(|v| (v.vr as usize) < SIGNAL_SLOTS
                    || start_parameter(v.vr).is_some()
                    || drive_parameter(v.vr).is_some()
                    || is_derivative(v.vr)
                    || v.vr >= FIRST_PARAMETER));
                for v in vars.iter().filter(|v| v.causality == "input") {
                    assert!(is_input(causality, v.vr), "{}", v.name);
                }
            }
        }
    }

    #[test]
    fn numbers_are_written_as_python_writes_them() {
        for (v, text) in [(50.0, "50.0"), (0.05, "0.05"), (0.000187, "0.000187"), (1e-6, "1e-06"), (1e16, "1e+16")] {
            assert_eq!(xml_number(v), text);
        }
        assert_eq!(xml_number(30.0 / std::f64::consts::PI), "9.549296585513721");
    }

    #[test]
    fn units_follow_the_suffixes() {
        assert_eq!(unit_of("pump_exit_radius_m"), "m");
        assert_eq!(unit_of("table_capacity_factor_nm_s2[3]"), "N.m.s2/rad2");
        assert_eq!(unit_of("table_speed_ratio[3]"), "1");
        assert_eq!(unit_of("pump_exit_angle_rad"), "rad");
        let states = SIGNALS.iter().filter(|s| s.state.is_some()).map(|s| derivative_unit(s.unit));
        for p in SIGNALS.iter().map(|s| s.unit.to_string()).chain(states).chain([RATE_UNIT.into()]) {
            assert!(UNITS.iter().any(|u| u.name == p), "{p}");
        }
    }

    #[test]
    fn parameter_names_are_unique() {
        let spec = [("a_m".to_string(), SpecValue::Scalar(1.0)), ("a_m".to_string(), SpecValue::Scalar(2.0))];
        assert!(parameters(&spec).unwrap_err().contains("a_m"));
    }
}
