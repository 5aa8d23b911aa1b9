//! The FMI 3.0 C API of the tcsim converter models, beside FMI 2.0 in the same library and over the
//! same [`Instance`]: Model Exchange (continuous states, their derivatives, the event indicators and
//! the mode switches in `fmi3UpdateDiscreteStates`) and Co-Simulation (tcsim's BDF inside
//! `fmi3DoStep`). The variables are those of FMI 2.0 ([`crate::variables`]), all `Float64`, with
//! two that FMI 3.0 adds: `time` (the independent variable, [`TIME`]) and the event indicators
//! ([`FIRST_EVENT_INDICATOR`](crate::variables::FIRST_EVENT_INDICATOR)).
//!
//! The instance checks the calling sequence (the FMI 3.0 state machine, [`State`]) and the
//! `instantiationToken` against `resources/model.json`. What the FMU does not have (other variable
//! types, clocks, scheduled execution, directional and adjoint derivatives,
//! configuration mode, Co-Simulation's event mode and intermediate update) returns `fmi3Error` with
//! a message through the logger. The FMU state is the FMI 2.0 one (`snapshot.rs`) with the
//! state-machine state. Every entry point catches panics: none crosses the C boundary.

use std::ffi::{c_char, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use serde_json::Value;

use crate::instance::{Configuration, Instance, Phase};
use crate::snapshot::Snapshot;
use crate::variables::{event_indicator, is_derivative, is_input, states, Model, FIRST_DERIVATIVE, SIGNAL_SLOTS, TIME};

type Status = i32;
const OK: Status = 0;
const ERROR: Status = 3;
const FATAL: Status = 4;

/// `fmi3LogMessageCallback`.
type LogMessage = unsafe extern "C" fn(*mut c_void, Status, *const c_char, *const c_char);

/// The key of `resources/model.json` that holds the `instantiationToken` of `modelDescription.xml`.
pub const TOKEN_KEY: &str = "instantiationToken";

/// The states of the FMI 3.0 state machine the FMU distinguishes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    Instantiated,
    Initialization,
    Event,
    ContinuousTime,
    Step,
    Terminated,
}

/// What an `fmi3Instance` points to.
pub struct Instance3 {
    name: CString,
    environment: *mut c_void,
    logger: Option<LogMessage>,
    instance: Instance,
    state: State,
}

impl Instance3 {
    fn log(&self, status: Status, message: &str) {
        let Some(logger) = self.logger else { return };
        // the instance name first: FMI 3.0's callback has no argument for it
        let text = format!("{}: {}", self.name.to_string_lossy(), message).replace('\0', " ");
        let msg = CString::new(text).unwrap_or_default();
        unsafe { logger(self.environment, status, c"logStatusError".as_ptr(), msg.as_ptr()) };
    }

    /// An error unless the instance is in one of `states`.
    fn expect(&self, function: &str, states: &[State]) -> Result<(), String> {
        if states.contains(&self.state) {
            Ok(())
        } else {
            let allowed: Vec<String> = states.iter().map(|s| format!("{s:?}")).collect();
            Err(format!("{function} in state {:?}: expected {}", self.state, allowed.join(" or ")))
        }
    }

    fn model(&self) -> Option<Model> {
        self.instance.config.model.get("kind").and_then(Value::as_str).and_then(Model::from_kind)
    }

    /// The number of continuous states and of event indicators (known from instantiation on).
    fn sizes(&self) -> (usize, usize) {
        match self.model() {
            Some(m) => (states(m, self.instance.config.causality, self.instance.lag()).len(), m.event_indicators()),
            None => (0, 0),
        }
    }

    /// `fmi3GetFloat64` of one value reference.
    fn get(&mut self, vr: u32) -> Result<f64, String> {
        if vr == TIME {
            return Ok(self.instance.time_now());
        }
        let output = (vr as usize) < SIGNAL_SLOTS && !is_input(self.instance.config.causality, vr);
        let indicator_or_derivative = event_indicator(vr).is_some() || is_derivative(vr);
        if (output || indicator_or_derivative) && self.state == State::Instantiated {
            return Err(format!("value reference {vr} is calculated: it has no value before initialisation"));
        }
        if indicator_or_derivative && self.state == State::Initialization {
            // (an output read in initialisation mode brings the instance up to date itself)
            self.instance.provisional()?;
        }
        if let Some(i) = event_indicator(vr) {
            if i >= self.sizes().1 {
                return Err(format!("no variable with value reference {vr}"));
            }
            return self.instance.event_indicator_now(i).ok_or(format!("event indicator {vr}: not initialised"));
        }
        if is_derivative(vr) {
            let c = (vr - FIRST_DERIVATIVE) as usize;
            let declared = self.model().is_some_and(|m| {
                states(m, self.instance.config.causality, self.instance.lag())
                    .iter()
                    .any(|&(_, coordinate)| coordinate == c)
            });
            if !declared {
                return Err(format!("no variable with value reference {vr}"));
            }
        }
        self.instance.read(vr)
    }

    /// In initialisation mode the Model Exchange state follows the inputs set so far.
    fn me_current(&mut self) -> Result<(), String> {
        self.instance.provisional()?;
        if self.instance.me_ready() {
            Ok(())
        } else {
            Err("Model Exchange call before initialisation".into())
        }
    }
}

/// Run `f` on the instance; an error or a panic is logged and becomes `fmi3Error`.
unsafe fn with(c: *mut c_void, f: impl FnOnce(&mut Instance3) -> Result<(), String>) -> Status {
    if c.is_null() {
        return ERROR;
    }
    let inst = unsafe { &mut *(c as *mut Instance3) };
    match catch_unwind(AssertUnwindSafe(|| f(inst))) {
        Ok(Ok(())) => OK,
        Ok(Err(msg)) => {
            inst.log(ERROR, &msg);
            ERROR
        }
        Err(payload) => {
            inst.log(FATAL, &format!("internal error: {}", panic_message(payload)));
            ERROR
        }
    }
}

use crate::{panic_message, slice, slice_mut};

unsafe fn text(p: *const c_char) -> Option<String> {
    if p.is_null() {
        None
    } else {
        Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }
}

/// The instance of `resources/model.json` in `resource_path`, if the token matches.
fn load(resource_path: Option<&str>, token: Option<&str>, model_exchange: bool) -> Result<Instance, String> {
    let dir = resource_path.ok_or("no resourcePath")?;
    let file = Path::new(dir).join("model.json");
    let text = std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
    let doc: Value = serde_json::from_str(&text).map_err(|e| format!("model.json: {e}"))?;
    let expected = doc.get(TOKEN_KEY).and_then(Value::as_str).ok_or(format!(
        "{}: no {TOKEN_KEY}: the FMU was not exported for FMI 3.0 (tcsim export-fmu --fmi-version 3)",
        file.display()
    ))?;
    match token {
        Some(t) if t == expected => {}
        Some(t) => return Err(format!("instantiationToken {t:?}: expected {expected:?} (modelDescription.xml)")),
        None => return Err(format!("no instantiationToken: expected {expected:?}")),
    }
    let mut instance = Instance::new(Configuration::parse(&text)?);
    instance.model_exchange = model_exchange;
    Ok(instance)
}

/// Instantiate, or log why not (with a null instance).
unsafe fn instantiate(
    name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    environment: *mut c_void,
    logger: Option<LogMessage>,
    model_exchange: bool,
    refuse: Option<String>,
) -> *mut c_void {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let name = unsafe { text(name) }.unwrap_or_default();
        let (token, path) = unsafe { (text(token), text(resource_path)) };
        let loaded = match refuse {
            Some(msg) => Err(msg),
            None => load(path.as_deref(), token.as_deref(), model_exchange),
        };
        let name = CString::new(name.replace('\0', " ")).unwrap_or_default();
        match loaded {
            Ok(instance) => {
                let inst = Instance3 { name, environment, logger, instance, state: State::Instantiated };
                Box::into_raw(Box::new(inst)) as *mut c_void
            }
            Err(msg) => {
                let config = Configuration::parse(r#"{"model": {}}"#).expect("an empty configuration parses");
                let inst = Instance3 {
                    name,
                    environment,
                    logger,
                    instance: Instance::new(config),
                    state: State::Instantiated,
                };
                inst.log(ERROR, &msg);
                std::ptr::null_mut()
            }
        }
    }));
    result.unwrap_or(std::ptr::null_mut())
}

// ---------------------------------------------------------------------------------------------
// Common functions

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    c: *mut c_void,
    _on: bool,
    _n: usize,
    _categories: *const *const c_char,
) -> Status {
    unsafe { with(c, |_| Ok(())) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    environment: *mut c_void,
    logger: Option<LogMessage>,
) -> *mut c_void {
    unsafe { instantiate(name, token, resource_path, environment, logger, true, None) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    event_mode_used: bool,
    _early_return_allowed: bool,
    _required_intermediate: *const u32,
    n_required_intermediate: usize,
    environment: *mut c_void,
    logger: Option<LogMessage>,
    _intermediate_update: *mut c_void,
) -> *mut c_void {
    let refuse = if event_mode_used {
        Some("eventModeUsed: this FMU has no Co-Simulation event mode (hasEventMode=\"false\")".to_string())
    } else if n_required_intermediate > 0 {
        Some("requiredIntermediateVariables: this FMU provides no intermediate update".to_string())
    } else {
        None
    };
    unsafe { instantiate(name, token, resource_path, environment, logger, false, refuse) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    environment: *mut c_void,
    logger: Option<LogMessage>,
    _clock_update: *mut c_void,
    _lock: *mut c_void,
    _unlock: *mut c_void,
) -> *mut c_void {
    let refuse = Some("Scheduled Execution is not supported by this FMU".to_string());
    unsafe { instantiate(name, token, resource_path, environment, logger, false, refuse) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(c as *mut Instance3) })));
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    c: *mut c_void,
    tolerance_defined: bool,
    tolerance: f64,
    start: f64,
    _stop_defined: bool,
    _stop: f64,
) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3EnterInitializationMode", &[State::Instantiated])?;
            if !start.is_finite() {
                return Err(format!("startTime = {start}: expected a finite time"));
            }
            if tolerance_defined && tolerance.is_finite() && tolerance > 0.0 {
                inst.instance.options.rtol = tolerance.min(1e-4);
            }
            inst.instance.start_time = start;
            inst.instance.enter_initialization()?;
            inst.state = State::Initialization;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(c: *mut c_void) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3ExitInitializationMode", &[State::Initialization])?;
            inst.instance.exit_initialization()?;
            inst.state = if inst.instance.model_exchange { State::Event } else { State::Step };
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterEventMode(c: *mut c_void) -> Status {
    unsafe {
        with(c, |inst| {
            if !inst.instance.model_exchange {
                return Err("fmi3EnterEventMode: this FMU has no Co-Simulation event mode".into());
            }
            inst.expect("fmi3EnterEventMode", &[State::ContinuousTime, State::Event])?;
            inst.state = State::Event;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(c: *mut c_void) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3Terminate", &[State::Event, State::ContinuousTime, State::Step])?;
            inst.instance.terminate()?;
            inst.state = State::Terminated;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(c: *mut c_void) -> Status {
    unsafe {
        with(c, |inst| {
            let model_exchange = inst.instance.model_exchange;
            inst.instance.reset();
            inst.instance.model_exchange = model_exchange;
            inst.state = State::Instantiated;
            Ok(())
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Variables: Float64 only

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    c: *mut c_void,
    vr: *const u32,
    n_vr: usize,
    values: *mut f64,
    n_values: usize,
) -> Status {
    unsafe {
        with(c, |inst| {
            if n_values != n_vr {
                return Err(format!("{n_values} values for {n_vr} value references: every variable is a scalar"));
            }
            let (vr, values) = (slice(vr, n_vr)?, slice_mut(values, n_values)?);
            for (r, v) in vr.iter().zip(values.iter_mut()) {
                *v = inst.get(*r)?;
            }
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    c: *mut c_void,
    vr: *const u32,
    n_vr: usize,
    values: *const f64,
    n_values: usize,
) -> Status {
    unsafe {
        with(c, |inst| {
            if inst.state == State::Terminated {
                return Err("fmi3SetFloat64 after fmi3Terminate".into());
            }
            if n_values != n_vr {
                return Err(format!("{n_values} values for {n_vr} value references: every variable is a scalar"));
            }
            let (vr, values) = (slice(vr, n_vr)?, slice(values, n_values)?);
            if let Some(r) = vr.iter().find(|&&r| r == TIME || event_indicator(r).is_some() || is_derivative(r)) {
                return Err(format!("value reference {r} is calculated and cannot be set"));
            }
            // all or nothing, as fmi2SetReal
            inst.instance.set_all(vr, values)
        })
    }
}

/// Variables of any type but Float64: the FMU has none.
unsafe fn none_of_type(c: *mut c_void, n: usize, what: &str) -> Status {
    unsafe { with(c, |_| if n == 0 { Ok(()) } else { Err(format!("{what}: this FMU has only Float64 variables")) }) }
}

macro_rules! no_variables_of_type {
    ($($get:ident, $set:ident, $t:ty;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $get(c: *mut c_void, _vr: *const u32, n: usize, _v: *mut $t, _nv: usize) -> Status {
            unsafe { none_of_type(c, n, stringify!($get)) }
        }
        #[no_mangle]
        pub unsafe extern "C" fn $set(c: *mut c_void, _vr: *const u32, n: usize, _v: *const $t, _nv: usize) -> Status {
            unsafe { none_of_type(c, n, stringify!($set)) }
        }
    )*};
}

no_variables_of_type! {
    fmi3GetFloat32, fmi3SetFloat32, f32;
    fmi3GetInt8, fmi3SetInt8, i8;
    fmi3GetUInt8, fmi3SetUInt8, u8;
    fmi3GetInt16, fmi3SetInt16, i16;
    fmi3GetUInt16, fmi3SetUInt16, u16;
    fmi3GetInt32, fmi3SetInt32, i32;
    fmi3GetUInt32, fmi3SetUInt32, u32;
    fmi3GetInt64, fmi3SetInt64, i64;
    fmi3GetUInt64, fmi3SetUInt64, u64;
    fmi3GetBoolean, fmi3SetBoolean, bool;
    fmi3GetString, fmi3SetString, *const c_char;
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBinary(
    c: *mut c_void,
    _vr: *const u32,
    n: usize,
    _sizes: *mut usize,
    _v: *mut *const u8,
    _nv: usize,
) -> Status {
    unsafe { none_of_type(c, n, "fmi3GetBinary") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBinary(
    c: *mut c_void,
    _vr: *const u32,
    n: usize,
    _sizes: *const usize,
    _v: *const *const u8,
    _nv: usize,
) -> Status {
    unsafe { none_of_type(c, n, "fmi3SetBinary") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetClock(c: *mut c_void, _vr: *const u32, n: usize, _v: *mut bool) -> Status {
    unsafe { none_of_type(c, n, "fmi3GetClock") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetClock(c: *mut c_void, _vr: *const u32, n: usize, _v: *const bool) -> Status {
    unsafe { none_of_type(c, n, "fmi3SetClock") }
}

// ---------------------------------------------------------------------------------------------
// What the FMU does not support

/// Capabilities the FMU declares it does not have.
unsafe fn unsupported(c: *mut c_void, what: &str) -> Status {
    unsafe { with(c, |_| Err(format!("{what} is not supported by this FMU"))) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(c: *mut c_void, _vr: u32, _n: *mut usize) -> Status {
    unsafe { unsupported(c, "fmi3GetNumberOfVariableDependencies (see <ModelStructure>)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    c: *mut c_void,
    _dependent: u32,
    _element_indices: *mut usize,
    _independents: *mut u32,
    _independent_indices: *mut usize,
    _kinds: *mut i32,
    _n: usize,
) -> Status {
    unsafe { unsupported(c, "fmi3GetVariableDependencies (see <ModelStructure>)") }
}

// ---------------------------------------------------------------------------------------------
// FMU state: the FMI 2.0 snapshot of the instance (`snapshot.rs`) and the FMI 3.0 state

/// An FMU state of FMI 3.0: the instance's snapshot and the state-machine state.
struct State3 {
    snapshot: Snapshot,
    state: State,
}

/// Store a new FMU state in `*s`, or overwrite the one there.
unsafe fn store(s: *mut *mut c_void, saved: State3) -> Result<(), String> {
    if s.is_null() {
        return Err("null fmi3FMUState pointer".into());
    }
    let existing = unsafe { *s } as *mut State3;
    if existing.is_null() {
        unsafe { *s = Box::into_raw(Box::new(saved)) as *mut c_void };
    } else {
        let existing = unsafe { &mut *existing };
        existing.snapshot.check_live()?;
        *existing = saved;
    }
    Ok(())
}

/// The FMU state behind `s`.
unsafe fn stored<'a>(s: *mut c_void) -> Result<&'a State3, String> {
    if s.is_null() {
        return Err("null fmi3FMUState".into());
    }
    let saved = unsafe { &*(s as *const State3) };
    saved.snapshot.check_live()?;
    Ok(saved)
}

/// The state-machine state of a restored instance phase (serialised states keep the phase only:
/// Model Exchange resumes in Event Mode, Co-Simulation in Step Mode).
fn state_of(phase: Phase, model_exchange: bool) -> State {
    match phase {
        Phase::Instantiated => State::Instantiated,
        Phase::Initialization => State::Initialization,
        Phase::Running if model_exchange => State::Event,
        Phase::Running => State::Step,
        Phase::Terminated => State::Terminated,
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(c: *mut c_void, s: *mut *mut c_void) -> Status {
    unsafe { with(c, |inst| store(s, State3 { snapshot: inst.instance.snapshot(), state: inst.state })) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(c: *mut c_void, s: *mut c_void) -> Status {
    unsafe {
        with(c, |inst| {
            let saved = stored(s)?;
            inst.instance.restore(&saved.snapshot)?;
            inst.state = saved.state;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(c: *mut c_void, s: *mut *mut c_void) -> Status {
    unsafe {
        with(c, |_| {
            if s.is_null() || (*s).is_null() {
                return Ok(());
            }
            stored(*s)?;
            let mut saved = Box::from_raw(*s as *mut State3);
            saved.snapshot.kill();
            drop(saved);
            *s = std::ptr::null_mut();
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(c: *mut c_void, s: *mut c_void, n: *mut usize) -> Status {
    unsafe {
        with(c, |_| {
            let size = stored(s)?.snapshot.to_bytes().len();
            if n.is_null() {
                return Err("null size pointer".into());
            }
            *n = size;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(c: *mut c_void, s: *mut c_void, b: *mut u8, n: usize) -> Status {
    unsafe {
        with(c, |_| {
            let bytes = stored(s)?.snapshot.to_bytes();
            if n < bytes.len() {
                return Err(format!("serialised FMU state of {} bytes: the buffer has {n}", bytes.len()));
            }
            slice_mut(b, bytes.len())?.copy_from_slice(&bytes);
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    c: *mut c_void,
    b: *const u8,
    n: usize,
    s: *mut *mut c_void,
) -> Status {
    unsafe {
        with(c, |inst| {
            let snapshot = Snapshot::from_bytes(slice(b, n)?, &inst.instance)?;
            let state = state_of(snapshot.phase(), inst.instance.model_exchange);
            store(s, State3 { snapshot, state })
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    c: *mut c_void,
    _unknowns: *const u32,
    _n_unknowns: usize,
    _knowns: *const u32,
    _n_knowns: usize,
    _seed: *const f64,
    _n_seed: usize,
    _sensitivity: *mut f64,
    _n_sensitivity: usize,
) -> Status {
    unsafe { unsupported(c, "fmi3GetDirectionalDerivative") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    c: *mut c_void,
    _unknowns: *const u32,
    _n_unknowns: usize,
    _knowns: *const u32,
    _n_knowns: usize,
    _seed: *const f64,
    _n_seed: usize,
    _sensitivity: *mut f64,
    _n_sensitivity: usize,
) -> Status {
    unsafe { unsupported(c, "fmi3GetAdjointDerivative") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterConfigurationMode(c: *mut c_void) -> Status {
    unsafe { unsupported(c, "fmi3EnterConfigurationMode (the FMU has no structural parameters)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitConfigurationMode(c: *mut c_void) -> Status {
    unsafe { unsupported(c, "fmi3ExitConfigurationMode (the FMU has no structural parameters)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalDecimal(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _intervals: *mut f64,
    _qualifiers: *mut i32,
) -> Status {
    unsafe { unsupported(c, "fmi3GetIntervalDecimal (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalFraction(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _counters: *mut u64,
    _resolutions: *mut u64,
    _qualifiers: *mut i32,
) -> Status {
    unsafe { unsupported(c, "fmi3GetIntervalFraction (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftDecimal(c: *mut c_void, _vr: *const u32, _n: usize, _shifts: *mut f64) -> Status {
    unsafe { unsupported(c, "fmi3GetShiftDecimal (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftFraction(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _counters: *mut u64,
    _resolutions: *mut u64,
) -> Status {
    unsafe { unsupported(c, "fmi3GetShiftFraction (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalDecimal(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _intervals: *const f64,
) -> Status {
    unsafe { unsupported(c, "fmi3SetIntervalDecimal (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalFraction(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _counters: *const u64,
    _resolutions: *const u64,
) -> Status {
    unsafe { unsupported(c, "fmi3SetIntervalFraction (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftDecimal(c: *mut c_void, _vr: *const u32, _n: usize, _s: *const f64) -> Status {
    unsafe { unsupported(c, "fmi3SetShiftDecimal (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftFraction(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _counters: *const u64,
    _resolutions: *const u64,
) -> Status {
    unsafe { unsupported(c, "fmi3SetShiftFraction (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(c: *mut c_void) -> Status {
    unsafe { unsupported(c, "fmi3EvaluateDiscreteStates (the FMU has no clocks)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ActivateModelPartition(c: *mut c_void, _clock: u32, _t: f64) -> Status {
    unsafe { unsupported(c, "fmi3ActivateModelPartition (Scheduled Execution)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _orders: *const i32,
    _values: *mut f64,
    _nv: usize,
) -> Status {
    unsafe { unsupported(c, "fmi3GetOutputDerivatives (maxOutputDerivativeOrder=\"0\")") }
}

// ---------------------------------------------------------------------------------------------
// Model Exchange

/// Write `value` to an optional output argument.
unsafe fn put<T>(p: *mut T, value: T) {
    if !p.is_null() {
        unsafe { *p = value };
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    c: *mut c_void,
    update_needed: *mut bool,
    terminate: *mut bool,
    nominals_changed: *mut bool,
    values_changed: *mut bool,
    next_time_defined: *mut bool,
    next_time: *mut f64,
) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3UpdateDiscreteStates", &[State::Event])?;
            let changed = inst.instance.me_new_discrete_states()?;
            put(update_needed, false);
            put(terminate, false);
            put(nominals_changed, false);
            put(values_changed, changed);
            put(next_time_defined, false);
            put(next_time, 0.0);
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(c: *mut c_void) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3EnterContinuousTimeMode", &[State::Event])?;
            inst.state = State::ContinuousTime;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
    c: *mut c_void,
    _no_prior: bool,
    enter_event_mode: *mut bool,
    terminate: *mut bool,
) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3CompletedIntegratorStep", &[State::ContinuousTime])?;
            put(enter_event_mode, false);
            put(terminate, false);
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetTime(c: *mut c_void, t: f64) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3SetTime", &[State::Event, State::ContinuousTime])?;
            if !t.is_finite() {
                return Err(format!("fmi3SetTime({t}): expected a finite time"));
            }
            inst.instance.me_set_time(t)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetContinuousStates(c: *mut c_void, x: *const f64, n: usize) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3SetContinuousStates", &[State::Event, State::ContinuousTime])?;
            inst.instance.me_set_states(slice(x, n)?)
        })
    }
}

/// Check the host's array size against the model's.
fn sized(n: usize, expected: usize, what: &str) -> Result<(), String> {
    if n == expected {
        Ok(())
    } else {
        Err(format!("{n} {what} asked for, the model has {expected}"))
    }
}

/// The states in which the Model Exchange getters answer.
const ME_GET: [State; 4] = [State::Initialization, State::Event, State::ContinuousTime, State::Terminated];

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(c: *mut c_void, dx: *mut f64, n: usize) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3GetContinuousStateDerivatives", &ME_GET)?;
            sized(n, inst.sizes().0, "derivatives")?;
            inst.me_current()?;
            inst.instance.me_derivatives(slice_mut(dx, n)?)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetEventIndicators(c: *mut c_void, g: *mut f64, n: usize) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3GetEventIndicators", &ME_GET)?;
            sized(n, inst.sizes().1, "event indicators")?;
            inst.me_current()?;
            inst.instance.me_indicators(slice_mut(g, n)?)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStates(c: *mut c_void, x: *mut f64, n: usize) -> Status {
    unsafe {
        with(c, |inst| {
            inst.expect("fmi3GetContinuousStates", &ME_GET)?;
            sized(n, inst.sizes().0, "continuous states")?;
            inst.me_current()?;
            inst.instance.me_get_states(slice_mut(x, n)?)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(c: *mut c_void, x: *mut f64, n: usize) -> Status {
    unsafe {
        with(c, |inst| {
            sized(n, inst.sizes().0, "continuous states")?;
            inst.instance.me_nominals(slice_mut(x, n)?)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(c: *mut c_void, n: *mut usize) -> Status {
    unsafe {
        with(c, |inst| {
            if n.is_null() {
                return Err("null nEventIndicators".into());
            }
            *n = inst.sizes().1;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(c: *mut c_void, n: *mut usize) -> Status {
    unsafe {
        with(c, |inst| {
            if n.is_null() {
                return Err("null nContinuousStates".into());
            }
            *n = inst.sizes().0;
            Ok(())
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Co-Simulation

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(c: *mut c_void) -> Status {
    unsafe { unsupported(c, "fmi3EnterStepMode (the FMU has no Co-Simulation event mode)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    c: *mut c_void,
    t: f64,
    h: f64,
    _no_prior: bool,
    event_handling_needed: *mut bool,
    terminate: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> Status {
    unsafe {
        put(event_handling_needed, false);
        put(terminate, false);
        put(early_return, false);
        with(c, |inst| {
            let result = inst.expect("fmi3DoStep", &[State::Step]).and_then(|()| {
                if !(h > 0.0 && h.is_finite() && t.is_finite()) {
                    return Err(format!("fmi3DoStep(t = {t}, h = {h}): expected a finite t and h > 0"));
                }
                inst.instance.do_step(t, h)
            });
            put(last_successful_time, inst.instance.time_now());
            result
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variables::{self, COORDINATES, FIRST_EVENT_INDICATOR, FIRST_PARAMETER, START_PARAMETERS};
    use tcsim_core::engine::mode_view::EVENT_INDICATORS;

    /// The value references FMI 3.0 adds are free in the FMI 2.0 table.
    #[test]
    fn the_fmi3_value_references_are_their_own() {
        let taken = |vr: u32| {
            (vr as usize) < SIGNAL_SLOTS
                || variables::start_parameter(vr).is_some()
                || (FIRST_DERIVATIVE..FIRST_DERIVATIVE + COORDINATES).contains(&vr)
                || vr >= FIRST_PARAMETER
        };
        assert!(!taken(TIME));
        for i in 0..EVENT_INDICATORS as u32 {
            assert!(!taken(FIRST_EVENT_INDICATOR + i) && FIRST_EVENT_INDICATOR + i != TIME);
            assert_eq!(event_indicator(FIRST_EVENT_INDICATOR + i), Some(i as usize));
        }
        assert!(START_PARAMETERS.iter().all(|s| s.vr != TIME));
        assert_eq!(event_indicator(FIRST_EVENT_INDICATOR + EVENT_INDICATORS as u32), None);
    }

    #[test]
    fn a_wrong_or_missing_token_is_refused() {
        let dir = std::env::temp_dir().join(format!("tcsim-fmi3-token-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let model = r#""model": {"kind": "table", "inertia_kg_m2": [0.109, 0.056, 0.01],
            "speed_ratio": [0.0, 1.0], "torque_ratio": [2.0, 1.0], "capacity_factor_nm_s2": [0.003, 0.0002]}"#;
        std::fs::write(dir.join("model.json"), format!(r#"{{"instantiationToken": "{{abc}}", {model}}}"#)).unwrap();
        let path = dir.to_str().unwrap();
        assert!(load(Some(path), Some("{abc}"), true).is_ok());
        assert!(load(Some(path), Some("{abd}"), true).err().unwrap().contains("{abc}"));
        assert!(load(Some(path), None, true).is_err());
        std::fs::write(dir.join("model.json"), format!("{{{model}}}")).unwrap();
        assert!(load(Some(path), Some("{abc}"), true).err().unwrap().contains("--fmi-version 3"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
