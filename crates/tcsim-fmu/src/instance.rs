//! One FMU instance: the model specification and its parameters, the inputs and outputs, and the
//! co-simulation stepper of the core. Safe Rust; the C boundary is in `lib.rs`.

use serde_json::{Map, Value};
use tcsim_core::dynamics::{build_model, ConverterDynamics, ModelSpec};
use tcsim_core::outputs::{row, COLUMNS};
use tcsim_core::stepper::{Causality, Stepper};
use tcsim_core::transient::{InitialState, Sample, SolverOptions};
use tcsim_core::CoreResult;

/// Value references of the signals, fixed whatever the causality.
pub const SIGNALS: [&str; 12] = [
    "pump_torque_nm",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
    "turbine_torque_nm",
    "speed_ratio",
    "torque_ratio",
    "flow_m3_s",
    "stator_speed_rad_s",
    "stator_torque_nm",
    "effective_pump_torque_nm",
    "effective_turbine_torque_nm",
    "effective_torque_ratio",
];
/// Value reference of the first parameter.
pub const FIRST_PARAMETER: u32 = 100;

/// A parameter: the spec entry `model[key]` (scalar) or `model[key][index]`.
#[derive(Debug, Clone)]
pub struct Parameter {
    pub key: String,
    pub index: usize,
    pub start: f64,
    pub value: f64,
}

/// What `resources/model.json` holds.
#[derive(Debug, Clone)]
pub struct Configuration {
    pub causality: Causality,
    pub model: Map<String, Value>,
    pub parameters: Vec<Parameter>,
}

fn spec_value(model: &Map<String, Value>, key: &str, index: usize) -> Option<f64> {
    match model.get(key)? {
        Value::Number(n) if index == 0 => n.as_f64(),
        Value::Array(a) => a.get(index)?.as_f64(),
        _ => None,
    }
}

impl Configuration {
    /// Parse `model.json`; the message names what is wrong.
    pub fn parse(text: &str) -> Result<Self, String> {
        let doc: Value = serde_json::from_str(text).map_err(|e| format!("model.json: {e}"))?;
        let causality = match doc.get("causality").and_then(Value::as_str) {
            Some("pump-torque") | None => Causality::PumpTorqueTurbineSpeed,
            Some("speeds") => Causality::Speeds,
            Some(other) => return Err(format!("model.json: causality {other:?}: expected pump-torque or speeds")),
        };
        let model = doc.get("model").and_then(Value::as_object).cloned().ok_or("model.json: no \"model\" object")?;
        let mut parameters = Vec::new();
        for (i, p) in doc.get("parameters").and_then(Value::as_array).cloned().unwrap_or_default().iter().enumerate() {
            let key = p.get("key").and_then(Value::as_str).ok_or(format!("model.json: parameters[{i}] has no key"))?.to_string();
            let index = p.get("index").and_then(Value::as_u64).unwrap_or(0) as usize;
            let start = spec_value(&model, &key, index).ok_or(format!("model.json: parameters[{i}] = {key}[{index}] is not a number of the model"))?;
            parameters.push(Parameter { key, index, start, value: start });
        }
        Ok(Self { causality, model, parameters })
    }
}

/// The model specification with the parameters' current values.
struct Spec<'a> {
    model: &'a Map<String, Value>,
    parameters: &'a [Parameter],
}

impl ModelSpec for Spec<'_> {
    fn kind(&self) -> CoreResult<String> {
        self.model.get("kind").and_then(Value::as_str).map(str::to_string).ok_or_else(|| tcsim_core::CoreError::new("kind", "missing", "a model kind"))
    }
    fn numbers(&self, key: &str) -> Option<Vec<f64>> {
        let mut v: Vec<f64> = match self.model.get(key)? {
            Value::Number(n) => vec![n.as_f64()?],
            Value::Array(a) => a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>()?,
            _ => return None,
        };
        for p in self.parameters.iter().filter(|p| p.key == key) {
            if let Some(slot) = v.get_mut(p.index) {
                *slot = p.value;
            }
        }
        Some(v)
    }
}

/// An instance between `fmi2Instantiate` and `fmi2FreeInstance`.
pub struct Instance {
    pub config: Configuration,
    pub options: SolverOptions,
    pub start_time: f64,
    /// Signal values by value reference (inputs as set, outputs as computed).
    pub signals: [f64; 12],
    /// Input rates given with `fmi2SetRealInputDerivatives` for the coming step.
    rates: [Option<f64>; 12],
    /// Inputs at the previous communication point, for the rate estimate.
    previous: Option<(f64, [f64; 2])>,
    stepper: Option<Stepper<Box<dyn ConverterDynamics + Send>>>,
    rebuild: bool,
    /// Between fmi2EnterInitializationMode and fmi2ExitInitializationMode.
    pub initializing: bool,
}

impl Instance {
    pub fn new(config: Configuration) -> Self {
        let mut signals = [f64::NAN; 12];
        signals[0] = 50.0;
        signals[1] = 150.0;
        signals[2] = 0.0;
        Self { config, options: SolverOptions::default(), start_time: 0.0, signals, rates: [None; 12], previous: None, stepper: None, rebuild: false, initializing: false }
    }

    /// The value references of the two inputs.
    pub fn input_refs(&self) -> [usize; 2] {
        match self.config.causality {
            Causality::PumpTorqueTurbineSpeed => [0, 2],
            Causality::Speeds => [1, 2],
        }
    }

    fn inputs(&self) -> [f64; 2] {
        let [a, b] = self.input_refs();
        [self.signals[a], self.signals[b]]
    }

    fn model(&self) -> CoreResult<Box<dyn ConverterDynamics + Send>> {
        build_model(&Spec { model: &self.config.model, parameters: &self.config.parameters })
    }

    pub fn get(&mut self, vr: u32) -> Option<f64> {
        if (vr as usize) < SIGNALS.len() {
            if self.initializing && !self.input_refs().contains(&(vr as usize)) {
                // in initialisation mode the outputs are the steady state for the inputs set so far
                let _ = self.initialize();
            }
            return Some(self.signals[vr as usize]);
        }
        let i = vr.checked_sub(FIRST_PARAMETER)? as usize;
        self.config.parameters.get(i).map(|p| p.value)
    }

    /// Set a value; inputs any time, parameters before or between steps (tunable). Outputs are
    /// not settable.
    pub fn set(&mut self, vr: u32, value: f64) -> Result<(), String> {
        if (vr as usize) < SIGNALS.len() {
            if !self.input_refs().contains(&(vr as usize)) {
                return Err(format!("{} is an output and cannot be set", SIGNALS[vr as usize]));
            }
            if !value.is_finite() {
                return Err(format!("{} = {value}: expected a finite value", SIGNALS[vr as usize]));
            }
            self.signals[vr as usize] = value;
            return Ok(());
        }
        let i = vr.checked_sub(FIRST_PARAMETER).map(|i| i as usize).filter(|&i| i < self.config.parameters.len()).ok_or(format!("no variable with value reference {vr}"))?;
        self.config.parameters[i].value = value;
        if self.stepper.is_some() {
            // tunable: check the new parameters now, apply them at the next step
            self.model().map_err(|e| e.to_string())?;
            self.rebuild = true;
        }
        Ok(())
    }

    pub fn set_rate(&mut self, vr: u32, order: i32, value: f64) -> Result<(), String> {
        if order != 1 || !self.input_refs().contains(&(vr as usize)) {
            return Err(format!("input derivatives of order 1 of the inputs only (value reference {vr}, order {order})"));
        }
        self.rates[vr as usize] = Some(value);
        Ok(())
    }

    fn publish(&mut self, sample: &Sample) {
        let Some(stepper) = &self.stepper else { return };
        let r = row(&stepper.model, sample);
        let inputs = self.input_refs();
        for (vr, name) in SIGNALS.iter().enumerate() {
            if !inputs.contains(&vr) {
                if let Some(c) = COLUMNS.iter().position(|c| c == name) {
                    self.signals[vr] = r[c];
                }
            }
        }
    }

    /// `fmi2ExitInitializationMode`: the steady state consistent with the inputs.
    pub fn initialize(&mut self) -> Result<(), String> {
        let model = self.model().map_err(|e| e.to_string())?;
        let mut stepper = Stepper::new(model, self.config.causality, self.options);
        let refs = self.input_refs();
        let rates = [self.rates[refs[0]].unwrap_or(0.0), self.rates[refs[1]].unwrap_or(0.0)];
        let sample = stepper.initialize(self.start_time, self.inputs(), rates, &InitialState::default()).map_err(|e| e.to_string())?;
        self.stepper = Some(stepper);
        self.previous = Some((self.start_time, self.inputs()));
        self.publish(&sample);
        Ok(())
    }

    /// `fmi2DoStep` from `t` over `h`: the inputs move linearly from their values at `t` with
    /// their given rates, or else the rates of the last interval (first-order hold).
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        if self.rebuild {
            let model = self.model().map_err(|e| e.to_string())?;
            if let Some(s) = self.stepper.as_mut() {
                s.model = model;
            }
            self.rebuild = false;
        }
        let start = self.inputs();
        let refs = self.input_refs();
        let estimated = match self.previous {
            Some((tp, prev)) if t > tp => [(start[0] - prev[0]) / (t - tp), (start[1] - prev[1]) / (t - tp)],
            _ => [0.0, 0.0],
        };
        let end = [0, 1].map(|k| start[k] + h * self.rates[refs[k]].unwrap_or(estimated[k]));
        let stepper = self.stepper.as_mut().ok_or("fmi2DoStep before initialisation")?;
        if (stepper.time_s() - t).abs() > 1e-9 * t.abs().max(1.0) {
            return Err(format!("communication point {t} s: expected the end of the last step, {} s", stepper.time_s()));
        }
        let sample = stepper.do_step(h, start, end).map_err(|e| e.to_string())?;
        self.previous = Some((t, start));
        self.rates = [None; 12];
        self.publish(&sample);
        Ok(())
    }

    /// `fmi2Reset`: back to the instantiated state, parameters at their start values.
    pub fn reset(&mut self) {
        for p in &mut self.config.parameters {
            p.value = p.start;
        }
        let config = self.config.clone();
        *self = Instance::new(config);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CONFIG: &str = r#"{"causality": "pump-torque",
        "model": {"kind": "table", "inertia_kg_m2": [0.109, 0.056, 0.01],
                  "speed_ratio": [0.0, 0.5, 1.0], "torque_ratio": [2.1, 1.4, 1.0],
                  "capacity_factor_nm_s2": [0.0032, 0.003, 0.0002]},
        "parameters": [{"key": "inertia_kg_m2", "index": 0}, {"key": "torque_ratio", "index": 0}]}"#;

    #[test]
    fn steps_from_the_steady_state_and_takes_tunable_parameters() {
        let mut inst = Instance::new(Configuration::parse(CONFIG).unwrap());
        inst.set(0, 100.0).unwrap();
        inst.set(2, 0.0).unwrap();
        inst.initializing = true;
        // outputs read in initialisation mode are the steady state for the inputs
        assert!((inst.get(1).unwrap() - (100.0f64 / 0.0032).sqrt()).abs() < 1e-9);
        inst.initializing = false;
        inst.initialize().unwrap();
        // steady state at stall: CF ω² = 100 N·m, turbine torque TR × 100
        assert!((inst.get(1).unwrap() - (100.0f64 / 0.0032).sqrt()).abs() < 1e-9);
        assert!((inst.get(3).unwrap() - 210.0).abs() < 1e-9);
        inst.do_step(0.0, 0.01).unwrap();
        assert_eq!(inst.set(101, 2.3), Ok(()));
        inst.do_step(0.01, 0.01).unwrap();
        assert!((inst.get(3).unwrap() / 100.0 - 2.3).abs() < 1e-3);
        assert!(inst.set(3, 1.0).is_err());
        assert!(inst.do_step(5.0, 0.01).is_err());
        inst.reset();
        assert_eq!(inst.get(101), Some(2.1));
    }

    #[test]
    fn bad_configurations_and_parameters_are_errors() {
        assert!(Configuration::parse("{").is_err());
        assert!(Configuration::parse(r#"{"model": {}, "parameters": [{"key": "x"}]}"#).unwrap_err().contains("parameters[0]"));
        let mut inst = Instance::new(Configuration::parse(CONFIG).unwrap());
        inst.set(100, -1.0).unwrap();
        assert!(inst.initialize().unwrap_err().contains("inertia.pump_kg_m2"));
    }
}
