//! One FMU instance: the model specification and its parameters, the inputs and outputs, and the
//! co-simulation stepper of the core. Safe Rust; the C boundary is in `lib.rs`.

use serde_json::{Map, Value};
use tcsim_core::converter::dynamics::ConverterDynamics;
use tcsim_core::converter::dynamics::FLOW;
use tcsim_core::converter::spec::{build_model, ModelSpec};
use tcsim_core::engine::converter_events::{Mode, Sample};
use tcsim_core::engine::isolated::{initial_mode, initial_state, Drive, InitialState, TurbineLoad};
use tcsim_core::engine::lockup::{self, ClutchMode, LockupCommand};
use tcsim_core::engine::mode_view::{ModeView, LOCKUP_INDICATOR};
use tcsim_core::engine::options::SolverOptions;
use tcsim_core::engine::outputs::{row, COLUMNS};
use tcsim_core::engine::signal::Signal;
use tcsim_core::engine::stepper::{Causality, Stepper, StepperDrive};
use tcsim_core::CoreResult;

use crate::variables::{
    self, causality_of, drive_parameter, has_signal, is_derivative, is_input, signal_name, start_parameter, vr, Model,
    COORDINATES, DRIVE_PARAMETERS, FIRST_DERIVATIVE, FIRST_PARAMETER, RATES, SIGNALS, SIGNAL_SLOTS, START_PARAMETERS,
};

/// Where an instance is in the FMI 2.0 calling sequence (Co-Simulation and Model Exchange; the
/// event and continuous-time modes of Model Exchange are both `Running`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// After `fmi2Instantiate` or `fmi2Reset`.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initialization,
    /// After `fmi2ExitInitializationMode` (stepComplete; event or continuous-time mode).
    Running,
    /// After `fmi2Terminate`.
    Terminated,
}

impl Phase {
    pub const ALL: [Phase; 4] = [Phase::Instantiated, Phase::Initialization, Phase::Running, Phase::Terminated];

    /// The state's name in the FMI 2.0 standard.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Instantiated => "instantiated",
            Phase::Initialization => "initialization mode",
            Phase::Running => "stepComplete/event/continuous-time mode",
            Phase::Terminated => "terminated",
        }
    }
}

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
            None => Causality::PumpTorqueTurbineSpeed,
            Some(name) => causality_of(name).ok_or_else(|| {
                let names: Vec<&str> = variables::CAUSALITIES.iter().map(|c| c.0).collect();
                format!("model.json: causality {name:?}: expected one of {}", names.join(", "))
            })?,
        };
        let model = doc.get("model").and_then(Value::as_object).cloned().ok_or("model.json: no \"model\" object")?;
        let mut parameters = Vec::new();
        for (i, p) in doc.get("parameters").and_then(Value::as_array).cloned().unwrap_or_default().iter().enumerate() {
            let key = p
                .get("key")
                .and_then(Value::as_str)
                .ok_or(format!("model.json: parameters[{i}] has no key"))?
                .to_string();
            let index = p.get("index").and_then(Value::as_u64).unwrap_or(0) as usize;
            let start = spec_value(&model, &key, index)
                .ok_or(format!("model.json: parameters[{i}] = {key}[{index}] is not a number of the model"))?;
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
        self.model
            .get("kind")
            .and_then(Value::as_str)
            .map(str::to_string)
            .ok_or_else(|| tcsim_core::CoreError::new("kind", "missing", "a model kind"))
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
    fn text(&self, key: &str) -> Option<String> {
        self.model.get(key).and_then(Value::as_str).map(str::to_string)
    }
}

/// An instance between `fmi2Instantiate` and `fmi2FreeInstance`.
pub struct Instance {
    pub config: Configuration,
    pub options: SolverOptions,
    pub start_time: f64,
    /// Signal values by value reference (inputs as set, outputs as computed).
    pub signals: [f64; SIGNAL_SLOTS],
    /// Input rates given with `fmi2SetRealInputDerivatives` for the coming step.
    pub(crate) rates: [Option<f64>; SIGNAL_SLOTS],
    /// Model Exchange: the model, all coordinates, the mode and the time.
    pub(crate) me: Option<ModelExchange>,
    /// Values of the start-value parameters ([`START_PARAMETERS`], value references 30–34).
    pub(crate) start: [f64; START_PARAMETERS.len()],
    /// Values of the drive's fixed parameters ([`DRIVE_PARAMETERS`], value references 35–37).
    pub(crate) drive: [f64; DRIVE_PARAMETERS.len()],
    /// Inputs at the previous communication point, for the rate estimate.
    pub(crate) previous: Option<(f64, [f64; 2])>,
    pub(crate) stepper: Option<Stepper<Box<dyn ConverterDynamics + Send>>>,
    pub(crate) rebuild: bool,
    /// Co-Simulation: the time derivatives of the coordinates at the last communication point.
    pub(crate) derivatives: [f64; COORDINATES as usize],
    /// The initialisation in initialisation mode is that of the current inputs and parameters.
    pub(crate) fresh: bool,
    /// Instantiated for Model Exchange (else Co-Simulation).
    pub model_exchange: bool,
    /// Where the instance is in the calling sequence.
    pub phase: Phase,
}

impl Instance {
    pub fn new(config: Configuration) -> Self {
        // the start values of the table: the inputs' (whatever the causality) and the rates'
        let mut signals = [f64::NAN; SIGNAL_SLOTS];
        for s in &SIGNALS {
            if let Some(start) = s.start {
                signals[s.vr as usize] = start;
            }
        }
        for r in &RATES {
            signals[r.vr as usize] = variables::RATE_START;
        }
        Self {
            config,
            options: SolverOptions::default(),
            start_time: 0.0,
            signals,
            rates: [None; SIGNAL_SLOTS],
            me: None,
            start: START_PARAMETERS.map(|s| s.start),
            drive: DRIVE_PARAMETERS.map(|d| d.start),
            previous: None,
            stepper: None,
            rebuild: false,
            derivatives: [f64::NAN; COORDINATES as usize],
            fresh: false,
            model_exchange: false,
            phase: Phase::Instantiated,
        }
    }

    /// An error unless the instance is in one of `allowed`.
    pub fn require(&self, call: &str, allowed: &[Phase]) -> Result<(), String> {
        if allowed.contains(&self.phase) {
            return Ok(());
        }
        let names: Vec<&str> = allowed.iter().map(|p| p.name()).collect();
        Err(format!("{call} is not allowed in state {}: expected {}", self.phase.name(), names.join(" or ")))
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> Result<(), String> {
        self.require("fmi2EnterInitializationMode", &[Phase::Instantiated])?;
        self.phase = Phase::Initialization;
        self.fresh = false;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: the initial state of the inputs and start values set so far.
    /// On failure the instance stays in initialisation mode (a corrected value may be set).
    pub fn exit_initialization(&mut self) -> Result<(), String> {
        self.require("fmi2ExitInitializationMode", &[Phase::Initialization])?;
        self.initialize()?;
        self.phase = Phase::Running;
        Ok(())
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> Result<(), String> {
        self.require("fmi2Terminate", &[Phase::Running])?;
        self.phase = Phase::Terminated;
        Ok(())
    }

    /// In initialisation mode, the initialisation of the current inputs and parameters (the
    /// outputs, states and derivatives read then are those of the steady state or start values).
    pub fn provisional(&mut self) -> Result<(), String> {
        if self.phase == Phase::Initialization && !self.fresh {
            self.initialize()?;
        }
        Ok(())
    }

    /// The value references of the two inputs.
    pub fn input_refs(&self) -> [usize; 2] {
        variables::inputs(self.config.causality).map(|vr| vr as usize)
    }

    /// Value references that may be set: the two inputs, and for Model Exchange their rates.
    fn settable(&self, vr: usize) -> bool {
        is_input(self.config.causality, vr as u32)
    }

    fn inputs(&self) -> [f64; 2] {
        let [a, b] = self.input_refs();
        [self.signals[a], self.signals[b]]
    }

    pub(crate) fn model(&self) -> CoreResult<Box<dyn ConverterDynamics + Send>> {
        build_model(&Spec { model: &self.config.model, parameters: &self.config.parameters })
    }

    pub fn get(&mut self, vr: u32) -> Option<f64> {
        self.read(vr).ok()
    }

    /// The value of `vr`. In initialisation mode the outputs and derivatives are those of the
    /// initial state for the inputs and start values set so far (which stay settable).
    pub fn read(&mut self, vr: u32) -> Result<f64, String> {
        let unknown = || format!("no variable with value reference {vr}");
        if let Some(i) = start_parameter(vr) {
            return Ok(self.start[i]);
        }
        if let Some(i) = drive_parameter(vr) {
            return Ok(self.drive[i]);
        }
        let computed = is_derivative(vr) || ((vr as usize) < SIGNAL_SLOTS && !self.settable(vr as usize));
        if computed {
            self.provisional()?;
        }
        if self.me.is_some() {
            return self.me_get(vr).ok_or_else(unknown);
        }
        if is_derivative(vr) {
            return Ok(self.derivatives[(vr - FIRST_DERIVATIVE) as usize]);
        }
        if (vr as usize) < SIGNAL_SLOTS {
            return Ok(self.signals[vr as usize]);
        }
        let i = vr.checked_sub(FIRST_PARAMETER).ok_or_else(unknown)? as usize;
        self.config.parameters.get(i).map(|p| p.value).ok_or_else(unknown)
    }

    /// Set one value: [`Instance::set_all`] of one.
    pub fn set(&mut self, vr: u32, value: f64) -> Result<(), String> {
        self.set_all(&[vr], &[value])
    }

    /// Set values (`fmi2SetReal`), all or none: inputs any time before `fmi2Terminate`, the
    /// start-value parameters before `fmi2ExitInitializationMode`, the tunable parameters any time
    /// (checked together when the simulation runs, else at `fmi2ExitInitializationMode`). Outputs
    /// are not settable, non-finite values are refused. A refused call changes nothing.
    pub fn set_all(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), String> {
        self.require("fmi2SetReal", &[Phase::Instantiated, Phase::Initialization, Phase::Running])?;
        let saved = (self.signals, self.rates, self.start, self.drive, self.config.parameters.clone());
        let result = self.apply(vrs, values);
        if result.is_err() {
            (self.signals, self.rates, self.start, self.drive, self.config.parameters) = saved;
        }
        self.fresh = false;
        result
    }

    fn apply(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), String> {
        let mut tuned = false;
        for (&vr, &value) in vrs.iter().zip(values) {
            tuned |= self.set_one(vr, value)?;
        }
        if tuned && self.phase == Phase::Running {
            // tunable: check the new parameters now; Co-Simulation applies them at the next step
            let model = self.model().map_err(|e| e.to_string())?;
            match self.me.as_mut() {
                Some(me) => me.model = model,
                None => self.rebuild = true,
            }
        }
        Ok(())
    }

    /// Set one value without the model check; whether it was a tunable parameter.
    fn set_one(&mut self, vr: u32, value: f64) -> Result<bool, String> {
        if let Some(i) = start_parameter(vr) {
            if !matches!(self.phase, Phase::Instantiated | Phase::Initialization) {
                return Err("the start-value parameters are fixed after initialisation".into());
            }
            if !value.is_finite() {
                return Err(format!("start-value parameter {vr} = {value}: expected a finite value"));
            }
            if vr == vr::START_FROM_STEADY_STATE && value != 0.0 && value != 1.0 {
                // a flag held as a Real: 0.5 or 2 would have meant 1 without a word
                return Err(format!("start_from_steady_state = {value}: expected 0 or 1"));
            }
            self.start[i] = value;
            return Ok(false);
        }
        if let Some(i) = drive_parameter(vr) {
            return self.set_drive_parameter(i, value);
        }
        if let Some(name) = signal_name(vr) {
            if !has_signal(self.config.causality, vr) && variables::signal_def(vr).is_some() {
                return Err(format!("no variable with value reference {vr} under this causality"));
            }
            if !self.settable(vr as usize) {
                return Err(format!("{name} is an output and cannot be set"));
            }
            if !value.is_finite() {
                return Err(format!("{name} = {value}: expected a finite value"));
            }
            if vr == vr::LOCKUP_CAPACITY {
                // the core's one check of a capacity command (0 to its limit)
                let command = LockupCommand::new(Signal::constant(value), lockup::DEFAULT_STATIC_TO_KINETIC);
                if let Err(e) = command {
                    return Err(format!("{name} = {value}: expected {}", e.expected));
                }
            }
            self.signals[vr as usize] = value;
            if let Some(rate) = RATES.iter().find(|r| r.vr == vr).filter(|_| !self.model_exchange) {
                // Co-Simulation: a rate input is the rate of its speed input over the coming step,
                // as fmi2SetRealInputDerivatives gives it (FMI 3.0 has no such call); a step
                // without it takes the rate of the last interval
                self.rates[rate.of as usize] = Some(value);
            }
            return Ok(false);
        }
        let i = vr
            .checked_sub(FIRST_PARAMETER)
            .map(|i| i as usize)
            .filter(|&i| i < self.config.parameters.len())
            .ok_or(format!("no variable with value reference {vr}"))?;
        if !value.is_finite() {
            return Err(format!("parameter {vr} = {value}: expected a finite value"));
        }
        self.config.parameters[i].value = value;
        Ok(true)
    }

    pub fn set_rate(&mut self, vr: u32, order: i32, value: f64) -> Result<(), String> {
        self.require("fmi2SetRealInputDerivatives", &[Phase::Initialization, Phase::Running])?;
        let input = self.input_refs().contains(&(vr as usize)) || variables::COMMON_INPUTS.contains(&vr);
        if order != 1 || !input {
            return Err(format!(
                "input derivatives of order 1 of the inputs only (value reference {vr}, order {order})"
            ));
        }
        if !value.is_finite() {
            return Err(format!("input derivative of value reference {vr} = {value}: expected a finite value"));
        }
        self.rates[vr as usize] = Some(value);
        self.fresh = false;
        Ok(())
    }

    fn publish(&mut self, sample: &Sample) {
        self.derivatives = sample.u_dot;
        let Some(stepper) = &self.stepper else { return };
        let r = row(&stepper.model, sample);
        let inputs = self.input_refs();
        for s in &SIGNALS {
            let vr = s.vr as usize;
            if !inputs.contains(&vr) {
                if let Some(c) = COLUMNS.iter().position(|c| *c == s.name) {
                    self.signals[vr] = r[c];
                }
            }
        }
        if stepper.model.lag_state() {
            self.signals[vr::LAG_TORQUE as usize] = sample.u[FLOW]; // the lag state is no output column
        }
    }

    /// `fmi2ExitInitializationMode`: the steady state consistent with the inputs.
    pub fn initialize(&mut self) -> Result<(), String> {
        if self.model_exchange {
            self.me_initialize()?;
            self.fresh = true;
            return Ok(());
        }
        let model = self.model().map_err(|e| e.to_string())?;
        let mut stepper = Stepper::new(model, self.config.causality, self.options);
        let capacity = self.signals[vr::LOCKUP_CAPACITY as usize];
        stepper.extra = self.stepper_drive([capacity, capacity]);
        let refs = self.input_refs();
        let rates = [self.rates[refs[0]].unwrap_or(0.0), self.rates[refs[1]].unwrap_or(0.0)];
        let sample =
            stepper.initialize(self.start_time, self.inputs(), rates, &self.initial()).map_err(|e| e.to_string())?;
        self.stepper = Some(stepper);
        self.previous = Some((self.start_time, self.inputs()));
        self.publish(&sample);
        self.fresh = true;
        Ok(())
    }

    /// `fmi2DoStep` from `t` over `h`. An input given a rate with `fmi2SetRealInputDerivatives`
    /// moves linearly with it over the whole step. Otherwise its rate is estimated from the last
    /// communication interval and used over at most that interval's length, then the input is
    /// held (bounded extrapolation: a step far longer than the last interval holds the input at
    /// its value one interval ahead). The first step holds the inputs.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        if self.model_exchange {
            return Err("fmi2DoStep on a Model Exchange instance".into());
        }
        self.require("fmi2DoStep", &[Phase::Running])?;
        if !(t.is_finite() && h.is_finite() && h > 0.0) {
            return Err(format!("fmi2DoStep(t = {t}, h = {h}): expected a finite time and a finite, positive step"));
        }
        if self.rebuild {
            let model = self.model().map_err(|e| e.to_string())?;
            if let Some(s) = self.stepper.as_mut() {
                s.model = model;
            }
            self.rebuild = false;
        }
        let start = self.inputs();
        let refs = self.input_refs();
        // each input's rate and for how long it applies
        let ramp: [(f64, f64); 2] = [0, 1].map(|k| match (self.rates[refs[k]], self.previous) {
            (Some(rate), _) => (rate, h),
            (None, Some((tp, prev))) if t > tp => ((start[k] - prev[k]) / (t - tp), (t - tp).min(h)),
            _ => (0.0, h),
        });
        // the capacity: held over the interval, unless its rate is given (then linear, not below 0)
        let capacity = self.signals[vr::LOCKUP_CAPACITY as usize];
        let capacity_rate = self.rates[vr::LOCKUP_CAPACITY as usize].unwrap_or(0.0);
        let capacity_at = move |tau: f64| (capacity + capacity_rate * tau).max(0.0);
        let extra = self.stepper_drive([capacity, capacity]);
        let stepper = self.stepper.as_mut().ok_or("fmi2DoStep before initialisation")?;
        stepper.extra = extra;
        if (stepper.time_s() - t).abs() > 1e-9 * t.abs().max(1.0) {
            return Err(format!(
                "communication point {t} s: expected the end of the last step, {} s",
                stepper.time_s()
            ));
        }
        // the corners of the piecewise-linear inputs (a ramp as long as the step has none)
        let mut corners: Vec<f64> = ramp.iter().map(|r| r.1).filter(|&c| c < h * (1.0 - 1e-9)).collect();
        corners.sort_by(f64::total_cmp);
        corners.dedup();
        corners.push(h);
        let at = |tau: f64| {
            [0, 1].map(|k| start[k] + ramp[k].0 * if ramp[k].1 >= h * (1.0 - 1e-9) { tau } else { tau.min(ramp[k].1) })
        };
        let (mut tau, mut sample, saved) = (0.0, None, stepper.state());
        for c in corners {
            stepper.extra.lockup_capacity_nm = Some([capacity_at(tau), capacity_at(c)]);
            match stepper.do_step(c - tau, at(tau), at(c)) {
                Ok(s) => sample = Some(s),
                Err(e) => {
                    stepper.set_state(&saved); // a failed step leaves the instance at t
                    return Err(e.to_string());
                }
            }
            tau = c;
        }
        self.previous = Some((t, start));
        self.rates = [None; SIGNAL_SLOTS];
        if let Some(sample) = sample {
            self.publish(&sample);
        }
        Ok(())
    }

    /// Whether the model is the table model with its first-order lag (a fourth state,
    /// [`variables::has_lag`]).
    pub(crate) fn lag(&self) -> bool {
        self.config.model.contains_key(tcsim_core::converter::spec::LAG_KEY)
    }

    /// The clutch and the load of the stepper, with the capacity at the start and end of an interval.
    fn stepper_drive(&self, capacity_nm: [f64; 2]) -> StepperDrive {
        let d = |vr: u32| drive_parameter(vr).map_or(f64::NAN, |i| self.drive[i]);
        StepperDrive {
            lockup_capacity_nm: Some(capacity_nm),
            lockup_static_to_kinetic: d(vr::LOCKUP_STATIC_TO_KINETIC),
            load_inertia_kg_m2: d(vr::LOAD_INERTIA),
            load_drag_nm_s2: d(vr::LOAD_DRAG),
        }
    }

    /// Set a drive parameter: before initialisation only, finite and at least its minimum.
    fn set_drive_parameter(&mut self, i: usize, value: f64) -> Result<bool, String> {
        let d = &DRIVE_PARAMETERS[i];
        if !matches!(self.phase, Phase::Instantiated | Phase::Initialization) {
            return Err(format!("{} is fixed after initialisation", d.name));
        }
        if !(value.is_finite() && value >= d.min) {
            return Err(format!("{} = {value}: expected a finite value of {} or more", d.name, d.min));
        }
        self.drive[i] = value;
        Ok(false)
    }

    /// `fmi2Reset`: back to the instantiated state, parameters at their start values.
    pub fn reset(&mut self) {
        let model_exchange = self.model_exchange;
        for p in &mut self.config.parameters {
            p.value = p.start;
        }
        let config = self.config.clone();
        *self = Instance::new(config);
        self.model_exchange = model_exchange;
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
        inst.enter_initialization().unwrap();
        // outputs read in initialisation mode are the steady state for the inputs
        assert!((inst.get(1).unwrap() - (100.0f64 / 0.0032).sqrt()).abs() < 1e-9);
        inst.exit_initialization().unwrap();
        // steady state at stall: CF ω² = 100 N·m, turbine torque TR × 100
        assert!((inst.get(1).unwrap() - (100.0f64 / 0.0032).sqrt()).abs() < 1e-9);
        assert!((inst.get(3).unwrap() - 210.0).abs() < 1e-9);
        inst.do_step(0.0, 0.01).unwrap();
        assert_eq!(inst.set(101, 2.3), Ok(()));
        inst.do_step(0.01, 0.01).unwrap();
        assert!((inst.get(3).unwrap() / 100.0 - 2.3).abs() < 1e-3);
        assert!(inst.set(3, 1.0).is_err());
        assert!(inst.set(30, 0.0).is_err()); // fixed after initialisation
        assert!(inst.do_step(5.0, 0.01).is_err());
        inst.reset();
        assert_eq!(inst.get(101), Some(2.1));
    }

    #[test]
    fn start_values_override_the_steady_state() {
        let mut inst = Instance::new(Configuration::parse(CONFIG).unwrap());
        inst.set(0, 100.0).unwrap();
        inst.set(30, 0.0).unwrap();
        inst.set(31, 123.0).unwrap();
        inst.initialize().unwrap();
        assert_eq!(inst.get(1), Some(123.0));
        assert_eq!(inst.get(31), Some(123.0));
        // the flag is 0 or 1: any other value is refused and changes nothing
        let mut inst = Instance::new(Configuration::parse(CONFIG).unwrap());
        for bad in [0.5, 2.0, -1.0] {
            assert!(inst.set(30, bad).unwrap_err().contains("expected 0 or 1"), "{bad}");
        }
        assert_eq!(inst.get(30), Some(1.0));
    }

    #[test]
    fn bad_configurations_and_parameters_are_errors() {
        assert!(Configuration::parse("{").is_err());
        assert!(Configuration::parse(r#"{"model": {}, "parameters": [{"key": "x"}]}"#)
            .unwrap_err()
            .contains("parameters[0]"));
        let mut inst = Instance::new(Configuration::parse(CONFIG).unwrap());
        inst.set(100, -1.0).unwrap();
        assert!(inst.initialize().unwrap_err().contains("inertia.pump_kg_m2"));
    }
}

/// The Model Exchange side of an instance.
pub struct ModelExchange {
    pub(crate) model: Box<dyn ConverterDynamics + Send>,
    /// All four coordinates; the state coordinates are set by the host.
    pub(crate) u: [f64; 4],
    pub(crate) mode: Mode,
    pub(crate) time_s: f64,
    pub(crate) coordinates: Vec<usize>,
}

impl Instance {
    /// The initial state the start-value parameters ask for (none: the steady state).
    fn initial(&self) -> InitialState {
        let start = |vr: u32| start_parameter(vr).map_or(f64::NAN, |i| self.start[i]);
        // drive (c): the turbine speed is a state; the steady start is at its initial value
        let turbine_speed_rad_s =
            (self.config.causality == Causality::Torques).then(|| start(vr::INITIAL_TURBINE_SPEED));
        if start(vr::START_FROM_STEADY_STATE) != 0.0 {
            return InitialState { turbine_speed_rad_s, ..InitialState::default() };
        }
        let pump_given = variables::inputs(self.config.causality).contains(&vr::PUMP_SPEED);
        InitialState {
            pump_speed_rad_s: (!pump_given).then(|| start(vr::INITIAL_PUMP_SPEED)),
            turbine_speed_rad_s,
            stator_speed_rad_s: Some(start(vr::INITIAL_STATOR_SPEED)),
            flow_m3_s: Some(start(vr::INITIAL_FLOW)),
        }
    }

    /// The drive of the current inputs and their rates (linear about the current time).
    pub(crate) fn me_drive(&self, t: f64) -> Result<Drive, String> {
        let line = |name: &str, value: f64, rate: f64| {
            Signal::new(name, vec![t, t + 1.0], vec![value, value + rate], 0.0).map_err(|e| e.to_string())
        };
        let s = |vr: u32| self.signals[vr as usize];
        let turbine = line("turbine_speed_rad_s", s(vr::TURBINE_SPEED), s(vr::TURBINE_ACCEL))?;
        let extra = self.stepper_drive([s(vr::LOCKUP_CAPACITY); 2]);
        let lockup = Some(LockupCommand {
            capacity_nm: Signal::constant(s(vr::LOCKUP_CAPACITY)),
            static_to_kinetic: extra.lockup_static_to_kinetic,
        });
        Ok(match self.config.causality {
            Causality::PumpTorqueTurbineSpeed => Drive::PumpTorqueTurbineSpeed {
                pump_torque_nm: Signal::constant(s(vr::PUMP_TORQUE)),
                turbine_speed_rad_s: turbine,
                lockup,
            },
            Causality::Speeds => Drive::Speeds {
                pump_speed_rad_s: line("pump_speed_rad_s", s(vr::PUMP_SPEED), s(vr::PUMP_ACCEL))?,
                turbine_speed_rad_s: turbine,
                lockup,
            },
            Causality::Torques => Drive::PumpTorqueLoad {
                pump_torque_nm: Signal::constant(s(vr::PUMP_TORQUE)),
                load: TurbineLoad {
                    torque_nm: Signal::constant(s(vr::LOAD_TORQUE)),
                    inertia_kg_m2: extra.load_inertia_kg_m2,
                    drag_nm_s2: extra.load_drag_nm_s2,
                },
                lockup,
            },
        })
    }

    fn me_initialize(&mut self) -> Result<(), String> {
        let model = self.model().map_err(|e| e.to_string())?;
        let t = self.start_time;
        let drive = self.me_drive(t)?;
        let u = initial_state(&model, &drive, t, &self.initial()).map_err(|e| e.to_string())?;
        let mode = initial_mode(&model, &drive, &u, t);
        let coordinates = ModeView::state_coordinates(&model, &drive);
        self.me = Some(ModelExchange { model, u, mode, time_s: t, coordinates });
        Ok(())
    }

    /// The number of continuous states and of event indicators (of the variable table, as the
    /// modelDescription.xml declares them: known from instantiation on).
    pub fn me_sizes(&self) -> (usize, usize) {
        match self.model_kind() {
            Some(m) => (variables::states(m, self.config.causality, self.lag()).len(), m.event_indicators()),
            None => (0, 0),
        }
    }

    /// The model of the configuration (by its `kind`).
    fn model_kind(&self) -> Option<Model> {
        self.config.model.get("kind").and_then(Value::as_str).and_then(Model::from_kind)
    }

    fn me_state(&self) -> Result<&ModelExchange, String> {
        self.me.as_ref().ok_or_else(|| "Model Exchange call before initialisation".to_string())
    }

    pub fn me_set_time(&mut self, t: f64) -> Result<(), String> {
        if !t.is_finite() {
            return Err(format!("fmi2SetTime({t}): expected a finite time"));
        }
        self.me.as_mut().ok_or("fmi2SetTime before initialisation")?.time_s = t;
        Ok(())
    }

    pub fn me_set_states(&mut self, x: &[f64]) -> Result<(), String> {
        if let Some(v) = x.iter().find(|v| !v.is_finite()) {
            return Err(format!("fmi2SetContinuousStates: a state = {v}: expected finite values"));
        }
        let me = self.me.as_mut().ok_or("fmi2SetContinuousStates before initialisation")?;
        if x.len() != me.coordinates.len() {
            return Err(format!("{} continuous states given, expected {}", x.len(), me.coordinates.len()));
        }
        for (&c, &v) in me.coordinates.iter().zip(x) {
            me.u[c] = v;
        }
        Ok(())
    }

    pub fn me_get_states(&self, x: &mut [f64]) -> Result<(), String> {
        let me = self.me_state()?;
        for (&c, v) in me.coordinates.iter().zip(x.iter_mut()) {
            *v = me.u[c];
        }
        Ok(())
    }

    /// The nominal values of the continuous states (100 rad/s, 0.05 m³/s), from instantiation on.
    pub fn me_nominals(&self, x: &mut [f64]) -> Result<(), String> {
        let model = self.model_kind().ok_or("no model kind")?;
        let lag = self.lag();
        for ((_, c), v) in variables::states(model, self.config.causality, lag).into_iter().zip(x.iter_mut()) {
            // the flow's scale, or (the table model's lag state, in the same slot) a torque's
            *v = if c == FLOW && !lag { 0.05 } else { 100.0 };
        }
        Ok(())
    }

    pub fn me_derivatives(&self, dx: &mut [f64]) -> Result<(), String> {
        let me = self.me_state()?;
        let drive = self.me_drive(me.time_s)?;
        let rates = ModeView::new(&me.model, &drive, me.mode).rates(&me.u, me.time_s);
        for (&c, v) in me.coordinates.iter().zip(dx.iter_mut()) {
            *v = rates[c];
        }
        Ok(())
    }

    pub fn me_indicators(&self, g: &mut [f64]) -> Result<(), String> {
        let me = self.me_state()?;
        let drive = self.me_drive(me.time_s)?;
        let mut values =
            ModeView::new(&me.model, &drive, me.mode).indicators(&me.u, me.time_s, &self.options.hysteresis);
        if self.locked_without_capacity(me.mode) {
            values[LOCKUP_INDICATOR] = -1.0; // the command fell to zero: the clutch opens
        }
        let slots = self.model_kind().map_or_else(Vec::new, Model::indicator_slots);
        for (v, &slot) in g.iter_mut().zip(&slots) {
            *v = values[slot];
        }
        Ok(())
    }

    /// A locked clutch whose command is zero (it has no roots: the host's zero opens it at once).
    fn locked_without_capacity(&self, mode: Mode) -> bool {
        mode.lockup.is_locked() && self.signals[vr::LOCKUP_CAPACITY as usize] <= 0.0
    }

    /// `fmi2NewDiscreteStates`: apply every due switch; whether the states changed.
    pub fn me_new_discrete_states(&mut self) -> Result<bool, String> {
        let h = self.options.hysteresis;
        let me = self.me.as_ref().ok_or("fmi2NewDiscreteStates before initialisation")?;
        let drive = self.me_drive(me.time_s)?;
        let (mut u, mut mode, t) = (me.u, me.mode, me.time_s);
        let mut changed = false;
        if self.locked_without_capacity(mode) {
            mode.lockup = ClutchMode::Unarmed { since_s: t };
            changed = true;
        }
        for _ in 0..8 {
            match ModeView::new(&me.model, &drive, mode).event(&mut u, t, &h) {
                Some((_, next)) => {
                    mode = next;
                    changed = true;
                }
                None => break,
            }
        }
        let me = self.me.as_mut().ok_or("no Model Exchange state")?;
        // keep the host's given coordinates out of the state: only free ones change
        me.u = u;
        me.mode = mode;
        Ok(changed)
    }

    fn me_get(&mut self, vr: u32) -> Option<f64> {
        let me = self.me.as_ref()?;
        if is_derivative(vr) {
            let drive = self.me_drive(me.time_s).ok()?;
            return Some(
                ModeView::new(&me.model, &drive, me.mode).rates(&me.u, me.time_s)[(vr - FIRST_DERIVATIVE) as usize],
            );
        }
        if let Some(name) = signal_name(vr) {
            if self.settable(vr as usize) {
                return Some(self.signals[vr as usize]);
            }
            let drive = self.me_drive(me.time_s).ok()?;
            let sample = ModeView::new(&me.model, &drive, me.mode).sample(&me.u, me.time_s);
            if vr == vr::LAG_TORQUE {
                return me.model.lag_state().then_some(sample.u[FLOW]);
            }
            let r = row(&me.model, &sample);
            return COLUMNS.iter().position(|c| *c == name).map(|c| r[c]);
        }
        let i = vr.checked_sub(FIRST_PARAMETER)? as usize;
        self.config.parameters.get(i).map(|p| p.value)
    }
}

/// What the FMI 3.0 layer (`fmi3.rs`) asks beyond the FMI 2.0 calls.
impl Instance {
    /// Whether the Model Exchange state exists (after initialisation, or an output read in it).
    pub fn me_ready(&self) -> bool {
        self.me.is_some()
    }

    /// The current time: the model's (Model Exchange), the last communication point
    /// (Co-Simulation), else the start time.
    pub fn time_now(&self) -> f64 {
        match (&self.me, &self.stepper) {
            (Some(me), _) => me.time_s,
            (None, Some(stepper)) => stepper.time_s(),
            (None, None) => self.start_time,
        }
    }

    /// Event indicator `i` now: Model Exchange's, or in Co-Simulation that of the state at the
    /// last communication point; none before initialisation.
    pub fn event_indicator_now(&self, i: usize) -> Option<f64> {
        let h = self.options.hysteresis;
        if let Some(me) = &self.me {
            let drive = self.me_drive(me.time_s).ok()?;
            return ModeView::new(&me.model, &drive, me.mode).indicators(&me.u, me.time_s, &h).get(i).copied();
        }
        let stepper = self.stepper.as_ref()?;
        let sample = stepper.sample()?;
        let drive = self.me_drive(sample.time_s).ok()?;
        ModeView::new(&stepper.model, &drive, sample.mode).indicators(&sample.u, sample.time_s, &h).get(i).copied()
    }
}

#[cfg(test)]
mod me_tests {
    use super::*;
    use crate::variables::SpecValue;

    /// A model specification of each kind (JSON).
    fn spec(model: Model) -> String {
        let table = r#""speed_ratio": [0.0, 0.5, 1.0], "torque_ratio": [2.1, 1.4, 1.0],
            "capacity_factor_nm_s2": [0.0032, 0.003, 0.0002]"#;
        let inertia = r#""inertia_kg_m2": [0.109, 0.056, 0.01]"#;
        match model {
            Model::Table => format!(r#"{{"kind": "table", {inertia}, {table}}}"#),
            Model::QuasiDynamic => format!(
                r#"{{"kind": "quasi-dynamic", {inertia}, {table}, "shape_effect_m2": [-0.00569, 0.00134],
                    "fluid_density_kg_m3": 870.0, "pump_exit_radius_m": 0.12, "flow_time_constant_s": 0.05}}"#
            ),
            Model::HrovatTobler => format!(
                r#"{{"kind": "hrovat-tobler", {inertia}, "fluid_length_m": 0.2914,
                    "shape_effect_m2": [-0.00569, 0.00134, 0.0009], "geometry": {:?}}}"#,
                tcsim_core::converter::hrovat_tobler::HtGeometry::appendix_d().values
            ),
        }
    }

    /// The table's states and event indicators are the engine's: the continuous states of Model
    /// Exchange, the derivatives' value references and the stator clutch.
    #[test]
    fn the_variable_table_agrees_with_the_engine() {
        // each model, and the table model with its first-order lag (a fourth state)
        let lagged = spec(Model::Table).replacen('{', r#"{"lag_time_constant_s": 0.05, "#, 1);
        let cases = Model::ALL.map(|m| (m, spec(m), false)).into_iter().chain([(Model::Table, lagged, true)]);
        for (model, model_spec, lag) in cases {
            let params = if lag { vec![("lag_time_constant_s".to_string(), SpecValue::Scalar(0.05))] } else { vec![] };
            let params = variables::parameters(&params).unwrap();
            let entries = if lag { r#"[{"key": "lag_time_constant_s"}]"# } else { "[]" };
            for (name, causality, _) in variables::CAUSALITIES {
                let text = format!(r#"{{"causality": "{name}", "model": {model_spec}, "parameters": {entries}}}"#);
                let mut inst = Instance::new(Configuration::parse(&text).unwrap());
                assert_eq!(inst.config.causality, causality);
                inst.model_exchange = true;
                inst.initialize().unwrap();
                let me = inst.me.as_ref().unwrap();
                assert_eq!(me.model.lag_state(), lag);
                let table: Vec<usize> = variables::states(model, causality, lag).iter().map(|&(_, c)| c).collect();
                assert_eq!(me.coordinates, table, "{model:?} {name}");
                assert_eq!(me.model.has_stator_clutch(), model.event_indicators() > 1, "{model:?}");
                assert_eq!(inst.me_sizes(), (table.len(), model.event_indicators()));
                for (s, c) in variables::states(model, causality, lag) {
                    let der = inst.get(FIRST_DERIVATIVE + c as u32).unwrap();
                    assert!(der.is_finite(), "der({}) = {der}", s.name);
                }
                // every declared variable can be read, every input set
                for v in variables::variables(model, causality, &params) {
                    assert!(inst.get(v.vr).is_some_and(f64::is_finite), "{model:?} {name}: {}", v.name);
                    if v.causality == "input" {
                        inst.set(v.vr, v.start.unwrap()).unwrap();
                    }
                }
            }
        }
    }

    /// Drive (c) in Model Exchange: both speeds are states; a locked clutch links the turbine to the
    /// pump (the momentum-conserving projection makes the two states equal, and their derivatives
    /// are equal while it holds); a command set to zero opens it at the next event.
    #[test]
    fn a_locked_clutch_in_drive_c_joins_the_speed_states() {
        let text = format!(r#"{{"causality": "torques", "model": {}, "parameters": []}}"#, spec(Model::Table));
        let mut inst = Instance::new(Configuration::parse(&text).unwrap());
        inst.model_exchange = true;
        inst.set(vr::PUMP_TORQUE, 100.0).unwrap();
        inst.set(vr::LOCKUP_CAPACITY, 500.0).unwrap();
        assert!(inst.set(vr::LOCKUP_CAPACITY, -1.0).unwrap_err().contains("lockup_capacity_nm = -1"));
        inst.initialize().unwrap();
        assert_eq!(inst.me_sizes(), (2, 1));
        assert_eq!(inst.get(vr::LOCKUP_STATE), Some(1.0)); // slipping from the stall
        inst.me_set_states(&[100.0, 99.8]).unwrap();
        let mut g = [0.0];
        inst.me_indicators(&mut g).unwrap();
        assert!(g[0] < 0.0, "the slip is below the sync threshold: {g:?}");
        assert!(inst.me_new_discrete_states().unwrap());
        let (mut x, mut dx) = ([0.0; 2], [0.0; 2]);
        inst.me_get_states(&mut x).unwrap();
        inst.me_derivatives(&mut dx).unwrap();
        assert!(x[0] == x[1] && dx[0] == dx[1] && x[0] > 99.8 && x[0] < 100.0, "{x:?} {dx:?}");
        assert_eq!(inst.get(vr::LOCKUP_STATE), Some(2.0));
        assert_eq!(inst.get(vr::LOCKUP_SLIP), Some(0.0));
        inst.set(vr::LOCKUP_CAPACITY, 0.0).unwrap();
        inst.me_indicators(&mut g).unwrap();
        assert!(g[0] < 0.0);
        assert!(inst.me_new_discrete_states().unwrap());
        assert_eq!(inst.get(vr::LOCKUP_STATE), Some(0.0));
    }

    #[test]
    fn model_exchange_states_derivatives_and_events() {
        let config = Configuration::parse(&format!(
            r#"{{"model": {{"kind": "hrovat-tobler", "inertia_kg_m2": [0.109, 0.056, 0.01], "fluid_length_m": 0.2914,
                "shape_effect_m2": [-0.00569, 0.00134, 0.0009], "geometry": {:?}}}, "parameters": []}}"#,
            tcsim_core::converter::hrovat_tobler::HtGeometry::appendix_d().values
        ))
        .unwrap();
        let mut inst = Instance::new(config);
        inst.model_exchange = true;
        inst.set(0, 150.0).unwrap();
        inst.set(2, 0.0).unwrap();
        inst.initialize().unwrap();
        assert_eq!(inst.me_sizes(), (3, 4));
        // at the steady state the derivatives vanish and no event is due
        let mut dx = [1.0; 3];
        inst.me_derivatives(&mut dx).unwrap();
        assert!(dx.iter().all(|d| d.abs() < 1e-6), "{dx:?}");
        let mut g = [0.0; 4];
        inst.me_indicators(&mut g).unwrap();
        assert!(g.iter().all(|v| *v > 0.0));
        assert!(!inst.me_new_discrete_states().unwrap());
        // at the locked steady state past the coupling point the holding torque is negative:
        // the stator releases
        let mut x = [0.0; 3];
        inst.me_get_states(&mut x).unwrap();
        let g_ht = tcsim_core::converter::hrovat_tobler::HtGeometry::appendix_d();
        let locked = tcsim_core::converter::hrovat_tobler::locked_steady_state(&g_ht, x[0], 0.97 * x[0]).unwrap();
        inst.set(2, 0.97 * x[0]).unwrap();
        inst.me_set_states(&[x[0], 0.0, locked.flow_m3_s]).unwrap();
        inst.me_indicators(&mut g).unwrap();
        assert!(g[0] < 0.0, "{g:?}");
        assert!(inst.me_new_discrete_states().unwrap());
        inst.me_indicators(&mut g).unwrap();
        assert!(g[0] > 0.0);
        assert_eq!(inst.get(3).map(|v| v.is_finite()), Some(true));
    }
}
